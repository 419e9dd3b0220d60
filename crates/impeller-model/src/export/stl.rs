//! Triangulated export of impeller parts as binary STL.
//!
//! **Tessellation.** Each NURBS surface is sampled on a tensor-product grid of parameter
//! breakpoints refined until the chord check passes: an interval of u is halved while, on any
//! grid line of v, the surface point at the interval's midpoint is farther than `chord_tol`
//! from the midpoint of the chord between the interval's end points (and likewise for v);
//! each cell is then split into two triangles along a diagonal and both cells' centres are
//! checked against that diagonal's midpoint, halving both intervals of a failing cell. The
//! check is made at those sample points (edge midpoints and cell centres), the usual chord
//! criterion. Refinement stops with an error past 2¹⁶ intervals in a direction.
//! Cost O(n_u · n_v) surface evaluations per refinement pass.
//!
//! Blades are tessellated once per row and rotated to every copy. The file is a surface
//! model (a triangle soup of the chosen faces, normals from the vertex order), not a closed
//! solid: blade sides extend through hub and shroud as the model does, and the hub and the
//! sides run on behind the blade-root fillets.
//!
//! **Fillets.** Each piece of a blade-root fillet ([`crate::fillet::FilletPiece`]) is a grid
//! of (side parameter `u`, arc fraction) points on its exact circular sections: the arc is
//! cut into `⌈θ / (2·acos(1 − chord_tol/(2R)))⌉` equal angles (each chord then within
//! `chord_tol/2` of its arc, `θ` the largest arc angle of the piece), and the `u` intervals
//! (starting from the fit's stations) are halved while the fitted section at an interval's
//! midpoint lies farther than `chord_tol/2` from the chord between its ends, at the arc's
//! ends and middle; a cell's centre is then within about `chord_tol` of the fillet. The fillet is built to [`crate::fillet::DEFAULT_FILLET_TOL_MM`];
//! triangles face the air (toward the rolling ball's centre).

use super::atomic::write_atomic;
use super::error::ExportError;
use crate::impeller::Impeller;
use nalgebra::Vector3;
use nurbs::NurbsSurface;
use std::path::Path;

/// Largest number of intervals per parameter direction.
const MAX_INTERVALS: usize = 1 << 16;

/// A part of the impeller to export.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// The hub (full surface of revolution).
    Hub,
    /// The shroud contour surface (the casing side of the blade tips; not material).
    Shroud,
    /// Both sides of every main blade.
    MainBlades,
    /// Both sides of every splitter blade.
    SplitterBlades,
    /// The blade-root fillets of every blade (none when the fillet radius is 0).
    Fillets,
    /// Hub, all blades and their fillets: the machined part.
    Impeller,
}

/// A triangle mesh.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions, mm.
    pub vertices: Vec<Vector3<f64>>,
    /// Triangles as vertex indices (counter-clockwise seen from the S_u × S_v side).
    pub triangles: Vec<[u32; 3]>,
}

impl TriMesh {
    /// Appends `other`, with every vertex mapped by `f`.
    pub fn append_mapped(&mut self, other: &TriMesh, f: impl Fn(&Vector3<f64>) -> Vector3<f64>) {
        let base = self.vertices.len() as u32;
        self.vertices.extend(other.vertices.iter().map(f));
        self.triangles.extend(
            other
                .triangles
                .iter()
                .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
        );
    }
}

/// What was written.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StlStats {
    /// Number of triangles.
    pub triangles: usize,
    /// The chord tolerance honoured, mm.
    pub chord_tol_mm: f64,
}

fn mid_dev(s: &NurbsSurface, a: (f64, f64), b: (f64, f64)) -> f64 {
    let pm = s.point(0.5 * (a.0 + b.0), 0.5 * (a.1 + b.1));
    let chord = 0.5 * (s.point(a.0, a.1) + s.point(b.0, b.1));
    (pm - chord).norm()
}

/// Splits each interval of `breaks` for which `fails(lo, hi)` holds; returns whether any was.
fn refine(breaks: &mut Vec<f64>, fails: impl Fn(f64, f64) -> bool) -> bool {
    let mut out = Vec::with_capacity(breaks.len() * 2);
    let mut any = false;
    for w in breaks.windows(2) {
        out.push(w[0]);
        if fails(w[0], w[1]) {
            out.push(0.5 * (w[0] + w[1]));
            any = true;
        }
    }
    if let Some(&last) = breaks.last() {
        out.push(last);
    }
    *breaks = out;
    any
}

/// Triangulates a surface within `chord_tol` (see the module docs).
pub fn tessellate(s: &NurbsSurface, chord_tol: f64, name: &str) -> Result<TriMesh, ExportError> {
    tessellate_grid(s, chord_tol, f64::INFINITY, name)
}

/// [`tessellate`] with every grid edge also at most `max_edge` mm long (intervals are
/// halved until the 3-D distance between neighbouring grid points along every grid line is
/// within it; a triangle's diagonal is then at most `√2·max_edge`). A surface nearly straight
/// in one direction (a ruled blade side along its rulings) otherwise gives slivers as long as
/// the rulings, whose bounding boxes make nearest-point searches in a bounding volume
/// hierarchy test many of them; compact triangles keep those searches short.
pub fn tessellate_compact(
    s: &NurbsSurface,
    chord_tol: f64,
    max_edge: f64,
    name: &str,
) -> Result<TriMesh, ExportError> {
    if !(max_edge.is_finite() && max_edge > 0.0) {
        return Err(ExportError::Invalid {
            field: "max_edge_mm",
            reason: format!("{max_edge} is not a positive length"),
        });
    }
    tessellate_grid(s, chord_tol, max_edge, name)
}

fn tessellate_grid(
    s: &NurbsSurface,
    chord_tol: f64,
    max_edge: f64,
    name: &str,
) -> Result<TriMesh, ExportError> {
    if !(chord_tol.is_finite() && chord_tol > 0.0) {
        return Err(ExportError::Invalid {
            field: "chord_tol_mm",
            reason: format!("{chord_tol} is not a positive length"),
        });
    }
    let long = |a: (f64, f64), b: (f64, f64)| {
        max_edge.is_finite() && (s.point(a.0, a.1) - s.point(b.0, b.1)).norm() > max_edge
    };
    let ((u0, u1), (v0, v1)) = s.domain();
    // Start from the knot breaks so every polynomial piece is sampled.
    let start = |knots: &[f64], a: f64, b: f64| {
        let mut v: Vec<f64> = vec![a];
        for &k in knots {
            if k > a && k < b && v.last().is_some_and(|&l| k > l) {
                v.push(k);
            }
        }
        v.push(b);
        v
    };
    let mut us = start(s.knots_u().knots(), u0, u1);
    let mut vs = start(s.knots_v().knots(), v0, v1);
    loop {
        if us.len() > MAX_INTERVALS || vs.len() > MAX_INTERVALS {
            return Err(ExportError::Tessellation {
                part: name.to_string(),
                reason: format!(
                    "chord tolerance {chord_tol} mm not reached with {MAX_INTERVALS} intervals"
                ),
            });
        }
        let vs_now = vs.clone();
        let us_now = us.clone();
        let a = refine(&mut us, |lo, hi| {
            vs_now
                .iter()
                .any(|&v| mid_dev(s, (lo, v), (hi, v)) > chord_tol || long((lo, v), (hi, v)))
        });
        let b = refine(&mut vs, |lo, hi| {
            us_now
                .iter()
                .any(|&u| mid_dev(s, (u, lo), (u, hi)) > chord_tol || long((u, lo), (u, hi)))
        });
        if a || b {
            continue;
        }
        // Cell centres against the diagonal (u_i, v_j) – (u_{i+1}, v_{j+1}).
        let mut split_u = vec![false; us.len() - 1];
        let mut split_v = vec![false; vs.len() - 1];
        for i in 0..us.len() - 1 {
            for j in 0..vs.len() - 1 {
                if mid_dev(s, (us[i], vs[j]), (us[i + 1], vs[j + 1])) > chord_tol {
                    split_u[i] = true;
                    split_v[j] = true;
                }
            }
        }
        if !split_u.iter().any(|&x| x) {
            break;
        }
        let split = |breaks: &mut Vec<f64>, flags: &[bool]| *breaks = halved(breaks, flags);
        split(&mut us, &split_u);
        split(&mut vs, &split_v);
    }
    let nv = vs.len();
    let mut mesh = TriMesh::default();
    for &u in &us {
        for &v in &vs {
            mesh.vertices.push(s.point(u, v));
        }
    }
    for i in 0..us.len() - 1 {
        for j in 0..nv - 1 {
            let a = (i * nv + j) as u32;
            let b = ((i + 1) * nv + j) as u32;
            let c = ((i + 1) * nv + j + 1) as u32;
            let d = (i * nv + j + 1) as u32;
            mesh.triangles.push([a, b, c]);
            mesh.triangles.push([a, c, d]);
        }
    }
    Ok(mesh)
}

/// `breaks` with the midpoint inserted into every interval `k` whose `flags[k]` is set.
fn halved(breaks: &[f64], flags: &[bool]) -> Vec<f64> {
    let mut out = Vec::with_capacity(breaks.len() * 2);
    for (k, w) in breaks.windows(2).enumerate() {
        out.push(w[0]);
        if flags.get(k).copied().unwrap_or(false) {
            out.push(0.5 * (w[0] + w[1]));
        }
    }
    out.extend(breaks.last().copied());
    out
}

/// Triangulates the chosen parts of an impeller within `chord_tol` mm.
pub fn mesh_parts(imp: &Impeller, parts: &[Part], chord_tol: f64) -> Result<TriMesh, ExportError> {
    let mut mesh = TriMesh::default();
    let want =
        |p: Part| parts.contains(&p) || (parts.contains(&Part::Impeller) && p != Part::Shroud);
    if want(Part::Hub) {
        mesh.append_mapped(&tessellate(imp.hub().surface(), chord_tol, "hub")?, |p| *p);
    }
    if parts.contains(&Part::Shroud) {
        mesh.append_mapped(
            &tessellate(imp.shroud().surface(), chord_tol, "shroud")?,
            |p| *p,
        );
    }
    let rows = [
        (Part::MainBlades, Some(imp.main()), "main blade"),
        (Part::SplitterBlades, imp.splitter(), "splitter blade"),
    ];
    for (part, row, name) in rows {
        let Some(row) = row.filter(|_| want(part)) else {
            continue;
        };
        let b = row.blade();
        let (p, s) = rayon::join(
            || tessellate(b.pressure(), chord_tol, &format!("{name} pressure side")),
            || tessellate(b.suction(), chord_tol, &format!("{name} suction side")),
        );
        let (p, s) = (p?, s?);
        for k in 0..row.count() {
            let rot = row.rotation(k);
            mesh.append_mapped(&p, |q| rot * q);
            mesh.append_mapped(&s, |q| rot * q);
        }
    }
    if want(Part::Fillets) {
        mesh.append_mapped(&mesh_fillets(imp, chord_tol)?, |p| *p);
    }
    Ok(mesh)
}

/// Triangulates the blade-root fillets of every blade within `chord_tol` mm (module docs);
/// empty when the impeller has no fillet radius.
pub fn mesh_fillets(imp: &Impeller, chord_tol: f64) -> Result<TriMesh, ExportError> {
    check_tol(chord_tol)?;
    let fillets = crate::fillet::ImpellerFillets::new(imp, crate::fillet::DEFAULT_FILLET_TOL_MM)
        .map_err(|e| ExportError::Tessellation {
            part: "blade-root fillet".into(),
            reason: e.to_string(),
        })?;
    match fillets {
        Some(f) => fillets_mesh(&f, chord_tol),
        None => Ok(TriMesh::default()),
    }
}

/// Triangulates already built fillets within `chord_tol` mm (module docs): each row's
/// pieces once, rotated to every blade instance.
pub fn fillets_mesh(
    fillets: &crate::fillet::ImpellerFillets,
    chord_tol: f64,
) -> Result<TriMesh, ExportError> {
    check_tol(chord_tol)?;
    let sides = [crate::Side::Pressure, crate::Side::Suction];
    let mut per_row = Vec::new();
    for row in 0.. {
        let row_fillets: Vec<_> = sides
            .iter()
            .filter_map(|&s| fillets.fillet(row, s))
            .collect();
        if row_fillets.is_empty() {
            break;
        }
        let mut m = TriMesh::default();
        for piece in row_fillets.iter().flat_map(|f| f.pieces()) {
            m.append_mapped(&tessellate_fillet_piece(piece, chord_tol)?, |p| *p);
        }
        per_row.push(m);
    }
    let mut mesh = TriMesh::default();
    for i in 0..fillets.instance_count() {
        if let Some((row, rot)) = fillets.instance(i) {
            if let Some(m) = per_row.get(row) {
                mesh.append_mapped(m, |q| rot * q);
            }
        }
    }
    Ok(mesh)
}

fn check_tol(chord_tol: f64) -> Result<(), ExportError> {
    if chord_tol.is_finite() && chord_tol > 0.0 {
        Ok(())
    } else {
        Err(ExportError::Invalid {
            field: "chord_tol_mm",
            reason: format!("{chord_tol} is not a positive length"),
        })
    }
}

/// Triangulates one fillet piece within `chord_tol` mm (module docs), triangles facing the
/// air. Cost O(n_u · n_arc) section evaluations per refinement pass.
pub fn tessellate_fillet_piece(
    piece: &crate::fillet::FilletPiece,
    chord_tol: f64,
) -> Result<TriMesh, ExportError> {
    check_tol(chord_tol)?;
    let secs = piece.sections();
    let radius = secs.first().map_or(0.0, |c| c.radius);
    let theta = secs
        .iter()
        .map(crate::fillet::FilletSection::arc_angle)
        .fold(0.0, f64::max);
    // Half the tolerance across the arc and half along it: a cell's centre then deviates
    // by at most their sum.
    let half = (1.0 - (0.5 * chord_tol / radius.max(1e-300)).min(1.0)).acos();
    let n_arc = ((theta / (2.0 * half.max(1e-9))).ceil() as usize).clamp(1, MAX_INTERVALS);
    let (u0, u1) = piece.u_range();
    let mut us: Vec<f64> = secs.iter().map(|c| c.u).collect();
    if us.len() < 2 {
        us = vec![u0, u1];
    }
    let at = |u: f64, f: f64| piece.section_at(u).arc_point(f);
    loop {
        let flags: Vec<bool> = us
            .windows(2)
            .map(|w| {
                let m = 0.5 * (w[0] + w[1]);
                [0.0, 0.5, 1.0].iter().any(|&f| {
                    (at(m, f) - 0.5 * (at(w[0], f) + at(w[1], f))).norm() > 0.5 * chord_tol
                })
            })
            .collect();
        if !flags.iter().any(|&x| x) {
            break;
        }
        if us.len() > MAX_INTERVALS {
            return Err(ExportError::Tessellation {
                part: "blade-root fillet".into(),
                reason: format!("more than {MAX_INTERVALS} intervals for {chord_tol} mm"),
            });
        }
        us = halved(&us, &flags);
    }
    let nf = n_arc + 1;
    let mut mesh = TriMesh::default();
    let mut centres = Vec::with_capacity(us.len());
    for &u in &us {
        let sec = piece.section_at(u);
        centres.push(sec.centre);
        for j in 0..nf {
            mesh.vertices.push(sec.arc_point(j as f64 / n_arc as f64));
        }
    }
    // Orientation: the first cell's normal toward the ball centre (the air side).
    let flip = if us.len() > 1 {
        let (a, b, c) = (mesh.vertices[0], mesh.vertices[nf], mesh.vertices[nf + 1]);
        (b - a).cross(&(c - a)).dot(&(centres[0] - a)) < 0.0
    } else {
        false
    };
    for i in 0..us.len().saturating_sub(1) {
        for j in 0..n_arc {
            let a = (i * nf + j) as u32;
            let b = ((i + 1) * nf + j) as u32;
            let c = ((i + 1) * nf + j + 1) as u32;
            let d = (i * nf + j + 1) as u32;
            if flip {
                mesh.triangles.push([a, c, b]);
                mesh.triangles.push([a, d, c]);
            } else {
                mesh.triangles.push([a, b, c]);
                mesh.triangles.push([a, c, d]);
            }
        }
    }
    Ok(mesh)
}

/// Binary STL bytes of a mesh (80-byte header, little-endian f32 normals and vertices).
pub fn stl_bytes(mesh: &TriMesh, header: &str) -> Vec<u8> {
    let mut out = Vec::with_capacity(84 + 50 * mesh.triangles.len());
    let mut h = [b' '; 80];
    for (d, s) in h.iter_mut().zip(header.bytes()) {
        *d = s;
    }
    out.extend_from_slice(&h);
    out.extend_from_slice(&(mesh.triangles.len() as u32).to_le_bytes());
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
        let n = (b - a)
            .cross(&(c - a))
            .try_normalize(0.0)
            .unwrap_or_else(Vector3::zeros);
        for v in [n, a, b, c] {
            for x in v.iter() {
                out.extend_from_slice(&(*x as f32).to_le_bytes());
            }
        }
        out.extend_from_slice(&0u16.to_le_bytes());
    }
    out
}

/// Writes the chosen parts as a binary STL file within `chord_tol` mm (temporary file, then
/// rename).
pub fn write_stl(
    imp: &Impeller,
    parts: &[Part],
    chord_tol: f64,
    path: &Path,
) -> Result<StlStats, ExportError> {
    let mesh = mesh_parts(imp, parts, chord_tol)?;
    let header = format!("impeller-cam {} chord {chord_tol} mm", imp.name());
    write_atomic(path, &stl_bytes(&mesh, &header))?;
    Ok(StlStats {
        triangles: mesh.triangles.len(),
        chord_tol_mm: chord_tol,
    })
}
