//! Exact surfaces of revolution (NURBS Book A8.1).

use nalgebra::Vector3;

use crate::arcs::{arc_layout, check_sweep};
use crate::curve::NurbsCurve;
use crate::error::NurbsError;
use crate::surface::NurbsSurface;

impl NurbsSurface {
    /// Sweeps `profile` about the axis through `axis_point` with direction `axis_dir` by
    /// `angle` radians (right-handed about `axis_dir`; a negative angle turns the other
    /// way; `0 < |angle| <= 2π`), NURBS Book A8.1.
    ///
    /// Parameters: `u` runs around the axis on `[0, 1]` (rational quadratic, one Bézier
    /// segment per ≤ 90°, as [`NurbsCurve::circle_arc`]); `v` is the profile's own
    /// parameter, so `S(0, v) = profile(v)`. Control net `(2 k + 1) × n_profile`, `k`
    /// segments. Exact: the distance of `S(u, v)` from the axis equals that of
    /// `profile(v)` to rounding (tested to 1e-12 relative). Profile points on the axis
    /// give a pole (the normal is undefined there). O(n_profile) control points × ≤ 9.
    pub fn revolution(
        profile: &NurbsCurve<3>,
        axis_point: Vector3<f64>,
        axis_dir: Vector3<f64>,
        angle: f64,
    ) -> Result<Self, NurbsError> {
        let len = axis_dir.norm();
        if !(len.is_finite() && len > 0.0 && axis_point.iter().all(|c| c.is_finite())) {
            return Err(NurbsError::InvalidGeometry(
                "revolution axis must have a finite point and a non-zero finite direction".into(),
            ));
        }
        let sweep = angle.abs();
        check_sweep(sweep)?;
        let t = axis_dir / len * angle.signum();
        let (narcs, ku) = arc_layout(sweep)?;
        let dtheta = sweep / narcs as f64;
        let wm = (dtheta / 2.0).cos();
        let n_u = 2 * narcs + 1;
        let pts = profile.control_points();
        let n_v = pts.len();
        let mut ctrl = vec![Vector3::zeros(); n_u * n_v];
        let mut weights = vec![1.0; n_u * n_v];
        for (j, pj) in pts.iter().enumerate() {
            let wj = profile.weights().map_or(1.0, |w| w[j]);
            let o = axis_point + t * (pj - axis_point).dot(&t);
            let xv = pj - o;
            let r = xv.norm();
            let (x, y) = if r > 0.0 {
                let x = xv / r;
                (x, t.cross(&x))
            } else {
                (Vector3::zeros(), Vector3::zeros())
            };
            let at = |a: f64, rad: f64| o + x * (rad * a.cos()) + y * (rad * a.sin());
            ctrl[j] = *pj;
            weights[j] = wj;
            for k in 0..narcs {
                let a0 = dtheta * k as f64;
                let a2 = if k + 1 == narcs { sweep } else { a0 + dtheta };
                let (im, i2) = (2 * k + 1, 2 * k + 2);
                ctrl[im * n_v + j] = at(a0 + dtheta / 2.0, r / wm);
                weights[im * n_v + j] = wj * wm;
                ctrl[i2 * n_v + j] = at(a2, r);
                weights[i2 * n_v + j] = wj;
            }
        }
        NurbsSurface::from_flat(ku, profile.knots().clone(), ctrl, Some(weights))
    }
}
