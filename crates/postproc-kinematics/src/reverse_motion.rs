//! Reverse motions of the rotary axes: places along a cutting run where the angular
//! displacement of an axis changes direction (paper 004: such reversals leave tool marks,
//! because the feed drive stops and backlash acts).

use crate::banded_lsq::{BandRow, BandedQr, MAX_BAND};
use crate::bspline_fit::{collocation_rows, ScalarBSpline};
use crate::error::PostError;
use crate::joints::{AxisId, Joints};
use crate::kinematics::LIMIT_SLACK;
use crate::machine::Machine;
use crate::post::PostedBlock;
use cam_core::{CutterLocation, MoveKind};
use nalgebra::DVector;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Angular steps smaller than this (rad) count as standing still when looking for direction
/// changes.
pub const REVERSE_DEAD_BAND_RAD: f64 = 1e-6;

/// Number of direction changes in a sequence of angles (rad): sign changes between
/// consecutive non-negligible steps (steps within `dead_band` are skipped). O(n).
pub fn count_reverse_motions(angles: &[f64], dead_band: f64) -> usize {
    let mut last_sign = 0.0;
    let mut count = 0;
    for w in angles.windows(2) {
        let d = w[1] - w[0];
        if d.abs() <= dead_band {
            continue;
        }
        let s = d.signum();
        if last_sign != 0.0 && s != last_sign {
            count += 1;
        }
        last_sign = s;
    }
    count
}

/// Index ranges `[start, end)` of the cutting runs of a block list: maximal runs of
/// consecutive non-rapid blocks, each including the block it starts from.
pub fn cutting_runs(blocks: &[PostedBlock]) -> Vec<(usize, usize)> {
    let mut runs = Vec::new();
    let mut i = 0;
    while i < blocks.len() {
        if i + 1 < blocks.len() && blocks[i + 1].kind != MoveKind::Rapid {
            let start = i;
            let mut end = i + 1;
            while end < blocks.len() && blocks[end].kind != MoveKind::Rapid {
                end += 1;
            }
            runs.push((start, end));
            i = end;
        } else {
            i += 1;
        }
    }
    runs
}

/// Reverse motions of one rotary axis over all cutting runs.
pub fn count_axis_reverse_motions(blocks: &[PostedBlock], axis: AxisId) -> usize {
    let mut angles = Vec::new();
    cutting_runs(blocks)
        .into_iter()
        .map(|(s, e)| {
            angles.clear();
            angles.extend(blocks[s..e].iter().map(|b| b.joints.get(axis)));
            count_reverse_motions(&angles, REVERSE_DEAD_BAND_RAD)
        })
        .sum()
}

/// Reverse motions of both rotary axes over all cutting runs.
pub fn count_path_reverse_motions(blocks: &[PostedBlock]) -> usize {
    count_axis_reverse_motions(blocks, AxisId::Tilt)
        + count_axis_reverse_motions(blocks, AxisId::Rotate)
}

// ---------------------------------------------------------------------------------------
// Removal (paper 004, "Modification of reverse movements" and steps 3–7 of its procedure).

/// Caller-supplied 5-axis accessibility test (gouge and collision) of a cutter location,
/// used to re-check postures changed by reverse-motion removal. `Sync`: the cutting runs of
/// a path are checked in parallel.
pub trait AccessibilityChecker: Sync {
    /// `true` when the cutter location is free of gouge and collision.
    fn is_accessible(&self, cl: &CutterLocation) -> bool;
}

impl<F: Fn(&CutterLocation) -> bool + Sync> AccessibilityChecker for F {
    fn is_accessible(&self, cl: &CutterLocation) -> bool {
        self(cl)
    }
}

/// Settings of reverse-motion removal (angles in rad).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ReverseMotionOptions {
    /// Shift `φ_L` applied per iteration to angles lying behind the direction of motion
    /// (default 0.5°).
    pub shift: f64,
    /// Control values of the least-squares cubic B-spline per cutting run (default 4, as in
    /// the paper: four cubic B-spline basis functions).
    pub control_points: usize,
    /// Largest shift-and-smooth iterations before the control values are projected onto a
    /// monotone sequence (default 50).
    pub max_iterations: usize,
    /// Largest change of any angle (default 10°); a run needing more keeps its angles.
    pub max_angle_change: f64,
    /// C increment `ΔC` for the accessibility repair (default 1.5°, paper: 1–2°).
    pub c_step: f64,
    /// Largest C change of the repair `C_max` (default 10°). The repair offset counts
    /// toward `max_angle_change`: a run whose smoothed change plus the offset would exceed
    /// it is not repaired by that offset.
    pub c_max: f64,
    /// Height along the tool axis (mm from the tip) of the point a changed posture turns the
    /// tool about. The ball radius for a ball end (its centre stays, so the ball surface and
    /// every contact on it stay where the CAM system put them); the middle of the contact
    /// line for flank contact; 0 turns about the tip. Default 0.
    #[serde(default)]
    pub pivot_height_mm: f64,
    /// Heights (mm from the tip) of the lowest and highest cutter point in contact with the
    /// part. Turning the axis by δ about the pivot moves a contact point at height h by at
    /// most `|h − pivot|·δ`; for a ball end with the pivot at its centre give `(r, r)`: the
    /// ball surface turns onto itself. Default `(0, 0)` (contact at the tip).
    #[serde(default)]
    pub contact_heights_mm: (f64, f64),
    /// Largest distance (mm) of a contact point from the tool axis: the bottom rim of a flat
    /// end or bull nose in bottom contact. Turning by δ about the pivot moves a point at
    /// height h and distance ρ from the axis by `√((h − pivot)² + ρ²)·δ`. Default 0.
    #[serde(default)]
    pub contact_radius_mm: f64,
    /// Largest movement of the contact allowed by a changed posture (mm, the surface
    /// deviation bound); a run needing more keeps its original postures. Default
    /// [`DEFAULT_MAX_CONTACT_SHIFT_MM`].
    #[serde(default = "default_max_contact_shift")]
    pub max_contact_shift_mm: f64,
}

/// Default bound of the contact movement of reverse-motion smoothing (mm): a tenth of the
/// usual 0.1 mm finishing tolerance of the project's fixtures.
pub const DEFAULT_MAX_CONTACT_SHIFT_MM: f64 = 0.01;

fn default_max_contact_shift() -> f64 {
    DEFAULT_MAX_CONTACT_SHIFT_MM
}

impl ReverseMotionOptions {
    /// Options keeping the contact of `cutter`: for a ball end (or tapered ball end) in
    /// point contact the pivot is the ball centre and the contact `(r, r)`; with
    /// `flank = Some((lo, hi))` (contact heights along the flutes, mm) the pivot is the middle
    /// of the contact line; a flat end, bull nose or tapered flat end in bottom contact turns
    /// about its tip with the contact on the bottom rim (`contact_radius_mm`), so only turns
    /// that move the rim less than `max_contact_shift_mm` are allowed.
    pub fn keeping_contact(cutter: &cam_core::Cutter, flank: Option<(f64, f64)>) -> Self {
        let mut o = Self::default();
        match (flank, &cutter.shape) {
            (Some((lo, hi)), _) => {
                o.pivot_height_mm = 0.5 * (lo + hi);
                o.contact_heights_mm = (lo, hi);
            }
            (None, cam_core::CutterShape::BallEnd { radius }) => {
                o.pivot_height_mm = *radius;
                o.contact_heights_mm = (*radius, *radius);
            }
            (None, cam_core::CutterShape::TaperedBallEnd { ball_radius, .. }) => {
                o.pivot_height_mm = *ball_radius;
                o.contact_heights_mm = (*ball_radius, *ball_radius);
            }
            (
                None,
                cam_core::CutterShape::FlatEnd { radius }
                | cam_core::CutterShape::BullNose { radius, .. },
            ) => o.contact_radius_mm = *radius,
            (None, cam_core::CutterShape::TaperedFlatEnd { tip_radius, .. }) => {
                o.contact_radius_mm = *tip_radius;
            }
        }
        o
    }

    /// Largest contact movement (mm) when the tool axis turns by `angle` (rad) about the
    /// pivot.
    pub fn contact_shift(&self, angle: f64) -> f64 {
        let (lo, hi) = self.contact_heights_mm;
        let p = self.pivot_height_mm;
        (lo - p)
            .abs()
            .max((hi - p).abs())
            .hypot(self.contact_radius_mm)
            * angle.abs()
    }
}

impl Default for ReverseMotionOptions {
    fn default() -> Self {
        Self {
            shift: 0.5f64.to_radians(),
            control_points: 4,
            max_iterations: 50,
            max_angle_change: 10f64.to_radians(),
            c_step: 1.5f64.to_radians(),
            c_max: 10f64.to_radians(),
            pivot_height_mm: 0.0,
            contact_heights_mm: (0.0, 0.0),
            contact_radius_mm: 0.0,
            max_contact_shift_mm: DEFAULT_MAX_CONTACT_SHIFT_MM,
        }
    }
}

impl ReverseMotionOptions {
    pub(crate) fn validate(&self) -> Result<(), PostError> {
        let bad = |field: &'static str, message: &str| {
            Err(PostError::InvalidOption {
                field,
                message: message.to_string(),
            })
        };
        let pos = |v: f64| v.is_finite() && v > 0.0;
        if !pos(self.shift) {
            return bad("reverse_motion.shift", "must be finite and > 0");
        }
        if self.control_points < 2 {
            return bad("reverse_motion.control_points", "must be >= 2");
        }
        if !pos(self.max_angle_change) {
            return bad("reverse_motion.max_angle_change", "must be finite and > 0");
        }
        if !(pos(self.c_step) && self.c_max.is_finite() && self.c_max >= 0.0) {
            return bad("reverse_motion.c_step", "c_step must be > 0 and c_max >= 0");
        }
        let (lo, hi) = self.contact_heights_mm;
        if !(self.pivot_height_mm.is_finite()
            && lo.is_finite()
            && hi.is_finite()
            && lo <= hi
            && self.contact_radius_mm.is_finite()
            && self.contact_radius_mm >= 0.0)
        {
            return bad(
                "reverse_motion.pivot_height_mm",
                "pivot and contact heights must be finite, contact low <= high",
            );
        }
        if !(self.max_contact_shift_mm.is_finite() && self.max_contact_shift_mm >= 0.0) {
            return bad(
                "reverse_motion.max_contact_shift_mm",
                "must be finite and >= 0",
            );
        }
        Ok(())
    }
}

/// Axis displacement curves along a path (for plots): one row per block, values in mm for
/// linear axes and degrees for rotary axes, against the cumulative tool-tip path length.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct DisplacementCurves {
    /// Axis letters in column order (X Y Z tilt C).
    pub letters: Vec<char>,
    /// Cumulative tip path length (mm) per block.
    pub path_length_mm: Vec<f64>,
    /// Axis values per block (mm / deg).
    pub values: Vec<[f64; 5]>,
}

impl DisplacementCurves {
    /// Curves of a block list.
    pub fn of_blocks(machine: &Machine, blocks: &[PostedBlock]) -> Self {
        let mut s = 0.0;
        let mut path_length_mm = Vec::with_capacity(blocks.len());
        let mut values = Vec::with_capacity(blocks.len());
        for (i, b) in blocks.iter().enumerate() {
            if i > 0 {
                s += (b.cl.tip - blocks[i - 1].cl.tip).norm();
            }
            path_length_mm.push(s);
            let w = machine.axis_words(&b.joints);
            values.push(std::array::from_fn(|k| w[k].1));
        }
        Self {
            letters: AxisId::ALL.iter().map(|a| machine.letter(*a)).collect(),
            path_length_mm,
            values,
        }
    }
}

/// Outcome of reverse-motion removal.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ReverseMotionReport {
    /// Reverse motions of the tilt axis before / after.
    pub tilt_before: usize,
    /// See `tilt_before`.
    pub tilt_after: usize,
    /// Reverse motions of C before / after.
    pub rotate_before: usize,
    /// See `rotate_before`.
    pub rotate_after: usize,
    /// Cutting runs whose angles were changed.
    pub runs_changed: usize,
    /// Cutting runs left unchanged because the change exceeded `max_angle_change`, left the
    /// axis limits or could not be made accessible.
    pub runs_kept: usize,
    /// Shift-and-smooth iterations (summed over runs and axes).
    pub iterations: usize,
    /// Fits (over runs × axes and control-value counts) that needed the monotone projection
    /// of the control values.
    pub projections: usize,
    /// Control values of the accepted B-spline fit of each smoothed run × axis, in run order
    /// (tilt before C); larger than `ReverseMotionOptions::control_points` where the adaptive
    /// refit of [`smooth_monotone_adaptive`] was needed.
    #[serde(default)]
    pub control_points_used: Vec<usize>,
    /// Fits beyond the first per run × axis (refits with more control values, the windows
    /// beyond the first, and the whole-run fit after windows that failed).
    #[serde(default)]
    pub refits: usize,
    /// Smoothed runs × axes whose change stayed within windows around the reversals
    /// ([`smooth_monotone_windowed`]; the other blocks kept their exact angles).
    #[serde(default)]
    pub windowed: usize,
    /// Runs whose C was turned by a multiple of `c_step` to restore accessibility.
    pub c_repaired_runs: usize,
    /// The C offsets applied to those runs (deg).
    pub c_offsets_deg: Vec<f64>,
    /// Source index of the first inaccessible (or out-of-limits) posture of each run that
    /// could not be repaired (the run was kept unchanged).
    pub inaccessible_blocks: Vec<usize>,
    /// Largest angle change applied (deg), C repair included.
    pub max_angle_change_deg: f64,
    /// Largest movement of the cutter's contact caused by the changed postures (mm): the
    /// bound of the surface deviation the smoothing introduces (see
    /// [`ReverseMotionOptions::contact_shift`]).
    #[serde(default)]
    pub max_contact_shift_mm: f64,
    /// Runs kept because the contact would have moved more than
    /// `ReverseMotionOptions::max_contact_shift_mm`.
    #[serde(default)]
    pub runs_kept_for_contact: usize,
    /// Runs kept because a changed posture (or the motion to it) failed the accessibility
    /// check or left the axis limits (with every C repair tried), the contact staying within
    /// its bound.
    #[serde(default)]
    pub runs_kept_for_clearance: usize,
    /// Runs kept because no fit free of reverse motions stays within `max_angle_change`.
    #[serde(default)]
    pub runs_kept_for_angle_limit: usize,
    /// Displacement curves before removal.
    pub before: DisplacementCurves,
    /// Displacement curves after removal.
    pub after: DisplacementCurves,
}

/// Parameters of a run for the B-spline fit: normalised cumulative tip path length, or the
/// normalised index when the tip does not move.
fn run_parameters(blocks: &[PostedBlock]) -> Vec<f64> {
    let mut t = Vec::with_capacity(blocks.len());
    let mut s = 0.0;
    for (i, b) in blocks.iter().enumerate() {
        if i > 0 {
            s += (b.cl.tip - blocks[i - 1].cl.tip).norm();
        }
        t.push(s);
    }
    let n = blocks.len();
    if s > 1e-9 {
        t.iter_mut().for_each(|v| *v /= s);
    } else {
        for (i, v) in t.iter_mut().enumerate() {
            *v = if n > 1 {
                i as f64 / (n - 1) as f64
            } else {
                0.0
            };
        }
    }
    t
}

/// Largest control-value count the adaptive refit of [`smooth_monotone_adaptive`] tries
/// (an absolute bound on top of half the run's block count, so that a refit of a long run
/// costs at most O(m · 128²) for the factorisation plus O(m · 128) per iteration).
pub const MAX_ADAPTIVE_CONTROL_POINTS: usize = 128;

/// Least number of blocks added on each side of the range of a reversal that
/// [`smooth_monotone_windowed`] smooths (the padding is half the range's length when that is
/// larger), so the smoothed range joins the untouched blocks with a gentle slope.
pub const WINDOW_PADDING_BLOCKS: usize = 3;

/// Shift-and-smooth of one angle sequence (paper 004) with the fixed control-value count
/// `opts.control_points`: angles lying behind the running extreme in the direction of motion
/// are shifted by at most `φ_L` toward it, the sequence is smoothed by the least-squares cubic
/// B-spline, and this repeats until no reverse motion is left; after `max_iterations` the
/// control values are projected onto a monotone sequence, which makes the spline monotone.
/// Returns the new angles, the iterations and whether the projection ran; `None` for fewer
/// than 3 angles or a rank-deficient fit. Cost O(m + n³) for the factorisation (banded
/// Givens QR and the rank test on its triangle) plus O(m + n) per iteration.
pub fn smooth_monotone(
    t: &[f64],
    angles: &[f64],
    opts: &ReverseMotionOptions,
) -> Option<(Vec<f64>, usize, bool)> {
    if angles.len() < 3 {
        return None;
    }
    let dir = run_direction(angles);
    shift_and_smooth(t, angles, opts, opts.control_points, dir, Pins::default())
}

/// Direction (±1) in which a run of angles should move: the sign of the net change, or of the
/// larger of the summed rises and falls when the run ends where it started.
fn run_direction(angles: &[f64]) -> f64 {
    let m = angles.len();
    let net = angles[m - 1] - angles[0];
    if net.abs() > REVERSE_DEAD_BAND_RAD {
        return net.signum();
    }
    let up: f64 = angles.windows(2).map(|w| (w[1] - w[0]).max(0.0)).sum();
    let down: f64 = angles.windows(2).map(|w| (w[0] - w[1]).max(0.0)).sum();
    if up >= down {
        1.0
    } else {
        -1.0
    }
}

/// End values a fit must keep exactly (a clamped B-spline passes through its first and last
/// control values, so pinning those pins the curve's ends).
#[derive(Debug, Clone, Copy, Default)]
struct Pins {
    start: Option<f64>,
    end: Option<f64>,
}

/// Least-squares projection onto the cubic B-splines of one parameter set and control-value
/// count, with optionally pinned first / last control values: the collocation matrix `A`
/// (`m × n`, `A[i][j] = N_j(t_i)`, `p + 1` non-zeros per row) kept by rows, and the Givens QR
/// of its free columns ([`crate::banded_lsq`]), factored once (O(m·p²)) and reused by every
/// shift-and-smooth iteration (O(m·p) each). The rank test is the one of
/// [`crate::bspline_fit::fit_least_squares`] (smallest singular value at least 10⁻¹⁰ of the
/// largest), read from the singular values of the triangular factor (those of `A`, O(n³)).
struct SplineProjector {
    template: ScalarBSpline,
    /// Row `i` of `A`: its first non-zero column and the `p + 1` values from there.
    rows: Vec<BandRow>,
    /// Number of columns (control values).
    k: usize,
    qr: BandedQr,
    pins: Pins,
}

impl SplineProjector {
    /// `None` when the fit with these parameters is rank deficient (the test of
    /// [`crate::bspline_fit::fit_least_squares`] on the whole collocation matrix, and on its
    /// free columns when an end is pinned) or nothing is free. O(m·p² + n³).
    fn new(t: &[f64], n_ctrl: usize, pins: Pins) -> Option<Self> {
        let (template, rows) = collocation_rows(t, n_ctrl)?;
        let k = template.control_points().len();
        let w = template.degree() + 1;
        let full_rank = |qr: &BandedQr| {
            if !qr.is_complete() {
                return false;
            }
            let sv = qr.r_dense().singular_values();
            let smax = sv.max();
            !(smax.is_nan() || smax <= 0.0 || sv.min() < 1e-10 * smax)
        };
        let lo = usize::from(pins.start.is_some());
        let hi = k - usize::from(pins.end.is_some());
        if lo >= hi {
            return None;
        }
        // Without pins the free columns are the whole matrix and its factor is the test.
        if (lo, hi) != (0, k) && !full_rank(&BandedQr::new(k, w, rows.iter().copied())) {
            return None;
        }
        // The free columns `lo..hi`, renumbered from 0.
        let free_rows = rows.iter().map(|&(first, v)| {
            let mut out = [0.0; MAX_BAND];
            let mut start = first;
            for (d, x) in v.iter().enumerate().take(w) {
                let col = first + d;
                if col >= lo && col < hi {
                    out[col - first] = *x;
                }
            }
            if start < lo {
                out.copy_within(lo - start..w, 0);
                out[w - (lo - start)..w].iter_mut().for_each(|x| *x = 0.0);
                start = lo;
            }
            (start - lo, out)
        });
        let qr = BandedQr::new(hi - lo, w, free_rows);
        if !full_rank(&qr) {
            return None;
        }
        Some(Self {
            template,
            rows,
            k,
            qr,
            pins,
        })
    }

    /// Least-squares control values of `y` (pinned ones fixed) and the fitted values `A·x`.
    fn fit(&self, y: &[f64]) -> Option<(DVector<f64>, Vec<f64>)> {
        let k = self.k;
        if y.len() != self.rows.len() {
            return None;
        }
        let (start, end) = (self.pins.start, self.pins.end);
        let rhs: Vec<f64> = self
            .rows
            .iter()
            .zip(y)
            .map(|(&(first, v), &yi)| {
                let mut r = yi;
                for (d, x) in v.iter().enumerate() {
                    match (first + d, start, end) {
                        (0, Some(s), _) => r -= x * s,
                        (c, _, Some(e)) if c + 1 == k => r -= x * e,
                        _ => {}
                    }
                }
                r
            })
            .collect();
        let xf = self.qr.solve(&rhs)?;
        let mut x = DVector::<f64>::zeros(k);
        let lo = usize::from(start.is_some());
        if let Some(v) = start {
            x[0] = v;
        }
        if let Some(v) = end {
            x[k - 1] = v;
        }
        for (j, v) in xf.into_iter().enumerate() {
            x[lo + j] = v;
        }
        let values = self
            .rows
            .iter()
            .map(|&(first, v)| {
                v.iter()
                    .enumerate()
                    .filter(|(d, _)| first + d < k)
                    .map(|(d, c)| c * x[first + d])
                    .sum()
            })
            .collect();
        Some((x, values))
    }

    /// The spline of control values `x` made monotone in direction `dir`: running extreme of
    /// the control values, kept between the pinned end values. By the variation-diminishing
    /// property the spline is then monotone.
    fn monotone_spline(&self, x: &DVector<f64>, dir: f64) -> Option<ScalarBSpline> {
        let mut c: Vec<f64> = x.iter().map(|v| dir * v).collect();
        for i in 1..c.len() {
            c[i] = c[i].max(c[i - 1]);
        }
        if let Some(e) = self.pins.end {
            c.iter_mut().for_each(|v| *v = v.min(dir * e));
        }
        self.template
            .with_control_points(c.into_iter().map(|v| dir * v).collect())
    }
}

/// Shift-and-smooth with `n_ctrl` control values in direction `dir` and optional pinned ends.
/// The fit uses the given parameters `t` (normalised path length) when they determine the
/// coefficients, otherwise the normalised block index (a knot span without samples, e.g.
/// across a long plunge). Cost O(m + n³) for the factorisation (banded Givens QR and the
/// rank test on its triangle) plus O(m + n) per iteration.
fn shift_and_smooth(
    t: &[f64],
    angles: &[f64],
    opts: &ReverseMotionOptions,
    n_ctrl: usize,
    dir: f64,
    pins: Pins,
) -> Option<(Vec<f64>, usize, bool)> {
    let m = angles.len();
    if m < 3 || t.len() != m {
        return None;
    }
    // The rank of the collocation matrix depends on the parameters only.
    let (params, proj) = match SplineProjector::new(t, n_ctrl, pins) {
        Some(p) => (t.to_vec(), p),
        None => {
            let uniform: Vec<f64> = (0..m).map(|i| i as f64 / (m - 1) as f64).collect();
            let p = SplineProjector::new(&uniform, n_ctrl, pins)?;
            (uniform, p)
        }
    };
    let mut cur = angles.to_vec();
    let mut last = None;
    for iter in 1..=opts.max_iterations {
        let mut ext = cur[0];
        for v in cur.iter_mut().skip(1) {
            let behind = dir * (ext - *v);
            if behind > 0.0 {
                *v += dir * behind.min(opts.shift);
            }
            ext = if dir > 0.0 { ext.max(*v) } else { ext.min(*v) };
        }
        let (x, values) = proj.fit(&cur)?;
        cur = values;
        if count_reverse_motions(&cur, REVERSE_DEAD_BAND_RAD) == 0 {
            return Some((cur, iter, false));
        }
        last = Some(x);
    }
    let spline = proj.monotone_spline(&last?, dir)?;
    let out: Vec<f64> = params.iter().map(|&ti| spline.eval(ti)).collect();
    Some((out, opts.max_iterations, true))
}

/// Result of [`smooth_monotone_adaptive`] / [`smooth_monotone_windowed`] for one axis of one
/// run.
#[derive(Debug, Clone, PartialEq)]
pub struct SmoothedAngles {
    /// The smoothed angles (rad), one per block; of the accepted fit, or of the fit with the
    /// smallest change when none was accepted.
    pub angles: Vec<f64>,
    /// Control values of that fit (the largest over the windows of a windowed fit).
    pub control_points: usize,
    /// Shift-and-smooth iterations summed over every fit tried.
    pub iterations: usize,
    /// Fits that ended with the monotone projection of the control values.
    pub projections: usize,
    /// Fits tried (1 when the fit with `opts.control_points` was accepted; summed over the
    /// windows of a windowed fit).
    pub fits: usize,
    /// Largest change of any angle (rad).
    pub max_change: f64,
    /// `true` when the angles are free of reverse motions and `max_change ≤ max_angle_change`.
    pub accepted: bool,
    /// Inclusive block ranges that were smoothed (the whole run for an unwindowed fit).
    pub windows: Vec<(usize, usize)>,
}

/// Upper bound of the control-value count tried for a run of `m` blocks starting from `n0`:
/// `max(n0, min(m / 2, MAX_ADAPTIVE_CONTROL_POINTS))`.
pub fn adaptive_control_cap(m: usize, n0: usize) -> usize {
    n0.max((m / 2).min(MAX_ADAPTIVE_CONTROL_POINTS))
}

/// Shift-and-smooth (paper 004, "Modification of reverse movements", procedure steps 3–5)
/// of a whole run with an adaptive number of cubic B-spline control values.
///
/// The paper smooths each tool path with four cubic B-splines. A run whose angles change
/// character sharply — a plunge with constant posture followed by a five-axis sweep — cannot
/// be followed by one cubic piece: the four-value fit either keeps reversing or moves some
/// angle by more than `opts.max_angle_change` away from the CAM posture, and the run would be
/// kept with its reverse motions. Rule: start with `n = opts.control_points`; when the result
/// still reverses (after the shift iterations and the monotone projection) or changes an angle
/// by more than `max_angle_change`, refit the original angles with `n ← min(2n, cap)`,
/// `cap =` [`adaptive_control_cap`]`(m, n0)` (half the blocks, at most
/// [`MAX_ADAPTIVE_CONTROL_POINTS`]: at least two samples per control value, so the fit stays
/// a least-squares smoothing and never interpolates the reversal back in); keep the first fit
/// that is free of reverse motions (dead band [`REVERSE_DEAD_BAND_RAD`]) and within
/// `max_angle_change`, i.e. the fit with the fewest control values (the smoothest) among
/// those tried that meets the tolerance.
///
/// `None` for fewer than 3 angles or when no control-value count gives a full-rank fit.
/// Cost: at most `⌈log₂(cap / n0)⌉ + 1` fits, each O(m + n³) (a banded Givens QR of the
/// collocation matrix and the singular values of its triangle) plus O(m + n) per
/// shift-and-smooth iteration.
pub fn smooth_monotone_adaptive(
    t: &[f64],
    angles: &[f64],
    opts: &ReverseMotionOptions,
) -> Option<SmoothedAngles> {
    if angles.len() < 3 {
        return None;
    }
    let dir = run_direction(angles);
    adaptive(t, angles, opts, dir, Pins::default())
}

/// The adaptive control-value rule of [`smooth_monotone_adaptive`] in direction `dir` with
/// optional pinned ends.
fn adaptive(
    t: &[f64],
    angles: &[f64],
    opts: &ReverseMotionOptions,
    dir: f64,
    pins: Pins,
) -> Option<SmoothedAngles> {
    let m = angles.len();
    let n0 = opts.control_points;
    let cap = adaptive_control_cap(m, n0);
    let mut n = n0;
    let (mut iterations, mut projections, mut fits) = (0, 0, 0);
    let mut best: Option<SmoothedAngles> = None;
    loop {
        if let Some((new, iters, projected)) = shift_and_smooth(t, angles, opts, n, dir, pins) {
            iterations += iters;
            projections += usize::from(projected);
            fits += 1;
            let max_change = max_abs_difference(angles, &new);
            let accepted = count_reverse_motions(&new, REVERSE_DEAD_BAND_RAD) == 0
                && max_change <= opts.max_angle_change;
            let better = best.as_ref().is_none_or(|b| max_change < b.max_change);
            if accepted || better {
                best = Some(SmoothedAngles {
                    angles: new,
                    control_points: n,
                    iterations: 0,
                    projections: 0,
                    fits: 0,
                    max_change,
                    accepted,
                    windows: vec![(0, m - 1)],
                });
            }
            if accepted {
                break;
            }
        }
        if n >= cap {
            break;
        }
        n = (2 * n).min(cap);
    }
    best.map(|b| SmoothedAngles {
        iterations,
        projections,
        fits,
        ..b
    })
}

fn max_abs_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Inclusive block ranges a monotone version of `angles` (direction `dir`) has to change,
/// each padded by `pad` blocks and merged where they meet. Block `i` must change when it lies
/// behind the running extreme of the blocks before it or ahead of an extreme of the blocks
/// after it (`dir·a_i < max_{j<i} dir·a_j` or `dir·a_i > min_{j>i} dir·a_j`, beyond the dead
/// band): the paper's "range having a different direction" with the blocks it shadows. The
/// blocks outside the ranges are monotone and lie between their neighbours' values, so each
/// range can be smoothed with its (unaffected) end values kept. O(m).
pub fn reversal_windows(angles: &[f64], dir: f64, pad: usize) -> Vec<(usize, usize)> {
    let m = angles.len();
    if m == 0 {
        return Vec::new();
    }
    let y: Vec<f64> = angles.iter().map(|a| dir * a).collect();
    let mut before = vec![f64::NEG_INFINITY; m];
    for i in 1..m {
        before[i] = before[i - 1].max(y[i - 1]);
    }
    let mut after = vec![f64::INFINITY; m];
    for i in (0..m - 1).rev() {
        after[i] = after[i + 1].min(y[i + 1]);
    }
    let mut windows: Vec<(usize, usize)> = Vec::new();
    for i in 0..m {
        let affected =
            y[i] < before[i] - REVERSE_DEAD_BAND_RAD || y[i] > after[i] + REVERSE_DEAD_BAND_RAD;
        if !affected {
            continue;
        }
        let (a, b) = (i.saturating_sub(pad), (i + pad).min(m - 1));
        match windows.last_mut() {
            Some(w) if a <= w.1 + 1 => w.1 = w.1.max(b),
            _ => windows.push((a, b)),
        }
    }
    windows
}

/// Shift-and-smooth restricted to windows around the reverse motions (paper 004: only "the
/// displacement values in the range having a different direction" are modified).
///
/// The windows are the [`reversal_windows`], each padded by half its length (at least
/// [`WINDOW_PADDING_BLOCKS`]) and merged where they meet; each window is
/// smoothed on its own by the adaptive rule of [`smooth_monotone_adaptive`] (parameters: the
/// window's path length renormalised to [0, 1]) with its first and last angle kept exactly
/// (pinned end control values of the clamped cubic B-spline) unless the window reaches the end
/// of the run on a block that itself must change. Blocks outside the windows keep their exact
/// angles, so the smoothing changes no more postures than the reversals require and the
/// accessibility re-check only meets those. Accepted when the whole run is then free of reverse
/// motions (dead band [`REVERSE_DEAD_BAND_RAD`]) and no angle changed by more than
/// `opts.max_angle_change`.
///
/// `None` for fewer than 3 angles, no reverse motion, or a window too short or rank deficient
/// to fit. Cost: O(m) for the windows plus, per window of `w` blocks, the adaptive fits of
/// O(w·n² + max_iterations·w·n).
pub fn smooth_monotone_windowed(
    t: &[f64],
    angles: &[f64],
    opts: &ReverseMotionOptions,
) -> Option<SmoothedAngles> {
    let m = angles.len();
    if m < 3 || t.len() != m {
        return None;
    }
    let dir = run_direction(angles);
    // Each range is padded by half its length (at least WINDOW_PADDING_BLOCKS): the
    // correction of a reversal spreads over a neighbourhood as long as the reversal instead
    // of being squeezed into the range's few blocks (tests/reverse_motion.rs, plunge and
    // swing: largest change 4.4° with this padding, 8.3° with a fixed 3 blocks, 4.6° for the
    // whole-run fit).
    let mut windows: Vec<(usize, usize)> = Vec::new();
    for (a, b) in reversal_windows(angles, dir, 0) {
        let pad = WINDOW_PADDING_BLOCKS.max((b - a + 1).div_ceil(2));
        let (a, b) = (a.saturating_sub(pad), (b + pad).min(m - 1));
        match windows.last_mut() {
            Some(w) if a <= w.1 + 1 => w.1 = w.1.max(b),
            _ => windows.push((a, b)),
        }
    }
    if windows.is_empty() {
        return None;
    }
    let unaffected = |i: usize| {
        let y = dir * angles[i];
        angles[..i]
            .iter()
            .all(|a| dir * a <= y + REVERSE_DEAD_BAND_RAD)
            && angles[i + 1..]
                .iter()
                .all(|a| dir * a >= y - REVERSE_DEAD_BAND_RAD)
    };
    let mut out = angles.to_vec();
    let (mut iterations, mut projections, mut fits, mut control_points) = (0, 0, 0, 0);
    for &(a, b) in &windows {
        let w = &angles[a..=b];
        if w.len() < 3 {
            return None;
        }
        let span = t[b] - t[a];
        let tw: Vec<f64> = if span > 1e-12 {
            t[a..=b].iter().map(|v| (v - t[a]) / span).collect()
        } else {
            (0..w.len())
                .map(|i| i as f64 / (w.len() - 1) as f64)
                .collect()
        };
        let pins = Pins {
            start: unaffected(a).then_some(angles[a]),
            end: unaffected(b).then_some(angles[b]),
        };
        let fit = adaptive(&tw, w, opts, dir, pins)?;
        iterations += fit.iterations;
        projections += fit.projections;
        fits += fit.fits;
        control_points = control_points.max(fit.control_points);
        out[a..=b].copy_from_slice(&fit.angles);
    }
    let max_change = max_abs_difference(angles, &out);
    let accepted = count_reverse_motions(&out, REVERSE_DEAD_BAND_RAD) == 0
        && max_change <= opts.max_angle_change;
    Some(SmoothedAngles {
        angles: out,
        control_points,
        iterations,
        projections,
        fits,
        max_change,
        accepted,
        windows,
    })
}

/// A run placed with one C offset: (offset, joints and cutter location per block, largest
/// contact movement).
type PlacedRun = (f64, Vec<(Joints, CutterLocation)>, f64);

/// A shift-and-smooth of one angle sequence (parameters, angles, options).
type SmoothingStrategy = fn(&[f64], &[f64], &ReverseMotionOptions) -> Option<SmoothedAngles>;

/// Removes reverse motions of the rotary axes run by run (paper 004 procedure steps 2–7):
/// shift-and-smooth each reversing axis within windows around its reversals
/// ([`smooth_monotone_windowed`]; the other blocks keep their exact angles), or, when the
/// windows cannot be made monotone within `max_angle_change`, over the whole run; both with
/// the adaptive control-value count of [`smooth_monotone_adaptive`] (the paper's four cubic
/// B-splines first, refitted with more control values when a run — e.g. a plunge followed by
/// a sweep — needs it); turn the tool of every changed posture about the point
/// `pivot_height_mm` up its original axis (the ball centre keeps a ball end's contact; the
/// middle of the contact line bounds a flank's) and recompute the linear axes
/// ([`Machine::joints_for_angles`]); refuse a posture whose contact would move more than
/// `max_contact_shift_mm` ([`ReverseMotionOptions::contact_shift`]); check limits and
/// re-check every changed posture, and the midpoint of the joint-interpolated motion into and
/// out of it, with `checker`; where one fails, turn C of the whole run by `±k·c_step`
/// (smallest first, up to `c_max`, and never beyond `max_angle_change` together with the
/// smoothing's own change; a constant offset keeps the run monotone) and re-check. A run that
/// cannot be repaired, or for which no tried fit is free of reverse motions within
/// `max_angle_change`, keeps its original postures. Blocks' `cl` becomes the turned cutter
/// location.
///
/// Cost: per run and reversing axis at most `⌈log₂(cap / n0)⌉ + 1` fits of
/// O(m + n³ + max_iterations·(m + n)) each (see [`smooth_monotone_adaptive`]), plus
/// `c_max / c_step` checker passes per run whose smoothed postures fail; runs in parallel
/// (rayon), reports added in run order.
pub fn remove_reverse_motions(
    machine: &Machine,
    blocks: &mut [PostedBlock],
    tool_length: f64,
    opts: &ReverseMotionOptions,
    checker: Option<&dyn AccessibilityChecker>,
) -> Result<ReverseMotionReport, PostError> {
    opts.validate()?;
    let mut rep = ReverseMotionReport {
        tilt_before: count_axis_reverse_motions(blocks, AxisId::Tilt),
        rotate_before: count_axis_reverse_motions(blocks, AxisId::Rotate),
        before: DisplacementCurves::of_blocks(machine, blocks),
        ..Default::default()
    };
    // Runs are independent (each changes only its own blocks): smooth them in parallel and
    // add their reports in run order, so the result does not depend on the thread count.
    let mut runs: Vec<&mut [PostedBlock]> = Vec::new();
    let mut rest: &mut [PostedBlock] = &mut *blocks;
    let mut at = 0;
    for (s, e) in cutting_runs(rest) {
        let (_, tail) = std::mem::take(&mut rest).split_at_mut(s - at);
        let (run, tail) = tail.split_at_mut(e - s);
        runs.push(run);
        rest = tail;
        at = e;
    }
    let outcomes: Vec<ReverseMotionReport> = runs
        .into_par_iter()
        .map(|run| {
            let mut rep = ReverseMotionReport::default();
            smooth_run(machine, run, tool_length, opts, checker, &mut rep);
            rep
        })
        .collect();
    for o in outcomes {
        rep.add_run(o);
    }
    rep.tilt_after = count_axis_reverse_motions(blocks, AxisId::Tilt);
    rep.rotate_after = count_axis_reverse_motions(blocks, AxisId::Rotate);
    rep.after = DisplacementCurves::of_blocks(machine, blocks);
    Ok(rep)
}

/// One cutting run of [`remove_reverse_motions`]: smooths its reversing axes, places and
/// checks the changed postures (with the C repair), or keeps the original postures; adds the
/// run's figures to `rep`.
fn smooth_run(
    machine: &Machine,
    run: &mut [PostedBlock],
    tool_length: f64,
    opts: &ReverseMotionOptions,
    checker: Option<&dyn AccessibilityChecker>,
    rep: &mut ReverseMotionReport,
) {
    let original: Vec<(Joints, CutterLocation)> = run.iter().map(|b| (b.joints, b.cl)).collect();
    let t = run_parameters(run);
    let mut changed = false;
    let mut ok = true;
    let mut run_max_change: f64 = 0.0;
    let mut run_control_points = Vec::new();
    let mut run_windowed = 0;
    for axis in [AxisId::Tilt, AxisId::Rotate] {
        let angles: Vec<f64> = run.iter().map(|b| b.joints.get(axis)).collect();
        if count_reverse_motions(&angles, REVERSE_DEAD_BAND_RAD) == 0 {
            continue;
        }
        // Windows around the reversals first; the whole run when they cannot be made
        // monotone within the limit.
        let strategies: [SmoothingStrategy; 2] =
            [smooth_monotone_windowed, smooth_monotone_adaptive];
        let mut accepted = None;
        let mut fits_tried = 0;
        for smooth in strategies {
            let Some(fit) = smooth(&t, &angles, opts) else {
                continue;
            };
            rep.iterations += fit.iterations;
            rep.projections += fit.projections;
            fits_tried += fit.fits;
            if fit.accepted {
                accepted = Some(fit);
                break;
            }
        }
        rep.refits += fits_tried.saturating_sub(1);
        let Some(fit) = accepted else {
            rep.runs_kept_for_angle_limit += 1;
            ok = false;
            break;
        };
        if fit.windows != [(0, angles.len() - 1)] {
            run_windowed += 1;
        }
        run_control_points.push(fit.control_points);
        run_max_change = run_max_change.max(fit.max_change);
        for (b, v) in run.iter_mut().zip(fit.angles) {
            b.joints.set(axis, v);
        }
        changed = true;
    }
    if ok && changed {
        // Recompute the positions for the changed postures and re-check them; when a
        // posture is not accessible, turn C of the whole run by ±k·ΔC (k = 1, 2, … up to
        // C_max) — a constant offset keeps the run free of reverse motions.
        let smoothed: Vec<(f64, f64)> = run
            .iter()
            .map(|b| (b.joints.tilt, b.joints.rotate))
            .collect();
        let steps = (opts.c_max / opts.c_step).floor() as usize;
        // The C repair counts toward the angle limit.
        let offsets = std::iter::once(0.0)
            .chain((1..=steps).flat_map(|k| {
                let d = k as f64 * opts.c_step;
                [d, -d]
            }))
            .filter(|off| run_max_change + off.abs() <= opts.max_angle_change + LIMIT_SLACK);
        let mut accepted: Option<PlacedRun> = None;
        let mut first_failure: Option<usize> = None;
        let mut contact_failure = false;
        'offsets: for off in offsets {
            let mut placed: Vec<(Joints, CutterLocation)> = Vec::with_capacity(run.len());
            let mut shift: f64 = 0.0;
            for (b, ((tilt, rot), (oj, ocl))) in run.iter().zip(smoothed.iter().zip(&original)) {
                let rot = rot + off;
                if *tilt == oj.tilt && rot == oj.rotate {
                    placed.push((*oj, *ocl));
                    continue;
                }
                // Turn about the pivot: the point `pivot` up the original axis stays.
                let axis = machine.tool_axis(*tilt, rot);
                let pivot = ocl.tip + ocl.axis.into_inner() * opts.pivot_height_mm;
                let tip = pivot - axis.into_inner() * opts.pivot_height_mm;
                let angle = ocl.axis.dot(&axis).clamp(-1.0, 1.0).acos();
                let s = opts.contact_shift(angle);
                if s > opts.max_contact_shift_mm {
                    contact_failure = true;
                    if first_failure.is_none() {
                        first_failure = Some(b.source_index);
                    }
                    continue 'offsets;
                }
                shift = shift.max(s);
                let j = machine.joints_for_angles(&tip, tool_length, *tilt, rot);
                let cl = CutterLocation { tip, axis };
                let fits = machine.check_limits(&j, LIMIT_SLACK).is_ok();
                if !fits || !checker.is_none_or(|c| c.is_accessible(&cl)) {
                    if first_failure.is_none() {
                        first_failure = Some(b.source_index);
                    }
                    continue 'offsets;
                }
                placed.push((j, cl));
            }
            // The motion between postures: the midpoint of every segment touching a
            // changed posture, as the controller interpolates it (joints linear).
            if let Some(c) = checker {
                for (k, w) in placed.windows(2).enumerate() {
                    let (a, b) = (&w[0], &w[1]);
                    if a.0 == original[k].0 && b.0 == original[k + 1].0 {
                        continue;
                    }
                    let mid = machine.forward(&a.0.lerp(&b.0, 0.5), tool_length);
                    if !c.is_accessible(&mid) {
                        if first_failure.is_none() {
                            first_failure = Some(run[k + 1].source_index);
                        }
                        continue 'offsets;
                    }
                }
            }
            accepted = Some((off, placed, shift));
            break;
        }
        match accepted {
            Some((off, placed, shift)) => {
                rep.max_contact_shift_mm = rep.max_contact_shift_mm.max(shift);
                for (b, (j, cl)) in run.iter_mut().zip(placed) {
                    b.joints = j;
                    b.cl = cl;
                }
                rep.runs_changed += 1;
                rep.control_points_used.append(&mut run_control_points);
                rep.windowed += run_windowed;
                if off != 0.0 {
                    rep.c_repaired_runs += 1;
                    rep.c_offsets_deg.push(off.to_degrees());
                }
                let change = run_max_change + off.abs();
                rep.max_angle_change_deg = rep.max_angle_change_deg.max(change.to_degrees());
            }
            None => {
                if contact_failure {
                    rep.runs_kept_for_contact += 1;
                } else {
                    rep.runs_kept_for_clearance += 1;
                }
                rep.inaccessible_blocks.extend(first_failure);
                ok = false;
            }
        }
    }
    if !ok {
        rep.runs_kept += 1;
        for (b, (j, cl)) in run.iter_mut().zip(original) {
            b.joints = j;
            b.cl = cl;
        }
    }
}

impl ReverseMotionReport {
    /// Adds the per-run figures of `o` (one run's report from [`smooth_run`]).
    fn add_run(&mut self, o: ReverseMotionReport) {
        self.runs_changed += o.runs_changed;
        self.runs_kept += o.runs_kept;
        self.iterations += o.iterations;
        self.projections += o.projections;
        self.control_points_used.extend(o.control_points_used);
        self.refits += o.refits;
        self.windowed += o.windowed;
        self.c_repaired_runs += o.c_repaired_runs;
        self.c_offsets_deg.extend(o.c_offsets_deg);
        self.inaccessible_blocks.extend(o.inaccessible_blocks);
        self.max_angle_change_deg = self.max_angle_change_deg.max(o.max_angle_change_deg);
        self.max_contact_shift_mm = self.max_contact_shift_mm.max(o.max_contact_shift_mm);
        self.runs_kept_for_contact += o.runs_kept_for_contact;
        self.runs_kept_for_clearance += o.runs_kept_for_clearance;
        self.runs_kept_for_angle_limit += o.runs_kept_for_angle_limit;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_direction_changes() {
        assert_eq!(count_reverse_motions(&[0.0, 1.0, 2.0, 3.0], 1e-9), 0);
        assert_eq!(count_reverse_motions(&[0.0, 1.0, 0.5, 2.0], 1e-9), 2);
        // standing still does not count, nor does a step within the dead band
        assert_eq!(
            count_reverse_motions(&[0.0, 1.0, 1.0, 1.0 - 1e-12, 2.0], 1e-9),
            0
        );
        assert_eq!(
            count_reverse_motions(&[3.0, 2.0, 2.5, 1.0, 0.0, 0.2], 1e-9),
            3
        );
    }

    #[test]
    fn smoothing_removes_a_swing() {
        let t: Vec<f64> = (0..100).map(|i| i as f64 / 99.0).collect();
        let a: Vec<f64> = t
            .iter()
            .map(|&x| x - 0.15 * (-((x - 0.5) / 0.05f64).powi(2)).exp() * (x - 0.5) / 0.05)
            .collect();
        assert!(count_reverse_motions(&a, REVERSE_DEAD_BAND_RAD) >= 2);
        let (s, _, _) = smooth_monotone(&t, &a, &ReverseMotionOptions::default()).unwrap();
        assert_eq!(count_reverse_motions(&s, REVERSE_DEAD_BAND_RAD), 0);
        assert!((s[0] - a[0]).abs() < 0.2 && (s[99] - a[99]).abs() < 0.2);
    }
}
