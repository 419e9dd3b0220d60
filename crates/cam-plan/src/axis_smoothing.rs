//! Smooth tool axes along a cutting run, planned once the postures are chosen: the axis
//! sequence of a ball-end point-milling run is made monotone and smooth in the two angles the
//! rotary axes follow, turning each posture about its ball centre (so the ball, and with it
//! every contact, stays exactly where the planner put it), and every changed posture and every
//! motion touching one is checked again with the planner's whole-tool clearance query. What
//! the check refuses keeps its planned posture, and every direction change left is reported
//! with its reason.
//!
//! # Why and in which angles
//! An accessibility search in fixed turning steps (paper 004: `±k·ΔC` about the impeller
//! axis) picks, from one point of a flow line to the next, postures that alternate between
//! neighbouring steps: the rotary axes chatter back and forth inside the cut (reverse
//! motions, which stop the feed drive, let backlash act and mark the surface). The tool axis
//! `a` is written in spherical angles about the workpiece's +Z (the impeller axis):
//! polar angle `θ = acos(a_z)` and azimuth `φ = atan2(a_y, a_x)` (unwrapped along the run).
//! A table-table or head-table machine whose C turns about the impeller axis moves C with
//! `φ` and its tilting axis with `θ` (`|A| = θ` on an A/C trunnion), so a run monotone in
//! `θ` and `φ` is free of reverse motions on those machines; the post counts the machine's
//! own axes afterwards and reports what is left. Postures within [`MIN_POLAR_RAD`] of +Z
//! (where `φ` is undefined) keep their planned axes; the run is smoothed between them.
//!
//! # The fit (per angle, per segment of a run)
//! 1. Direction `d`: the sign of the angle's net change over the segment (of its
//!    least-squares slope when the ends are equal).
//! 2. Monotone least squares: the isotonic regression of `d·x` (pool-adjacent-violators,
//!    exact, O(m)) — the non-decreasing sequence nearest the planned angles in the sum of
//!    squares.
//! 3. Smoothing: a Nadaraya–Watson average with the Gaussian kernel of width `h =
//!    kernel_spacings × (median ball-centre spacing)` over the ball centres' arc length,
//!    truncated at `4h`. Both the Gaussian and the band indicator are totally positive
//!    kernels, so the average of a monotone sequence is monotone; a running maximum removes
//!    the rounding-level steps against the direction. Cost O(m·w), `w` the points within
//!    `4h`.
//!
//! # Keeping the contact and the clearance
//! The new axis `a'ᵢ` keeps the ball centre `cᵢ = tipᵢ + r·aᵢ`: `tip'ᵢ = cᵢ − r·a'ᵢ` (the ball
//! is the same ball: exact to rounding, ~1e-12 mm). A posture turned more than
//! `max_change_rad` from its planned axis ([`DEFAULT_MAX_CHANGE_DEG`]) is refused: a larger
//! turn is a different posture, not a smoothing.
//! The changed postures are checked with [`PostureCheck::posture_clear`] and every motion
//! with a changed end with [`PostureCheck::motion_clear`] (for [`PassCheck`]: the whole tool,
//! cutter, shank and holder, against the whole design, the motion certified as the
//! controller interpolates it). When the smooth fit is refused, the two one-sided monotone
//! envelopes ([`monotone_envelope`]: every angle moved on, or held back, to the nearest
//! monotone sequence) are tried: each turns every posture to one side of its planned one
//! only, which keeps the clearance where the planner turned the axis away from an obstacle
//! by whole steps. A segment whose fits all fail keeps the planned postures at the indices
//! the smooth fit was refused at (*pinned*; the one turned most, for the angle limit) and is
//! split there;
//! each part is fitted and checked on its own, up to `max_fits` fits per run. A segment left
//! failing when the budget is spent keeps its planned postures. Segments are separated by
//! pinned postures and each check includes the motions to its pinned neighbours, so accepted
//! segments never meet an unchecked motion.
//!
//! Every reversal left in the run is attributed to the nearest pinned posture or kept
//! segment and its reason ([`KeptReason`]).
//!
//! Cost per run: at most `max_fits` fits of O(m·w) and checks of the changed postures and
//! motions (the clearance queries dominate). Postures of one check run in parallel (rayon).

use crate::pass_check::PassCheck;
use crate::{Metrics, Plot, PlotKind, PlotSeries};
use cam_core::{CutterLocation, Point3, Vector3};
use rayon::prelude::*;
use std::f64::consts::{PI, TAU};
use std::sync::OnceLock;

/// Angle steps (rad) within which an angle counts as standing still when direction changes
/// are counted (the post's dead band).
pub const DEAD_BAND_RAD: f64 = 1e-6;

/// Default largest turn of a posture by the smoothing (deg): below the 10° that paper 004
/// allows its reverse-motion removal (and the post's smoothing, `max_angle_change`), and four
/// of the 1.5° steps of the hub and blade-root accessibility searches (two of point
/// milling's 3°): the smoothing may flatten the small rises and falls of the planned axis
/// along a run, not choose another posture family.
pub const DEFAULT_MAX_CHANGE_DEG: f64 = 6.0;

/// Closest approach of the tool axis to +Z (rad) for which the azimuth is smoothed.
pub const MIN_POLAR_RAD: f64 = 1.0 * PI / 180.0;

/// The whole-tool check of a smoothed run. `index` is the posture's index in the run, for
/// planners whose limits vary along it (an axis range in a local frame).
///
/// A posture's check measures what the checks of the motions to and from it need (its
/// clearances, [`PostureCheck::Clear`]): [`smooth_run`] keeps that measure and hands it to
/// both motions, so each posture is measured once per fit instead of once more for each of
/// its motions, and each planned posture once per run.
pub trait PostureCheck: Sync {
    /// What a clear posture's check measured that its motions' checks use.
    type Clear: Send + Sync;
    /// The measure of the tool at `cl`, in place of posture `index`, when it keeps the
    /// planner's floors; `None` otherwise.
    fn posture_clear(&self, index: usize, cl: &CutterLocation) -> Option<Self::Clear>;
    /// The measure of posture `index` as the planner placed it (the unchanged end of a
    /// motion), `None` when a motion from or to it cannot be certified. By default the
    /// posture check itself.
    fn planned_clear(&self, index: usize, cl: &CutterLocation) -> Option<Self::Clear> {
        self.posture_clear(index, cl)
    }
    /// Whether the motion from `a` (in place of posture `index`) to `b` (of `index + 1`),
    /// both clear with the measures given, keeps the floors.
    fn motion_clear(
        &self,
        index: usize,
        a: (&CutterLocation, &Self::Clear),
        b: (&CutterLocation, &Self::Clear),
    ) -> bool;
}

impl PostureCheck for PassCheck<'_> {
    type Clear = crate::pass_check::PostureClearance;
    fn posture_clear(&self, _: usize, cl: &CutterLocation) -> Option<Self::Clear> {
        self.clear_posture(cl)
    }
    fn motion_clear(
        &self,
        _: usize,
        a: (&CutterLocation, &Self::Clear),
        b: (&CutterLocation, &Self::Clear),
    ) -> bool {
        self.motion(0, a, b).is_none()
    }
}

/// Settings of [`smooth_run`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisSmoothing {
    /// Height of the kept point above the tip (mm): the ball radius for a ball end.
    pub pivot_mm: f64,
    /// Largest turn of any posture from its planned axis (rad; default
    /// [`DEFAULT_MAX_CHANGE_DEG`]).
    pub max_change_rad: f64,
    /// Width of the Gaussian smoothing kernel in median ball-centre spacings (default 2).
    pub kernel_spacings: f64,
    /// Largest number of fits (and checks) per run (default 24).
    pub max_fits: usize,
    /// The reason given to a direction change kept because the fit turns a posture more than
    /// `max_change_rad`: [`KeptReason::AngleLimit`] for the default limit,
    /// [`KeptReason::Accuracy`] where the limit is an accuracy budget (a flank pass: the
    /// turn that moves the cutter's flank by the pass's accuracy slack).
    pub limit_reason: KeptReason,
}

impl AxisSmoothing {
    /// Defaults for a ball end of radius `ball_radius_mm`.
    pub fn ball_end(ball_radius_mm: f64) -> Self {
        Self {
            pivot_mm: ball_radius_mm,
            max_change_rad: DEFAULT_MAX_CHANGE_DEG.to_radians(),
            kernel_spacings: 2.0,
            max_fits: 24,
            limit_reason: KeptReason::AngleLimit,
        }
    }
}

/// Why a direction change was left in a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum KeptReason {
    /// A smoothed posture, or a motion to it, comes nearer to the design than the floor:
    /// the axis changes direction to stay clear.
    Clearance,
    /// The monotone fit turns a posture more than `max_change_rad` from its planned axis
    /// (the planned axes really change direction here).
    AngleLimit,
    /// The posture lies within [`MIN_POLAR_RAD`] of the impeller axis, where the azimuth is
    /// undefined (it keeps its planned axis).
    NearPole,
    /// The fit budget `max_fits` was spent.
    Budget,
    /// The smoothed run would move the cutting edge beyond the operation's accuracy
    /// tolerance (a flank pass, whose axis is the ruling it cuts with: the turn exceeds the
    /// accuracy budget, or the re-measured pass misses the tolerance).
    Accuracy,
}

impl KeptReason {
    /// All reasons, in report order.
    pub const ALL: [KeptReason; 5] = [
        KeptReason::Clearance,
        KeptReason::AngleLimit,
        KeptReason::NearPole,
        KeptReason::Budget,
        KeptReason::Accuracy,
    ];
    /// The operation metric that counts the direction changes kept for this reason
    /// (`axis_reversals_kept_<name>`).
    pub fn metric(self) -> String {
        format!("axis_reversals_kept_{}", self.name())
    }
    /// Snake-case name for metrics.
    pub fn name(self) -> &'static str {
        match self {
            KeptReason::Clearance => "clearance",
            KeptReason::AngleLimit => "angle_limit",
            KeptReason::NearPole => "near_pole",
            KeptReason::Budget => "budget",
            KeptReason::Accuracy => "accuracy",
        }
    }
}

/// A direction change left in a smoothed run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KeptReversal {
    /// Index (in the run) of the posture the reversing step arrives at.
    pub index: usize,
    /// `true` for the azimuth `φ`, `false` for the polar angle `θ`.
    pub azimuth: bool,
    /// Why it stays.
    pub reason: KeptReason,
}

/// What [`smooth_run`] did to one run.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RunSmoothing {
    /// The run's postures after smoothing (the planned ones where nothing changed).
    pub postures: Vec<CutterLocation>,
    /// Direction changes of `(θ, φ)` before.
    pub reversals_before: (usize, usize),
    /// Direction changes of `(θ, φ)` after.
    pub reversals_after: (usize, usize),
    /// Those left, with their reasons.
    pub kept: Vec<KeptReversal>,
    /// Postures changed.
    pub changed: usize,
    /// Largest turn of a posture from its planned axis (rad).
    pub max_change_rad: f64,
    /// Largest movement of a ball centre (mm; rounding only).
    pub max_centre_shift_mm: f64,
    /// Fits tried.
    pub fits: usize,
    /// Planned and smoothed `(θ, φ)` per posture (rad), for plots.
    pub angles_before: Vec<(f64, f64)>,
    /// See `angles_before`.
    pub angles_after: Vec<(f64, f64)>,
}

/// Number of direction changes of a sequence (steps within [`DEAD_BAND_RAD`] skipped), with
/// the index each reversing step arrives at.
pub fn reversal_indices(x: &[f64]) -> Vec<usize> {
    let mut last = 0.0;
    let mut out = Vec::new();
    for k in 1..x.len() {
        let d = x[k] - x[k - 1];
        if d.abs() <= DEAD_BAND_RAD {
            continue;
        }
        let s = d.signum();
        if last != 0.0 && s != last {
            out.push(k);
        }
        last = s;
    }
    out
}

/// `(θ, φ)` of every axis, `φ` unwrapped along the sequence.
pub fn spherical_angles(cls: &[CutterLocation]) -> Vec<(f64, f64)> {
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(cls.len());
    for cl in cls {
        let a = cl.axis.into_inner();
        let theta = a.z.clamp(-1.0, 1.0).acos();
        let mut phi = a.y.atan2(a.x);
        if let Some(&(_, p)) = out.last() {
            phi += TAU * ((p - phi) / TAU).round();
        }
        out.push((theta, phi));
    }
    out
}

fn axis_of(theta: f64, phi: f64) -> Vector3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    Vector3::new(st * cp, st * sp, ct)
}

/// Isotonic (non-decreasing) least-squares fit of `x` by pool-adjacent-violators. O(m).
pub fn isotonic_increasing(x: &[f64]) -> Vec<f64> {
    // Blocks of (sum, count).
    let mut blocks: Vec<(f64, usize)> = Vec::with_capacity(x.len());
    for &v in x {
        blocks.push((v, 1));
        while blocks.len() >= 2 {
            let (s1, n1) = blocks[blocks.len() - 1];
            let (s0, n0) = blocks[blocks.len() - 2];
            if s0 / n0 as f64 <= s1 / n1 as f64 {
                break;
            }
            blocks.pop();
            let last = blocks.len() - 1;
            blocks[last] = (s0 + s1, n0 + n1);
        }
    }
    let mut out = Vec::with_capacity(x.len());
    for (s, n) in blocks {
        out.extend(std::iter::repeat_n(s / n as f64, n));
    }
    out
}

/// The monotone smooth fit of one angle over arc-length parameters `s` (module docs, steps
/// 1–3): monotone in the direction of the angle's net change.
pub fn monotone_smooth(s: &[f64], x: &[f64], kernel_spacings: f64) -> Vec<f64> {
    let m = x.len();
    if m < 3 {
        return x.to_vec();
    }
    let mut dir = (x[m - 1] - x[0]).signum();
    if x[m - 1] == x[0] {
        let sm = s.iter().sum::<f64>() / m as f64;
        let xm = x.iter().sum::<f64>() / m as f64;
        let slope: f64 = s.iter().zip(x).map(|(a, b)| (a - sm) * (b - xm)).sum();
        dir = if slope < 0.0 { -1.0 } else { 1.0 };
    }
    let y: Vec<f64> = x.iter().map(|v| dir * v).collect();
    let y = isotonic_increasing(&y);
    // Median spacing; the index when the centres stand still.
    let mut gaps: Vec<f64> = s.windows(2).map(|w| w[1] - w[0]).collect();
    gaps.sort_by(f64::total_cmp);
    let med = gaps[gaps.len() / 2];
    let idx: Vec<f64>;
    let (s, h) = if med > 1e-9 {
        (s, kernel_spacings * med)
    } else {
        idx = (0..m).map(|i| i as f64).collect();
        (&idx[..], kernel_spacings)
    };
    let h = h.max(1e-12);
    let reach = 4.0 * h;
    let mut out = Vec::with_capacity(m);
    let mut lo = 0;
    for i in 0..m {
        while s[i] - s[lo] > reach {
            lo += 1;
        }
        let (mut num, mut den) = (0.0, 0.0);
        let mut j = lo;
        while j < m && s[j] - s[i] <= reach {
            let u = (s[j] - s[i]) / h;
            let w = (-0.5 * u * u).exp();
            num += w * y[j];
            den += w;
            j += 1;
        }
        let v = num / den;
        out.push(match out.last() {
            Some(&p) if v < p => p,
            _ => v,
        });
    }
    out.into_iter().map(|v| dir * v).collect()
}

/// The fits tried on a segment, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Fit {
    /// Isotonic least squares, then the Gaussian average (module docs).
    Smooth,
    /// The smallest monotone sequence at or beyond every planned angle in the direction of
    /// the net change ([`monotone_envelope`]).
    Ahead,
    /// The largest monotone sequence at or behind every planned angle.
    Behind,
}

/// A one-sided monotone envelope of `x` in the direction `d` of its net change: with
/// `ahead`, `yᵢ = d·max_{j ≤ i} d·xⱼ` (every angle moved on in the direction of travel, the
/// smallest such monotone sequence), else `yᵢ = d·min_{j ≥ i} d·xⱼ` (every angle held back,
/// the largest such). Each posture turns only to one side of its planned one: where the
/// planner's accessibility search turned the axis away from an obstacle by whole steps, the
/// envelope that keeps the larger turn keeps its clearance when the average does not. O(m).
pub fn monotone_envelope(x: &[f64], ahead: bool) -> Vec<f64> {
    let m = x.len();
    if m == 0 {
        return Vec::new();
    }
    let d = if x[m - 1] < x[0] { -1.0 } else { 1.0 };
    let mut y: Vec<f64> = x.iter().map(|v| d * v).collect();
    if ahead {
        for i in 1..m {
            y[i] = y[i].max(y[i - 1]);
        }
    } else {
        for i in (0..m - 1).rev() {
            y[i] = y[i].min(y[i + 1]);
        }
    }
    y.into_iter().map(|v| d * v).collect()
}

/// Why a segment's fit was refused: the indices to pin and the reason. `planned_clear`
/// holds the measures of the planned postures asked so far (filled on demand, kept for the
/// whole run).
fn refused<C: PostureCheck + ?Sized>(
    seg: (usize, usize),
    planned: &[CutterLocation],
    cand: &[CutterLocation],
    opts: &AxisSmoothing,
    check: &C,
    planned_clear: &[OnceLock<Option<C::Clear>>],
) -> Option<(Vec<usize>, KeptReason)> {
    let (a, b) = seg;
    // The angle limit: pin the posture turned most.
    let (worst, turn) = (a..b)
        .map(|i| (i, planned[i].axis.angle(&cand[i].axis)))
        .max_by(|x, y| x.1.total_cmp(&y.1))?;
    if turn > opts.max_change_rad {
        return Some((vec![worst], opts.limit_reason));
    }
    // The changed postures' measures, in index order (`None`: not clear).
    let changed: Vec<(usize, Option<C::Clear>)> = (a..b)
        .into_par_iter()
        .filter(|&i| cand[i] != planned[i])
        .map(|i| (i, check.posture_clear(i, &cand[i])))
        .collect();
    let bad: Vec<usize> = changed
        .iter()
        .filter(|(_, c)| c.is_none())
        .map(|(i, _)| *i)
        .collect();
    if !bad.is_empty() {
        return Some((bad, KeptReason::Clearance));
    }
    let measure = |i: usize| -> Option<&C::Clear> {
        if cand[i] != planned[i] {
            let k = changed.binary_search_by_key(&i, |(j, _)| *j).ok()?;
            changed[k].1.as_ref()
        } else {
            planned_clear[i]
                .get_or_init(|| check.planned_clear(i, &planned[i]))
                .as_ref()
        }
    };
    // Motions with a changed end: inside the segment and to its pinned neighbours.
    let lo = a.saturating_sub(1);
    let hi = (b + 1).min(cand.len());
    let bad: Vec<usize> = (lo..hi.saturating_sub(1))
        .into_par_iter()
        .filter(|&i| {
            (cand[i] != planned[i] || cand[i + 1] != planned[i + 1])
                && !match (measure(i), measure(i + 1)) {
                    (Some(ca), Some(cb)) => {
                        check.motion_clear(i, (&cand[i], ca), (&cand[i + 1], cb))
                    }
                    _ => false,
                }
        })
        .map(|i| if cand[i] != planned[i] { i } else { i + 1 })
        .collect();
    if !bad.is_empty() {
        return Some((bad, KeptReason::Clearance));
    }
    None
}

/// Smooths the tool axes of one ball-end cutting run (module docs). `run` holds the planned
/// postures in machining order.
pub fn smooth_run<C: PostureCheck + ?Sized>(
    run: &[CutterLocation],
    opts: &AxisSmoothing,
    check: &C,
) -> RunSmoothing {
    let n = run.len();
    let before = spherical_angles(run);
    let thetas: Vec<f64> = before.iter().map(|a| a.0).collect();
    let phis: Vec<f64> = before.iter().map(|a| a.1).collect();
    let rev = (reversal_indices(&thetas), reversal_indices(&phis));
    let mut out = RunSmoothing {
        postures: run.to_vec(),
        reversals_before: (rev.0.len(), rev.1.len()),
        reversals_after: (rev.0.len(), rev.1.len()),
        angles_before: before.clone(),
        angles_after: before.clone(),
        ..RunSmoothing::default()
    };
    if n < 3 || (rev.0.is_empty() && rev.1.is_empty()) {
        return out;
    }
    let centres: Vec<Vector3> = run
        .iter()
        .map(|c| c.axis_point(opts.pivot_mm).coords)
        .collect();
    let mut s = vec![0.0; n];
    for i in 1..n {
        s[i] = s[i - 1] + (centres[i] - centres[i - 1]).norm();
    }
    // (index, reason) of every posture kept as planned, and segments kept whole.
    let mut pinned: Vec<(usize, KeptReason)> = Vec::new();
    let mut kept_segments: Vec<((usize, usize), KeptReason)> = Vec::new();
    // Postures within MIN_POLAR_RAD of +Z keep their planned axes; the segments between them
    // are smoothed.
    let mut work = Vec::new();
    let mut from = 0;
    for (i, t) in thetas.iter().enumerate() {
        if t.sin() < MIN_POLAR_RAD.sin() {
            pinned.push((i, KeptReason::NearPole));
            work.push((from, i));
            from = i + 1;
        }
    }
    work.push((from, n));
    {
        let mut cand = run.to_vec();
        let planned_clear: Vec<OnceLock<Option<C::Clear>>> =
            (0..n).map(|_| OnceLock::new()).collect();
        while let Some((a, b)) = work.pop() {
            let th = &thetas[a..b];
            let ph = &phis[a..b];
            let (rt, rp) = (
                !reversal_indices(th).is_empty(),
                !reversal_indices(ph).is_empty(),
            );
            if b - a < 3 || !(rt || rp) {
                continue;
            }
            if out.fits >= opts.max_fits {
                kept_segments.push(((a, b), KeptReason::Budget));
                continue;
            }
            out.fits += 1;
            // The smooth fit first, then the two one-sided monotone envelopes.
            let mut first_refusal = None;
            for fit in [Fit::Smooth, Fit::Ahead, Fit::Behind] {
                let angles = |x: &[f64], reverses: bool| {
                    if !reverses {
                        return x.to_vec();
                    }
                    match fit {
                        Fit::Smooth => monotone_smooth(&s[a..b], x, opts.kernel_spacings),
                        Fit::Ahead => monotone_envelope(x, true),
                        Fit::Behind => monotone_envelope(x, false),
                    }
                };
                let (th2, ph2) = (angles(th, rt), angles(ph, rp));
                for (k, i) in (a..b).enumerate() {
                    if th2[k] == thetas[i] && ph2[k] == phis[i] {
                        cand[i] = run[i];
                        continue;
                    }
                    let axis = axis_of(th2[k], ph2[k]);
                    cand[i] = CutterLocation {
                        tip: Point3::from(centres[i] - axis * opts.pivot_mm),
                        axis: nalgebra::Unit::new_normalize(axis),
                    };
                }
                match refused((a, b), run, &cand, opts, check, &planned_clear) {
                    None => {
                        first_refusal = None;
                        break;
                    }
                    Some(r) => {
                        first_refusal.get_or_insert(r);
                    }
                }
            }
            if let Some((bad, reason)) = first_refusal {
                cand[a..b].copy_from_slice(&run[a..b]);
                let mut cut = a;
                let mut bad = bad;
                bad.sort_unstable();
                bad.dedup();
                for &i in &bad {
                    pinned.push((i, reason));
                    work.push((cut, i));
                    cut = i + 1;
                }
                work.push((cut, b));
            }
        }
        out.postures = cand;
    }
    let after = spherical_angles(&out.postures);
    let ta: Vec<f64> = after.iter().map(|a| a.0).collect();
    let pa: Vec<f64> = after.iter().map(|a| a.1).collect();
    out.reversals_after = (reversal_indices(&ta).len(), reversal_indices(&pa).len());
    // Attribute each reversal left to the nearest pinned posture or kept segment.
    let reason_at = |k: usize| -> KeptReason {
        let seg = kept_segments
            .iter()
            .filter(|((a, b), _)| *a <= k && k < *b)
            .map(|(_, r)| *r)
            .next();
        seg.or_else(|| {
            pinned
                .iter()
                .min_by_key(|(i, _)| i.abs_diff(k))
                .map(|(_, r)| *r)
        })
        .unwrap_or(KeptReason::Budget)
    };
    for (azimuth, x) in [(false, &ta), (true, &pa)] {
        for k in reversal_indices(x) {
            out.kept.push(KeptReversal {
                index: k,
                azimuth,
                reason: reason_at(k),
            });
        }
    }
    for (i, (p, q)) in run.iter().zip(&out.postures).enumerate() {
        if p != q {
            out.changed += 1;
            out.max_change_rad = out.max_change_rad.max(p.axis.angle(&q.axis));
            let c = q.axis_point(opts.pivot_mm).coords;
            out.max_centre_shift_mm = out.max_centre_shift_mm.max((c - centres[i]).norm());
        }
    }
    out.angles_after = after;
    out
}

/// The run with the most reversals before smoothing: (reversals, planned `(θ, φ)`,
/// smoothed `(θ, φ)`).
pub type WorstRun = (usize, Vec<(f64, f64)>, Vec<(f64, f64)>);

/// Figures of the axis smoothing of a whole operation ([`SmoothingSummary::add`] per run),
/// for its metrics, notes and plot.
#[derive(Debug, Clone, Default)]
pub struct SmoothingSummary {
    /// Runs looked at.
    pub runs: usize,
    /// Runs with a changed posture.
    pub runs_smoothed: usize,
    /// Runs with a direction change left.
    pub runs_kept: usize,
    /// Direction changes of θ and φ inside runs, before.
    pub reversals_before: usize,
    /// The same after.
    pub reversals_after: usize,
    /// Those left, per reason (in [`KeptReason::ALL`] order).
    pub kept: [usize; 5],
    /// Largest turn of a posture (rad).
    pub max_change_rad: f64,
    /// Largest movement of a ball centre (mm).
    pub max_centre_shift_mm: f64,
    /// The run with the most reversals before: planned and smoothed `(θ, φ)` against the
    /// index.
    pub worst: Option<WorstRun>,
}

impl SmoothingSummary {
    /// Adds one run.
    pub fn add(&mut self, r: &RunSmoothing) {
        self.runs += 1;
        self.runs_smoothed += usize::from(r.changed > 0);
        self.runs_kept += usize::from(!r.kept.is_empty());
        let before = r.reversals_before.0 + r.reversals_before.1;
        self.reversals_before += before;
        self.reversals_after += r.reversals_after.0 + r.reversals_after.1;
        for k in &r.kept {
            let i = KeptReason::ALL
                .iter()
                .position(|x| *x == k.reason)
                .unwrap_or(3);
            self.kept[i] += 1;
        }
        self.max_change_rad = self.max_change_rad.max(r.max_change_rad);
        self.max_centre_shift_mm = self.max_centre_shift_mm.max(r.max_centre_shift_mm);
        if before > 0 && self.worst.as_ref().is_none_or(|w| before > w.0) {
            self.worst = Some((before, r.angles_before.clone(), r.angles_after.clone()));
        }
    }

    /// Adds the figures of another summary (the worst run kept when it has more reversals).
    pub fn merge(&mut self, o: &SmoothingSummary) {
        self.runs += o.runs;
        self.runs_smoothed += o.runs_smoothed;
        self.runs_kept += o.runs_kept;
        self.reversals_before += o.reversals_before;
        self.reversals_after += o.reversals_after;
        for (a, b) in self.kept.iter_mut().zip(o.kept) {
            *a += b;
        }
        self.max_change_rad = self.max_change_rad.max(o.max_change_rad);
        self.max_centre_shift_mm = self.max_centre_shift_mm.max(o.max_centre_shift_mm);
        if let Some(w) = &o.worst {
            if self.worst.as_ref().is_none_or(|x| w.0 > x.0) {
                self.worst = Some(w.clone());
            }
        }
    }

    /// Scales the counts by `copies` (an operation planned on one channel and copied).
    pub fn times(mut self, copies: usize) -> Self {
        self.runs *= copies;
        self.runs_smoothed *= copies;
        self.runs_kept *= copies;
        self.reversals_before *= copies;
        self.reversals_after *= copies;
        self.kept.iter_mut().for_each(|k| *k *= copies);
        self
    }

    /// The operation's metrics: `axis_smoothing_runs`, `axis_smoothing_runs_smoothed`,
    /// `axis_smoothing_runs_kept`, `axis_reversals_before`, `axis_reversals_after`,
    /// `axis_reversals_kept_<reason>`, `axis_smoothing_max_turn_deg`,
    /// `axis_smoothing_max_centre_shift_mm`.
    pub fn add_metrics(&self, m: &mut Metrics) {
        m.count("axis_smoothing_runs", self.runs)
            .count("axis_smoothing_runs_smoothed", self.runs_smoothed)
            .count("axis_smoothing_runs_kept", self.runs_kept)
            .count("axis_reversals_before", self.reversals_before)
            .count("axis_reversals_after", self.reversals_after)
            .number(
                "axis_smoothing_max_turn_deg",
                self.max_change_rad.to_degrees(),
            )
            .number(
                "axis_smoothing_max_centre_shift_mm",
                self.max_centre_shift_mm,
            );
        for (r, k) in KeptReason::ALL.iter().zip(self.kept) {
            m.count(&r.metric(), k);
        }
    }

    /// The direction changes an operation's metrics report as kept, over every reason (the
    /// sum of its `axis_reversals_kept_*`, which [`Self::add_metrics`] writes); `None` when
    /// one of them is missing.
    pub fn kept_in(m: &Metrics) -> Option<usize> {
        KeptReason::ALL
            .iter()
            .map(|r| {
                m.get(&r.metric())
                    .and_then(|v| v.as_f64())
                    .map(|v| v as usize)
            })
            .sum()
    }

    /// One note: what was smoothed and why reversals stay.
    pub fn note(&self) -> String {
        let reasons: Vec<String> = KeptReason::ALL
            .iter()
            .zip(self.kept)
            .filter(|(_, k)| *k > 0)
            .map(|(r, k)| format!("{k} {}", r.name().replace('_', " ")))
            .collect();
        format!(
            "tool axes smoothed about the ball centre in {} of {} runs (direction \
             changes of the axis angles inside runs {} → {}; largest turn {:.2}°){}",
            self.runs_smoothed,
            self.runs,
            self.reversals_before,
            self.reversals_after,
            self.max_change_rad.to_degrees(),
            if reasons.is_empty() {
                String::new()
            } else {
                format!("; kept: {}", reasons.join(", "))
            }
        )
    }

    /// The plot of the run with the most reversals: its axis angles before and after.
    pub fn plot(&self) -> Option<Plot> {
        let (_, before, after) = self.worst.as_ref()?;
        let series = |label: &str, v: &[(f64, f64)], pick: fn(&(f64, f64)) -> f64| PlotSeries {
            label: label.to_string(),
            points: v
                .iter()
                .enumerate()
                .map(|(i, a)| [i as f64, pick(a).to_degrees()])
                .collect(),
        };
        Some(Plot {
            title: "Tool-axis angles (about the impeller axis) of the run with the most \
                    direction changes, planned and smoothed"
                .into(),
            kind: PlotKind::Lines {
                x_label: "posture along the run".into(),
                y_label: "angle (deg)".into(),
                series: vec![
                    series("polar θ planned", before, |a| a.0),
                    series("polar θ smoothed", after, |a| a.0),
                    series("azimuth φ planned", before, |a| a.1),
                    series("azimuth φ smoothed", after, |a| a.1),
                ],
                equal_aspect: false,
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const R: f64 = 3.0;

    /// A run of ball centres along a line with the axis at polar 20° and an azimuth rising
    /// 0.2° per posture with ±0.5° chatter.
    fn chattering_run(n: usize) -> Vec<CutterLocation> {
        (0..n)
            .map(|i| {
                let phi =
                    (30.0f64 + 0.2 * i as f64 + if i % 2 == 0 { 0.5 } else { -0.5 }).to_radians();
                let theta = (20.0f64 + if i % 3 == 0 { 0.5 } else { -0.5 }).to_radians();
                let c = Vector3::new(i as f64, 10.0, R);
                let a = axis_of(theta, phi);
                CutterLocation::new(Point3::from(c - a * R), a).unwrap()
            })
            .collect()
    }

    struct Always;
    impl PostureCheck for Always {
        type Clear = ();
        fn posture_clear(&self, _: usize, _: &CutterLocation) -> Option<()> {
            Some(())
        }
        fn motion_clear(
            &self,
            _: usize,
            _: (&CutterLocation, &()),
            _: (&CutterLocation, &()),
        ) -> bool {
            true
        }
    }

    /// Chatter of ±0.5° in both angles is smoothed to monotone angles; every ball centre
    /// stays within 1e-6 mm.
    #[test]
    fn chatter_becomes_monotone_keeping_the_ball() {
        let run = chattering_run(41);
        let before = spherical_angles(&run);
        let phis: Vec<f64> = before.iter().map(|a| a.1).collect();
        assert!(reversal_indices(&phis).len() > 30);
        let r = smooth_run(&run, &AxisSmoothing::ball_end(R), &Always);
        assert!(
            r.reversals_before.0 > 10 && r.reversals_before.1 > 30,
            "{r:?}"
        );
        assert_eq!(r.reversals_after, (0, 0), "{:?}", r.kept);
        assert!(r.kept.is_empty());
        let after = spherical_angles(&r.postures);
        for w in after.windows(2) {
            assert!(
                w[1].1 - w[0].1 >= -DEAD_BAND_RAD,
                "azimuth not rising: {w:?}"
            );
            assert!((w[1].0 - w[0].0).abs() <= DEAD_BAND_RAD || w[1].0 <= w[0].0 + 1.0);
        }
        let ta: Vec<f64> = after.iter().map(|a| a.0).collect();
        assert!(reversal_indices(&ta).is_empty());
        for (p, q) in run.iter().zip(&r.postures) {
            let d = (p.axis_point(R) - q.axis_point(R)).norm();
            assert!(d <= 1e-6, "ball centre moved {d} mm");
        }
        assert!(r.max_centre_shift_mm <= 1e-6);
        assert!(r.changed > 30);
        // The smoothed azimuth stays within the chatter of the planned one.
        assert!(r.max_change_rad < 1f64.to_radians(), "{}", r.max_change_rad);
    }

    /// An accuracy budget (a flank pass: the turn that moves the flank by its slack) below
    /// the chatter: nothing is turned beyond it, and every reversal left is reported as kept
    /// for accuracy, not as the angle limit.
    #[test]
    fn reversals_beyond_an_accuracy_budget_are_kept_for_accuracy() {
        let run = chattering_run(41);
        let budget = 0.05f64.to_radians();
        let opts = AxisSmoothing {
            max_change_rad: budget,
            limit_reason: KeptReason::Accuracy,
            ..AxisSmoothing::ball_end(R)
        };
        let r = smooth_run(&run, &opts, &Always);
        assert!(r.reversals_after.0 + r.reversals_after.1 > 0, "{r:?}");
        assert_eq!(
            r.kept.len(),
            r.reversals_after.0 + r.reversals_after.1,
            "every reversal left is reported"
        );
        assert!(
            r.kept.iter().all(|k| k.reason == KeptReason::Accuracy),
            "{:?}",
            r.kept
        );
        assert!(r.max_change_rad <= budget + 1e-12, "{}", r.max_change_rad);
        let mut sum = SmoothingSummary::default();
        sum.add(&r);
        let mut m = Metrics::new();
        sum.add_metrics(&mut m);
        assert!(sum.note().contains("accuracy"), "{}", sum.note());
        assert_eq!(sum.kept[4], r.kept.len());
    }

    /// The tool must lean 10° further round and back to pass a wall in the middle of the run
    /// (postures are clear only within 0.3° of the planned azimuth there): the reversal at the
    /// top stays, with its reason.
    #[test]
    fn reversal_needed_for_clearance_is_kept_with_its_reason() {
        let n = 41;
        let planned: Vec<f64> = (0..n)
            .map(|i| {
                let bump = 4.0 * (1.0 - ((i as f64 - 20.0) / 10.0).abs()).max(0.0);
                let chatter = if i % 2 == 0 { 0.3 } else { -0.3 };
                (30.0f64 + bump + chatter).to_radians()
            })
            .collect();
        let run: Vec<CutterLocation> = planned
            .iter()
            .enumerate()
            .map(|(i, phi)| {
                let c = Vector3::new(i as f64, 10.0, R);
                let a = axis_of(20f64.to_radians(), *phi);
                CutterLocation::new(Point3::from(c - a * R), a).unwrap()
            })
            .collect();
        struct Wall(Vec<f64>);
        impl PostureCheck for Wall {
            type Clear = ();
            fn posture_clear(&self, i: usize, cl: &CutterLocation) -> Option<()> {
                let a = cl.axis.into_inner();
                let phi = a.y.atan2(a.x);
                ((12..=28).contains(&i) && (phi - self.0[i]).abs() <= 0.3f64.to_radians()
                    || !(12..=28).contains(&i))
                .then_some(())
            }
            fn motion_clear(
                &self,
                _: usize,
                _: (&CutterLocation, &()),
                _: (&CutterLocation, &()),
            ) -> bool {
                true
            }
        }
        let check = Wall(planned.clone());
        // A turn limit above the bump: only the wall can refuse the smooth fit.
        let opts = AxisSmoothing {
            max_change_rad: 10f64.to_radians(),
            ..AxisSmoothing::ball_end(R)
        };
        let r = smooth_run(&run, &opts, &check);
        assert!(r.reversals_after.1 >= 1, "{r:?}");
        assert!(r.reversals_after.1 < r.reversals_before.1);
        assert!(!r.kept.is_empty());
        assert!(
            r.kept.iter().all(|k| k.reason == KeptReason::Clearance),
            "{:?}",
            r.kept
        );
        // Every kept posture is clear and every ball centre stayed.
        for (i, (p, q)) in run.iter().zip(&r.postures).enumerate() {
            assert!(check.posture_clear(i, q).is_some());
            assert!((p.axis_point(R) - q.axis_point(R)).norm() <= 1e-6);
        }
        // The chatter outside the wall is gone.
        let after = spherical_angles(&r.postures);
        let pa: Vec<f64> = after.iter().map(|a| a.1).collect();
        assert!(reversal_indices(&pa[..10]).is_empty(), "{:?}", &pa[..10]);
        assert!(reversal_indices(&pa[31..]).is_empty());
    }

    /// Each motion check receives, for each end, the measure the posture check returned for
    /// that very posture (a turned one's from `posture_clear`, an unchanged one's from
    /// `planned_clear`), and a planned posture is measured at most once per run although
    /// several fits check motions to it: the motions to posture `W` are refused while it is
    /// turned, so it is pinned and both segments beside it check their motions to it.
    #[test]
    fn motions_get_their_ends_measures_and_planned_postures_are_measured_once() {
        use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
        let n = 41;
        // A posture the smooth fit turns (the fit keeps every other one of this run).
        const W: usize = 21;
        let run = chattering_run(n);
        struct Counting {
            run: Vec<CutterLocation>,
            planned_calls: Vec<AtomicUsize>,
            wrong_measure: AtomicBool,
        }
        impl PostureCheck for Counting {
            /// The posture measured.
            type Clear = CutterLocation;
            fn posture_clear(&self, _: usize, cl: &CutterLocation) -> Option<CutterLocation> {
                Some(*cl)
            }
            fn planned_clear(&self, i: usize, cl: &CutterLocation) -> Option<CutterLocation> {
                self.planned_calls[i].fetch_add(1, Ordering::Relaxed);
                Some(*cl)
            }
            fn motion_clear(
                &self,
                i: usize,
                (a, ma): (&CutterLocation, &CutterLocation),
                (b, mb): (&CutterLocation, &CutterLocation),
            ) -> bool {
                if a != ma || b != mb {
                    self.wrong_measure.store(true, Ordering::Relaxed);
                }
                let turned_w = (i + 1 == W && *b != self.run[W]) || (i == W && *a != self.run[W]);
                !turned_w
            }
        }
        let check = Counting {
            run: run.clone(),
            planned_calls: (0..n).map(|_| AtomicUsize::new(0)).collect(),
            wrong_measure: AtomicBool::new(false),
        };
        let r = smooth_run(&run, &AxisSmoothing::ball_end(R), &check);
        assert_eq!(r.postures[W], run[W], "posture {W} pinned");
        assert!(r.fits >= 3, "{r:?}");
        assert!(!check.wrong_measure.load(Ordering::Relaxed));
        let calls: Vec<usize> = check
            .planned_calls
            .iter()
            .map(|c| c.load(Ordering::Relaxed))
            .collect();
        assert_eq!(calls[W], 1, "{calls:?}");
        assert!(calls.iter().all(|&c| c <= 1), "{calls:?}");
    }

    /// The envelopes are monotone and stay on one side of the planned angles.
    #[test]
    fn envelopes_are_one_sided() {
        let x = [0.0, 1.5, 0.0, 3.0, 1.5, 4.5];
        assert_eq!(
            monotone_envelope(&x, true),
            vec![0.0, 1.5, 1.5, 3.0, 3.0, 4.5]
        );
        assert_eq!(
            monotone_envelope(&x, false),
            vec![0.0, 0.0, 0.0, 1.5, 1.5, 4.5]
        );
        let down: Vec<f64> = x.iter().map(|v| -v).collect();
        assert_eq!(
            monotone_envelope(&down, true),
            vec![0.0, -1.5, -1.5, -3.0, -3.0, -4.5]
        );
    }

    #[test]
    fn isotonic_fit_is_the_pooled_mean() {
        assert_eq!(
            isotonic_increasing(&[1.0, 3.0, 2.0, 4.0]),
            vec![1.0, 2.5, 2.5, 4.0]
        );
        assert_eq!(isotonic_increasing(&[3.0, 2.0, 1.0]), vec![2.0, 2.0, 2.0]);
    }
}
