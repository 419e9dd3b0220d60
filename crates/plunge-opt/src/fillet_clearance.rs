//! Plunges kept off the blade-root fillets: the flat-end cutter at a plunge's depth must
//! keep the roughing allowance from the fillet material
//! ([`impeller_model::fillet::ImpellerFillets`]), which fills the corner between hub and
//! blade that the hub floor and the blade clearance leave open. A cutter keeping the blade
//! allowance from the sharp blade and the hub allowance above the hub can still cut the
//! fillet with its bottom edge: on impeller-plunge-400 (R = 4 mm, allowances 1.0 / 0.5 mm)
//! the first Ø30 plunges cut 0.14 mm into it (read at the job's 1 mm verification).
//!
//! # Test
//! The fillet material lies within its extent of the blade side and of the hub
//! ([`ImpellerFillets::extent_mm`]: `R·cot(β/2)` each in a planar corner of angle `β`; with
//! [`impeller_model::fillet::CORNER_SLACK`]`·R` for the walls' curvature). A cutter whose
//! blade clearance exceeds the extent from the side plus the allowance cannot come within
//! the allowance of it and is not sampled, so plunges away from the blades cost nothing.
//! Otherwise the cutter surface that can meet the fillet is its bottom rim and its side up
//! to the extent above the hub plus the allowance (the bottom lies on the hub allowance).
//! Sampled on a grid `s` apart ([`SAMPLE_MM`]) around the rim and up the side, every cutter
//! point there lies within `s/√2` of a sample, and the fillet distance is 1-Lipschitz, so
//! samples whose fillet distance is at least `allowance + s/√2` prove the cutter keeps the
//! allowance (conservative for a corner radius: the sharp rim encloses a rounded one). Cost: O((2πρ/s)·(reach/s))
//! fillet queries for a cutter of radius ρ beside a blade.

use cam_core::{CutterLocation, Vector3};
use impeller_model::fillet::ImpellerFillets;

/// Largest spine error of the fillets the plunges are held to (mm): the model's default.
pub const FILLET_TOL_MM: f64 = impeller_model::fillet::DEFAULT_FILLET_TOL_MM;

/// Spacing of the cutter samples (mm).
pub const SAMPLE_MM: f64 = 1.0;

/// Whether the flat-end cutter of radius `radius` at `cl`, whose clearance to the blades is
/// `blade_clearance`, keeps `allowance` from every fillet (module docs).
pub fn cutter_clears_fillets(
    fillets: &ImpellerFillets,
    cl: &CutterLocation,
    radius: f64,
    blade_clearance: f64,
    allowance: f64,
) -> bool {
    let slack = impeller_model::fillet::CORNER_SLACK * fillets.radius();
    let (from_side, height) = fillets.extent_mm();
    if blade_clearance > from_side + slack + allowance {
        return true;
    }
    let axis: Vector3 = cl.axis.into_inner();
    let (e1, e2) = crate::axial_depth::perpendicular_frame(&axis);
    let around = ((std::f64::consts::TAU * radius / SAMPLE_MM).ceil() as usize).max(8);
    let up = ((height + slack + allowance) / SAMPLE_MM).ceil() as usize;
    let need = allowance + SAMPLE_MM * std::f64::consts::FRAC_1_SQRT_2;
    for k in 0..around {
        let t = std::f64::consts::TAU * k as f64 / around as f64;
        let rim = cl.tip.coords + (e1 * t.cos() + e2 * t.sin()) * radius;
        for j in 0..=up {
            let q = rim + axis * (j as f64 * SAMPLE_MM);
            if fillets.closest(&q).is_some_and(|(d, _)| d < need) {
                return false;
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use impeller_model::fillet::FilletSection;
    use impeller_model::{fixtures, Side};
    use nalgebra::Unit;

    /// A flat end whose rim reaches 0.15 mm into the fillet beside a main blade's pressure
    /// side (its bottom on the hub's tangent plane there, the cutter toward the channel) is
    /// refused, although the hub and the sharp blade alone would not see it (the rim point
    /// lies in the corner, outside both); moved 1.5 mm into the channel (its far rim still
    /// clear of the next blade's fillet) it passes.
    #[test]
    fn a_rim_in_the_fillet_is_refused_and_one_clear_of_it_passes() {
        let imp = fixtures::default_impeller().unwrap();
        let fillets = ImpellerFillets::new(&imp, FILLET_TOL_MM).unwrap().unwrap();
        let blade = imp.main().blade();
        let s = FilletSection::solve(imp.hub(), blade, Side::Pressure, 0.5, 1.0).unwrap();
        // The bisector from the ball centre toward the corner.
        let into = -(s.hub_normal + s.blade_normal).normalize();
        let q0 = s.centre + into * (s.radius + 0.15);
        let d = fillets.closest(&q0).unwrap().0;
        assert!((d + 0.15).abs() < 1e-3, "{d}");
        assert!(imp.hub().signed_distance(&q0) > 0.0);
        let nh = s.hub_normal;
        let w = (s.blade_normal - nh * s.blade_normal.dot(&nh)).normalize();
        let rho = 1.0;
        let cl = |shift: f64| CutterLocation {
            tip: (q0 + w * (rho + shift)).into(),
            axis: Unit::new_normalize(nh),
        };
        assert!(!cutter_clears_fillets(&fillets, &cl(0.0), rho, 0.0, 0.0));
        assert!(cutter_clears_fillets(&fillets, &cl(1.5), rho, 0.0, 0.0));
        // A blade clearance beyond the fillet's extent skips the samples.
        assert!(cutter_clears_fillets(&fillets, &cl(0.0), rho, 10.0, 0.0));
    }
}
