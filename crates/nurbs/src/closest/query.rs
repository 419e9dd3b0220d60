//! One vocabulary for point queries against a shape, as parry's `PointQuery`: a closest
//! point, a signed distance with one stated sign convention, an optional warm-start hint
//! (the previous answer along a path of queries) and a flag saying whether the answer is
//! proven to be the global minimum.
//!
//! **Sign convention.** The distance is positive on the side the shape's *outward* normal
//! points to and negative on the other: for a part of a workpiece, positive outside the
//! material; for a bare NURBS surface, positive along `S_u × S_v`. A query point on the shape
//! has distance 0. Implementations say which side is outward in their docs.
//!
//! ```
//! use nalgebra::Vector3;
//! use nurbs::closest::{PointQuery, SurfaceProjector};
//! use nurbs::NurbsSurface;
//!
//! // The plane z = 0 over [0, 10]², as a bilinear patch; S_u × S_v = +Z.
//! let ctrl = vec![
//!     vec![Vector3::new(0.0, 0.0, 0.0), Vector3::new(0.0, 10.0, 0.0)],
//!     vec![Vector3::new(10.0, 0.0, 0.0), Vector3::new(10.0, 10.0, 0.0)],
//! ];
//! let k = vec![0.0, 0.0, 1.0, 1.0];
//! let plane = NurbsSurface::new(1, 1, k.clone(), k, ctrl, None).unwrap();
//! let proj = SurfaceProjector::new(&plane);
//! let below = proj.query(&Vector3::new(3.0, 4.0, -2.0), None);
//! assert!((below.signed_distance + 2.0).abs() < 1e-12);
//! assert!((below.point - Vector3::new(3.0, 4.0, 0.0)).norm() < 1e-12);
//! // Warm start from the previous answer.
//! let next = proj.query(&Vector3::new(3.1, 4.0, -2.0), Some(below.hint));
//! assert!((next.signed_distance + 2.0).abs() < 1e-12);
//! ```

use nalgebra::Vector3;

/// The answer of a [`PointQuery`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointProjection<H> {
    /// The closest point of the shape found.
    pub point: Vector3<f64>,
    /// Distance to it, signed by the shape's convention (positive along its outward normal).
    pub signed_distance: f64,
    /// Where the answer lies on the shape, to warm-start the next query.
    pub hint: H,
    /// The answer is proven to be the global minimum (otherwise: the best found by a search
    /// whose bounds are not rigorous for this shape).
    pub certified: bool,
}

/// Closest point and signed distance of a query point to a shape (see the module docs).
pub trait PointQuery {
    /// Warm-start data: the surface parameters `(u, v)` for a surface, `()` where none
    /// helps.
    type Hint: Copy;

    /// The closest point of the shape to `q` and the signed distance, starting from `hint`
    /// when given (the answer does not depend on it, only the cost).
    fn query(&self, q: &Vector3<f64>, hint: Option<Self::Hint>) -> PointProjection<Self::Hint>;

    /// The signed distance alone.
    fn signed_distance(&self, q: &Vector3<f64>) -> f64 {
        self.query(q, None).signed_distance
    }
}

impl PointQuery for super::SurfaceProjector {
    type Hint = (f64, f64);

    /// Signed along `S_u × S_v` at the closest point (at a degenerate normal, or on the
    /// boundary where `S − q` is not normal, the sign of `(q − S)·(S_u × S_v)` still decides;
    /// 0 counts as positive). Certified for polynomial and rational (positive weights)
    /// surfaces alike: the bounds are rigorous (hodographs of the polynomial or of the
    /// homogeneous net).
    fn query(&self, q: &Vector3<f64>, hint: Option<(f64, f64)>) -> PointProjection<(f64, f64)> {
        let r = self.closest_point_with_hint(q, hint);
        let sign = if (q - r.point).dot(&r.normal) < 0.0 {
            -1.0
        } else {
            1.0
        };
        PointProjection {
            point: r.point,
            signed_distance: sign * r.distance,
            hint: (r.u, r.v),
            certified: r.distance.is_finite(),
        }
    }
}
