//! Collisions of the non-cutting parts (shank, holder; the whole tool on rapid moves) with
//! the design, through parry's BVH over the design's triangle mesh.
//!
//! Each part piece is a convex polyhedron: the hull of rings circumscribing the piece's
//! circles (radius / cos(π/N), N = [`RING_SEGMENTS`]) at its slab heights (and at intermediate
//! heights for curved pieces), so the polyhedron contains the true solid. A position collides
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
use parry3d_f64::query;
use parry3d_f64::shape::{ConvexPolyhedron, TriMesh};

/// Number of sides of the polygons approximating the part circles.
pub const RING_SEGMENTS: usize = 24;

/// A tool part as convex polyhedra in the tool frame (tip at origin, axis +Z).
#[derive(Debug, Clone)]
pub struct PartShapes {
    pieces: Vec<(ConvexPolyhedron, f64, PartKind)>,
}

fn piece_polyhedron(p: &Piece) -> Option<(ConvexPolyhedron, f64)> {
    let (h0, h1) = p.heights();
    let rings = match p {
        Piece::Frustum { .. } => 2,
        _ => 6,
    };
    let scale = 1.0 / (std::f64::consts::PI / RING_SEGMENTS as f64).cos();
    let mut pts = Vec::with_capacity(rings * RING_SEGMENTS);
    for k in 0..rings {
        let h = h0 + (h1 - h0) * k as f64 / (rings - 1) as f64;
        // Curved pieces: use the largest radius of the neighbouring band so the hull
        // contains the piece.
        let r = match p {
            Piece::Frustum { .. } => p.radius_at(h),
            _ => p.max_radius(),
        } * scale;
        for s in 0..RING_SEGMENTS {
            let t = std::f64::consts::TAU * s as f64 / RING_SEGMENTS as f64;
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
                if let Some((c, hm)) = piece_polyhedron(p) {
                    pieces.push((c, hm, kind));
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
        for (shape, hm, kind) in &parts.pieces {
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
}
