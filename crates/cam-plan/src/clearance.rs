//! The design clearance query: how far the cutter, its shank and its holder are from the
//! design (hub, every blade, optionally the shroud contour), and which part is nearest.
//!
//! # Geometry
//! The design material is the union of the hub body and the blades:
//! - hub body: the points below the hub surface of revolution, capped by the plane of the
//!   hub's inlet end and the cylinder of its outlet radius (where the meridional distance
//!   alone would extend the body past the contour's ends); signed distance
//!   `max(d_hub, z − z_inlet, r − r_outlet)`, exact near the hub surface;
//! - blade k: the points inside both sides (each side's signed distance is positive along its
//!   outward normal) and below the shroud contour: `max(d_pressure, d_suction, d_shroud)`, except
//!   beyond a leading or trailing edge (both side distances positive), where that over-reads
//!   and `max(d_shroud, min(d_pressure, d_suction) − g/2)` bounds it (`g` the gap between the
//!   sides at that edge: 0 at a rounded edge, the face width at a blunt one)
//!   (`impeller_model::query::blade_solid_distance`).
//!   Only the two instances of each row that enclose the query's polar angle are evaluated
//!   (the reference blade's angle at the nearest meridional position is tabulated), so an
//!   exact query costs four blade-side projections however many blades there are.
//!
//! A [`DesignMesh`] triangulates the design within a chord tolerance `c` (hub surface with its
//! inlet disc and outlet cylinder, every blade side clipped at the shroud contour; parry BVH):
//! the true surfaces lie within `c` of the mesh. It also holds the blade sides whole (as far
//! as the exact side distances measure, past the shroud too) at a coarser chord `c_b ≥ c`
//! ([`BOUND_CHORD_MM`]), for every instance and for each row's reference blade alone: these
//! only bound the exact distances from below (`d_m − c_b`, `d_m` the unsigned distance to that
//! mesh), and only where the point is outside every blade, which `d_m − c_b ≥ t/2` shows (`t`
//! the thickest blade: a point inside a blade is within `t/2` of a side).
//!
//! **Cutter** (the fluted part, `0 ≤ h ≤ L`): a solid of revolution of radius `ρ(h)` about the
//! axis. Its cross-section at height `h` is a disc inside the ball of radius `ρ(h)` about
//! `c(h) = tip + h·axis`, so `d(c(h)) − ρ(h)` (`d` the design's signed distance) bounds the
//! disc's clearance from below. The answer is the minimum over sample heights: the ball
//! centre of ball and tapered-ball ends (where the ball is the cutter's end exactly), then a
//! grid up the flutes with a step `s ≤ min(ρ/2, √(2·ρ·tol))`; between two samples the union of
//! balls misses a rim band of depth `≤ s²/(4ρ) ≤ tol/2`. Each sample's value is
//! `min(d_hub, d_shroud, d_blade) − ρ` with the hub and shroud distances exact (meridional
//! projections), the blade distance exact (NURBS projections) within [`EXACT_BAND_MM`] of the
//! ball and the mesh bound `d_m − c_b` beyond it (`d_m − c_b − t/2 ≥ ρ + EXACT_BAND_MM`).
//!
//! The minimum is found without evaluating most samples, by best-first branch and bound over
//! runs of consecutive samples, using that a distance is 1-Lipschitz along the axis:
//! `|d(c(h)) − d(c(h'))| ≤ |h − h'|`. A run between two samples of known distance `D_l`, `D_r`
//! has every distance at least the lowest point of the cones `D_l − (h − h_l)` and
//! `D_r − (h_r − h)` over it, so its clearance is at least that less its widest radius; a run
//! whose bound is not below the least clearance found so far (or a check's threshold) holds
//! no sample that could lower the answer or fail the check, and is dropped whole. Runs are
//! split at their middle sample, the lowest bound first:
//! - hub: the samples at both ends, then middles. The capped hub distance is 1-Lipschitz
//!   except across the rays beyond an end `e` of the contour on its material side
//!   (`e + s·T`, `T` the tangent pointing away), where the distance to the contour jumps from
//!   `−s` to `s`; at an end where the inlet plane or the outlet cylinder passes through `e`
//!   perpendicular to `T`, the cap reads `s` there and nothing jumps (so on the fixtures'
//!   hubs everywhere). Otherwise the search runs only when the axis segment's meridional
//!   trace stays out of the quadrant `(x − e)·T ≥ 0, (x − e)·n ≤ 0` beyond that end (checked
//!   in O(1): `z` is linear along the segment and `r` convex), and every sample is evaluated
//!   if not;
//! - blades: the middle sample's mesh distance (BVH point query capped where the whole run
//!   would be dropped: nothing within the cap drops it at once); a sample whose mesh bound
//!   already shows it cannot lower the answer keeps the bound, one beyond the band takes it
//!   as its value, and the others wait, bounded, for their exact distance, also taken lowest
//!   bound first. An exact distance projects on the two instances of each row around the
//!   point nearest in polar angle first, and leaves out an instance its row's reference mesh
//!   (the point turned into that blade's frame) keeps `c_b + max(t/2, x)` away, `x` the
//!   least distance so far or the value below which the sample matters.
//!
//! So the answer is the minimum over every sample exactly as an exhaustive evaluation would
//! give it wherever that minimum lies within [`EXACT_BAND_MM`] of a blade, and a lower bound of
//! it elsewhere (`DesignClearance::clearance_exhaustive` keeps the exhaustive evaluation for
//! the tests that check so).
//!
//! **Shank and holder**: the frusta of [`cam_core::Cutter::frusta`] above the flutes, each as
//! a convex polyhedron circumscribing it (polygon rings whose sides stay within `c` of the
//! circle), placed at the posture and measured against the hub and blade meshes with parry's
//! contact query (signed: negative = penetration depth), minus `c` for the mesh. A frustum
//! buried entirely inside material (no mesh crossing) is caught by the exact signed distance
//! at its axis midpoint (unless the hub distance and the blade mesh show that point outside). Unlike balls as wide as the holder, this does not reach down the axis
//! by the holder's radius: a holder 5 mm above a plane is 5 mm clear.
//!
//! Stated error: the answer is a lower bound of the true clearance, tighter than `tol/2`
//! (cutter sampling) near a surface for the cutter, and than `2c` (mesh chord + polygon) for
//! shank and holder. The shroud contour, when asked for ([`PartSet::shroud`]), is measured
//! with the balls at every sample height up to the holder's top (exact 2D projections;
//! conservative for wide parts).
//!
//! A flat bottom is tested with the ball about the tip, which reaches below it (conservative);
//! operations whose tools touch a floor with a flat bottom (plunge roughing) ask for the blades
//! only ([`ClearanceOptions::parts`]).
//!
//! Cost per posture: O(log(L / s)) hub projections and capped BVH point queries when the tool
//! is clear of the design by more than its sampling's Lipschitz slack (far from everything:
//! a few µs), up to O(L / s) of each plus exact projections for the samples near the minimum
//! when a long stretch of the flutes runs close to a blade; one BVH contact query per frustum
//! and mesh. [`DesignClearance::is_clear`] prunes against its threshold and stops at the first
//! failing part; [`DesignClearance::segment_clearance`] asks each midpoint only up to the
//! value that settles both halves of its interval. No allocation per query (the open runs
//! live in a per-thread buffer).
//!
//! Dependency: parry3d-f64 (the workspace's chosen BVH and convex-shape queries).

use crate::mesh_distance::MeshDistance;
use crate::{PlanError, Point3, Tool, Vector3};
use cam_core::{CutterLocation, CutterShape};
use impeller_model::export::stl::{tessellate, tessellate_compact};
use impeller_model::query::blade_side_distance;
use impeller_model::{BladeSet, Impeller, Side};
use parry3d_f64::math::{Pose, Rotation, Vector as PVec};
use parry3d_f64::query;
use parry3d_f64::shape::TriMesh;
use std::sync::Arc;

/// Default sampling tolerance of the swept balls (mm): the largest rim band between two
/// sample heights the union of balls may miss; also the chord of the design mesh and of the
/// frusta polygons built by [`DesignClearance::new`].
pub const DEFAULT_SAMPLE_TOL_MM: f64 = 0.01;

/// Width beyond a cutter ball within which blade distances are computed exactly (mm): a
/// bound from the mesh is used only when it leaves at least this much room, so every answer
/// within this distance of a blade is exact.
pub const EXACT_BAND_MM: f64 = 1.0;

/// Coarsest chord of the design mesh (mm): a finer `sample_tol_mm` makes the mesh follow it,
/// a coarser one is capped here so the shank/holder answers stay within 0.1 mm.
pub const MAX_MESH_CHORD_MM: f64 = 0.05;

/// Coarsest chord (mm) of the mesh of the whole blade sides, which only bounds the exact blade
/// distances of the cutter samples from below (a finer design chord is kept): a coarser mesh
/// is cheaper to query and loosens the bounds by its chord, leaving more exact projections.
pub const BOUND_CHORD_MM: f64 = 0.05;

/// Longest grid edge (mm) of the blade-side meshes that bound the exact distances.
pub const BOUND_MAX_EDGE_MM: f64 = MAX_EDGE_DBG;
const MAX_EDGE_DBG: f64 = 3.0;

/// Blade thickness grid (u × v samples per pressure side) for the thickest blade `t`.
const THICKNESS_GRID: (usize, usize) = (24, 8);

/// A blade row.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Row {
    /// The main blades.
    Main,
    /// The splitter blades.
    Splitter,
}

/// A part of the design.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DesignPart {
    /// The hub body.
    Hub,
    /// The shroud contour (not material: a boundary the paths of some operations respect).
    Shroud,
    /// The blade-root fillets (material in the corner between hub and blades, measured by
    /// [`crate::FilletMargin`] where an operation asks for it).
    Fillet,
    /// Blade `index` of the main or splitter row.
    Blade {
        /// Main or splitter row.
        row: Row,
        /// Instance number in its row.
        index: usize,
    },
}

/// A part of the tool assembly.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ToolPart {
    /// The fluted cutting part.
    Cutter,
    /// The shank between the flutes and the holder.
    Shank,
    /// The holder.
    Holder,
}

/// Which design parts a query measures against.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PartSet {
    /// The hub body.
    pub hub: bool,
    /// Every blade.
    pub blades: bool,
    /// The shroud contour (clearance positive below it, i.e. inside the channel envelope).
    pub shroud: bool,
}

impl PartSet {
    /// Hub and blades: the design material.
    pub const MATERIAL: Self = Self {
        hub: true,
        blades: true,
        shroud: false,
    };
    /// Blades only.
    pub const BLADES: Self = Self {
        hub: false,
        blades: true,
        shroud: false,
    };
}

/// Options of a clearance query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClearanceOptions {
    /// Design parts measured against.
    pub parts: PartSet,
    /// Sampling tolerance of the swept balls (mm, > 0).
    pub sample_tol_mm: f64,
    /// Tool samples at heights up to this (mm above the tip) are left out of the query: the
    /// part of the tool a contact planner places exactly itself (a ball end touching the
    /// surface it finishes, whose samples near the tip are conservative spheres that would
    /// read a false penetration). 0 (the default) queries the whole tool.
    pub above_mm: f64,
}

impl Default for ClearanceOptions {
    fn default() -> Self {
        Self {
            parts: PartSet::MATERIAL,
            sample_tol_mm: DEFAULT_SAMPLE_TOL_MM,
            above_mm: 0.0,
        }
    }
}

/// The answer of a clearance query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clearance {
    /// Signed clearance (mm): positive = free by that much, negative = penetration (a lower
    /// bound of the true clearance, see the module docs).
    pub distance_mm: f64,
    /// The design part nearest to the tool.
    pub design_part: DesignPart,
    /// The tool part nearest to the design.
    pub tool_part: ToolPart,
    /// Height above the tip of the nearest sample (mm).
    pub height_mm: f64,
}

/// Tabulated polar angle of a row's reference blade over the meridional (z, r) plane.
#[derive(Debug, Clone)]
struct RowAngles {
    zr: Vec<[f64; 2]>,
    theta: Vec<f64>,
    /// Half the gap between the sides at the u-min and u-max edges (0 where they meet).
    edge_half_gaps: [f64; 2],
}

impl RowAngles {
    fn new(set: &BladeSet) -> Self {
        let blade = set.blade();
        let s = blade.pressure();
        let ((u0, u1), (v0, v1)) = s.domain();
        let (nu, nv) = (48, 12);
        let mut zr = Vec::with_capacity((nu + 1) * (nv + 1));
        let mut theta = Vec::with_capacity(zr.capacity());
        for i in 0..=nu {
            for j in 0..=nv {
                let p = s.point(
                    u0 + (u1 - u0) * i as f64 / nu as f64,
                    v0 + (v1 - v0) * j as f64 / nv as f64,
                );
                zr.push([p.z, p.x.hypot(p.y)]);
                theta.push(p.y.atan2(p.x));
            }
        }
        Self {
            zr,
            theta,
            edge_half_gaps: impeller_model::query::blade_edge_half_gaps(blade),
        }
    }

    /// The reference blade's polar angle nearest to `p`'s meridional position.
    fn angle_near(&self, p: &Point3) -> f64 {
        let (z, r) = (p.z, p.x.hypot(p.y));
        let mut best = (f64::INFINITY, 0.0);
        for (q, t) in self.zr.iter().zip(&self.theta) {
            let d = (q[0] - z).powi(2) + (q[1] - r).powi(2);
            if d < best.0 {
                best = (d, *t);
            }
        }
        best.1
    }
}

/// The design triangulated within a chord tolerance, with a BVH (parry): the hub surface
/// closed by its inlet disc and outlet cylinder, and every blade side of every instance.
/// Built once per impeller and shared by the clearance queries of every tool.
#[derive(Clone)]
pub struct DesignMesh {
    hub: TriMesh,
    blades: TriMesh,
    /// (row, instance) of each blade triangle.
    blade_of: Vec<(Row, usize)>,
    /// The blade sides whole, including where they reach past the shroud contour (the exact
    /// side distances measure to them there).
    blade_sides: MeshDistance,
    /// (row, instance) of each triangle of `blade_sides`.
    side_of: Vec<(Row, usize)>,
    /// The chord of `blade_sides`.
    side_chord_mm: f64,
    /// Each row's reference blade (instance 0), both sides whole, in its own frame: the
    /// blade distance of one instance is bounded by turning the point into that frame.
    reference_sides: Vec<(Row, MeshDistance)>,
    /// `blades` for point distances.
    blades_distance: MeshDistance,
    chord_mm: f64,
    thickest_blade_mm: f64,
}

impl std::fmt::Debug for DesignMesh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DesignMesh")
            .field("hub_triangles", &self.hub.indices().len())
            .field("blade_triangles", &self.blade_of.len())
            .field("chord_mm", &self.chord_mm)
            .field("thickest_blade_mm", &self.thickest_blade_mm)
            .finish()
    }
}

fn pv(p: &Point3) -> PVec {
    PVec::new(p.x, p.y, p.z)
}

impl DesignMesh {
    /// Triangulates `impeller` within `chord_mm` (> 0; capped at [`MAX_MESH_CHORD_MM`]).
    /// Cost: the tessellation of the hub and of each row's two sides (O(area / chord)), the
    /// copies to every instance, and a BVH build O(T log T).
    ///
    /// Errors: a chord that is not finite and > 0; a surface the tessellation cannot meet the
    /// chord on.
    pub fn new(impeller: &Impeller, chord_mm: f64) -> Result<Self, PlanError> {
        if !(chord_mm.is_finite() && chord_mm > 0.0) {
            return Err(PlanError::param(
                "-",
                "tolerances.chord_tol",
                format!("{chord_mm} must be finite and > 0"),
            ));
        }
        let chord = chord_mm.min(MAX_MESH_CHORD_MM);
        let side_chord = chord.max(BOUND_CHORD_MM);
        let mesh_err = |e: impeller_model::export::ExportError| {
            PlanError::geometry("-", "design mesh", e.to_string())
        };
        // Hub surface, inlet disc (z = z_inlet, r ≤ r_inlet) and outlet cylinder
        // (r = r_outlet, 0 ≤ z ≤ z_outlet): the capped hub body's boundary.
        let hub_surface = tessellate(impeller.hub().surface(), chord, "hub").map_err(mesh_err)?;
        let mut hub_v: Vec<PVec> = hub_surface
            .vertices
            .iter()
            .map(|v| PVec::new(v.x, v.y, v.z))
            .collect();
        let mut hub_t = hub_surface.triangles.clone();
        let m = impeller.hub().meridional();
        let (t0, t1) = m.domain();
        let (a, b) = (m.point(t0), m.point(t1));
        let (inlet, outlet) = if a[0] >= b[0] { (a, b) } else { (b, a) };
        // Polygon sides within the chord of circles up to the outlet radius.
        let r_max = inlet[1].max(outlet[1]).max(chord);
        let n = (std::f64::consts::PI / (1.0 - chord / r_max).clamp(-1.0, 1.0).acos())
            .ceil()
            .max(12.0) as usize;
        let ring = |r: f64, z: f64| -> Vec<PVec> {
            (0..n)
                .map(|k| {
                    let t = std::f64::consts::TAU * k as f64 / n as f64;
                    PVec::new(r * t.cos(), r * t.sin(), z)
                })
                .collect()
        };
        let centre = hub_v.len() as u32;
        hub_v.push(PVec::new(0.0, 0.0, inlet[0]));
        let base = hub_v.len() as u32;
        hub_v.extend(ring(inlet[1], inlet[0]));
        for k in 0..n as u32 {
            hub_t.push([centre, base + k, base + (k + 1) % n as u32]);
        }
        if outlet[0] > 0.0 {
            let lo = hub_v.len() as u32;
            hub_v.extend(ring(outlet[1], 0.0));
            let hi = hub_v.len() as u32;
            hub_v.extend(ring(outlet[1], outlet[0]));
            for k in 0..n as u32 {
                let k1 = (k + 1) % n as u32;
                hub_t.push([lo + k, lo + k1, hi + k1]);
                hub_t.push([lo + k, hi + k1, hi + k]);
            }
        }
        let hub = TriMesh::new(hub_v, hub_t)
            .map_err(|e| PlanError::geometry("-", "hub mesh", format!("{e:?}")))?;

        // Every instance of each row's sides: clipped at the shroud (the material, for the
        // shank and holder) and whole (as far as the exact side distances reach, for the
        // cutter samples' bounds).
        let mut clipped = BladeTriangles::default();
        let mut whole = BladeTriangles::default();
        let mut thickest: f64 = 0.0;
        let rows = std::iter::once((Row::Main, impeller.main()))
            .chain(impeller.splitter().map(|s| (Row::Splitter, s)));
        let mut reference = Vec::new();
        for (row, set) in rows {
            let blade = set.blade();
            let mut own = BladeTriangles::default();
            for side in [Side::Pressure, Side::Suction] {
                let name = format!("{row:?} blade {side:?} side");
                let sm = tessellate(blade.side(side), chord, &name).map_err(mesh_err)?;
                clipped.add_instances(&clip_at_shroud(impeller, &sm), row, set);
                let coarse =
                    tessellate_compact(blade.side(side), side_chord, BOUND_MAX_EDGE_MM, &name)
                        .map_err(mesh_err)?;
                whole.add_instances(&coarse, row, set);
                own.add(&coarse, row, 0, &nalgebra::Rotation3::identity());
            }
            reference.push((row, own));
            // Thickest blade: suction-side distance of pressure-side grid points.
            let ps = blade.side(Side::Pressure);
            let ((u0, u1), (v0, v1)) = ps.domain();
            let (nu, nv) = THICKNESS_GRID;
            for i in 0..=nu {
                for j in 0..=nv {
                    let p = ps.point(
                        u0 + (u1 - u0) * i as f64 / nu as f64,
                        v0 + (v1 - v0) * j as f64 / nv as f64,
                    );
                    let (_, d) = blade_side_distance(blade, Side::Suction, &p, None);
                    thickest = thickest.max(-d);
                }
            }
        }
        let blade_mesh = |t: BladeTriangles| {
            TriMesh::new(t.vertices, t.triangles)
                .map(|m| (m, t.blade_of))
                .map_err(|e| PlanError::geometry("-", "blade mesh", format!("{e:?}")))
        };
        let (blades, blade_of) = blade_mesh(clipped)?;
        let (blade_sides, side_of) = blade_mesh(whole)?;
        let blade_sides = MeshDistance::new(&blade_sides);
        let reference_sides = reference
            .into_iter()
            .map(|(row, t)| blade_mesh(t).map(|(m, _)| (row, MeshDistance::new(&m))))
            .collect::<Result<Vec<_>, _>>()?;
        let blades_distance = MeshDistance::new(&blades);
        Ok(Self {
            hub,
            blades,
            blades_distance,
            blade_of,
            blade_sides,
            side_of,
            chord_mm: chord,
            side_chord_mm: side_chord,
            reference_sides,
            thickest_blade_mm: thickest,
        })
    }

    /// The chord tolerance of the mesh (mm).
    pub fn chord_mm(&self) -> f64 {
        self.chord_mm
    }

    /// The thickest blade found (mm).
    pub fn thickest_blade_mm(&self) -> f64 {
        self.thickest_blade_mm
    }

    /// Unsigned distance from `p` to the nearest triangle of the whole blade sides and the
    /// blade it belongs to when it is below `max_dist`, else `None` (the search prunes every
    /// BVH node beyond `max_dist`: cheap far from the blades). O(log T).
    fn side_mesh_distance_within(&self, p: &Point3, max_dist: f64) -> Option<(f64, DesignPart)> {
        let (tri, d) = self.blade_sides.nearest_within(pv(p), max_dist)?;
        let part = self
            .side_of
            .get(tri as usize)
            .map_or(DesignPart::Hub, |&(row, index)| DesignPart::Blade {
                row,
                index,
            });
        Some((d, part))
    }

    /// Unsigned distance from `p` to the nearest blade side triangle and the blade it
    /// belongs to. O(log T).
    fn blade_mesh_distance(&self, p: &Point3) -> (f64, DesignPart) {
        let Some((tri, d)) = self.blades_distance.nearest_within(pv(p), f64::INFINITY) else {
            return (f64::INFINITY, DesignPart::Hub);
        };
        let part = self
            .blade_of
            .get(tri as usize)
            .map_or(DesignPart::Hub, |&(row, index)| DesignPart::Blade {
                row,
                index,
            });
        (d, part)
    }
}

/// Triangles of blade sides copied to every instance of their rows.
#[derive(Default)]
struct BladeTriangles {
    vertices: Vec<PVec>,
    triangles: Vec<[u32; 3]>,
    blade_of: Vec<(Row, usize)>,
}

impl BladeTriangles {
    /// Adds `mesh` (of the reference blade) at every instance of `set`.
    fn add_instances(
        &mut self,
        mesh: &impeller_model::export::stl::TriMesh,
        row: Row,
        set: &BladeSet,
    ) {
        for k in 0..set.count() {
            self.add(mesh, row, k, &set.rotation(k));
        }
    }

    /// Adds `mesh` turned by `rot` as instance `k` of `row`.
    fn add(
        &mut self,
        mesh: &impeller_model::export::stl::TriMesh,
        row: Row,
        k: usize,
        rot: &nalgebra::Rotation3<f64>,
    ) {
        let base = self.vertices.len() as u32;
        self.vertices.extend(mesh.vertices.iter().map(|v| {
            let q = rot * v;
            PVec::new(q.x, q.y, q.z)
        }));
        self.triangles.extend(
            mesh.triangles
                .iter()
                .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
        );
        self.blade_of
            .extend(std::iter::repeat_n((row, k), mesh.triangles.len()));
    }
}

/// The part of a blade side's mesh below the shroud contour (blade sides extend a little
/// beyond it, as the model does; the blade material stops at the shroud). Each triangle is
/// clipped by the zero set of the shroud's signed distance, interpolated linearly along its
/// edges (Sutherland–Hodgman against one linear function): exact where the distance is linear
/// across the triangle, within its second-order variation otherwise. O(T).
fn clip_at_shroud(
    impeller: &Impeller,
    mesh: &impeller_model::export::stl::TriMesh,
) -> impeller_model::export::stl::TriMesh {
    let d: Vec<f64> = mesh
        .vertices
        .iter()
        .map(|v| impeller.shroud().signed_distance(v))
        .collect();
    let mut out = impeller_model::export::stl::TriMesh::default();
    for t in &mesh.triangles {
        let idx = t.map(|i| i as usize);
        if idx.iter().all(|&i| d[i] <= 0.0) {
            let base = out.vertices.len() as u32;
            out.vertices.extend(idx.iter().map(|&i| mesh.vertices[i]));
            out.triangles.push([base, base + 1, base + 2]);
            continue;
        }
        // Keep the polygon where d ≤ 0.
        let mut poly = Vec::with_capacity(4);
        for k in 0..3 {
            let (a, b) = (idx[k], idx[(k + 1) % 3]);
            let (da, db) = (d[a], d[b]);
            if da <= 0.0 {
                poly.push(mesh.vertices[a]);
            }
            if (da <= 0.0) != (db <= 0.0) {
                let f = da / (da - db);
                poly.push(mesh.vertices[a] + (mesh.vertices[b] - mesh.vertices[a]) * f);
            }
        }
        if poly.len() >= 3 {
            let base = out.vertices.len() as u32;
            out.vertices.extend(poly.iter().copied());
            for k in 1..poly.len() as u32 - 1 {
                out.triangles.push([base, base + k, base + k + 1]);
            }
        }
    }
    out
}

/// One shank or holder frustum as a convex polyhedron in the tool frame (tip at the origin,
/// axis +Z).
#[derive(Clone)]
struct FrustumShape {
    shape: RingFrustum,
    h_mid: f64,
    r_mid: f64,
    part: ToolPart,
}

/// The convex polyhedron circumscribing the frustum `(h0, r0)–(h1, r1)`: two rings of `n`
/// vertices at the same angles `2πk/n`, at radius `r / cos(π/n)`, with `n` chosen so the
/// polygon's sides stay within `chord` of the circle.
///
/// Its support function (the vertex farthest along a direction, what GJK and EPA ask for) is
/// answered in O(1) instead of by a scan of the `2n` vertices (parry's `ConvexPolyhedron`):
/// within a ring, `p_k·d = ρ (cos t_k d_x + sin t_k d_y) + h d_z` is largest at the vertex
/// whose angle `t_k` is nearest the direction's azimuth, the same `k` for both rings (their
/// radii are ≥ 0), so the support is the better of two candidates. Same polyhedron, same
/// answers up to ties; the shank and holder tests of blade-root finishing spent half their
/// time in the vertex scan (perf, default job, 2026-11-26).
#[derive(Clone, Debug)]
struct RingFrustum {
    n: usize,
    /// Heights and circumscribed radii of the two rings.
    h: [f64; 2],
    rho: [f64; 2],
    /// `(cos t_k, sin t_k)` of the vertex angles.
    dirs: Vec<(f64, f64)>,
}

impl RingFrustum {
    fn vertex(&self, ring: usize, k: usize) -> PVec {
        let (c, s) = self.dirs.get(k).copied().unwrap_or((1.0, 0.0));
        PVec::new(self.rho[ring] * c, self.rho[ring] * s, self.h[ring])
    }

    /// Axis-aligned box of the frustum at `pose` (of the circumscribed cone frustum, which
    /// contains the polyhedron): each ring is a circle of radius `ρ` in the plane normal to
    /// the axis `a`, whose extent along a world axis `e` is `ρ·√(1 − (a·e)²)`.
    fn world_aabb(&self, pose: &Pose) -> parry3d_f64::bounding_volume::Aabb {
        let a = pose.rotation * PVec::Z;
        let mut lo = PVec::splat(f64::INFINITY);
        let mut hi = PVec::splat(f64::NEG_INFINITY);
        for ring in 0..2 {
            let c = pose.translation + a * self.h[ring];
            let ext = PVec::new(
                (1.0 - a.x * a.x).max(0.0).sqrt(),
                (1.0 - a.y * a.y).max(0.0).sqrt(),
                (1.0 - a.z * a.z).max(0.0).sqrt(),
            ) * (self.rho[ring] * (1.0 + 1e-12));
            lo = lo.min(c - ext);
            hi = hi.max(c + ext);
        }
        parry3d_f64::bounding_volume::Aabb::new(lo, hi)
    }
}

impl parry3d_f64::shape::SupportMap for RingFrustum {
    #[inline]
    fn local_support_point(&self, dir: PVec) -> PVec {
        let step = std::f64::consts::TAU / self.n as f64;
        let k = if dir.x == 0.0 && dir.y == 0.0 {
            0
        } else {
            let phi = dir.y.atan2(dir.x);
            ((phi / step).round() as i64).rem_euclid(self.n as i64) as usize
        };
        let (a, b) = (self.vertex(0, k), self.vertex(1, k));
        if b.dot(dir) > a.dot(dir) {
            b
        } else {
            a
        }
    }
}

/// See [`RingFrustum`]; `None` for a degenerate frustum (no height or no radius).
fn frustum_shape(h0: f64, h1: f64, r0: f64, r1: f64, chord: f64) -> Option<RingFrustum> {
    let r = r0.max(r1).max(chord);
    let n = (std::f64::consts::PI / (1.0 / (1.0 + chord / r)).acos())
        .ceil()
        .max(8.0) as usize;
    let scale = 1.0 / (std::f64::consts::PI / n as f64).cos();
    let ok = [h0, h1, r0, r1].iter().all(|x| x.is_finite())
        && h1 != h0
        && r0 >= 0.0
        && r1 >= 0.0
        && r0.max(r1) > 0.0;
    ok.then(|| RingFrustum {
        n,
        h: [h0, h1],
        rho: [r0 * scale, r1 * scale],
        dirs: (0..n)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / n as f64;
                (t.cos(), t.sin())
            })
            .collect(),
    })
}

/// Deepest contact (or nearest within `prediction`) between a frustum at `pose` and a mesh
/// in the world frame: the least signed distance (negative: penetration depth) over the
/// mesh's triangles, each by GJK/EPA against the frustum's support function (what parry's
/// `query::contact` does for a convex shape against a mesh), and the point on the mesh.
///
/// Branch and bound over the mesh's BVH (parry's best-first `find_best`): a node or triangle
/// is bounded from below by its bounding sphere against the solid cylinder of the largest
/// ring radius between the two ring planes (which contains the polyhedron), a node also by
/// the gap between its box and the frustum's, and one whose
/// bound is positive and not below the least distance found so far (initially
/// `prediction`) holds no triangle that could lower the answer, so it is skipped whole. A
/// bound ≤ 0 says nothing of a penetration's depth, so such nodes are always opened and
/// such triangles always solved. The answer is that of solving every triangle within
/// `prediction` (up to ties); only the number of GJK solves changes — on the blade-root
/// finishing of the default job, 816 solves among 12 000 candidate triangles per frustum
/// query when the triangles were taken in the order of an AABB query.
fn frustum_mesh_contact(
    pose: &Pose,
    f: &RingFrustum,
    mesh: &TriMesh,
    prediction: f64,
) -> Option<(f64, PVec)> {
    let axis = pose.rotation * PVec::Z;
    let (h_lo, h_hi) = (f.h[0].min(f.h[1]), f.h[0].max(f.h[1]));
    let r_max = f.rho[0].max(f.rho[1]);
    // Lower bound of the distance from a ball (centre `m`, radius `r`) to the frustum.
    let lower = |m: PVec, r: f64| {
        let w = m - pose.translation;
        let z = w.dot(axis);
        let rho = (w.length_squared() - z * z).max(0.0).sqrt();
        let (dr, dz) = ((rho - r_max).max(0.0), (h_lo - z).max(z - h_hi).max(0.0));
        let d = (dr * dr + dz * dz).sqrt() - r;
        if d > 0.0 {
            d
        } else {
            f64::NEG_INFINITY
        }
    };
    let frame = f.world_aabb(pose);
    let (_, hit) = mesh.bvh().find_best(
        prediction.next_up(),
        |node, _| {
            let (lo, hi) = (node.mins(), node.maxs());
            // The gap between the node's box and the frustum's box bounds it too.
            let gap = (frame.mins - hi)
                .max(lo - frame.maxs)
                .max(PVec::ZERO)
                .length();
            let ball = lower(0.5 * (lo + hi), 0.5 * (hi - lo).length());
            if gap > 0.0 {
                gap.max(ball)
            } else {
                ball
            }
        },
        |id, best| {
            let tri = mesh.triangle(id);
            let m = (tri.a + tri.b + tri.c) / 3.0;
            let tri_r = (tri.a - m)
                .length()
                .max((tri.b - m).length())
                .max((tri.c - m).length());
            if lower(m, tri_r) >= best {
                return None;
            }
            query::contact::contact_support_map_support_map(pose, &tri, f, prediction).map(|c| {
                MeshContact {
                    dist: c.dist,
                    point: c.point1,
                }
            })
        },
    )?;
    Some((hit.dist, hit.point))
}

/// A frustum–triangle contact as a cost of the BVH search (its signed distance).
struct MeshContact {
    dist: f64,
    point: PVec,
}

impl parry3d_f64::partitioning::BvhLeafCost for MeshContact {
    fn cost(&self) -> f64 {
        self.dist
    }
}

/// Clearance of one tool against one impeller's design.
#[derive(Clone)]
pub struct DesignClearance<'a> {
    impeller: &'a Impeller,
    options: ClearanceOptions,
    /// (height, radius, tool part) of each cutter sample; with the shroud in the part set,
    /// also of shank and holder heights (see the module docs).
    samples: Vec<(f64, f64, ToolPart)>,
    /// Ball samples of the shank and holder, for the shroud contour only.
    upper_samples: Vec<(f64, f64, ToolPart)>,
    frusta: Vec<FrustumShape>,
    mesh: Arc<DesignMesh>,
    hub_z_max: f64,
    hub_r_max: f64,
    /// The two ends of the hub contour.
    hub_ends: [ContourEnd; 2],
    rows: Vec<(Row, RowAngles)>,
    /// Largest distance of a tool point from the tip (top of the holder plus its radius):
    /// the lever arm of a change of tool axis in [`DesignClearance::segment_clearance`].
    reach_mm: f64,
    /// The same lever arm for the cutter samples alone (highest sample plus the widest
    /// sample radius): the flutes' part of [`DesignClearance::segment_clearance`].
    flute_reach_mm: f64,
    /// Height of the ball centre above the tip for ball and tapered ball ends.
    ball_centre_mm: Option<f64>,
    /// How far a cutter sample's sphere reaches beyond the tool's surface at most: a cone
    /// of half angle θ is `ρ·cos θ` from the axis point where the cross-section's radius is
    /// `ρ`, so the sphere pokes out by `ρ(1 − cos θ)`.
    sphere_poke_mm: f64,
    /// How much nearer than measured the shank and holder read against the material
    /// ([`DesignClearance::with_non_cutting_margin`]; 0 by default).
    non_cutting_margin_mm: f64,
}

impl std::fmt::Debug for DesignClearance<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DesignClearance")
            .field("impeller", &self.impeller.name())
            .field("options", &self.options)
            .field("samples", &self.samples.len())
            .field("frusta", &self.frusta.len())
            .field("mesh", &self.mesh)
            .finish()
    }
}

impl<'a> DesignClearance<'a> {
    /// The query of `tool` against `impeller`, with a design mesh of its own at the options'
    /// sampling tolerance (see [`DesignClearance::with_mesh`] to share one).
    ///
    /// Errors: invalid tool, a sampling tolerance that is not finite and > 0, a design the
    /// mesh cannot be built for.
    pub fn new(
        impeller: &'a Impeller,
        tool: &Tool,
        options: ClearanceOptions,
    ) -> Result<Self, PlanError> {
        let tol = options.sample_tol_mm;
        if !(tol.is_finite() && tol > 0.0) {
            return Err(PlanError::param(
                "-",
                "clearance.sample_tol_mm",
                format!("{tol} must be finite and > 0"),
            ));
        }
        let mesh = Arc::new(DesignMesh::new(impeller, tol)?);
        Self::with_mesh(impeller, mesh, tool, options)
    }

    /// The query of `tool` against `impeller` over a shared design mesh of that impeller.
    ///
    /// Errors: invalid tool or a sampling tolerance that is not finite and > 0.
    pub fn with_mesh(
        impeller: &'a Impeller,
        mesh: Arc<DesignMesh>,
        tool: &Tool,
        options: ClearanceOptions,
    ) -> Result<Self, PlanError> {
        tool.validate()?;
        let tol = options.sample_tol_mm;
        if !(tol.is_finite() && tol > 0.0) {
            return Err(PlanError::param(
                "-",
                "clearance.sample_tol_mm",
                format!("{tol} must be finite and > 0"),
            ));
        }
        let c = &tool.cutter;
        let mut samples = Vec::new();
        let mut upper_samples = Vec::new();
        let (centre, grid_start) = match c.shape {
            CutterShape::BallEnd { radius } => (Some(radius), radius),
            CutterShape::TaperedBallEnd {
                ball_radius,
                half_angle,
            } => (Some(ball_radius), ball_radius * (1.0 - half_angle.sin())),
            CutterShape::BullNose { corner_radius, .. } => (Some(corner_radius), 0.0),
            _ => (None, 0.0),
        };
        if let Some(h) = centre.filter(|h| *h <= c.flute_length) {
            samples.push((h, c.shape.radius_at(h), ToolPart::Cutter));
        }
        let holder_len: f64 = c.holder.iter().map(|s| s.length).sum();
        let top = c.overall_length + holder_len;
        let mut h = grid_start.min(c.flute_length);
        loop {
            let rho = c.assembly_radius_at(h).unwrap_or(0.0);
            let part = if h <= c.flute_length {
                ToolPart::Cutter
            } else if h <= c.overall_length {
                ToolPart::Shank
            } else {
                ToolPart::Holder
            };
            if part == ToolPart::Cutter {
                samples.push((h, rho, part));
            } else {
                upper_samples.push((h, rho, part));
            }
            if h >= top {
                break;
            }
            let nominal = rho.max(tool.nominal_radius().min(rho.max(1e-3)));
            let step = (nominal / 2.0).min((2.0 * nominal * tol).sqrt()).max(1e-3);
            // Never step over a part boundary: sample both ends of every part.
            let mut next = h + step;
            for b in [c.flute_length, c.overall_length, top] {
                if h < b && next > b {
                    next = b;
                }
            }
            h = next;
        }
        // By height: the blade search bisects runs of neighbouring samples.
        samples.sort_by(|a, b| a.0.total_cmp(&b.0));
        let chord = mesh.chord_mm;
        let frusta = c
            .frusta(chord)
            .map_err(|e| PlanError::tool("-", &c.name, e.to_string()))?
            .into_iter()
            .filter(|f| f.h0 >= c.flute_length - 1e-12)
            .filter_map(|f| {
                let part = if f.h0 < c.overall_length - 1e-12 {
                    ToolPart::Shank
                } else {
                    ToolPart::Holder
                };
                frustum_shape(f.h0, f.h1, f.r0, f.r1, chord).map(|shape| FrustumShape {
                    shape,
                    h_mid: 0.5 * (f.h0 + f.h1),
                    r_mid: 0.5 * (f.r0 + f.r1),
                    part,
                })
            })
            .collect();
        let hub = impeller.hub().meridional();
        let (t0, t1) = hub.domain();
        let (a, b) = (hub.point(t0), hub.point(t1));
        let mut rows = vec![(Row::Main, RowAngles::new(impeller.main()))];
        if let Some(s) = impeller.splitter() {
            rows.push((Row::Splitter, RowAngles::new(s)));
        }
        let flute_reach_mm = samples.iter().map(|s| s.0).fold(0.0, f64::max)
            + samples.iter().map(|s| s.1).fold(0.0, f64::max);
        let widest = samples
            .iter()
            .chain(&upper_samples)
            .map(|s| s.1)
            .fold(c.shank_radius, f64::max);
        let widest = c
            .holder
            .iter()
            .map(|h| h.bottom_radius.max(h.top_radius))
            .fold(widest, f64::max);
        let sphere_poke_mm = match c.shape {
            CutterShape::TaperedBallEnd { half_angle, .. }
            | CutterShape::TaperedFlatEnd { half_angle, .. } => {
                samples.iter().map(|s| s.1).fold(0.0, f64::max) * (1.0 - half_angle.cos())
            }
            _ => 0.0,
        };
        Ok(Self {
            impeller,
            options,
            samples,
            upper_samples,
            frusta,
            mesh,
            hub_z_max: a[0].max(b[0]),
            hub_r_max: a[1].max(b[1]),
            hub_ends: [
                ContourEnd::new(hub, t0, -1.0, (a[0].max(b[0]), a[1].max(b[1]))),
                ContourEnd::new(hub, t1, 1.0, (a[0].max(b[0]), a[1].max(b[1]))),
            ],
            rows,
            reach_mm: top + widest,
            flute_reach_mm,
            sphere_poke_mm,
            ball_centre_mm: match c.shape {
                CutterShape::BallEnd { radius } => Some(radius),
                CutterShape::TaperedBallEnd { ball_radius, .. } => Some(ball_radius),
                _ => None,
            }
            .filter(|h| *h <= c.flute_length),
            non_cutting_margin_mm: 0.0,
        })
    }

    /// The same query with other options (the design mesh is kept: its chord stays that of
    /// the original sampling tolerance).
    pub fn with_options(&self, options: ClearanceOptions) -> Self {
        Self {
            options,
            ..self.clone()
        }
    }

    /// The same query with the shank and holder read `margin_mm` nearer to the hub and
    /// blades than they are (as if that much wider): a check against a floor `f` then keeps
    /// the cutting part `f` and the parts that do not cut `f + margin_mm` from the material.
    /// A finishing floor lets the flutes reach the tolerance into the surface they finish;
    /// shank and holder must not touch the finished part at all. The value stays a lower
    /// bound of the (shifted) clearance and 1-Lipschitz in every tool point's displacement,
    /// so the motion certificates hold unchanged. Negative margins are taken as 0.
    pub fn with_non_cutting_margin(&self, margin_mm: f64) -> Self {
        Self {
            non_cutting_margin_mm: margin_mm.max(0.0),
            ..self.clone()
        }
    }

    /// Height of the ball centre above the tip (ball and tapered ball ends): the sample
    /// there is the ball itself, exactly; the samples below it bound the ball from outside
    /// (conservative spheres that reach below the tip).
    pub fn ball_centre_mm(&self) -> Option<f64> {
        self.ball_centre_mm
    }

    /// The largest amount by which [`Self::clearance`] of the cutter can read below the true
    /// clearance near a surface (mm): half the sampling tolerance (the rim band between two
    /// samples) plus how far a sample's sphere pokes out of a tapered cutter's cone. A check
    /// against a floor the tool is meant to reach exactly allows this much below it.
    pub fn sampling_error_mm(&self) -> f64 {
        0.5 * self.options.sample_tol_mm + self.sphere_poke_mm
    }

    /// The options of this query.
    pub fn options(&self) -> ClearanceOptions {
        self.options
    }

    /// The design mesh (shareable with [`DesignClearance::with_mesh`]).
    pub fn mesh(&self) -> &Arc<DesignMesh> {
        &self.mesh
    }

    /// The cutter's sample (height, radius) pairs along the tool axis.
    pub fn samples(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.samples.iter().map(|s| (s.0, s.1))
    }

    /// Signed distance of the hub body at `p` (negative inside).
    pub fn hub_signed_distance(&self, p: &Point3) -> f64 {
        let d = self.impeller.hub().signed_distance(&p.coords);
        let r = p.x.hypot(p.y);
        d.max(p.z - self.hub_z_max).max(r - self.hub_r_max)
    }

    /// Signed distance below the shroud contour (positive inside the channel envelope).
    pub fn shroud_signed_distance(&self, p: &Point3) -> f64 {
        -self.impeller.shroud().signed_distance(&p.coords)
    }

    /// Signed distance of the nearest blade (negative inside it) and which blade it is
    /// (exact: NURBS projections on the two instances of each row around `p`).
    pub fn blade_signed_distance(&self, p: &Point3) -> (f64, DesignPart) {
        self.blade_signed_distance_below(p, f64::INFINITY).0
    }

    /// Whether the nearest blade is at least `d` from `p`: [`Self::blade_signed_distance`]
    /// `≥ d`, with the instances the blade meshes keep farther than `d` left unprojected (the
    /// same answer for the cost of the mesh bounds wherever no blade comes near).
    pub fn blade_distance_at_least(&self, p: &Point3, d: f64) -> bool {
        self.blade_signed_distance_below(p, d).0 .0 >= d
    }

    /// [`Self::blade_signed_distance`] where only distances below `floor` matter. The
    /// candidate instances are projected on nearest in polar angle first; an instance whose
    /// whole-sides mesh (turned into the reference blade's frame) keeps `p` at least
    /// `c + max(t/2, x)` away, `x` the smaller of `floor` and the least distance so far, is
    /// outside it by at least `x` and is not projected on. Returns the least exact distance
    /// of the projected instances and whether one was left out only by the floor: the answer
    /// is exact when it is below `floor` or none was.
    fn blade_signed_distance_below(&self, p: &Point3, floor: f64) -> ((f64, DesignPart), bool) {
        self.blade_distance_of_candidates(p, floor, true)
    }

    /// [`Self::blade_signed_distance`] projecting on every candidate instance (no mesh
    /// bound): the reference the tests hold the pruned distance to.
    #[doc(hidden)]
    pub fn blade_signed_distance_exhaustive(&self, p: &Point3) -> (f64, DesignPart) {
        self.blade_distance_of_candidates(p, f64::INFINITY, false).0
    }

    /// The distance of the two instances of each row around `p` (see
    /// [`Self::blade_signed_distance_below`]; `prune` false projects on all of them).
    fn blade_distance_of_candidates(
        &self,
        p: &Point3,
        floor: f64,
        prune: bool,
    ) -> ((f64, DesignPart), bool) {
        let c = self.mesh.side_chord_mm;
        let half_t = 0.5 * self.mesh.thickest_blade_mm;
        // The two instances of each row around `p`, nearest in polar angle first.
        let mut candidates: [Option<(f64, Row, usize)>; 4] = [None; 4];
        for (slot, (row, angles)) in self.rows.iter().enumerate().take(2) {
            let Some(set) = self.row_set(*row) else {
                continue;
            };
            let n = set.count();
            let pitch = set.pitch_rad();
            let rel = (p.y.atan2(p.x) - angles.angle_near(p)).rem_euclid(std::f64::consts::TAU);
            let k0 = ((rel / pitch).floor() as usize) % n;
            let behind = rel - k0 as f64 * pitch;
            candidates[2 * slot] = Some((behind, *row, k0));
            candidates[2 * slot + 1] = Some((pitch - behind, *row, (k0 + 1) % n));
        }
        candidates.sort_by(|a, b| {
            let key = |x: &Option<(f64, Row, usize)>| x.map_or(f64::INFINITY, |x| x.0);
            key(a).total_cmp(&key(b))
        });
        let d_shroud = self.impeller.shroud().signed_distance(&p.coords);
        let mut best = (f64::INFINITY, DesignPart::Hub);
        let mut skipped = false;
        for &(_, row, k) in candidates.iter().flatten() {
            let Some(set) = self.row_set(row) else {
                continue;
            };
            let local = set.rotation(k).inverse() * p.coords;
            // An instance the mesh keeps `c + max(t/2, x)` away is outside it by at least
            // `x`: it cannot come below the floor nor the best distance so far.
            let cap = c + half_t.max(floor.min(best.0));
            let cap = cap + 1e-9 * (1.0 + cap.abs());
            let mesh = self.mesh.reference_sides.iter().find(|(r, _)| *r == row);
            if let Some((_, mesh)) = mesh.filter(|_| prune && cap.is_finite()) {
                let q = PVec::new(local.x, local.y, local.z);
                if !mesh.any_within(q, cap) {
                    skipped |= floor < best.0;
                    continue;
                }
            }
            let (sp, dp) = blade_side_distance(set.blade(), Side::Pressure, &local, None);
            let (_, ds) = blade_side_distance(set.blade(), Side::Suction, &local, None);
            let ((u0, u1), _) = set.blade().side(Side::Pressure).domain();
            let end = usize::from(sp.u > 0.5 * (u0 + u1));
            let half_gap = self
                .rows
                .iter()
                .find(|(r, _)| *r == row)
                .map_or(half_t, |(_, angles)| angles.edge_half_gaps[end]);
            let d = impeller_model::query::blade_solid_distance(dp, ds, d_shroud, half_gap);
            if d < best.0 {
                best = (d, DesignPart::Blade { row, index: k });
            }
        }
        (best, skipped)
    }

    /// The blade set of `row`.
    fn row_set(&self, row: Row) -> Option<&BladeSet> {
        match row {
            Row::Main => Some(self.impeller.main()),
            Row::Splitter => self.impeller.splitter(),
        }
    }

    /// Signed distance of the selected design parts at `p` (negative inside material; for
    /// the shroud, negative beyond it) and the nearest part. Exact (NURBS).
    pub fn design_signed_distance(&self, p: &Point3) -> (f64, DesignPart) {
        self.parts_signed_distance(&self.options.parts, p)
    }

    /// [`Self::design_signed_distance`] of the parts `parts`.
    fn parts_signed_distance(&self, parts: &PartSet, p: &Point3) -> (f64, DesignPart) {
        let mut best = (f64::INFINITY, DesignPart::Hub);
        if parts.hub {
            best = (self.hub_signed_distance(p), DesignPart::Hub);
        }
        if parts.shroud {
            let d = self.shroud_signed_distance(p);
            if d < best.0 {
                best = (d, DesignPart::Shroud);
            }
        }
        if parts.blades {
            let b = self.blade_signed_distance(p);
            if b.0 < best.0 {
                best = b;
            }
        }
        best
    }

    /// The smallest clearance of the tool at `cl` (see the module docs for what it bounds).
    pub fn clearance(&self, cl: &CutterLocation) -> Clearance {
        self.evaluate(cl, Want::MINIMUM)
    }

    /// Whether the tool at `cl` keeps at least `min_clearance_mm` from the design (stops at
    /// the first part that fails).
    pub fn is_clear(&self, cl: &CutterLocation, min_clearance_mm: f64) -> bool {
        self.evaluate(
            cl,
            Want {
                cap: min_clearance_mm,
                fail_below: min_clearance_mm,
                upper: true,
            },
        )
        .distance_mm
            >= min_clearance_mm
    }

    /// The smallest clearance when it is below `cap_mm`, else a value of at least `cap_mm`
    /// (the search stops refining where nothing can fall below the cap): a lower bound of
    /// the clearance for the certified motion checks, which need no more than that.
    pub fn clearance_capped(&self, cl: &CutterLocation, cap_mm: f64) -> Clearance {
        self.evaluate(
            cl,
            Want {
                cap: cap_mm,
                fail_below: f64::NEG_INFINITY,
                upper: true,
            },
        )
    }

    /// [`Self::clearance`] when it is at least `min_clearance_mm`, else `None`: one query where
    /// [`Self::is_clear`] followed by [`Self::clearance`] would take two (it stops at the
    /// first part found below `min_clearance_mm`, and otherwise finds the minimum).
    pub fn clearance_if_clear(
        &self,
        cl: &CutterLocation,
        min_clearance_mm: f64,
    ) -> Option<Clearance> {
        let c = self.evaluate(
            cl,
            Want {
                cap: f64::INFINITY,
                fail_below: min_clearance_mm,
                upper: true,
            },
        );
        (c.distance_mm >= min_clearance_mm).then_some(c)
    }

    /// Whether the whole motion from `a` to `b` keeps at least `min_clearance_mm − tol_mm` from
    /// the design: tip on the straight line, tool axis on the great circle (the motion a
    /// five-axis controller makes between two blocks, up to the post's linearisation
    /// tolerance). Returns the parameter `s ∈ (0, 1)` of the first sampled posture found
    /// below `min_clearance_mm` when the motion is not clear.
    ///
    /// Method: certified bisection. Between two postures `s₀ < s₁`, no tool point moves more
    /// than `D = (|Δtip| + θ·R)(s₁ − s₀)`, with `θ` the angle between the end axes and `R` the
    /// tool's reach (holder top plus its radius), and the clearance is 1-Lipschitz in that
    /// displacement, so the clearance on `[s₀, s₁]` is at least `(c₀ + c₁ − D)/2`. Intervals
    /// whose bound reaches `min_clearance_mm − tol_mm` are accepted; the others are split at
    /// their midpoint, which is queried. The bound is as exact as [`Self::clearance`] itself.
    ///
    /// The lever arm is split by tool part: the shank and holder (with the shroud samples
    /// above the flutes) reach `R`, the cutter samples only `R_f` (highest sample plus the
    /// widest sample radius), typically a fifth of `R`. The upper parts are measured first at
    /// both ends (capped where they settle the whole motion): when both keep them
    /// `floor + D_u/2` clear (`D_u = |Δtip| + θ·R`), the bound `(u₀ + u₁ − D_u)/2 ≥ floor` holds
    /// for them on `[0, 1]`. Otherwise the upper parts are bisected on their own, from their
    /// end clearances `u₀, u₁` with `D_u`, each midpoint measuring only them (frusta against
    /// the meshes: no blade projection). The cutter is bisected on its own with
    /// `D_f = |Δtip| + θ·R_f` from the ends' whole-tool clearances (which bound the cutter's
    /// from below). The whole tool is clear where both parts are, so the two bisections
    /// certify the motion as one bisection of the whole tool with `D_u` would, with fewer
    /// and cheaper queries: a cutter running beside a blade no longer pays for the holder's
    /// lever arm.
    ///
    /// Cost: 2 queries when the ends are clear by more than `D/2`; about
    /// `log₂(D/tol_mm)` more per place where the motion comes within `D/2` of the design,
    /// at most `max_queries` (then the motion counts as not clear, at the last midpoint);
    /// two capped shank/holder queries more when the whole tool does not settle at once.
    pub fn segment_clearance(
        &self,
        a: &CutterLocation,
        b: &CutterLocation,
        min_clearance_mm: f64,
        tol_mm: f64,
        max_queries: usize,
    ) -> Result<(), f64> {
        let ca = self.clearance(a).distance_mm;
        let cb = self.clearance(b).distance_mm;
        self.segment_clearance_between(
            (a, ca),
            (b, cb),
            min_clearance_mm,
            tol_mm,
            max_queries.saturating_sub(2),
        )
    }

    /// [`Self::segment_clearance`] when the clearances `ca`, `cb` of the end postures are
    /// already known (from [`Self::clearance`]); `max_queries` counts the midpoints only.
    pub fn segment_clearance_between(
        &self,
        (a, ca): (&CutterLocation, f64),
        (b, cb): (&CutterLocation, f64),
        min_clearance_mm: f64,
        tol_mm: f64,
        max_queries: usize,
    ) -> Result<(), f64> {
        if ca < min_clearance_mm {
            return Err(0.0);
        }
        if cb < min_clearance_mm {
            return Err(1.0);
        }
        let at = |s: f64| CutterLocation {
            tip: a.tip + (b.tip - a.tip) * s,
            axis: a.axis.slerp(&b.axis, s),
        };
        let floor = min_clearance_mm - tol_mm.max(0.0);
        let (shift, turn) = ((b.tip - a.tip).norm(), a.axis.angle(&b.axis));
        let whole = shift + turn * self.reach_mm;
        if 0.5 * (ca + cb - whole) >= floor {
            return Ok(());
        }
        // The upper parts at both ends, exact below `need` (where they settle on [0, 1]).
        let need = floor + 0.5 * whole;
        let upper_at = |cl: &CutterLocation, c: f64| {
            let mut best = NO_CLEARANCE;
            let only_upper = Want {
                cap: need,
                fail_below: f64::NEG_INFINITY,
                upper: true,
            };
            self.upper_and_frusta(cl, only_upper, &mut best);
            // The whole tool's clearance bounds the upper parts' from below too.
            best.distance_mm.min(need).max(c)
        };
        let (ua, ub) = (upper_at(a, ca), upper_at(b, cb));
        let mut queries = 0;
        if ua < need || ub < need {
            // The upper parts bisected on their own with the holder's lever arm.
            self.bisect(
                (ua, ub),
                whole,
                floor,
                min_clearance_mm,
                (max_queries, &mut queries),
                |s, cap| {
                    let mut best = NO_CLEARANCE;
                    let want = Want {
                        cap,
                        fail_below: min_clearance_mm,
                        upper: true,
                    };
                    self.upper_and_frusta(&at(s), want, &mut best);
                    best.distance_mm.min(cap)
                },
            )?;
        }
        // The cutter with its own lever arm, from its own clearances at the ends when the
        // whole tool's (the upper parts' where they are the nearer) do not settle it: exact
        // below `floor + D_f/2`, where it settles on [0, 1].
        let flute = shift + turn * self.flute_reach_mm;
        let (ka, kb) = if 0.5 * (ca + cb - flute) >= floor {
            (ca, cb)
        } else {
            let settle = floor + 0.5 * flute;
            let cutter_at = |cl: &CutterLocation, c: f64| {
                if c >= settle {
                    return c;
                }
                self.evaluate(
                    cl,
                    Want {
                        cap: settle,
                        fail_below: f64::NEG_INFINITY,
                        upper: false,
                    },
                )
                .distance_mm
                .max(c)
            };
            (cutter_at(a, ca), cutter_at(b, cb))
        };
        self.bisect(
            (ka, kb),
            flute,
            floor,
            min_clearance_mm,
            (max_queries, &mut queries),
            |s, cap| {
                self.evaluate(
                    &at(s),
                    Want {
                        cap,
                        fail_below: min_clearance_mm,
                        upper: false,
                    },
                )
                .distance_mm
            },
        )
    }

    /// Certified bisection of one part's clearance over `s ∈ [0, 1]` (see
    /// [`Self::segment_clearance_between`]): end values `(c0, c1)`, displacement `span` over
    /// the whole motion, accepted where `(c₀ + c₁ − span·Δs)/2 ≥ floor`; `measure(s, cap)`
    /// gives the part's clearance at `s`, exact below `cap`. `Err(s)` at a midpoint below
    /// `min_clearance` or when the shared query budget `(max, used)` runs out.
    fn bisect(
        &self,
        (c0, c1): (f64, f64),
        span: f64,
        floor: f64,
        min_clearance: f64,
        (max_queries, queries): (usize, &mut usize),
        measure: impl Fn(f64, f64) -> f64,
    ) -> Result<(), f64> {
        let mut stack = vec![(0.0, c0, 1.0, c1)];
        while let Some((s0, c0, s1, c1)) = stack.pop() {
            if 0.5 * (c0 + c1 - span * (s1 - s0)) >= floor {
                continue;
            }
            let sm = 0.5 * (s0 + s1);
            if *queries >= max_queries {
                return Err(sm);
            }
            // The midpoint's clearance matters only up to the value that settles both
            // halves; above it, that value itself is the bound the halves need.
            let settle = 2.0 * floor - c0.min(c1) + 0.5 * span * (s1 - s0);
            let cm = measure(sm, settle.max(min_clearance));
            *queries += 1;
            if cm < min_clearance {
                return Err(sm);
            }
            stack.push((sm, cm, s1, c1));
            stack.push((s0, c0, sm, cm));
        }
        Ok(())
    }

    /// The clearance of the reference method: every cutter sample measured, with the exact
    /// blade distance wherever the blade mesh comes within [`EXACT_BAND_MM`] of its ball (else
    /// the mesh's lower bound, as in [`Self::clearance`]) and no pruning; then the shroud
    /// samples and the shank and holder frusta as [`Self::clearance`] measures them. The
    /// fast query is a lower bound of this answer and equals it where it lies within
    /// [`EXACT_BAND_MM`]; kept for the tests that check so. Cost: O(L / s) mesh queries and
    /// as many exact blade projections as samples in the band.
    #[doc(hidden)]
    pub fn clearance_exhaustive(&self, cl: &CutterLocation) -> Clearance {
        let axis: Vector3 = cl.axis.into_inner();
        let parts = self.options.parts;
        let c = self.mesh.side_chord_mm;
        let half_t = 0.5 * self.mesh.thickest_blade_mm;
        let mut best = NO_CLEARANCE;
        for &(h, rho, part) in &self.samples {
            if h <= self.options.above_mm {
                continue;
            }
            let p = cl.tip + axis * h;
            let mut d = self.parts_signed_distance(
                &PartSet {
                    blades: false,
                    ..parts
                },
                &p,
            );
            if parts.blades {
                let (dm, dp) = self
                    .mesh
                    .side_mesh_distance_within(&p, f64::INFINITY)
                    .unwrap_or((f64::INFINITY, DesignPart::Hub));
                let b = if dm - c - half_t >= rho + EXACT_BAND_MM {
                    (dm - c, dp)
                } else {
                    self.blade_signed_distance_exhaustive(&p)
                };
                if b.0 < d.0 {
                    d = b;
                }
            }
            if d.0 - rho < best.distance_mm {
                best = Clearance {
                    distance_mm: d.0 - rho,
                    design_part: d.1,
                    tool_part: part,
                    height_mm: h,
                };
            }
        }
        self.upper_and_frusta(cl, Want::MINIMUM, &mut best);
        best
    }

    /// The clearance at `cl` as `want` asks for it: exact below `want.cap`, else `want.cap`
    /// (a lower bound); returns as soon as a part is found below `want.fail_below`.
    fn evaluate(&self, cl: &CutterLocation, want: Want) -> Clearance {
        let mut best = self.evaluate_parts(cl, want);
        best.distance_mm = best.distance_mm.min(want.cap);
        best
    }

    /// [`Self::evaluate`] before the cap: the smallest clearance found, which is above the cap
    /// (possibly infinite) when nothing comes below it.
    fn evaluate_parts(&self, cl: &CutterLocation, want: Want) -> Clearance {
        let axis: Vector3 = cl.axis.into_inner();
        let mut best = NO_CLEARANCE;
        // Below this the check fails (−∞: no check, the minimum is wanted).
        let parts = self.options.parts;
        let first = self
            .samples
            .partition_point(|s| s.0 <= self.options.above_mm);
        let samples = &self.samples[first..];
        // The exact and cheap parts first (a meridional projection each): they fix a bound
        // the blade search below prunes with, and fail a check early.
        if parts.shroud {
            for &(h, rho, part) in samples {
                let ds = self.shroud_signed_distance(&(cl.tip + axis * h));
                if ds - rho < best.distance_mm {
                    best = Clearance {
                        distance_mm: ds - rho,
                        design_part: DesignPart::Shroud,
                        tool_part: part,
                        height_mm: h,
                    };
                    if want.failed(&best) {
                        return best;
                    }
                }
            }
        }
        if parts.hub && !samples.is_empty() && self.hub_search(cl, samples, want, &mut best) {
            return best;
        }
        if parts.blades && !samples.is_empty() && self.blade_search(cl, samples, want, &mut best) {
            return best;
        }
        if want.upper {
            self.upper_and_frusta(cl, want, &mut best);
        }
        best
    }

    /// The hub against the cutter samples `samples` (sorted by height), best first (see the
    /// module docs): lowers `best`; `true` when the check `want` failed.
    fn hub_search(
        &self,
        cl: &CutterLocation,
        samples: &[(f64, f64, ToolPart)],
        want: Want,
        best: &mut Clearance,
    ) -> bool {
        let axis: Vector3 = cl.axis.into_inner();
        let n = samples.len();
        let failed = |b: &Clearance| want.failed(b);
        let hub_at = |i: usize, best: &mut Clearance| -> f64 {
            let (h, rho, part) = samples[i];
            let d = self.hub_signed_distance(&(cl.tip + axis * h));
            if d - rho < best.distance_mm {
                *best = Clearance {
                    distance_mm: d - rho,
                    design_part: DesignPart::Hub,
                    tool_part: part,
                    height_mm: h,
                };
            }
            d
        };
        let (first, last) = (samples[0].0, samples[n - 1].0);
        if n < 3 || !self.hub_is_lipschitz_on(&(cl.tip + axis * first), &(cl.tip + axis * last)) {
            for i in 0..n {
                hub_at(i, best);
                if failed(best) {
                    return true;
                }
            }
            return false;
        }
        let d0 = hub_at(0, best);
        let d1 = hub_at(n - 1, best);
        if failed(best) {
            return true;
        }
        let mut open = SCRATCH.with(|s| s.take());
        open.clear();
        open.push(Pending::range(
            samples,
            1,
            n - 2,
            Some((first, d0)),
            Some((last, d1)),
            |valley| valley,
        ));
        let mut failed_now = false;
        while !open.is_empty() {
            let need = want.need(best);
            let k = Pending::lowest(&open);
            if open[k].bound() >= need {
                break;
            }
            if let Pending::Range {
                lo,
                hi,
                left,
                right,
                ..
            } = open.swap_remove(k)
            {
                let m = lo + (hi - lo) / 2;
                let anchor = Some((samples[m].0, hub_at(m, best)));
                if failed(best) {
                    failed_now = true;
                    break;
                }
                if m > lo {
                    open.push(Pending::range(samples, lo, m - 1, left, anchor, |v| v));
                }
                if m < hi {
                    open.push(Pending::range(samples, m + 1, hi, anchor, right, |v| v));
                }
            }
        }
        open.clear();
        SCRATCH.with(|s| s.replace(open));
        failed_now
    }

    /// Whether the hub's signed distance is 1-Lipschitz along the segment `p0 p1` (module
    /// docs): at each end `e` of the contour that no cap covers, the meridional trace of the
    /// segment stays out of the quadrant beyond the end on the material side,
    /// `(x − e)·T ≥ 0` and `(x − e)·n ≤ 0` (`T` the tangent pointing away from the contour,
    /// `n` the channel-side normal), where the sign of the distance to the contour jumps on
    /// the ray `e + s·T`. O(1).
    fn hub_is_lipschitz_on(&self, p0: &Point3, p1: &Point3) -> bool {
        let zr = |p: &Point3| [p.z, p.x.hypot(p.y)];
        let (a, b) = (zr(p0), zr(p1));
        // Least radius along the segment: its distance from the axis.
        let (dx, dy) = (p1.x - p0.x, p1.y - p0.y);
        let l2 = dx * dx + dy * dy;
        let s = if l2 > 0.0 {
            (-(p0.x * dx + p0.y * dy) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let r_min = (p0.x + s * dx).hypot(p0.y + s * dy);
        // Largest value along the segment of g = w·((z, r) − e): z is linear in the segment
        // parameter and r convex, so g is convex when w_r ≥ 0 (largest at an end), and
        // below its linear part plus w_r·(r_min − e_r) otherwise.
        let sup = |w: [f64; 2], e: [f64; 2]| -> f64 {
            let lin = |q: [f64; 2], r: f64| w[0] * (q[0] - e[0]) + w[1] * (r - e[1]);
            if w[1] >= 0.0 {
                lin(a, a[1]).max(lin(b, b[1]))
            } else {
                lin(a, r_min).max(lin(b, r_min))
            }
        };
        self.hub_ends.iter().all(|end| {
            end.capped
                || sup(end.away, end.point) < 0.0
                || sup([-end.normal[0], -end.normal[1]], end.point) < 0.0
        })
    }

    /// The blades against the cutter samples `samples` (sorted by height), best first (see
    /// the module docs): lowers `best`; `true` when the check `want` failed.
    fn blade_search(
        &self,
        cl: &CutterLocation,
        samples: &[(f64, f64, ToolPart)],
        want: Want,
        best: &mut Clearance,
    ) -> bool {
        let axis: Vector3 = cl.axis.into_inner();
        let c = self.mesh.side_chord_mm;
        let half_t = 0.5 * self.mesh.thickest_blade_mm;
        let n = samples.len();
        let mut open = SCRATCH.with(|s| s.take());
        open.clear();
        open.push(Pending::Range {
            lo: 0,
            hi: n - 1,
            left: None,
            right: None,
            bound: f64::NEG_INFINITY,
        });
        let mut failed = false;
        while !open.is_empty() {
            // Only samples that could lower the answer (or fail the check) matter.
            let need = want.need(best);
            let k = Pending::lowest(&open);
            if open[k].bound() >= need {
                break;
            }
            match open.swap_remove(k) {
                Pending::Exact { index, .. } => {
                    let (h, rho, part) = samples[index];
                    let ((d, dp), skipped) =
                        self.blade_signed_distance_below(&(cl.tip + axis * h), need + rho);
                    // A left-out blade is only known to be at least `need` away: nothing to
                    // record unless an exact distance came below that.
                    if (d < need + rho || !skipped) && d - rho < best.distance_mm {
                        *best = Clearance {
                            distance_mm: d - rho,
                            design_part: dp,
                            tool_part: part,
                            height_mm: h,
                        };
                    }
                }
                Pending::Range {
                    lo,
                    hi,
                    left,
                    right,
                    ..
                } => {
                    let m = lo + (hi - lo) / 2;
                    let (h, rho, part) = samples[m];
                    let reach = (h - samples[lo].0).max(samples[hi].0 - h);
                    let rho_max = samples[lo..=hi].iter().map(|s| s.1).fold(rho, f64::max);
                    // Beyond this, no sample of the range is inside a blade or below `need`.
                    let cap = c + half_t.max(need + rho_max) + reach;
                    let Some((dm, dp)) = self
                        .mesh
                        .side_mesh_distance_within(&(cl.tip + axis * h), cap + 1e-9 * (1.0 + cap))
                    else {
                        continue;
                    };
                    let outside = dm - c - half_t >= 0.0;
                    if (outside && dm - c - rho >= need) || dm - c - half_t >= rho + EXACT_BAND_MM {
                        if dm - c - rho < best.distance_mm {
                            *best = Clearance {
                                distance_mm: dm - c - rho,
                                design_part: dp,
                                tool_part: part,
                                height_mm: h,
                            };
                        }
                    } else {
                        open.push(Pending::Exact {
                            index: m,
                            bound: if outside {
                                dm - c - rho
                            } else {
                                f64::NEG_INFINITY
                            },
                        });
                    }
                    let anchor = Some((h, dm));
                    // The mesh bound holds only where the run is outside every blade.
                    let bound = |valley: f64| {
                        if valley - c >= half_t {
                            valley - c
                        } else {
                            f64::NEG_INFINITY
                        }
                    };
                    if m > lo {
                        open.push(Pending::range(samples, lo, m - 1, left, anchor, bound));
                    }
                    if m < hi {
                        open.push(Pending::range(samples, m + 1, hi, anchor, right, bound));
                    }
                }
            }
            if want.failed(best) {
                failed = true;
                break;
            }
        }
        open.clear();
        SCRATCH.with(|s| s.replace(open));
        failed
    }

    /// The shroud samples above the flutes and the shank and holder frusta (module docs):
    /// lowers `best`; `true` when the check `want` failed.
    fn upper_and_frusta(&self, cl: &CutterLocation, want: Want, best: &mut Clearance) -> bool {
        let axis: Vector3 = cl.axis.into_inner();
        let failed = |b: &Clearance| want.failed(b);
        if self.options.parts.shroud {
            for &(h, rho, part) in &self.upper_samples {
                let d = self.shroud_signed_distance(&(cl.tip + axis * h));
                if d - rho < best.distance_mm {
                    *best = Clearance {
                        distance_mm: d - rho,
                        design_part: DesignPart::Shroud,
                        tool_part: part,
                        height_mm: h,
                    };
                    if failed(best) {
                        return true;
                    }
                }
            }
        }
        if self.frusta.is_empty() || !(self.options.parts.hub || self.options.parts.blades) {
            return false;
        }
        let a = PVec::new(axis.x, axis.y, axis.z);
        let pose = Pose::from_parts(pv(&cl.tip), Rotation::from_rotation_arc(PVec::Z, a));
        let c = self.mesh.chord_mm;
        let lift = self.non_cutting_margin_mm;
        let meshes = [
            (self.options.parts.hub, &self.mesh.hub, false),
            (self.options.parts.blades, &self.mesh.blades, true),
        ];
        for f in &self.frusta {
            let mut crossed = false;
            for &(wanted, mesh, blades) in &meshes {
                if !wanted {
                    continue;
                }
                // Only contacts that could lower the answer (or fail the check) matter.
                let reach = want.need(best);
                let prediction = (reach + c + lift).max(0.0);
                let Some((dist, point)) = frustum_mesh_contact(&pose, &f.shape, mesh, prediction)
                else {
                    continue;
                };
                crossed |= dist <= 0.0;
                let d = dist - c - lift;
                if d < best.distance_mm {
                    let at = Point3::new(point.x, point.y, point.z);
                    *best = Clearance {
                        distance_mm: d,
                        design_part: if blades {
                            self.mesh.blade_mesh_distance(&at).1
                        } else {
                            DesignPart::Hub
                        },
                        tool_part: f.part,
                        height_mm: (at - cl.tip).dot(&axis).max(0.0),
                    };
                    if failed(best) {
                        return true;
                    }
                }
            }
            // A frustum buried inside material crosses no mesh triangle; its axis midpoint is
            // then inside, which the hub distance and the blade mesh rule out cheaply first.
            if !crossed && self.may_be_inside(&(cl.tip + axis * f.h_mid)) {
                let mid = cl.tip + axis * f.h_mid;
                let (d, dp) = self.design_signed_distance(&mid);
                if d < 0.0 && d - f.r_mid - lift < best.distance_mm {
                    *best = Clearance {
                        distance_mm: d - f.r_mid - lift,
                        design_part: dp,
                        tool_part: f.part,
                        height_mm: f.h_mid,
                    };
                    if failed(best) {
                        return true;
                    }
                }
            }
        }
        false
    }

    /// Whether `p` may lie inside the selected material: `false` only when the hub distance
    /// is positive and the blade mesh keeps `p` outside every blade (`d_m − c ≥ t/2`).
    fn may_be_inside(&self, p: &Point3) -> bool {
        let parts = self.options.parts;
        if parts.hub && self.hub_signed_distance(p) < 0.0 {
            return true;
        }
        if parts.shroud && self.shroud_signed_distance(p) < 0.0 {
            return true;
        }
        if parts.blades {
            let far = self.mesh.side_chord_mm + 0.5 * self.mesh.thickest_blade_mm;
            return self.mesh.side_mesh_distance_within(p, far).is_some();
        }
        false
    }
}

/// An end of a meridional contour, in the (z, r) half plane.
#[derive(Debug, Clone, Copy)]
struct ContourEnd {
    point: [f64; 2],
    /// Unit tangent pointing away from the contour.
    away: [f64; 2],
    /// Unit channel-side normal.
    normal: [f64; 2],
    /// Whether a cap of the hub body (the inlet plane `z = z_max` or the outlet cylinder
    /// `r = r_max`) passes through the end perpendicular to the tangent: then on the ray
    /// `e + s·T`, where the distance to the contour jumps from `−s` to `s`, the cap's own
    /// distance is `s`, and the capped distance does not jump.
    capped: bool,
}

impl ContourEnd {
    /// The end at parameter `t` of `curve`, whose tangent points away from the contour when
    /// multiplied by `sign` (−1 at the start, +1 at the end of the domain). A degenerate
    /// tangent leaves `away` zero (no segment then passes the Lipschitz test).
    /// `z_max`, `r_max`: the caps of the hub body (module docs).
    fn new(
        curve: &impeller_model::meridional::MeridionalCurve,
        t: f64,
        sign: f64,
        (z_max, r_max): (f64, f64),
    ) -> Self {
        let p = curve.point(t);
        let d = curve.curve().derivs2(t)[1] * sign;
        let l = d.norm();
        let away = if l > 0.0 && l.is_finite() {
            [d[0] / l, d[1] / l]
        } else {
            [0.0, 0.0]
        };
        let n = curve.normal(t);
        // Within 1e-12 (a jump below 1e-9 mm anywhere within 1 m of the end).
        let on_cap = |k: usize, cap: f64| {
            away[k] >= 1.0 - 1e-12 && (p[k] - cap).abs() <= 1e-12 * (1.0 + cap.abs())
        };
        Self {
            point: [p[0], p[1]],
            away,
            normal: [n[0], n[1]],
            capped: on_cap(0, z_max) || on_cap(1, r_max),
        }
    }
}

/// What a query needs: the clearance exactly where it is below `cap` (above, any lower bound
/// at least `cap` will do), and none at all once it is below `fail_below`.
#[derive(Debug, Clone, Copy)]
struct Want {
    cap: f64,
    fail_below: f64,
    /// Whether the shank, the holder and the shroud samples above the flutes are measured
    /// (else the cutter samples alone).
    upper: bool,
}

impl Want {
    /// The exact minimum.
    const MINIMUM: Self = Self {
        cap: f64::INFINITY,
        fail_below: f64::NEG_INFINITY,
        upper: true,
    };

    /// The value below which a sample or part still matters, given the answer so far.
    fn need(&self, best: &Clearance) -> f64 {
        self.cap.min(best.distance_mm)
    }

    fn failed(&self, best: &Clearance) -> bool {
        best.distance_mm < self.fail_below
    }
}

/// No answer yet: infinitely clear.
const NO_CLEARANCE: Clearance = Clearance {
    distance_mm: f64::INFINITY,
    design_part: DesignPart::Hub,
    tool_part: ToolPart::Cutter,
    height_mm: 0.0,
};

/// Open work of the blade search: a run of cutter samples not yet looked at, or one sample
/// whose blade distance must be computed exactly; each with a lower bound of the clearance it
/// can still give (−∞ when nothing bounds it yet).
#[derive(Debug, Clone, Copy)]
enum Pending {
    /// Samples `lo..=hi`, between the samples of known blade mesh distance `left` and `right`
    /// (height, distance).
    Range {
        lo: usize,
        hi: usize,
        left: Option<(f64, f64)>,
        right: Option<(f64, f64)>,
        bound: f64,
    },
    /// Sample `index`, whose mesh bound came within the exact band.
    Exact { index: usize, bound: f64 },
}

impl Pending {
    /// Index of the item with the lowest bound in a non-empty work list (the first of equal
    /// ones).
    fn lowest(open: &[Pending]) -> usize {
        let mut k = 0;
        for (j, item) in open.iter().enumerate() {
            if item.bound() < open[k].bound() {
                k = j;
            }
        }
        k
    }

    fn bound(&self) -> f64 {
        match self {
            Self::Range { bound, .. } | Self::Exact { bound, .. } => *bound,
        }
    }

    /// The run `lo..=hi` between the samples of known distance `left` and `right` (height,
    /// value) of a function 1-Lipschitz along the axis, with the bound `bound(valley) − ρ_max`:
    /// `valley` the lowest point over the run of the two cones `D_l − (h − h_l)` and
    /// `D_r − (h_r − h)` (the least value the function can take there), `ρ_max` the widest
    /// sample radius of the run.
    fn range(
        samples: &[(f64, f64, ToolPart)],
        lo: usize,
        hi: usize,
        left: Option<(f64, f64)>,
        right: Option<(f64, f64)>,
        bound: impl Fn(f64) -> f64,
    ) -> Self {
        let (ha, hb) = (samples[lo].0, samples[hi].0);
        let valley = match (left, right) {
            (Some((hl, dl)), Some((hr, dr))) => {
                let x = (0.5 * (dl - dr + hl + hr)).clamp(ha, hb);
                (dl - (x - hl)).max(dr - (hr - x))
            }
            (Some((hl, dl)), None) => dl - (hb - hl),
            (None, Some((hr, dr))) => dr - (hr - ha),
            (None, None) => f64::NEG_INFINITY,
        };
        let rho_max = samples[lo..=hi].iter().map(|s| s.1).fold(0.0, f64::max);
        Self::Range {
            lo,
            hi,
            left,
            right,
            bound: bound(valley) - rho_max,
        }
    }
}

thread_local! {
    /// The blade search's open list, kept between queries of a thread (no allocation per
    /// query once grown).
    static SCRATCH: std::cell::RefCell<Vec<Pending>> = const { std::cell::RefCell::new(Vec::new()) };
}

#[cfg(test)]
mod ring_frustum_tests {
    use super::*;
    use parry3d_f64::shape::SupportMap;
    use proptest::prelude::*;

    proptest! {
        /// The O(1) support point of the ring frustum is a vertex and attains the largest
        /// `p·d` over all `2n` vertices (brute force), to 1e-12 relative.
        #[test]
        fn support_point_is_the_farthest_vertex(
            h0 in 0.0f64..50.0, dh in 0.5f64..80.0,
            r0 in 0.0f64..30.0, r1 in 0.1f64..30.0,
            chord in 0.005f64..0.2,
            dx in -1.0f64..1.0, dy in -1.0f64..1.0, dz in -1.0f64..1.0,
        ) {
            let f = frustum_shape(h0, h0 + dh, r0, r1, chord).unwrap();
            let d = PVec::new(dx, dy, dz);
            let s = f.local_support_point(d);
            let mut best = f64::NEG_INFINITY;
            let mut is_vertex = false;
            for ring in 0..2 {
                for k in 0..f.n {
                    let v = f.vertex(ring, k);
                    best = best.max(v.dot(d));
                    is_vertex |= (v - s).length() <= 1e-12 * (1.0 + v.length());
                }
            }
            prop_assert!(is_vertex);
            prop_assert!(s.dot(d) >= best - 1e-12 * (1.0 + best.abs()), "{} < {}", s.dot(d), best);
        }
    }

    /// The contact of a frustum with a mesh (own traversal, O(1) support, culling) equals
    /// parry's `query::contact` of the same polyhedron as a `ConvexPolyhedron` against the
    /// same mesh, apart, touching within the prediction and penetrating (1e-7 mm).
    #[test]
    fn mesh_contact_matches_parry_on_the_same_polyhedron() {
        use parry3d_f64::shape::ConvexPolyhedron;
        // A wavy sheet z = 2 sin(x/7) cos(y/5) over 60 × 60 mm, 1.5 mm triangles.
        let n = 40;
        let mut v = Vec::new();
        let mut t = Vec::new();
        for i in 0..=n {
            for j in 0..=n {
                let (x, y) = (-30.0 + 1.5 * i as f64, -30.0 + 1.5 * j as f64);
                v.push(PVec::new(x, y, 2.0 * (x / 7.0).sin() * (y / 5.0).cos()));
            }
        }
        for i in 0..n as u32 {
            for j in 0..n as u32 {
                let a = i * (n as u32 + 1) + j;
                let b = a + n as u32 + 1;
                t.push([a, b, b + 1]);
                t.push([a, b + 1, a + 1]);
            }
        }
        let mesh = TriMesh::new(v, t).unwrap();
        let f = frustum_shape(2.0, 30.0, 3.0, 6.0, 0.05).unwrap();
        let pts: Vec<PVec> = (0..2)
            .flat_map(|r| (0..f.n).map(move |k| (r, k)))
            .map(|(r, k)| f.vertex(r, k))
            .collect();
        let poly = ConvexPolyhedron::from_convex_hull(&pts).unwrap();
        let mut compared = [0usize; 3];
        for k in 0..60 {
            let s = k as f64;
            let a = PVec::new((0.37 * s).sin() * 0.6, (0.23 * s).cos() * 0.6, 1.0).normalize();
            // Tip heights from 6 mm above the sheet to 4 mm into it.
            let tip = PVec::new(
                10.0 * (0.11 * s).sin(),
                10.0 * (0.17 * s).cos(),
                6.0 - 0.3 * s,
            );
            let pose = Pose::from_parts(tip, Rotation::from_rotation_arc(PVec::Z, a));
            for prediction in [0.5, 8.0] {
                let ours = frustum_mesh_contact(&pose, &f, &mesh, prediction);
                let theirs =
                    query::contact(&pose, &poly, &Pose::IDENTITY, &mesh, prediction).unwrap();
                match (ours, theirs) {
                    (None, None) => compared[0] += 1,
                    (Some((d, _)), Some(c)) => {
                        assert!((d - c.dist).abs() <= 1e-7, "pose {k}: {d} vs {}", c.dist);
                        compared[if d < 0.0 { 2 } else { 1 }] += 1;
                    }
                    (o, t) => panic!("pose {k}: ours {o:?}, parry {:?}", t.map(|c| c.dist)),
                }
            }
        }
        assert!(
            compared.iter().all(|&c| c > 0),
            "cases apart/near/penetrating: {compared:?}"
        );
    }

    /// The world box contains every vertex of the frustum at a tilted pose.
    #[test]
    fn world_box_contains_the_polyhedron() {
        let f = frustum_shape(5.0, 40.0, 3.0, 8.0, 0.01).unwrap();
        let a = PVec::new(0.3, -0.5, 0.81).normalize();
        let pose = Pose::from_parts(
            PVec::new(10.0, -4.0, 2.0),
            Rotation::from_rotation_arc(PVec::Z, a),
        );
        let b = f.world_aabb(&pose);
        for ring in 0..2 {
            for k in 0..f.n {
                let p = pose * f.vertex(ring, k);
                assert!(b.contains_local_point(p), "{p:?} outside {b:?}");
            }
        }
    }
}
