//! Monotone cutter-axis optimisation (paper 000 §3).
//!
//! Along a row, plunges go from the outlet to the inlet. With αᵢ the angle between the hub
//! normal at the cutter-contact point and the cutter axis of plunge `i`, the paper's rule is
//! that α must increase strictly from one plunge to the next, and by the smallest possible
//! amount: then every plunge leans toward the material still to be cut and its non-cutting
//! centre stays out of the hub layer the previous plunge left (paper Figs. 2–4, 9).
//!
//! Method (§3 ①–③), per row:
//! 1. fit a NURBS curve through the shroud points `Wᵢ` of the row's conventional axes
//!    (cubic global interpolation, chord-length parameters, `nurbs::fit::interpolate_curve`;
//!    the cutter-centre points `Mᵢ` stay where they are — the curve through them the paper
//!    also fits would only reproduce them);
//! 2. discretise the W curve with a parameter step (default 1e-5, the paper's "walking
//!    distance");
//! 3. keep the first plunge; for `i = 2, …` keep `Wᵢ` if `αᵢ > αᵢ₋₁`, otherwise walk the
//!    discrete points from `Wᵢ`'s parameter toward the inlet (increasing parameter) and take
//!    the first one whose axis `Mᵢ → W` gives `αᵢ > αᵢ₋₁`. Each candidate's α needs the
//!    contact point of its axis: the depth solve of [`crate::axial_depth`], warm-started from
//!    the previous candidate (2–3 Newton steps). The walk strides over [`WALK_STRIDE`]
//!    points and re-walks the last stride point by point, so it costs O(moved steps / 64 +
//!    64) solves rather than O(moved steps).
//!
//! The result is the smallest move in the discrete sense: the discrete point one step toward
//! the outlet does not satisfy the inequality (tested). When the curve's inlet end is reached
//! without success the plunge keeps its conventional axis and the row is reported
//! non-monotone. Cost: O(moved steps) depth solves per plunge; no allocation per step.

use crate::axial_depth::ContactSeed;
use crate::conventional_axes::{Posture, PostureBuilder};
use cam_core::Vector3;
use cam_plan::PlanError;
use nurbs::fit::{interpolate_curve, parameters, Parametrisation};
use nurbs::NurbsCurve;

/// The paper's discretisation step of the W curve's parameter ("it is advisable to set the
/// walking distance as 10⁻⁵").
pub const DEFAULT_W_STEP: f64 = 1e-5;

/// One row after optimisation.
#[derive(Debug, Clone)]
pub struct OptimisedRow {
    /// The postures, outlet → inlet.
    pub postures: Vec<Posture>,
    /// α of the conventional axes (rad).
    pub alpha_before: Vec<f64>,
    /// α after optimisation (rad).
    pub alpha_after: Vec<f64>,
    /// Discrete W-curve index each moved plunge took, with the index the walk started at.
    pub moves: Vec<Option<(usize, usize)>>,
    /// Whether α increases strictly along the row.
    pub monotone: bool,
    /// The fitted W curve (parameter 0 at the outlet end), when the row has ≥ 2 plunges.
    pub w_curve: Option<NurbsCurve<3>>,
    /// The discretisation step used.
    pub step: f64,
    /// Plunges whose smallest α-raising move was not admissible (it would break the blade
    /// allowance, or make the centre disk run into more material) and that kept their
    /// conventional axis.
    pub kept_for_clearance: usize,
}

/// Fits the W curve of a row: the curve and the parameter of each `Wᵢ`.
pub fn fit_w_curve(
    row: &[Posture],
    operation: &str,
) -> Result<(NurbsCurve<3>, Vec<f64>), PlanError> {
    let pts: Vec<Vector3> = row.iter().map(|p| p.w).collect();
    let degree = 3.min(pts.len().saturating_sub(1)).max(1);
    let err = |e: nurbs::fit::FitError| {
        PlanError::geometry(operation, "W curve of a row", format!("fit: {e}"))
    };
    let curve = interpolate_curve(&pts, degree, Parametrisation::ChordLength, None).map_err(err)?;
    let params = parameters(&pts, Parametrisation::ChordLength).map_err(err)?;
    Ok((curve, params))
}

/// Stride of the coarse walk over the discrete W points: 64 steps of 1e-5 move W by ~0.1 mm
/// on impeller-sized curves; inside a stride every point is tried in order, so the result is
/// the first satisfying point unless α rises above and falls back below αᵢ₋₁ within one
/// stride without the stride's end satisfying it (a wiggle of α over 0.1 mm of W travel).
pub const WALK_STRIDE: usize = 64;

/// The first discrete index in `from..=to` whose axis gives α > `prev` (`to` satisfies it).
#[allow(clippy::too_many_arguments)]
fn first_in(
    builder: &PostureBuilder<'_>,
    curve: &NurbsCurve<3>,
    step: f64,
    centre: &Vector3,
    from: usize,
    to: usize,
    prev: f64,
    seed: Option<((f64, f64), f64)>,
) -> Option<(usize, Vector3, ContactSeed)> {
    let mut seed = seed;
    for k in from..=to {
        let w = curve.point(k as f64 * step);
        if let Some((a, s)) = alpha_of(builder, centre, &w, seed) {
            seed = Some(s);
            if a > prev {
                return Some((k, w, s));
            }
        }
    }
    None
}

/// α of the axis through `centre` and `w`, with the contact seed for the next candidate.
fn alpha_of(
    builder: &PostureBuilder<'_>,
    centre: &Vector3,
    w: &Vector3,
    seed: Option<((f64, f64), f64)>,
) -> Option<(f64, ContactSeed)> {
    let (q, c) = builder.contact(centre, w, seed).ok()?;
    Some((builder.alpha(&q, &c), (c.uv, c.t)))
}

/// Optimises one row's axes (outlet → inlet) with W-curve parameter step `step`.
pub fn optimise_row(
    builder: &PostureBuilder<'_>,
    row: &[Posture],
    step: f64,
    operation: &str,
) -> Result<OptimisedRow, PlanError> {
    optimise_row_within(builder, row, step, operation, &|_, _, _| true)
}

/// [`optimise_row`] where a moved posture must also pass `admissible(moved, unmoved,
/// before)` (`unmoved` the plunge as given, `before` the plunges before it as optimised so
/// far; e.g. the blade allowance of cutter, shank and holder, and that the move does not
/// make its centre disk run into more material): the smallest move that makes α rise is
/// taken only when the posture it gives is admissible; otherwise the plunge keeps its
/// conventional axis (placed clear of the blades by the row planner), the row is not
/// monotone there, and the position is counted in [`OptimisedRow::kept_for_clearance`].
/// Checks run once per moved plunge.
pub fn optimise_row_within(
    builder: &PostureBuilder<'_>,
    row: &[Posture],
    step: f64,
    operation: &str,
    admissible: &(dyn Fn(&Posture, &Posture, &[Posture]) -> bool + Sync),
) -> Result<OptimisedRow, PlanError> {
    let alpha_before: Vec<f64> = row.iter().map(|p| p.alpha).collect();
    if row.len() < 2 {
        return Ok(OptimisedRow {
            postures: row.to_vec(),
            alpha_after: alpha_before.clone(),
            alpha_before,
            moves: vec![None; row.len()],
            monotone: true,
            w_curve: None,
            step,
            kept_for_clearance: 0,
        });
    }
    let (curve, params) = fit_w_curve(row, operation)?;
    let last = (1.0 / step).floor() as usize;
    let mut postures = row.to_vec();
    let mut moves = vec![None; row.len()];
    let mut monotone = true;
    let mut kept_for_clearance = 0;
    for i in 1..row.len() {
        let prev = postures[i - 1].alpha;
        if postures[i].alpha > prev {
            continue;
        }
        let p = row[i];
        let k0 = (params[i] / step).ceil() as usize;
        let mut seed = Some((p.contact.uv, p.contact.t));
        // Walk in strides of WALK_STRIDE discrete points; when a stride's end satisfies
        // the inequality, walk the stride again point by point for the first that does.
        let mut found = None;
        let mut k = k0;
        let mut from = k0;
        while k <= last {
            let w = curve.point(k as f64 * step);
            match alpha_of(builder, &p.centre, &w, seed) {
                Some((a, s)) => {
                    seed = Some(s);
                    if a > prev {
                        found = first_in(builder, &curve, step, &p.centre, from, k, prev, seed);
                        break;
                    }
                }
                None => seed = None,
            }
            from = k + 1;
            k = if k == last {
                last + 1
            } else {
                (k + WALK_STRIDE).min(last)
            };
        }
        match found {
            Some((k, w, s)) => {
                let moved = builder.through(p.m, p.s, p.centre, w, Some(s))?;
                if admissible(&moved, &row[i], &postures[..i]) {
                    postures[i] = moved;
                    moves[i] = Some((k, k0));
                } else {
                    kept_for_clearance += 1;
                    monotone = false;
                }
            }
            None => monotone = false,
        }
    }
    let alpha_after: Vec<f64> = postures.iter().map(|p| p.alpha).collect();
    monotone &= alpha_after.windows(2).all(|w| w[1] > w[0]);
    Ok(OptimisedRow {
        postures,
        alpha_before,
        alpha_after,
        moves,
        monotone,
        w_curve: Some(curve),
        step,
        kept_for_clearance,
    })
}

/// α of the axis through plunge `i`'s centre and the W-curve point of discrete index `k`
/// (for checking the smallest-move property).
pub fn alpha_at_index(
    builder: &PostureBuilder<'_>,
    row: &OptimisedRow,
    i: usize,
    k: usize,
) -> Option<f64> {
    let curve = row.w_curve.as_ref()?;
    let p = row.postures.get(i)?;
    let w = curve.point(k as f64 * row.step);
    alpha_of(builder, &p.centre, &w, Some((p.contact.uv, p.contact.t))).map(|a| a.0)
}
