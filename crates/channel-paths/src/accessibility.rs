//! Accessibility of a ball-end position: clearance of the tool above its ball.

use cam_core::CutterShape;
use cam_plan::{PlanContext, PlanError, Point3};
use nalgebra::Vector3;

/// The ball radius of the context's tool (ball end or tapered ball end); otherwise a tool
/// error saying that `what` needs one.
pub(crate) fn ball_radius(
    ctx: &PlanContext<'_>,
    operation: &str,
    what: &str,
) -> Result<f64, PlanError> {
    match ctx.tool.cutter.shape {
        CutterShape::BallEnd { radius } => Ok(radius),
        CutterShape::TaperedBallEnd { ball_radius, .. } => Ok(ball_radius),
        _ => Err(PlanError::tool(
            operation,
            ctx.tool.name(),
            format!("{what} needs a ball-end or tapered ball-end cutter"),
        )),
    }
}

/// `a` turned toward the unit normal `n` (in their common plane) until their angle is at most
/// `max` (rad); unchanged when it already is. O(1).
pub(crate) fn limit_tilt(a: Vector3<f64>, n: &Vector3<f64>, max: f64) -> Vector3<f64> {
    let c = a.dot(n).clamp(-1.0, 1.0);
    if c.acos() <= max {
        return a;
    }
    let perp = (a - n * c)
        .try_normalize(1e-12)
        .unwrap_or_else(|| n.cross(&Vector3::x()));
    (n * max.cos() + perp * max.sin()).normalize()
}

/// Smallest signed clearance (mm) of the tool samples above the ball — flutes, shank and
/// holder from [`cam_plan::DesignClearance::samples`] — with the ball centre at `centre` and
/// unit `axis`, against hub and blades. The ball itself is placed by the planners at a known
/// distance from the design, so samples at heights `≤ r` (the tool's ball radius) are
/// skipped. With `ball ≠ r` the same assembly is evaluated with ball and flutes of radius
/// `ball` (samples of radius `r` take radius `ball`; heights shift by `ball − r`): used to
/// find the largest ball that fits. Stops at the first sample below `stop_below` (then the
/// returned value is that sample's clearance, an upper bound of the minimum; pass
/// `f64::NEG_INFINITY` for the exact minimum). O(samples · design distance).
pub(crate) fn upper_clearance(
    ctx: &PlanContext<'_>,
    centre: &Vector3<f64>,
    axis: &Vector3<f64>,
    r: f64,
    ball: f64,
    stop_below: f64,
) -> f64 {
    let tip = centre - axis * ball;
    let mut best = f64::INFINITY;
    for (h, rho) in ctx.clearance.samples() {
        if h <= r {
            continue;
        }
        let rho = if (rho - r).abs() <= 1e-9 { ball } else { rho };
        let h = h - r + ball;
        let p = Point3::from(tip + axis * h);
        let d = ctx.clearance.design_signed_distance(&p).0 - rho;
        best = best.min(d);
        if best < stop_below {
            return best;
        }
    }
    best
}
