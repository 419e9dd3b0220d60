//! The interactive 3D view of `report.html`: the design part, each operation's tool path, the
//! tool (cutter, shank, holder) at any move, and the machined stock coloured by its signed
//! deviation from the design, with the defects marked.
//!
//! **Data.** Everything the view draws is written once into the page as one JSON document
//! (`<script type="application/json" id="view3d-data">`) whose bulk arrays are base64 of
//! little-endian typed arrays:
//! - positions (part and stock vertices, tool tips, shroud outline) are quantised on one grid
//!   over the scene's bounding box: `p = origin + q·step`, `q` a `u16` per coordinate, so
//!   `step = extent / 65535` and a decoded position is within `step / 2` of the written one
//!   per coordinate (0.002 mm on a 130 mm scene);
//! - tool axes are `i16` per coordinate, `a = q / 32767` (within 1.5·10⁻⁵ per coordinate);
//! - the stock's deviation is an `i16` per vertex in micrometres (clamped to ±32.767 mm;
//!   −32768 = not measured);
//! - move kinds are one byte per move (0 rapid, 1 plunge, 2 feed, 3 retract).
//!
//! **Stock deviation.** Each vertex of the machined stock's surface (surface nets on the
//! verifier's tri-dexel stock, [`machining_sim::extract_surface`], at a lattice of at least
//! [`STOCK_SPACING_MM`]) takes the signed deviation of the verification maps' samples
//! (`verification_maps.json`) nearest it: residual thickness (+) or overcut depth (−)
//! measured along the design surface's normal there; of the samples within one lattice
//! spacing of the nearest distance, the worst (an overcut beyond `machining_tol` before
//! anything else, otherwise the larger magnitude), so that in a corner (blade root) the worse
//! of the two surfaces shows. Vertices
//! farther than
//! [`STOCK_NEAR_MM`] from every sample (blank material away from the design surfaces) are not
//! measured and drawn neutral. The nearest sample is found in a uniform hash grid of cell
//! [`STOCK_NEAR_MM`] (3×3×3 neighbouring cells), O(V + S) on average for V vertices and S
//! samples.
//!
//! **Defect markers.** The largest overcut, the largest residual and each collision are
//! marked at the verifier's point. The move each marker leads to is the move whose tool
//! surface passes nearest that point (the revolved profile of the cutter, or of the whole
//! tool for a collision: distance `|ρ − R(h)|` with `h` the height along the axis and `ρ` the
//! distance from it), O(moves) per marker: the verifier does not record which move removed a
//! dexel, so this is where the tool was when it could have.
//!
//! **Renderer.** three.js r170 (MIT, `assets/three/`, see the crate README for how to update
//! it) is embedded in the page as text and imported from a blob URL, so the report opens
//! from disk with no network. The viewer's own script is `assets/view3d.js`.

use cam_core::{Cutter, MoveKind};
use impeller_model::Impeller;
use serde_json::{json, Value};
use std::fmt::Write as _;

/// The vendored three.js module build (r170).
const THREE_JS: &str = include_str!("../assets/three/three.module.min.js");
/// three.js' OrbitControls (r170), which imports from `three`.
const ORBIT_CONTROLS_JS: &str = include_str!("../assets/three/OrbitControls.js");
/// The viewer.
const VIEW_JS: &str = include_str!("../assets/view3d.js");

/// Smallest lattice spacing of the stock mesh in the view (mm): coarser than the verifier's
/// dexels at fine resolutions, so the default job's report stays small.
pub const STOCK_SPACING_MM: f64 = 0.5;
/// Largest number of stock triangles written; the lattice is coarsened (×2) until it fits.
pub const MAX_STOCK_TRIANGLES: usize = 1_500_000;
/// A stock vertex farther than this from every verification sample is not measured (mm).
pub const STOCK_NEAR_MM: f64 = 2.0;
/// Chord tolerance of the design part's triangles in the view (mm).
pub const PART_CHORD_TOL_MM: f64 = 0.05;

/// Operation colours (cutting moves), one per operation in program order; the same order
/// as the 2D plots' series colours.
pub const OP_COLOURS: [&str; 8] = [
    "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2", "#bcbd22",
];

/// A defect marked in the view.
#[derive(Debug, Clone)]
pub struct Marker {
    /// `overcut`, `residual` or `collision`.
    pub kind: String,
    /// What the list shows.
    pub label: String,
    /// Where (mm, workpiece frame).
    pub point: [f64; 3],
    /// Operation whose moves are searched for the nearest one (`None`: all operations).
    pub operation: Option<String>,
    /// Measure the whole tool (shank, holder), not the cutter only.
    pub whole_tool: bool,
}

#[derive(Debug, Clone)]
struct OpView {
    name: String,
    kind: String,
    tool: String,
    tips: Vec<[f64; 3]>,
    axes: Vec<[f64; 3]>,
    kinds: Vec<u8>,
    cutter: Option<Cutter>,
}

#[derive(Debug, Clone)]
struct StockView {
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    deviation: Vec<Option<f64>>,
    overcut_limit_mm: f64,
    machining_tol_mm: f64,
    resolution_mm: f64,
    spacing_mm: f64,
}

/// Everything the 3D view draws, gathered over the run.
#[derive(Debug, Clone, Default)]
pub struct Scene {
    part_vertices: Vec<[f64; 3]>,
    part_triangles: Vec<[u32; 3]>,
    shroud_lines: Vec<[f64; 3]>,
    operations: Vec<OpView>,
    stock: Option<StockView>,
    markers: Vec<Marker>,
    notes: Vec<String>,
}

impl Scene {
    /// The design part (hub and blades within [`PART_CHORD_TOL_MM`]) and the shroud contour's
    /// outline (its meridional curve at every main blade's angle, and circles at its ends).
    pub fn set_part(&mut self, imp: &Impeller) {
        use impeller_model::export::{mesh_parts, Part};
        match mesh_parts(imp, &[Part::Impeller], PART_CHORD_TOL_MM) {
            Ok(mesh) => {
                self.part_vertices = mesh.vertices.iter().map(|p| [p.x, p.y, p.z]).collect();
                self.part_triangles = mesh.triangles;
            }
            Err(e) => self.notes.push(format!("3D view: no design part ({e})")),
        }
        let m = imp.shroud().meridional();
        let (t0, t1) = m.domain();
        const N: usize = 40;
        let zr: Vec<(f64, f64)> = (0..=N)
            .map(|i| {
                let p = m.point(t0 + (t1 - t0) * i as f64 / N as f64);
                (p.x, p.y)
            })
            .collect();
        let blades = imp.main().count().max(1);
        for k in 0..blades {
            let phi = std::f64::consts::TAU * k as f64 / blades as f64;
            for w in zr.windows(2) {
                for &(z, r) in w {
                    self.shroud_lines.push([r * phi.cos(), r * phi.sin(), z]);
                }
            }
        }
        for &(z, r) in [zr.first(), zr.last()].into_iter().flatten() {
            const M: usize = 96;
            for i in 0..M {
                for j in [i, i + 1] {
                    let phi = std::f64::consts::TAU * j as f64 / M as f64;
                    self.shroud_lines.push([r * phi.cos(), r * phi.sin(), z]);
                }
            }
        }
    }

    /// One operation's moves (tips, axes, kinds) and its cutter.
    pub fn add_operation(&mut self, op: &crate::pipeline::JobOperation) {
        let path = &op.cl.path;
        self.operations.push(OpView {
            name: path.name.clone(),
            kind: op.kind.clone(),
            tool: path.tool.clone(),
            tips: path
                .moves
                .iter()
                .map(|m| [m.cl.tip.x, m.cl.tip.y, m.cl.tip.z])
                .collect(),
            axes: path
                .moves
                .iter()
                .map(|m| [m.cl.axis.x, m.cl.axis.y, m.cl.axis.z])
                .collect(),
            kinds: path.moves.iter().map(|m| kind_code(m.kind)).collect(),
            cutter: op.cl.cutter.clone(),
        });
    }

    /// The machined stock's surface with each vertex's deviation from the nearest
    /// verification sample (see the module docs), and the thresholds in force.
    pub fn set_stock(
        &mut self,
        stock: &machining_sim::TriDexel,
        maps: &[machining_sim::SurfaceMap],
        machining_tol_mm: f64,
        overcut_limit_mm: f64,
    ) {
        let h = stock.cell();
        let mut stride = (STOCK_SPACING_MM / h).round().max(1.0) as usize;
        let mut mesh = machining_sim::extract_surface(stock, stride);
        while mesh.triangles.len() > MAX_STOCK_TRIANGLES && stride < 64 {
            stride *= 2;
            mesh = machining_sim::extract_surface(stock, stride);
        }
        let spacing_mm = stride as f64 * h;
        let deviation = nearest_deviation(
            &mesh.vertices,
            maps,
            STOCK_NEAR_MM,
            spacing_mm,
            machining_tol_mm,
        );
        self.stock = Some(StockView {
            vertices: mesh.vertices,
            triangles: mesh.triangles,
            deviation,
            overcut_limit_mm,
            machining_tol_mm,
            resolution_mm: h,
            spacing_mm,
        });
    }

    /// Marks a defect.
    pub fn add_marker(&mut self, marker: Marker) {
        self.markers.push(marker);
    }

    /// Whether there is anything to draw.
    pub fn is_empty(&self) -> bool {
        self.part_triangles.is_empty() && self.operations.is_empty() && self.stock.is_none()
    }

    /// The view's JSON document (see the module docs for the encoding).
    pub fn data(&self) -> Value {
        let mut all = self
            .part_vertices
            .iter()
            .chain(&self.shroud_lines)
            .chain(self.operations.iter().flat_map(|o| o.tips.iter()))
            .chain(self.stock.iter().flat_map(|s| s.vertices.iter()))
            .chain(self.markers.iter().map(|m| &m.point))
            .filter(|p| p.iter().all(|c| c.is_finite()));
        let Some(first) = all.next() else {
            return json!({ "version": 1, "empty": true });
        };
        let (mut lo, mut hi) = (*first, *first);
        for p in all {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let extent = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
        let step = if extent > 0.0 { extent / 65535.0 } else { 1.0 };
        let grid = Grid { origin: lo, step };
        let mut first_move = 0usize;
        let mut operations = Vec::new();
        for (k, o) in self.operations.iter().enumerate() {
            let axes: Vec<u8> = o
                .axes
                .iter()
                .flat_map(|a| a.iter().flat_map(|&c| quantise_unit(c).to_le_bytes()))
                .collect();
            let profile = o.cutter.as_ref().map(tool_profile);
            operations.push(json!({
                "name": o.name,
                "kind": o.kind,
                "tool": o.tool,
                "colour": OP_COLOURS[k % OP_COLOURS.len()],
                "first_move": first_move,
                "moves": o.tips.len(),
                "tips": base64(&grid.bytes(&o.tips)),
                "axes": base64(&axes),
                "kinds": base64(&o.kinds),
                "profile": profile,
            }));
            first_move += o.tips.len();
        }
        let stock = self.stock.as_ref().map(|s| {
            let dev: Vec<u8> = s
                .deviation
                .iter()
                .flat_map(|d| quantise_deviation(*d).to_le_bytes())
                .collect();
            let residual_max = s.deviation.iter().flatten().fold(0.0f64, |a, &b| a.max(b));
            json!({
                "positions": base64(&grid.bytes(&s.vertices)),
                "indices": base64(&indices(&s.triangles)),
                "deviation_um": base64(&dev),
                "vertices": s.vertices.len(),
                "triangles": s.triangles.len(),
                "overcut_limit_mm": s.overcut_limit_mm,
                "machining_tol_mm": s.machining_tol_mm,
                "residual_max_mm": residual_max,
                "resolution_mm": s.resolution_mm,
                "spacing_mm": s.spacing_mm,
            })
        });
        let markers: Vec<Value> = self
            .markers
            .iter()
            .map(|m| {
                let near = self.nearest_move(m);
                json!({
                    "kind": m.kind,
                    "label": m.label,
                    "point": m.point,
                    "move": near.map(|(i, _)| i),
                    "distance_mm": near.map(|(_, d)| d),
                })
            })
            .collect();
        json!({
            "version": 1,
            "origin": grid.origin,
            "step": grid.step,
            "moves": first_move,
            "part": {
                "positions": base64(&grid.bytes(&self.part_vertices)),
                "indices": base64(&indices(&self.part_triangles)),
                "triangles": self.part_triangles.len(),
                "chord_tol_mm": PART_CHORD_TOL_MM,
            },
            "shroud": base64(&grid.bytes(&self.shroud_lines)),
            "operations": operations,
            "stock": stock,
            "markers": markers,
            "notes": self.notes,
        })
    }

    /// The global index of the move (over the operations in program order) whose tool
    /// surface passes nearest the marker's point, with that distance (mm).
    fn nearest_move(&self, m: &Marker) -> Option<(usize, f64)> {
        let mut best: Option<(usize, f64)> = None;
        let mut first = 0usize;
        for o in &self.operations {
            let wanted = m.operation.as_ref().is_none_or(|n| *n == o.name);
            if let (true, Some(c)) = (wanted, &o.cutter) {
                let profile = revolved_profile(c, m.whole_tool);
                for (i, (tip, axis)) in o.tips.iter().zip(&o.axes).enumerate() {
                    if m.kind != "collision" && o.kinds[i] == 0 {
                        continue;
                    }
                    let d = distance_to_revolved(&profile, tip, axis, &m.point);
                    if best.is_none_or(|(_, b)| d < b) {
                        best = Some((first + i, d));
                    }
                }
            }
            first += o.tips.len();
        }
        best
    }

    /// The `<section>` of the report: the viewer's markup, the data, three.js and the viewer
    /// script.
    pub fn html(&self) -> String {
        let mut h = String::new();
        if self.is_empty() {
            return h;
        }
        h.push_str(
            "<h2 id=\"view3d-title\">3D view</h2>\
             <p class=\"hint\">Drag to turn, wheel to zoom, right-drag to pan. The slider moves \
             the tool through the program; click a defect (list or marker) to go to the move \
             nearest it. <a href=\"#view3d\">Full window</a></p>\
             <div id=\"view3d\" data-drawn=\"0\" data-errors=\"\">\
             <div id=\"view3d-canvas\"></div>\
             <div id=\"view3d-panel\"></div>\
             <div id=\"view3d-bar\"><button id=\"view3d-play\">play</button>\
             <input id=\"view3d-slider\" type=\"range\" min=\"0\" max=\"0\" value=\"0\">\
             <span id=\"view3d-move\"></span></div>\
             </div>",
        );
        let data = self.data().to_string();
        let _ = write!(
            h,
            "<script type=\"application/json\" id=\"view3d-data\">{}</script>",
            data.replace('<', "\\u003c")
        );
        let _ = write!(
            h,
            "<script type=\"text/plain\" id=\"three-module\">{}</script>\
             <script type=\"text/plain\" id=\"three-orbit\">{}</script>\
             <script>{}</script>",
            script_safe(THREE_JS),
            script_safe(ORBIT_CONTROLS_JS),
            script_safe(VIEW_JS)
        );
        h
    }
}

/// CSS of the view (added to the report's style sheet).
pub const CSS: &str = "#view3d{position:relative;width:100%;height:640px;border:1px solid #ccc;\
background:#f7f7f7}#view3d-canvas{position:absolute;inset:0 0 36px 0}\
#view3d-panel{position:absolute;top:6px;right:6px;max-width:300px;max-height:560px;overflow:auto;\
background:rgba(255,255,255,.9);font-size:12px;padding:6px;border:1px solid #ddd}\
#view3d-panel label{display:block}#view3d-panel li{cursor:pointer;color:#0645ad}\
#view3d-bar{position:absolute;left:0;right:0;bottom:0;height:36px;display:flex;gap:8px;\
align-items:center;padding:0 8px;font-size:12px}#view3d-slider{flex:1}\
body.view3d-only>*:not(#view3d){display:none}\
body.view3d-only{margin:0;max-width:none}body.view3d-only #view3d{height:100vh;border:0}\
.hint{font-size:12px;color:#555}";

/// The verification's part of the view: the machined stock coloured by deviation (with the
/// job's `machining_tol` and the overcut limit in force), and markers at the largest
/// overcut, the largest residual and each collision (at most [`MAX_COLLISION_MARKERS`]).
pub fn add_verification(
    scene: &mut Scene,
    stock: &machining_sim::TriDexel,
    rep: &machining_sim::Report,
    job: &crate::job::Job,
    overcut_limit_mm: f64,
) {
    scene.set_stock(
        stock,
        &rep.maps,
        job.tolerances.machining_tol,
        overcut_limit_mm,
    );
    if let Some(e) = &rep.max_overcut {
        scene.add_marker(Marker {
            kind: "overcut".into(),
            label: format!("largest overcut {:.4} mm on {}", e.value_mm, e.surface),
            point: e.point,
            operation: None,
            whole_tool: false,
        });
    }
    if let Some(e) = &rep.max_residual {
        scene.add_marker(Marker {
            kind: "residual".into(),
            label: format!(
                "largest residual {:.4} mm{} on {}",
                e.value_mm,
                if e.capped {
                    " (probe depth, at least)"
                } else {
                    ""
                },
                e.surface
            ),
            point: e.point,
            operation: None,
            whole_tool: false,
        });
    }
    for c in rep.collisions.iter().take(MAX_COLLISION_MARKERS) {
        scene.add_marker(Marker {
            kind: "collision".into(),
            label: format!("collision: {}", crate::verdict::collision_text(c)),
            point: c.point,
            operation: Some(c.operation.clone()),
            whole_tool: true,
        });
    }
}

/// Collisions marked in the view (the report lists them all).
pub const MAX_COLLISION_MARKERS: usize = 50;

fn kind_code(k: MoveKind) -> u8 {
    match k {
        MoveKind::Rapid => 0,
        MoveKind::Plunge => 1,
        // A link at feed is drawn with the cut it joins (the view colours by rate).
        MoveKind::Feed | MoveKind::Link => 2,
        MoveKind::Retract => 3,
    }
}

/// The quantisation grid of positions.
struct Grid {
    origin: [f64; 3],
    step: f64,
}

impl Grid {
    fn bytes(&self, points: &[[f64; 3]]) -> Vec<u8> {
        let mut out = Vec::with_capacity(points.len() * 6);
        for p in points {
            for (c, o) in p.iter().zip(&self.origin) {
                let q = ((c - o) / self.step).round();
                let q = if q.is_finite() {
                    q.clamp(0.0, 65535.0)
                } else {
                    0.0
                };
                out.extend_from_slice(&(q as u16).to_le_bytes());
            }
        }
        out
    }
}

fn quantise_unit(c: f64) -> i16 {
    (c.clamp(-1.0, 1.0) * 32767.0).round() as i16
}

fn quantise_deviation(d: Option<f64>) -> i16 {
    match d {
        Some(v) if v.is_finite() => (v * 1000.0).round().clamp(-32767.0, 32767.0) as i16,
        _ => i16::MIN,
    }
}

fn indices(triangles: &[[u32; 3]]) -> Vec<u8> {
    triangles
        .iter()
        .flat_map(|t| t.iter().flat_map(|i| i.to_le_bytes()))
        .collect()
}

/// The signed deviation of one verification sample: −overcut where the design was cut into,
/// otherwise +residual (mm); `None` when neither was measured.
pub fn sample_deviation(overcut: Option<f64>, residual: Option<f64>) -> Option<f64> {
    match (overcut, residual) {
        (Some(o), _) if o > 0.0 => Some(-o),
        (_, Some(r)) => Some(r),
        (Some(o), None) => Some(-o),
        (None, None) => None,
    }
}

/// The order of badness of deviations: an overcut deeper than `tol` (the job's
/// `machining_tol`) is worse than anything else, the deeper the worse; otherwise the larger
/// magnitude is worse (a 0.0003 mm overcut does not hide a 0.25 mm residual).
pub fn badness(d: f64, tol: f64) -> f64 {
    if d < -tol {
        1.0e6 - d
    } else {
        d.abs()
    }
}

/// For each vertex, the worst ([`badness`] with `tol`) deviation among the measured
/// verification samples within `band` mm of its nearest one, all within `near` mm (see the
/// module docs);
/// `None` when no sample is that near. The band (one stock lattice spacing) keeps a corner
/// (a blade root, where the blade's and the hub's samples are about as near) from hiding
/// the worse of the two.
pub fn nearest_deviation(
    vertices: &[[f64; 3]],
    maps: &[machining_sim::SurfaceMap],
    near: f64,
    band: f64,
    tol: f64,
) -> Vec<Option<f64>> {
    use rayon::prelude::*;
    use std::collections::HashMap;
    let cell = |p: &[f64; 3]| -> [i64; 3] { p.map(|c| (c / near).floor() as i64) };
    let mut grid: HashMap<[i64; 3], Vec<([f64; 3], f64)>> = HashMap::new();
    for m in maps {
        for (k, p) in m.points.iter().enumerate() {
            let o = m.overcut_mm.get(k).copied().flatten();
            let r = m.residual_mm.get(k).copied().flatten();
            if let Some(d) = sample_deviation(o, r) {
                grid.entry(cell(p)).or_default().push((*p, d));
            }
        }
    }
    vertices
        .par_iter()
        .map(|v| {
            let c = cell(v);
            let around = || {
                (-1..=1)
                    .flat_map(move |dx| {
                        (-1..=1).flat_map(move |dy| (-1..=1).map(move |dz| [dx, dy, dz]))
                    })
                    .filter_map(|d: [i64; 3]| grid.get(&[c[0] + d[0], c[1] + d[1], c[2] + d[2]]))
                    .flatten()
                    .map(|(p, d)| {
                        (
                            ((0..3).map(|k| (p[k] - v[k]).powi(2)).sum::<f64>()).sqrt(),
                            *d,
                        )
                    })
                    .filter(|(e, _)| *e <= near)
            };
            let nearest = around().map(|(e, _)| e).fold(f64::INFINITY, f64::min);
            around()
                .filter(|(e, _)| *e <= nearest + band)
                .map(|(_, d)| d)
                .max_by(|a, b| badness(*a, tol).total_cmp(&badness(*b, tol)))
        })
        .collect()
}

/// The tool's outline for drawing: `(radius, height)` points from the tip up, in three
/// parts (cutter to the flute length, shank to the holder face, holder segments).
fn tool_profile(c: &Cutter) -> Value {
    const N: usize = 24;
    let cutter: Vec<[f64; 2]> = (0..=N)
        .map(|i| {
            let h = c.flute_length * i as f64 / N as f64;
            [c.shape.radius_at(h), h]
        })
        .collect();
    let shank = vec![
        [c.shank_radius, c.flute_length],
        [c.shank_radius, c.overall_length],
    ];
    let mut holder = Vec::new();
    let mut z = c.overall_length;
    for s in &c.holder {
        holder.push([s.bottom_radius, z]);
        z += s.length;
        holder.push([s.top_radius, z]);
    }
    json!({ "cutter": cutter, "shank": shank, "holder": holder })
}

/// The tool's revolved outline as `(height, radius)` pieces, linear between points: the
/// cutter (sampled every 1/64 of the flute length), and with `whole_tool` the shank and
/// holder.
fn revolved_profile(c: &Cutter, whole_tool: bool) -> Vec<(f64, f64)> {
    const N: usize = 64;
    let mut p: Vec<(f64, f64)> = (0..=N)
        .map(|i| {
            let h = c.flute_length * i as f64 / N as f64;
            (h, c.shape.radius_at(h))
        })
        .collect();
    if whole_tool {
        p.push((c.flute_length, c.shank_radius));
        p.push((c.overall_length, c.shank_radius));
        let mut z = c.overall_length;
        for s in &c.holder {
            p.push((z, s.bottom_radius));
            z += s.length;
            p.push((z, s.top_radius));
        }
    }
    p
}

/// Distance from `q` to the surface of revolution of `profile` about the axis through `tip`
/// along `axis`, measured in the meridional half-plane of `q` as the distance to the
/// polyline `(h, r)`. O(profile).
fn distance_to_revolved(
    profile: &[(f64, f64)],
    tip: &[f64; 3],
    axis: &[f64; 3],
    q: &[f64; 3],
) -> f64 {
    let d = [q[0] - tip[0], q[1] - tip[1], q[2] - tip[2]];
    let h = d[0] * axis[0] + d[1] * axis[1] + d[2] * axis[2];
    let rho2 = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) - h * h;
    let rho = rho2.max(0.0).sqrt();
    let mut best = f64::INFINITY;
    for w in profile.windows(2) {
        let (a, b) = (w[0], w[1]);
        let (ex, ey) = (b.0 - a.0, b.1 - a.1);
        let len2 = ex * ex + ey * ey;
        let t = if len2 > 0.0 {
            (((h - a.0) * ex + (rho - a.1) * ey) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let (px, py) = (a.0 + t * ex, a.1 + t * ey);
        best = best.min((h - px).hypot(rho - py));
    }
    best
}

/// Standard base64 (RFC 4648, with padding).
pub fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let n = (u32::from(c[0]) << 16)
            | (u32::from(c.get(1).copied().unwrap_or(0)) << 8)
            | u32::from(c.get(2).copied().unwrap_or(0));
        for k in 0..4 {
            if k <= c.len() {
                s.push(A[((n >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

/// Text that cannot end the `<script>` element it is written into.
fn script_safe(s: &str) -> String {
    s.replace("</script", "<\\/script")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc4648_test_vectors() {
        for (i, o) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(i.as_bytes()), o);
        }
    }

    #[test]
    fn deviation_is_minus_overcut_or_plus_residual_and_quantised_to_a_micrometre() {
        assert_eq!(sample_deviation(Some(0.02), Some(0.0)), Some(-0.02));
        assert_eq!(sample_deviation(Some(0.0), Some(0.3)), Some(0.3));
        assert_eq!(sample_deviation(None, None), None);
        assert_eq!(quantise_deviation(Some(-0.0204)), -20);
        assert_eq!(quantise_deviation(Some(100.0)), 32767);
        assert_eq!(quantise_deviation(None), i16::MIN);
    }

    #[test]
    fn distance_to_a_ball_end_is_distance_to_its_sphere() {
        let c = Cutter {
            name: "b".into(),
            shape: cam_core::CutterShape::BallEnd { radius: 2.0 },
            flute_length: 10.0,
            shank_radius: 2.0,
            overall_length: 30.0,
            holder: vec![],
        };
        let p = revolved_profile(&c, false);
        // 1 mm below the ball's bottom: 1 mm; 0.5 mm beside the side at h = 5: 0.5 mm.
        let d = distance_to_revolved(&p, &[0.0, 0.0, 0.0], &[0.0, 0.0, 1.0], &[0.0, 0.0, -1.0]);
        assert!((d - 1.0).abs() < 1e-3, "{d}");
        let d = distance_to_revolved(&p, &[0.0, 0.0, 0.0], &[0.0, 0.0, 1.0], &[2.5, 0.0, 5.0]);
        assert!((d - 0.5).abs() < 1e-9, "{d}");
    }

    #[test]
    fn script_text_cannot_close_its_element() {
        assert_eq!(script_safe("a</script>b"), "a<\\/script>b");
    }
}
