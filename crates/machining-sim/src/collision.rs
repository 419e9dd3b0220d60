//! Collisions of the non-cutting parts (shank, holder; the whole tool on rapid moves) with
//! the design, through parry's BVH over the design's triangle mesh.
//!
//! Each part piece is a convex polyhedron: the hull of rings circumscribing the piece's
//! circles (radius / cos(π/N)) at its slab heights (and at intermediate heights for curved
//! pieces), so the polyhedron contains the true solid. `N` ([`ring_segments`]) keeps the
//! polygon within [`RING_EXCESS_MM`] of the circle: a fixed 24 sides stood 0.09 mm proud
//! of a Ø21 holder and read a holder that cleared a blade tip by 0.024 mm as 0.042 mm deep
//! in it. A position collides
//! when a piece's polyhedron intersects the mesh (parry `intersection_test`, BVH-accelerated,
//! O(log T) for T triangles) or when the middle of the piece's axis lies inside the design
//! (a piece buried entirely inside the material does not cross the mesh). The depth is
//! parry's penetration depth (`contact`) against the mesh triangles.
//!
//! Collisions with the stock are found in process on the dexels instead (see
//! [`crate::removal`]): the stock changes with every move, so a mesh of it would have to be
//! rebuilt per move, while the dexels are exact along their rays at no extra cost.

use crate::design::{DesignModel, TriangleMesh};
use crate::error::SimError;
use crate::removal::{PartKind, ToolBody};
use crate::tool_solid::{Piece, RevolvedSolid};
use cam_core::Point3;
use parry3d_f64::math::{Pose, Rotation, Vector};
use parry3d_f64::query::{self, ClosestPoints};
use parry3d_f64::shape::{Capsule, ConvexPolyhedron, TriMesh};

/// Fewest sides of the polygons approximating the part circles.
pub const RING_SEGMENTS: usize = 24;

/// Largest distance (mm) by which a part's circumscribing polygon stands outside its circle
/// (at the polygon's corners): the polyhedra contain the true parts within this much.
pub const RING_EXCESS_MM: f64 = 0.005;

/// Sides of the polygon circumscribing a circle of radius `r` within [`RING_EXCESS_MM`]:
/// the least `N ≥ RING_SEGMENTS` with `r / cos(π/N) − r ≤ RING_EXCESS_MM`.
pub fn ring_segments(r: f64) -> usize {
    if !(r.is_finite() && r > 0.0) {
        return RING_SEGMENTS;
    }
    let half = (r / (r + RING_EXCESS_MM)).clamp(-1.0, 1.0).acos();
    let n = (std::f64::consts::PI / half.max(1e-6)).ceil();
    (n as usize).clamp(RING_SEGMENTS, 4096)
}

/// `1 / cos(π/N)`: how far the corners of the `N`-gon circumscribing a circle stand out, as
/// a factor of its radius.
fn ring_scale(n: usize) -> f64 {
    1.0 / (std::f64::consts::PI / n as f64).cos()
}

/// Slack (mm) subtracted from every clearance cached by [`DesignCollider::check_cached`]:
/// covers the convergence tolerance of parry's distance query (GJK) and rounding.
pub const CLEARANCE_SLACK_MM: f64 = 1e-3;

/// Largest mesh clearance measured by [`DesignCollider::check_cached`] (mm): the capsule–mesh
/// query stops at this distance, which keeps it cheap (BVH pruning) while letting a clear
/// piece skip the positions of a few millimetres of motion.
pub const CLEARANCE_PROBE_MM: f64 = 4.0;

/// One piece of a tool part: its polyhedron in the tool frame, the height of its axis middle,
/// its part, and its bounding capsule (axis heights `h0..h1`, radius: the polyhedron's
/// largest ring radius).
#[derive(Debug, Clone)]
struct PartPiece {
    shape: ConvexPolyhedron,
    mid: f64,
    kind: PartKind,
    h0: f64,
    h1: f64,
    capsule_radius: f64,
}

/// A tool part as convex polyhedra in the tool frame (tip at origin, axis +Z).
#[derive(Debug, Clone)]
pub struct PartShapes {
    pieces: Vec<PartPiece>,
}

fn piece_polyhedron(p: &Piece) -> Option<(ConvexPolyhedron, f64)> {
    let (h0, h1) = p.heights();
    let rings = match p {
        Piece::Frustum { .. } => 2,
        _ => 6,
    };
    let n = ring_segments(p.max_radius());
    let scale = ring_scale(n);
    let mut pts = Vec::with_capacity(rings * n);
    for k in 0..rings {
        let h = h0 + (h1 - h0) * k as f64 / (rings - 1) as f64;
        // Curved pieces: use the largest radius of the neighbouring band so the hull
        // contains the piece.
        let r = match p {
            Piece::Frustum { .. } => p.radius_at(h),
            _ => p.max_radius(),
        } * scale;
        for s in 0..n {
            let t = std::f64::consts::TAU * s as f64 / n as f64;
            pts.push(Vector::new(r * t.cos(), r * t.sin(), h));
        }
    }
    ConvexPolyhedron::from_convex_hull(&pts).map(|c| (c, 0.5 * (h0 + h1)))
}

impl PartShapes {
    /// Shapes of the shank and holder (`rapid = false`) or of the whole tool (`rapid = true`).
    pub fn new(body: &ToolBody, rapid: bool) -> Self {
        let mut pieces = Vec::new();
        let mut add = |s: &RevolvedSolid, kind: PartKind| {
            for p in s.pieces() {
                if let Some((shape, mid)) = piece_polyhedron(p) {
                    let (h0, h1) = p.heights();
                    pieces.push(PartPiece {
                        shape,
                        mid,
                        kind,
                        h0,
                        h1,
                        capsule_radius: p.max_radius() * ring_scale(ring_segments(p.max_radius())),
                    });
                }
            }
        };
        if rapid {
            add(&body.cutting, PartKind::RapidMove);
            add(&body.shank, PartKind::RapidMove);
            add(&body.holder, PartKind::RapidMove);
        } else {
            add(&body.shank, PartKind::Shank);
            add(&body.holder, PartKind::Holder);
        }
        Self { pieces }
    }
}

/// A design contact of one part at one position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DesignHit {
    /// Part.
    pub part: PartKind,
    /// Penetration depth (mm); 0 when only the buried-axis test fired and parry gave none.
    pub depth: f64,
    /// Contact point on the design (mm).
    pub point: [f64; 3],
}

/// BVH over the design mesh.
#[derive(Debug, Clone)]
pub struct DesignCollider {
    mesh: TriMesh,
}

impl DesignCollider {
    /// Builds the BVH. Errors if the mesh is empty or invalid.
    pub fn new(mesh: &TriangleMesh) -> Result<Self, SimError> {
        let vertices = mesh
            .vertices
            .iter()
            .map(|v| Vector::new(v[0], v[1], v[2]))
            .collect();
        let mesh = TriMesh::new(vertices, mesh.triangles.clone())
            .map_err(|e| SimError::Design(format!("design mesh: {e:?}")))?;
        Ok(Self { mesh })
    }

    /// Contacts of `parts` placed at (`tip`, `axis`) with the design, one per part kind
    /// (deepest).
    pub fn check(
        &self,
        design: &dyn DesignModel,
        parts: &PartShapes,
        tip: &[f64; 3],
        axis: &[f64; 3],
    ) -> Vec<DesignHit> {
        let a = Vector::new(axis[0], axis[1], axis[2]);
        let rot = Rotation::from_rotation_arc(Vector::Z, a.normalize());
        let pose = Pose::from_parts(Vector::new(tip[0], tip[1], tip[2]), rot);
        let mesh_pose = Pose::IDENTITY;
        let mut out: Vec<DesignHit> = Vec::new();
        for PartPiece {
            shape,
            mid: hm,
            kind,
            ..
        } in &parts.pieces
        {
            let hits = matches!(
                query::intersection_test(&pose, shape, &mesh_pose, &self.mesh),
                Ok(r) if r.intersecting
            );
            let mid = Point3::new(tip[0] + hm * a.x, tip[1] + hm * a.y, tip[2] + hm * a.z);
            let buried = !hits && design.contains(&mid);
            if !(hits || buried) {
                continue;
            }
            let (depth, point) = match query::contact(&pose, shape, &mesh_pose, &self.mesh, 0.0) {
                Ok(Some(c)) => ((-c.dist).max(0.0), [c.point2.x, c.point2.y, c.point2.z]),
                _ => (0.0, [mid.x, mid.y, mid.z]),
            };
            let depth = if buried {
                depth.max(-design.signed_distance(&mid))
            } else {
                depth
            };
            match out.iter_mut().find(|h| h.part == *kind) {
                Some(h) if h.depth < depth => {
                    h.depth = depth;
                    h.point = point;
                }
                Some(_) => {}
                None => out.push(DesignHit {
                    part: *kind,
                    depth,
                    point,
                }),
            }
        }
        out
    }

    /// [`check`](Self::check) for a sequence of positions of the same parts, skipping the
    /// pieces proven clear. `cache` holds one entry per piece of `parts` (start with
    /// [`ClearanceCache::new`]; use one cache per part set and sequence of positions).
    ///
    /// Whenever a piece is tested in full and found clear (no mesh intersection, axis middle
    /// outside the design), the cache keeps its axis end points and a clearance `c`: the
    /// smaller of the distance from the piece's bounding capsule to the mesh (capped at
    /// [`CLEARANCE_PROBE_MM`]) and the design's
    /// signed distance at the axis middle, less [`CLEARANCE_SLACK_MM`]. A later position whose
    /// axis end points moved less than `c` (every point of the capsule moves at most the
    /// larger end-point displacement, the axis middle at most that much) keeps the capsule —
    /// hence the polyhedron — off the mesh, and the middle outside the design (the
    /// [`DesignModel`] contract: the signed distance never exceeds the true distance, with
    /// the right sign), so the full test would report nothing: the result is exactly that of
    /// [`check`](Self::check). Cost: one capsule–mesh distance and one signed distance per
    /// refreshed piece, O(1) per skipped piece.
    pub fn check_cached(
        &self,
        design: &dyn DesignModel,
        parts: &PartShapes,
        tip: &[f64; 3],
        axis: &[f64; 3],
        cache: &mut ClearanceCache,
    ) -> Vec<DesignHit> {
        cache.entries.resize(parts.pieces.len(), None);
        let at = |h: f64| {
            [
                tip[0] + h * axis[0],
                tip[1] + h * axis[1],
                tip[2] + h * axis[2],
            ]
        };
        let dist = |a: &[f64; 3], b: &[f64; 3]| {
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
        };
        let mut out: Vec<DesignHit> = Vec::new();
        let mut single = PartShapes { pieces: Vec::new() };
        for (piece, entry) in parts.pieces.iter().zip(cache.entries.iter_mut()) {
            let (e0, e1) = (at(piece.h0), at(piece.h1));
            if let Some(c) = entry {
                if dist(&e0, &c.ends[0]).max(dist(&e1, &c.ends[1])) < c.clearance {
                    continue;
                }
            }
            single.pieces.clear();
            single.pieces.push(piece.clone());
            let hits = self.check(design, &single, tip, axis);
            *entry = None;
            if hits.is_empty() {
                let capsule = Capsule::new(
                    Vector::new(e0[0], e0[1], e0[2]),
                    Vector::new(e1[0], e1[1], e1[2]),
                    piece.capsule_radius,
                );
                // Capped query: the BVH prunes everything farther than the cap.
                let mesh_clear = match query::closest_points(
                    &Pose::IDENTITY,
                    &capsule,
                    &Pose::IDENTITY,
                    &self.mesh,
                    CLEARANCE_PROBE_MM,
                ) {
                    Ok(ClosestPoints::Disjoint) => CLEARANCE_PROBE_MM,
                    Ok(ClosestPoints::WithinMargin(a, b)) => (a - b).length(),
                    _ => 0.0,
                };
                if mesh_clear <= CLEARANCE_SLACK_MM {
                    // Touching the mesh: no clearance to keep (and no hit, `hits` is empty).
                    continue;
                }
                let m = at(piece.mid);
                let sd = design.signed_distance(&Point3::new(m[0], m[1], m[2]));
                let clearance = mesh_clear.min(sd) - CLEARANCE_SLACK_MM;
                if clearance > 0.0 {
                    *entry = Some(Clearance {
                        ends: [e0, e1],
                        clearance,
                    });
                }
            }
            for h in hits {
                match out.iter_mut().find(|o| o.part == h.part) {
                    Some(o) if o.depth < h.depth => {
                        o.depth = h.depth;
                        o.point = h.point;
                    }
                    Some(_) => {}
                    None => out.push(h),
                }
            }
        }
        out
    }
}

/// A clear piece position remembered by [`DesignCollider::check_cached`].
#[derive(Debug, Clone, Copy, PartialEq)]
struct Clearance {
    ends: [[f64; 3]; 2],
    clearance: f64,
}

/// Per-piece clearances of one part set along a sequence of positions (see
/// [`DesignCollider::check_cached`]).
#[derive(Debug, Clone, Default)]
pub struct ClearanceCache {
    entries: Vec<Option<Clearance>>,
}

impl ClearanceCache {
    /// An empty cache (every piece is tested in full at first).
    pub fn new() -> Self {
        Self::default()
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::design::BoxDesign;
    use crate::synthetic::workload_cutter;

    /// A 20 × 20 × 20 mm block design (x, y in ±10, z in 0..20), its collider and the
    /// synthetic workload tool (Ø40 holder from 50 mm above the tip).
    fn block_case() -> (BoxDesign, DesignCollider, ToolBody) {
        let design = BoxDesign {
            min: [-10.0, -10.0, 0.0],
            max: [10.0, 10.0, 20.0],
            sample_spacing: 2.0,
        };
        let collider = DesignCollider::new(&design.triangle_mesh()).unwrap();
        (design, collider, ToolBody::new(&workload_cutter()))
    }

    /// The polygons stand at most `RING_EXCESS_MM` outside their circles, from a needle to
    /// a Ø80 holder.
    #[test]
    fn ring_polygons_stay_within_their_excess() {
        for r in [0.05, 0.5, 1.5, 3.0, 10.5, 13.5, 20.0, 40.0] {
            let n = ring_segments(r);
            let excess = r * ring_scale(n) - r;
            assert!(
                n >= RING_SEGMENTS && excess <= RING_EXCESS_MM + 1e-12,
                "r {r}: {n}, {excess}"
            );
            // The least such N: one side fewer stands out more (or is the floor of 24).
            assert!(
                n == RING_SEGMENTS || r * ring_scale(n - 1) - r > RING_EXCESS_MM,
                "r {r}"
            );
        }
    }

    /// A Ø40 holder 0.02 mm beside a wall is clear, 0.01 mm into it is not: with 24 sides the
    /// polygon's corner stood 0.17 mm proud and read the clear one as a collision.
    #[test]
    fn a_holder_just_clear_of_a_wall_is_clear() {
        let (design, collider, body) = block_case();
        let parts = PartShapes::new(&body, false);
        // Axis +Z, the holder (radius 20, 50–90 mm above the tip) beside the face x = 10.
        for (gap, hit) in [(0.02, false), (-0.01, true)] {
            let tip = [10.0 + 20.0 + gap, 0.0, -45.0];
            let hits = collider.check(&design, &parts, &tip, &[0.0, 0.0, 1.0]);
            assert_eq!(!hits.is_empty(), hit, "gap {gap}: {hits:?}");
            if hit {
                assert_eq!(hits[0].part, PartKind::Holder);
                assert!(
                    (hits[0].depth - 0.01).abs() <= RING_EXCESS_MM + 1e-6,
                    "{hits:?}"
                );
            }
        }
    }

    /// The cached check reports exactly what the full check reports, position by position,
    /// along a sweep that approaches, enters (shank and holder) and leaves a block design.
    #[test]
    fn cached_check_equals_full_check() {
        let (design, collider, body) = block_case();
        for rapid in [false, true] {
            let parts = PartShapes::new(&body, rapid);
            let mut cache = ClearanceCache::new();
            let (mut hits, mut skipped_somewhere) = (0usize, false);
            for k in 0..600 {
                let t = k as f64 / 600.0;
                let tip = [
                    -40.0 + 80.0 * t,
                    3.0 * (9.0 * t).sin(),
                    30.0 - 40.0 * (3.0 * t).sin(),
                ];
                let (s, c) = (0.4 * (5.0 * t).sin(), 0.4 * (5.0 * t).cos());
                let n = (s * s + c * c + 1.0f64).sqrt();
                let axis = [s / n, c / n, 1.0 / n];
                let full = collider.check(&design, &parts, &tip, &axis);
                let before = cache.entries.clone();
                let cached = collider.check_cached(&design, &parts, &tip, &axis, &mut cache);
                assert_eq!(full, cached, "position {k}");
                hits += full.len();
                skipped_somewhere |= before
                    .iter()
                    .zip(&cache.entries)
                    .any(|(a, b)| a.is_some() && a == b);
            }
            assert!(hits > 0, "the sweep must collide");
            assert!(skipped_somewhere, "the cache must skip some pieces");
        }
    }
}
