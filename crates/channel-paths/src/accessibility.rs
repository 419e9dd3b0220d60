//! Accessibility of a ball-end position: clearance of the tool above its ball.

use cam_plan::{PlanContext, Point3};
use nalgebra::Vector3;

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
