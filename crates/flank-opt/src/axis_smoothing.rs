//! Smooth tool axes along a written flank pass within its accuracy slack: the shared
//! smoothing of [`cam_plan::axis_smoothing`] (monotone least squares and a Gaussian average of
//! the axis angles about the impeller axis, each posture turned about its ball centre, the
//! whole tool re-checked for clearance), limited to the turn that keeps the flank where the
//! accuracy allows, then the smoothed pass measured densely again against the design side.
//!
//! # Why a limit
//! In flank milling the tool axis *is* the ruling the flank cuts with: turning it moves the
//! contact line. The minimax path of [`crate::finishing`] (and the strip passes of
//! [`crate::semi`]) bend the axis exactly as the blade's rulings twist; where their axis
//! angles change direction inside a pass (on impeller-8+8: by 0.001° to 0.24°), a monotone
//! axis is a different cut, allowed only while the pass keeps its tolerance.
//!
//! # The accuracy budget (a bound, then a measurement)
//! A rotation by `δ` about the ball centre moves a point at distance `ρ` from it by
//! `2ρ·sin(δ/2)`. Every point of the cutting part (ball and flank up to the flute length
//! `L`) lies within `ρ_max = hypot(L − r, R(L))` of the ball centre (`r` the ball radius,
//! `R(L)` the cutter radius at the flute top), so a turn
//! `δ ≤ 2·asin(s / (2ρ_max))` ([`accuracy_turn_limit`]) moves no point of it more than the
//! slack `s = min(overcut_tol − overcut, undercut_tol − undercut)` of the planned pass. The
//! written motion is measured ([`crate::measure`]) as the sphere family whose centres move
//! linearly between locations; a convex combination of displacements of at most `s` is at
//! most `s`, so each interpolated sphere moves at most `s` too, and every signed deviation
//! of the pass changes by at most `s`: the smoothed pass keeps both tolerances. The ball
//! centres stay, so the hub tangency stays exact.
//!
//! The fit is tried first with [`WIDER_LIMIT`] times that budget (the bound is a worst case:
//! a turn in the blade's tangent plane moves the contact line along the blade, not off it),
//! then with the budget itself; each smoothed pass is accepted only when its dense
//! measurement holds the tolerances (certified queries included). Otherwise the planned pass
//! stays and each of its direction changes is reported with [`KeptReason::Accuracy`].
//!
//! Cost: up to two smoothings (clearance queries of the changed postures and motions) and two
//! dense measurements per pass.

use crate::geometry::{ball_radius, member_radius, FlankSide};
use crate::measure::{measure_written_path, DenseGrid, WrittenDeviation};
use crate::FlankError;
use cam_core::{CutterLocation, CutterShape};
use cam_plan::axis_smoothing::{
    reversal_indices, smooth_run, spherical_angles, AxisSmoothing, KeptReason, KeptReversal,
    PostureCheck, RunSmoothing,
};

/// Multiple of the accuracy budget tried first (the smoothed pass then measured densely).
pub const WIDER_LIMIT: f64 = 4.0;

/// Largest turn (rad) about the ball centre that moves no point of the cutting part of
/// `shape` (up to `flute_length` above the tip) more than `slack_mm` (module docs).
pub fn accuracy_turn_limit(shape: &CutterShape, flute_length: f64, slack_mm: f64) -> f64 {
    if slack_mm <= 0.0 || !slack_mm.is_finite() {
        return 0.0;
    }
    let r = ball_radius(shape);
    let reach = (flute_length - r)
        .max(0.0)
        .hypot(member_radius(shape, flute_length))
        .max(r);
    2.0 * (slack_mm / (2.0 * reach)).min(1.0).asin()
}

/// What the accuracy-limited smoothing of one flank pass did.
#[derive(Debug, Clone)]
pub struct PassSmoothing {
    /// The smoothing of the pass (the planned postures when nothing was accepted), with every
    /// direction change left and its reason.
    pub run: RunSmoothing,
    /// The dense measurement of the accepted smoothed pass (`None`: the planned pass kept).
    pub dense: Option<WrittenDeviation>,
    /// The accuracy slack of the planned pass (mm) and the turn budget it allows (rad).
    pub slack_mm: f64,
    /// See `slack_mm`.
    pub budget_rad: f64,
}

/// The planned pass and its accuracy, as [`smooth_pass`] needs them.
#[derive(Debug, Clone, Copy)]
pub struct PlannedPass<'a> {
    /// The written locations of the pass.
    pub locations: &'a [CutterLocation],
    /// The design side the pass cuts (with the optimiser's samples).
    pub side: &'a FlankSide,
    /// The cutter.
    pub shape: CutterShape,
    /// Flute length (mm).
    pub flute_length: f64,
    /// Height above the hub below which undercut is not counted ([`measure_written_path`]).
    pub root: f64,
    /// Overcut and undercut tolerances (mm).
    pub tol_mm: (f64, f64),
    /// The planned pass's dense overcut and undercut (mm).
    pub measured_mm: (f64, f64),
    /// Points reported by the dense measurement beyond this deviation (mm).
    pub report_mm: f64,
}

/// The accuracy-limited fits of a flank pass at `locations` (module docs): the shared
/// smoothing with the turn limited to [`WIDER_LIMIT`] times `budget` (rad), then `budget`,
/// each changed pass handed to `measure`, which returns its measurement when the pass keeps
/// its tolerances. The first accepted smoothing with its measurement, or `None` (no direction
/// change, no budget, or no fit accepted). Cost: up to two smoothings and two measurements.
pub fn within_budget<T, C: PostureCheck + ?Sized>(
    locations: &[CutterLocation],
    shape: &CutterShape,
    budget: f64,
    check: &C,
    mut measure: impl FnMut(&[CutterLocation]) -> Result<Option<T>, FlankError>,
) -> Result<Option<(RunSmoothing, T)>, FlankError> {
    let angles = spherical_angles(locations);
    let th: Vec<f64> = angles.iter().map(|a| a.0).collect();
    let ph: Vec<f64> = angles.iter().map(|a| a.1).collect();
    let reverses = !reversal_indices(&th).is_empty() || !reversal_indices(&ph).is_empty();
    if !reverses || budget <= 0.0 {
        return Ok(None);
    }
    for limit in [WIDER_LIMIT * budget, budget] {
        let opts = AxisSmoothing {
            max_change_rad: limit,
            limit_reason: KeptReason::Accuracy,
            ..AxisSmoothing::ball_end(ball_radius(shape))
        };
        let run = smooth_run(locations, &opts, check);
        if run.changed == 0 {
            continue;
        }
        if let Some(m) = measure(&run.postures)? {
            return Ok(Some((run, m)));
        }
    }
    Ok(None)
}

/// Smooths the axes of one flank pass within its accuracy slack (module docs), each smoothed
/// pass measured densely ([`measure_written_path`]) and accepted when it holds both
/// tolerances (certified queries included); `check` is the whole-tool clearance query of the
/// pass.
pub fn smooth_pass<C: PostureCheck + ?Sized>(
    pass: &PlannedPass<'_>,
    check: &C,
) -> Result<PassSmoothing, FlankError> {
    let slack = (pass.tol_mm.0 - pass.measured_mm.0).min(pass.tol_mm.1 - pass.measured_mm.1);
    let budget = accuracy_turn_limit(&pass.shape, pass.flute_length, slack);
    let accepted = within_budget(pass.locations, &pass.shape, budget, check, |postures| {
        let dense = measure_written_path(
            pass.side,
            &pass.shape,
            pass.flute_length,
            postures,
            pass.root,
            DenseGrid::default(),
            pass.report_mm,
        )?;
        let holds = dense.max_overcut_mm <= pass.tol_mm.0
            && dense.max_undercut_mm <= pass.tol_mm.1
            && dense.uncertified_max_overcut_mm <= pass.tol_mm.0;
        Ok(holds.then_some(dense))
    })?;
    let (run, dense) = match accepted {
        Some((run, dense)) => (run, Some(dense)),
        None => (kept_for_accuracy(pass.locations), None),
    };
    Ok(PassSmoothing {
        run,
        dense,
        slack_mm: slack,
        budget_rad: budget,
    })
}

/// The planned pass unchanged, every direction change of its axis angles reported with
/// [`KeptReason::Accuracy`].
pub fn kept_for_accuracy(locations: &[CutterLocation]) -> RunSmoothing {
    let angles = spherical_angles(locations);
    let th: Vec<f64> = angles.iter().map(|a| a.0).collect();
    let ph: Vec<f64> = angles.iter().map(|a| a.1).collect();
    let (rt, rp) = (reversal_indices(&th), reversal_indices(&ph));
    let kept = rt
        .iter()
        .map(|&i| (i, false))
        .chain(rp.iter().map(|&i| (i, true)))
        .map(|(index, azimuth)| KeptReversal {
            index,
            azimuth,
            reason: KeptReason::Accuracy,
        })
        .collect();
    RunSmoothing {
        postures: locations.to_vec(),
        reversals_before: (rt.len(), rp.len()),
        reversals_after: (rt.len(), rp.len()),
        kept,
        angles_before: angles.clone(),
        angles_after: angles,
        ..RunSmoothing::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_turn_limit_moves_no_cutter_point_beyond_the_slack() {
        let shape = CutterShape::TaperedBallEnd {
            ball_radius: 1.0,
            half_angle: 2f64.to_radians(),
        };
        let (flute, slack) = (20.0, 0.002);
        let d = accuracy_turn_limit(&shape, flute, slack);
        assert!(d > 0.0);
        // The flute-top rim point, the farthest from the ball centre: moved by the chord.
        let reach = (flute - 1.0f64).hypot(member_radius(&shape, flute));
        let moved = 2.0 * reach * (0.5 * d).sin();
        assert!((moved - slack).abs() <= 1e-12, "{moved}");
        // Points lower on the flank move less.
        for c in [1.0, 5.0, 12.0] {
            let rho = (c - 1.0f64).hypot(member_radius(&shape, c));
            assert!(2.0 * rho * (0.5 * d).sin() <= slack);
        }
        assert_eq!(accuracy_turn_limit(&shape, flute, 0.0), 0.0);
        assert_eq!(accuracy_turn_limit(&shape, flute, -1.0), 0.0);
    }
}
