//! Exact circular arcs as rational quadratic NURBS (NURBS Book A7.1).

use nalgebra::SVector;

use crate::curve::NurbsCurve;
use crate::error::NurbsError;
use crate::knots::KnotVector;

/// Number of rational quadratic segments A7.1 uses for a sweep (≤ 90° per segment) and
/// the resulting clamped knot vector on `[0, 1]` (interior knots doubled).
pub(crate) fn arc_layout(sweep: f64) -> Result<(usize, KnotVector), NurbsError> {
    let quarter = std::f64::consts::FRAC_PI_2 * (1.0 + 1e-12);
    let narcs = if sweep <= quarter {
        1
    } else if sweep <= 2.0 * quarter {
        2
    } else if sweep <= 3.0 * quarter {
        3
    } else {
        4
    };
    let mut knots = vec![0.0; 3];
    for k in 1..narcs {
        let t = k as f64 / narcs as f64;
        knots.extend([t, t]);
    }
    knots.extend([1.0; 3]);
    Ok((narcs, KnotVector::new(2, knots)?))
}

/// Checks a sweep angle: finite, non-zero, at most one full turn (1e-12 relative slack).
pub(crate) fn check_sweep(sweep: f64) -> Result<(), NurbsError> {
    let full = 2.0 * std::f64::consts::PI;
    if !(sweep.is_finite() && sweep > 0.0 && sweep <= full * (1.0 + 1e-12)) {
        return Err(NurbsError::InvalidGeometry(format!(
            "sweep angle {sweep} rad must be in (0, 2π]"
        )));
    }
    Ok(())
}

impl<const D: usize> NurbsCurve<D> {
    /// Exact circular arc `C(θ) = O + r cos θ X + r sin θ Y`, `θ` from `start_angle` to
    /// `end_angle` (radians, `0 < end − start <= 2π`), as a rational quadratic NURBS on
    /// `[0, 1]` (NURBS Book A7.1: one Bézier segment per ≤ 90°, middle weights
    /// `cos(Δθ/2)`). `x_axis` is normalised and `y_axis` made orthonormal to it
    /// (Gram–Schmidt), so any two independent vectors spanning the plane work. Points lie
    /// on the circle to rounding (≈1e-16 relative; tested to 1e-14 for the unit quarter
    /// circle); the parametrisation is not arc length. O(1): at most 9 control points.
    pub fn circle_arc(
        center: SVector<f64, D>,
        x_axis: SVector<f64, D>,
        y_axis: SVector<f64, D>,
        radius: f64,
        start_angle: f64,
        end_angle: f64,
    ) -> Result<Self, NurbsError> {
        if !(radius.is_finite() && radius > 0.0) {
            return Err(NurbsError::InvalidGeometry(format!(
                "arc radius {radius} must be positive and finite"
            )));
        }
        if !(start_angle.is_finite() && end_angle.is_finite()) {
            return Err(NurbsError::InvalidGeometry(
                "arc angles must be finite".into(),
            ));
        }
        let sweep = end_angle - start_angle;
        check_sweep(sweep)?;
        let xn = x_axis.norm();
        if !(xn.is_finite() && xn > 0.0) {
            return Err(NurbsError::InvalidGeometry("arc x axis is zero".into()));
        }
        let x = x_axis / xn;
        let y_perp = y_axis - x * y_axis.dot(&x);
        let yn = y_perp.norm();
        if !(yn.is_finite() && yn > 1e-12 * y_axis.norm()) {
            return Err(NurbsError::InvalidGeometry(
                "arc y axis is zero or parallel to the x axis".into(),
            ));
        }
        let y = y_perp / yn;
        let (narcs, kv) = arc_layout(sweep)?;
        let dtheta = sweep / narcs as f64;
        let w1 = (dtheta / 2.0).cos();
        let at = |angle: f64, r: f64| center + x * (r * angle.cos()) + y * (r * angle.sin());
        let mut ctrl = Vec::with_capacity(2 * narcs + 1);
        let mut weights = Vec::with_capacity(2 * narcs + 1);
        ctrl.push(at(start_angle, radius));
        weights.push(1.0);
        for i in 0..narcs {
            let a0 = start_angle + dtheta * i as f64;
            let a2 = if i + 1 == narcs {
                end_angle
            } else {
                a0 + dtheta
            };
            ctrl.push(at(a0 + dtheta / 2.0, radius / w1));
            weights.push(w1);
            ctrl.push(at(a2, radius));
            weights.push(1.0);
        }
        NurbsCurve::from_knot_vector(kv, ctrl, Some(weights))
    }
}
