//! The W walk of paper 000 §3: the smallest move of a plunge's upper axis point along the
//! row's W curve that removes its centre interference.
//!
//! Method (§3 ①–③), per row:
//! 1. fit a NURBS curve through the shroud points `Wᵢ` of the row's conventional axes
//!    (cubic global interpolation, chord-length parameters, `nurbs::fit::interpolate_curve`;
//!    parameter 0 at the outlet end; the cutter-centre points `Mᵢ` stay where they are — the
//!    curve through them the paper also fits would only reproduce them);
//! 2. discretise it with a parameter step (default 1e-5, the paper's "walking distance"): the
//!    candidates of plunge `i` are the parameters `uᵢ ± k·step`, `uᵢ` its own `Wᵢ`'s;
//! 3. move `Wᵢ` along the discrete points **in the feed direction of the plunge's segment**
//!    ([`crate::feed`]: toward the inlet for a segment fed toward the inlet, as in the paper,
//!    toward the outlet otherwise), which leans the axis further toward the material still to
//!    be cut, and take the first point whose axis `Mᵢ → W` satisfies the criterion; when no
//!    point in that direction does, the same against the feed (see [`walk`]: on a floor
//!    convex across the feed the axes must turn less than the normals, not lean further).
//!
//! # Criterion
//! The paper's criterion is "αᵢ > αᵢ₋₁". With signed α ([`crate::feed::signed_alpha`]) it is
//! neither necessary nor sufficient on `impeller-plunge-400`: rows fed inlet → outlet have α
//! falling by 2–3° over 20 plunges with no interference at all (hub curvature turns the
//! normals with the rows), and where two segments meet α must fall to zero, which no
//! increasing rule allows. So the walk is applied only to plunges that still interfere after
//! the feed direction is chosen ("the W walk then only corrects what is left", issue 33), and
//! its criterion is what the rule stands for: the centre disk's travel through material left
//! by everything machined before ([`crate::interference`]) is at most
//! [`crate::interference::INTERFERENCE_TRAVEL_TOL_MM`]. A candidate must also be admissible
//! (blade allowance of cutter, shank and holder; shank and holder out of the stock); the walk
//! stops at the first inadmissible one, since leaning further only moves the tool further
//! toward the blades.
//!
//! # Search and smallest move
//! The travel is costly (thousands of disk samples), so the walk does not try every discrete
//! point: it doubles the move (1, 2, 4, … steps) up to a stride of [`WALK_MAX_STRIDE_MM`] of W
//! travel, then goes on in that stride, until a candidate satisfies the criterion, and
//! bisects between the last failing and the first satisfying move. The result `k` is the
//! smallest move in the discrete sense on that bracket: `k` satisfies the criterion and
//! `k − 1` does not (tested); a clean range narrower than the stride before it can be
//! missed. A direction ends at the curve's end, at an inadmissible candidate, after the
//! caller's reach of W travel, or once the travel has grown [`WALK_GIVE_UP_MM`] over the
//! least seen (the centre has left the earlier holes). When both directions end without a
//! clean candidate the plunge keeps its axis. Cost per walked plunge: O(log₂ stride + W
//! travel / stride + log₂ stride) posture and travel evaluations per direction.

use crate::conventional_axes::{Posture, PostureBuilder};
use crate::feed::Feed;
use cam_core::Vector3;
use cam_plan::PlanError;
use nurbs::fit::{interpolate_curve, parameters, Parametrisation};
use nurbs::NurbsCurve;

/// The paper's discretisation step of the W curve's parameter ("it is advisable to set the
/// walking distance as 10⁻⁵").
pub const DEFAULT_W_STEP: f64 = 1e-5;

/// The W curve of one row: the curve through its conventional shroud points (outlet →
/// inlet), the parameter of each, and the discretisation step.
#[derive(Debug, Clone)]
pub struct WCurve {
    /// The fitted curve (parameter 0 at the outlet end).
    pub curve: NurbsCurve<3>,
    /// Parameter of each station's `Wᵢ`.
    pub params: Vec<f64>,
    /// Discretisation step of the parameter.
    pub step: f64,
}

/// Fits the W curve of a row (postures in station order). `None` for a row of fewer than two
/// plunges (nothing to walk along).
pub fn fit_w_curve(
    row: &[Posture],
    step: f64,
    operation: &str,
) -> Result<Option<WCurve>, PlanError> {
    if row.len() < 2 {
        return Ok(None);
    }
    let pts: Vec<Vector3> = row.iter().map(|p| p.w).collect();
    let degree = 3.min(pts.len() - 1);
    let err = |e: nurbs::fit::FitError| {
        PlanError::geometry(operation, "W curve of a row", format!("fit: {e}"))
    };
    let curve = interpolate_curve(&pts, degree, Parametrisation::ChordLength, None).map_err(err)?;
    let params = parameters(&pts, Parametrisation::ChordLength).map_err(err)?;
    Ok(Some(WCurve {
        curve,
        params,
        step,
    }))
}

/// Largest stride (mm of W travel) of the walk's scan: a clean range of W narrower than this
/// can be stepped over (the doubling from one discrete step reaches it first).
pub const WALK_MAX_STRIDE_MM: f64 = 0.25;
/// The walk gives a direction up once the travel exceeds the smallest seen by this much (mm):
/// the centre disk has then left the earlier holes and leaning further only adds material.
pub const WALK_GIVE_UP_MM: f64 = 0.5;

/// What a candidate axis gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Verdict {
    /// Breaks the blade allowance or the stock clearance: the walk stops in this direction.
    Inadmissible,
    /// Admissible; the centre disk's travel through material (mm).
    Travel(f64),
}

/// A plunge after the walk.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Walked {
    /// The moved posture.
    pub posture: Posture,
    /// Discrete steps moved.
    pub steps: usize,
    /// Whether `W` moved in the feed direction (the paper's) or against it.
    pub toward_feed: bool,
    /// W-curve parameter of the new `W`.
    pub param: f64,
}

/// The W-curve parameter `d` steps from station `station`'s `W` toward the inlet
/// (increasing parameter) or the outlet, `None` beyond the curve.
pub fn param_at(curve: &WCurve, station: usize, toward: Feed, d: usize) -> Option<f64> {
    let u0 = *curve.params.get(station)?;
    let du = d as f64 * curve.step;
    let u = match toward {
        Feed::TowardInlet => u0 + du,
        Feed::TowardOutlet => u0 - du,
    };
    (0.0..=1.0).contains(&u).then_some(u)
}

/// The posture of plunge `p` (station `station` of the row of `curve`) with its upper point
/// moved `d` discrete steps along the W curve toward the inlet or the outlet; `None` beyond
/// the curve or where no contact exists.
pub fn moved(
    builder: &PostureBuilder<'_>,
    curve: &WCurve,
    p: &Posture,
    station: usize,
    toward: Feed,
    d: usize,
) -> Option<(Posture, f64)> {
    let u = param_at(curve, station, toward, d)?;
    let w = curve.curve.point(u);
    builder
        .through(p.m, p.s, p.centre, w, Some((p.contact.uv, p.contact.t)))
        .ok()
        .map(|q| (q, u))
}

/// How far a walk may go and what it must reach.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WalkGoal {
    /// Largest W travel (mm) in either direction.
    pub reach_mm: f64,
    /// Largest travel (mm) a clean candidate has.
    pub tol: f64,
}

/// The smallest move of `p`'s `W` along `curve` whose posture `judge` finds admissible with
/// a travel of at most `goal.tol`: first in the feed direction `feed` (the paper's, leaning further
/// toward the material to be cut), then against it (on a floor convex across the feed, e.g.
/// around the hub near the inlet, consecutive flat bottoms that follow the turning normals
/// leave a wedge the next centre meets: the axis must turn less). W moves at most
/// `goal.reach_mm` (the caller's bound: the cutting-edge length beyond the previous plunge's
/// W, further the centre leaves the previous hole). `None` when neither direction finds one.
pub fn walk(
    builder: &PostureBuilder<'_>,
    curve: &WCurve,
    p: &Posture,
    station: usize,
    feed: Feed,
    goal: WalkGoal,
    judge: &dyn Fn(&Posture) -> Verdict,
) -> Option<Walked> {
    [feed, feed.reversed()].into_iter().find_map(|toward| {
        walk_toward(builder, curve, p, station, toward, goal, judge).map(|mut w| {
            w.toward_feed = toward == feed;
            w
        })
    })
}

/// [`walk`] in one direction: doubling from one discrete step up to a stride of
/// [`WALK_MAX_STRIDE_MM`] of W travel, then that stride, until a clean candidate; then
/// bisection between the last failing and the first clean move.
fn walk_toward(
    builder: &PostureBuilder<'_>,
    curve: &WCurve,
    p: &Posture,
    station: usize,
    toward: Feed,
    goal: WalkGoal,
    judge: &dyn Fn(&Posture) -> Verdict,
) -> Option<Walked> {
    let WalkGoal { reach_mm, tol } = goal;
    let u0 = *curve.params.get(station)?;
    // W travel per discrete step at this point of the curve (mm).
    let speed = curve.curve.derivs(u0, 1).get(1)?.norm() * curve.step;
    if !(speed.is_finite() && speed > 0.0) {
        return None;
    }
    let room = match toward {
        Feed::TowardInlet => 1.0 - u0,
        Feed::TowardOutlet => u0,
    };
    let max_d = ((room / curve.step).floor() as usize).min((reach_mm / speed).ceil() as usize);
    let max_stride = ((WALK_MAX_STRIDE_MM / speed).floor() as usize).max(1);
    let try_d = |d: usize| -> Option<(Verdict, Posture, f64)> {
        let (q, u) = moved(builder, curve, p, station, toward, d)?;
        Some((judge(&q), q, u))
    };
    let (mut lo, mut d) = (0usize, 1usize);
    let mut least = f64::INFINITY;
    let (mut hi, mut best) = loop {
        if d > max_d {
            return None;
        }
        match try_d(d)? {
            (Verdict::Inadmissible, ..) => return None,
            (Verdict::Travel(t), q, u) if t <= tol => break (d, (q, u)),
            (Verdict::Travel(t), ..) => {
                if t > least + WALK_GIVE_UP_MM {
                    return None;
                }
                least = least.min(t);
                lo = d;
                d = if d == max_d {
                    max_d + 1
                } else {
                    (d + d.min(max_stride)).min(max_d)
                };
            }
        }
    };
    // Bisection: `lo` interferes (or is the unmoved plunge), `hi` is clean.
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        match try_d(mid) {
            Some((Verdict::Travel(t), q, u)) if t <= tol => {
                hi = mid;
                best = (q, u);
            }
            _ => lo = mid,
        }
    }
    Some(Walked {
        posture: best.0,
        steps: hi,
        toward_feed: true,
        param: best.1,
    })
}
