//! Local closest point on a surface from a known start (point inversion, The NURBS Book
//! §6.1), for callers that already hold a good start: the same parameters on the other side
//! of a thin blade, the previous answer along a dense path.
//!
//! Bound-constrained Newton on `½|S(u, v) − q|²` from the start (module `newton`: projected
//! Newton with an active set, Gauss–Newton where the Hessian is not positive definite,
//! backtracking so the distance never grows). The answer is a local minimum (a KKT point on
//! the domain's boundary) reached from the start; it is **not** certified global — use
//! [`crate::closest::SurfaceProjector`] for that. Tolerance: stops when the predicted 3D step
//! is below `1e-13 × (1 + control-net diagonal)` mm and `S − q` is normal to every free
//! tangent within `1e-11`. Cost: a few (3–6 from a good start, at most 40) second-derivative
//! evaluations; no allocation.

use nalgebra::Vector3;

use super::newton::minimise;
use super::SurfacePoint;
use crate::NurbsSurface;

/// Local closest point of `surface` to `q` by bound-constrained Newton from `start` = (u, v)
/// (clamped into the domain); see the module docs. Not certified global.
///
/// ```
/// use nalgebra::Vector3;
/// use nurbs::{closest::local_closest_point, NurbsSurface};
/// // The plane z = 0 over [0, 2] × [0, 2] as a bilinear patch.
/// let s = NurbsSurface::new(
///     1,
///     1,
///     vec![0.0, 0.0, 1.0, 1.0],
///     vec![0.0, 0.0, 1.0, 1.0],
///     vec![
///         vec![Vector3::new(0.0, 0.0, 0.0), Vector3::new(0.0, 2.0, 0.0)],
///         vec![Vector3::new(2.0, 0.0, 0.0), Vector3::new(2.0, 2.0, 0.0)],
///     ],
///     None,
/// )
/// .unwrap();
/// let p = local_closest_point(&s, &Vector3::new(0.5, 1.5, 3.0), (0.9, 0.1));
/// assert!((p.point - Vector3::new(0.5, 1.5, 0.0)).norm() < 1e-12);
/// assert!((p.distance - 3.0).abs() < 1e-12);
/// ```
pub fn local_closest_point(
    surface: &NurbsSurface,
    q: &Vector3<f64>,
    start: (f64, f64),
) -> SurfacePoint {
    let ((u0, u1), (v0, v1)) = surface.domain();
    let (mut lo, mut hi) = (
        Vector3::repeat(f64::INFINITY),
        Vector3::repeat(-f64::INFINITY),
    );
    for c in surface.control_points() {
        lo = lo.inf(c);
        hi = hi.sup(c);
    }
    let diag = (hi - lo).norm();
    let step_tol = 1e-13 * (1.0 + if diag.is_finite() { diag } else { 0.0 });
    let start = (
        if start.0.is_finite() { start.0 } else { u0 },
        if start.1.is_finite() { start.1 } else { v0 },
    );
    let l = minimise(
        |u, v| surface.derivs2(u, v),
        q,
        (u0, v0),
        (u1, v1),
        start,
        step_tol,
    );
    SurfacePoint {
        u: l.u,
        v: l.v,
        point: l.point,
        normal: l.normal,
        distance: l.d2.sqrt(),
        on_boundary: l.active[0] != 0 || l.active[1] != 0,
    }
}
