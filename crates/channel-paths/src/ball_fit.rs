//! Whether a ball fits beside a blade: the distance from a ball centre to the blade's whole
//! boundary — both side patches and, at a blunt (open) edge, the face closing it.
//!
//! # Geometry
//! The blade solid is bounded by its pressure and suction sides and, where they end apart at
//! the leading or trailing edge, by the flat edge face spanning the gap
//! ([`impeller_model::Blade::edge_face`], the ruled surface between the two sides' edge
//! isocurves). A ball of radius `ρ` centred at `c` outside the solid stays out of it exactly
//! when every boundary point is at least `ρ` from `c`:
//!
//! `gap(c) = min(|c − S_p|, |c − S_s|, |c − F_le|, |c − F_te|) − ρ ≥ 0`
//!
//! with `|c − S|` the exact (global) distance to a patch. A centre that lies *inside* the
//! solid fails too: the segment from the foot point on its own side (at distance `ρ` by
//! construction, outside along the outward normal) to the centre then crosses the boundary
//! again, closer than `ρ`. So one distance per patch decides both "the centre lies inside the
//! blade" and "the ball reaches the edge face or the other side beyond a blunt edge" — and a
//! concave region tighter than the ball, where the side's offset surface folds.
//!
//! At a rounded (closed) edge the sides meet and there is no face: the offset of the nose is
//! smooth, the gap stays 0 around it and the ball passes (the root path runs around it).
//!
//! Tolerance: the projections are exact to 1e-9 mm (nurbs' global closest point: Bézier
//! patches in a bounding-volume tree, Newton per candidate leaf). Cost: four global
//! projections, O(log patches) each; the faces' projectors are built once per blade.

use impeller_model::{Blade, BladeEdge, Side};
use nalgebra::Vector3;
use nurbs::closest::SurfaceProjector;

/// The part of a blade's boundary nearest to a ball centre.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BoundaryPart {
    /// One of the two side patches.
    Side(Side),
    /// The flat face closing a blunt (open) edge.
    EdgeFace(BladeEdge),
}

impl std::fmt::Display for BoundaryPart {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BoundaryPart::Side(Side::Pressure) => f.write_str("pressure side"),
            BoundaryPart::Side(Side::Suction) => f.write_str("suction side"),
            BoundaryPart::EdgeFace(BladeEdge::Leading) => f.write_str("leading-edge face"),
            BoundaryPart::EdgeFace(BladeEdge::Trailing) => f.write_str("trailing-edge face"),
        }
    }
}

/// A blade's boundary with the closest-point structures of its edge faces.
pub struct BladeBoundary<'a> {
    blade: &'a Blade,
    faces: Vec<(BladeEdge, SurfaceProjector)>,
}

impl std::fmt::Debug for BladeBoundary<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BladeBoundary")
            .field(
                "edge_faces",
                &self.faces.iter().map(|f| f.0).collect::<Vec<_>>(),
            )
            .finish()
    }
}

impl<'a> BladeBoundary<'a> {
    /// The boundary of `blade`: its sides and the faces of its blunt edges. An edge face that
    /// cannot be built (degenerate edge curves) is left out: then the sides alone bound the
    /// answer, as at a rounded edge.
    pub fn new(blade: &'a Blade) -> Self {
        let faces = [BladeEdge::Leading, BladeEdge::Trailing]
            .into_iter()
            .filter_map(|e| match blade.edge_face(e) {
                Ok(Some(face)) => Some((e, SurfaceProjector::new(&face))),
                _ => None,
            })
            .collect();
        Self { blade, faces }
    }

    /// Whether the blade has a blunt (open) `edge`, closed by a face.
    pub fn has_face(&self, edge: BladeEdge) -> bool {
        self.faces.iter().any(|(e, _)| *e == edge)
    }

    /// `gap(c)` of the module docs for a ball of radius `rho` (mm; negative: the ball reaches
    /// into the blade by that much, or its centre lies inside) and the boundary part nearest
    /// to `c`.
    pub fn gap(&self, c: &Vector3<f64>, rho: f64) -> (f64, BoundaryPart) {
        let mut best = (f64::INFINITY, BoundaryPart::Side(Side::Pressure));
        for side in [Side::Pressure, Side::Suction] {
            let d = self.blade.projector(side).closest_point(c).distance;
            if d < best.0 {
                best = (d, BoundaryPart::Side(side));
            }
        }
        for (edge, face) in &self.faces {
            let d = face.closest_point(c).distance;
            if d < best.0 {
                best = (d, BoundaryPart::EdgeFace(*edge));
            }
        }
        (best.0 - rho, best.1)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn a_ball_on_the_offset_fits_and_one_beyond_the_blunt_edge_face_does_not() {
        // impeller-8+8: rounded leading edge (no face), blunt 0.8 mm trailing edge.
        let imp = impeller_model::fixtures::default_impeller().unwrap();
        let blade = imp.main().blade();
        let b = BladeBoundary::new(blade);
        assert!(b.has_face(BladeEdge::Trailing));
        assert!(!b.has_face(BladeEdge::Leading));
        let s = blade.side(Side::Pressure);
        let ((_, u1), (v0, v1)) = s.domain();
        let v = 0.5 * (v0 + v1);
        // On the pressure side's offset by 1 mm in mid-blade: gap 0 (within the projection's
        // accuracy), nearest part the pressure side.
        let n = blade.outward_normal(Side::Pressure, 0.5, v).unwrap();
        let (g, part) = b.gap(&(s.point(0.5, v) + n), 1.0);
        assert!(g.abs() < 1e-6, "{g}");
        assert_eq!(part, BoundaryPart::Side(Side::Pressure));
        // 0.3 mm behind the middle of the trailing-edge face (along the sides' u tangent):
        // a ball of 1 mm reaches 0.7 mm into the face; both side points are farther.
        let ps = s.point(u1, v);
        let ss = blade.side(Side::Suction).point(u1, v);
        let t = s.derivs2(u1, v).su.normalize();
        let c = 0.5 * (ps + ss) + t * 0.3;
        let (g, part) = b.gap(&c, 1.0);
        assert_eq!(part, BoundaryPart::EdgeFace(BladeEdge::Trailing));
        assert!((g + 0.7).abs() < 0.02, "{g}");
        // A centre inside the 0.8 mm blade, halfway between its sides: 0.4 mm from both, so
        // the 1 mm ball reaches 0.6 mm beyond them.
        let inside = 0.5 * (s.point(0.5, v) + blade.side(Side::Suction).point(0.5, v));
        let (g, _) = b.gap(&inside, 1.0);
        assert!((g + 0.6).abs() < 0.02, "{g}");
    }
}
