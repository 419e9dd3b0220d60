//! Hub finishing ("flow passage" finishing, paper 003 Table 1, process 8): ball-end point
//! milling of the hub between the blades along flow lines, with the step-over that leaves the
//! target scallop and a tool axis that leans with the blades inside the channel.
//!
//! # Geometry
//! The hub is a surface of revolution `H(t, φ)` with the exact channel-side unit normal
//! `n(t, φ)`. A ball of radius `r` touching the hub at `H(t, φ)` (hub allowance `a_h`) has its
//! centre on the hub's offset surface, `c(t, φ) = H(t, φ) + (r + a_h)·n(t, φ)` — exact, since
//! the offset of a surface of revolution along its normal stays in the meridian plane (valid
//! while the hub's concave radius exceeds `r + a_h`, checked: every centre is measured back to
//! the hub, `|d_hub(c) − (r + a_h)| ≤ 1e-6 mm`, else the plan fails).
//!
//! At each of `stations` meridional stations `t` between the main blades' leading and
//! trailing edges (uniform in meridional arc length) the *free arcs* are the angles `φ` of the
//! channel (between the bounding main blades' roots, [`impeller_model::channel::Channel`])
//! where the centre keeps `ρ_b = max(r, 2R_f − r) + a_b + tol/2` from every blade
//! (`blade_signed_distance` exact on the NURBS sides; `R_f` the design fillet radius, `a_b` the
//! blade allowance). With `r ≥ R_f` a ball clear of hub and blade is a union of balls of
//! radius `R_f` clear of both, so it cannot touch the fillet (the fillet is what those
//! rolling balls leave); with `r < R_f` the ball lies inside the `R_f`-ball whose centre is
//! `R_f − r` further along the hub normal, which keeps `R_f` from the blade when the centre
//! keeps `2R_f − r`. The strip between the free arc and the blade root is left to
//! blade-root finishing (paper 003 processes 8 → 10). Arcs are found by 120 samples of the
//! distance across the channel and bisection of each sign change (50 steps). Stations with
//! the same number of arcs form a *region*; each arc of a region is a *lane* (upstream of the
//! splitter one lane, beside it two). Where the count changes between two stations, the
//! station where it changes is found by bisection and the region with fewer arcs is extended
//! to it; the gap left between it and the first station of the region with more arcs (beside
//! the splitter nose) is crossed by *cross lines* along the free arcs at constant `t`, at
//! most one step-over apart ([`runs`], [`cross_stations`]), so the whole hub between the
//! stations is cut.
//!
//! # Flow lines and step-over
//! In a lane with arcs `[φ_L(t), φ_R(t)]` the flow lines are `φ_f(t) = φ_L + f·(φ_R − φ_L)` at
//! `n` equally spaced fractions `f`, `n − 1 = ⌈w_max / s⌉` with `w_max` the widest contact arc
//! `r_hub(t)·(φ_R − φ_L)` of the lane and `s` the step-over that leaves `scallop_mm` on a
//! surface of the hub's largest convex cross curvature `κ = n_r / r_hub` (the exact inverse
//! [`cam_core::ball_step_over`] of the circle–circle scallop), capped by the process'
//! `width_of_cut_mm`. Between stations a line is subdivided in `(t, φ)` until the chord of the
//! centres is within `tol/4` of the exact centre at the parameter midpoint (at most 2⁶ pieces).
//! Lines are machined zig-zag (the cross lines after the flow lines); the step between line
//! ends is a feed move when the certified motion check below passes, else a link over the
//! safety surface.
//!
//! # Tool axis and accessibility
//! The first axis at `(t, φ)` interpolates, at the point's angular fraction between the two
//! blade sides bounding it (main–main upstream of the splitter, main–splitter and
//! splitter–main beside it), the *rulings* of those sides (hub edge to shroud edge at the `u`
//! whose hub foot is at `t`, from a table of 121 `u` samples), limited to `max_tilt_deg` from
//! the hub normal. If the tool (ball, flutes, shank, holder) is not clear of the design by
//! `−tol/2` ([`cam_plan::DesignClearance`]), the axis is turned about the impeller axis
//! through the ball centre by `±k·step_deg` (alternating, paper 004's accessibility search)
//! up to `max_turn_deg`, then the hub normal is tried; a point with no clear posture is left
//! uncut (the line is split there, `skipped_locations`). Every motion between consecutive
//! locations is checked as a whole: the tool against the blades is certified with
//! [`cam_plan::DesignClearance::segment_clearance_between`] (clearance `≥ −tol/2` within
//! `tol/4`); the ball, which touches the hub all along (clearance ≈ 0, where a Lipschitz
//! bisection cannot certify anything), by the exact hub distance of its centre at the quarter
//! points of the motion (`≥ r − tol/2`; the subdivision keeps the chord sag within `tol/4`);
//! the tool's samples between the ball and twice its radius are checked against the blades
//! only (their bounding spheres would dip into the hub the ball touches; the flutes there
//! clear a locally flat hub by `r(1 − sin θ)` at tilt `θ ≤ max_tilt_deg`). A motion that fails splits the line
//! (`split_motions`). The stock simulation of the written program is the independent check.
//!
//! The search in whole steps makes neighbouring points of a line alternate between turns
//! (the rotary axes chatter inside the cut): once a line's runs are planned, their axes are
//! smoothed about the ball centres by the shared step [`cam_plan::axis_smoothing`], every
//! changed posture and motion checked again with the checks above (`axis_reversals_*`,
//! `axis_smoothing_*` metrics; a plot of the run with the most direction changes).
//!
//! # Measured, not assumed
//! `max_scallop_mm`: on a grid of every lane (40 stations × 4 samples between adjacent lines; the
//! gaps crossed by cross lines are not on it: a test measures them independently;
//! samples where a ball kept `ρ_b` from the blades cannot touch the hub are left out: that
//! strip is blade-root finishing's) the residual height along the hub normal above each hub
//! point, exact per ball (ray–sphere
//! entry) against the emitted ball centres densified to `r/4` along each line, capped at `r`.
//! `max_overcut_mm`: the largest penetration of any emitted ball into hub or blades (exact
//! distances). `min_blade_clearance_mm`: the tool's smallest clearance to the blades.
//!
//! Cost: O(stations · 120 · blade distance) for the arcs, O(locations · (1 + turns) ·
//! clearance query) for the postures, O(grid · 4 lines · dense centres) for the scallop.
//! Lines run in parallel (rayon).

use cam_core::{CutterLocation, Move, ToolPath};

use crate::accessibility::{ball_radius, limit_tilt};
use cam_plan::{
    pattern, ClearanceOptions, Metrics, Operation, OperationSpec, PartSet, PlanContext, PlanError,
    PlannedOperation, Plot, PlotKind, PlotSeries, Point3,
};
use impeller_model::channel::edge_v;
use impeller_model::meridional::MeridionalCurve;
use impeller_model::{Blade, Impeller, Side};
use nalgebra::{Rotation3, Vector3};
use rayon::prelude::*;
use serde::Deserialize;

/// Kind key of hub finishing in job files.
pub const HUB_FINISHING: &str = "hub_finishing";

/// Samples of the blade distance across the channel per station.
const ARC_SAMPLES: usize = 120;
/// Bisection steps of a free-arc end (2⁻⁵⁰ of a sample interval).
const ARC_BISECTIONS: usize = 50;
/// u samples of a blade side's ruling table.
const RULING_SAMPLES: usize = 121;
/// Deepest subdivision of a line between stations (2⁶ pieces).
const MAX_SUBDIVISION: usize = 6;
/// Bisection depth of the ball's blade clearance along a motion (2⁻⁸ of the motion).
const BALL_BISECTIONS: usize = 8;
/// Levels of planned midpoints inserted into a motion that is not clear as a whole.
const MIDPOINT_DEPTH: usize = 3;
/// Midpoint queries allowed per motion check.
const SEGMENT_QUERIES: usize = 24;
/// Approach length above a path's first point (mm).
const APPROACH_MM: f64 = 2.0;
/// Scallop grid: stations along a lane, samples between adjacent lines.
const SCALLOP_ALONG: usize = 40;
const SCALLOP_BETWEEN: usize = 4;

fn default_scallop() -> f64 {
    0.01
}
fn default_stations() -> usize {
    80
}
fn default_max_tilt() -> f64 {
    30.0
}
fn default_step() -> f64 {
    1.5
}
fn default_max_turn() -> f64 {
    30.0
}

/// The kind's own job keys.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    /// Target scallop height on the hub (mm).
    #[serde(default = "default_scallop")]
    scallop_mm: f64,
    /// Meridional stations between leading and trailing edge.
    #[serde(default = "default_stations")]
    stations: usize,
    /// Largest angle between tool axis and hub normal (degrees).
    #[serde(default = "default_max_tilt")]
    max_tilt_deg: f64,
    /// Turning step of the accessibility search (degrees).
    #[serde(default = "default_step")]
    step_deg: f64,
    /// Largest turn of the accessibility search (degrees).
    #[serde(default = "default_max_turn")]
    max_turn_deg: f64,
}

/// Hub finishing, kind [`HUB_FINISHING`].
#[derive(Debug, Clone)]
pub struct HubFinishing {
    name: String,
    tool: String,
    params: Params,
}

/// Builds a [`HubFinishing`] from its job table. Keys: `scallop_mm` (> 0, default 0.01),
/// `stations` (4..=2000, default 80), `max_tilt_deg` ([0, 80], default 30), `step_deg`
/// ((0, 5], default 1.5), `max_turn_deg` ([0, 90], default 30).
pub fn build_hub_finishing(spec: &OperationSpec) -> Result<Box<dyn Operation>, PlanError> {
    let p: Params = cam_plan::params::parse(spec)?;
    let bad = |key: &str, why: String| Err(PlanError::param(&spec.name, key, why));
    if !(p.scallop_mm.is_finite() && p.scallop_mm > 0.0) {
        return bad(
            "scallop_mm",
            format!("{} must be finite and > 0", p.scallop_mm),
        );
    }
    if !(4..=2000).contains(&p.stations) {
        return bad("stations", format!("{} must be in 4..=2000", p.stations));
    }
    if !(p.max_tilt_deg.is_finite() && (0.0..=80.0).contains(&p.max_tilt_deg)) {
        return bad(
            "max_tilt_deg",
            format!("{} must be in [0, 80]", p.max_tilt_deg),
        );
    }
    if !(p.step_deg.is_finite() && p.step_deg > 0.0 && p.step_deg <= 5.0) {
        return bad("step_deg", format!("{} must be in (0, 5]", p.step_deg));
    }
    if !(p.max_turn_deg.is_finite() && (0.0..=90.0).contains(&p.max_turn_deg)) {
        return bad(
            "max_turn_deg",
            format!("{} must be in [0, 90]", p.max_turn_deg),
        );
    }
    Ok(Box::new(HubFinishing {
        name: spec.name.clone(),
        tool: spec.tool.clone(),
        params: p,
    }))
}

/// Rulings of one blade side by the meridional foot of its hub edge: `(t, unit ruling)`,
/// sorted by `t`.
#[derive(Debug, Clone)]
struct RulingTable(Vec<(f64, Vector3<f64>)>);

impl RulingTable {
    fn new(imp: &Impeller, blade: &Blade, side: Side) -> Self {
        let s = blade.side(side);
        let ((u0, u1), (v0, v1)) = s.domain();
        let hub = imp.hub();
        let mut rows: Vec<(f64, Vector3<f64>)> = (0..RULING_SAMPLES)
            .filter_map(|k| {
                let u = u0 + (u1 - u0) * k as f64 / (RULING_SAMPLES - 1) as f64;
                // Past the hub edge's ends there is no ruling: skip this u.
                let vh = edge_v(blade, side, hub, u).ok()?;
                let vs = edge_v(blade, side, imp.shroud(), u).unwrap_or(v1.max(v0));
                let ph = s.point(u, vh);
                let ruling = (s.point(u, vs) - ph).try_normalize(1e-12)?;
                let t = hub.meridional().closest(MeridionalCurve::zr_of(&ph)).0;
                Some((t, ruling))
            })
            .collect();
        rows.sort_by(|a, b| a.0.total_cmp(&b.0));
        Self(rows)
    }

    /// The ruling at hub foot `t` (linear between samples, the end rulings beyond them).
    fn at(&self, t: f64) -> Option<Vector3<f64>> {
        let rows = &self.0;
        let first = rows.first()?;
        let last = rows.last()?;
        if t <= first.0 {
            return Some(first.1);
        }
        if t >= last.0 {
            return Some(last.1);
        }
        let k = rows.partition_point(|r| r.0 <= t).clamp(1, rows.len() - 1);
        let (a, b) = (rows[k - 1], rows[k]);
        let w = if b.0 > a.0 {
            (t - a.0) / (b.0 - a.0)
        } else {
            0.0
        };
        (a.1 * (1.0 - w) + b.1 * w).try_normalize(1e-12)
    }
}

/// One meridional station: its contour parameter, the channel's root angles and the free
/// arcs of the ball centre.
#[derive(Debug, Clone)]
struct Station {
    t: f64,
    left: f64,
    right: f64,
    /// Mid angle of the splitter at this station, when it reaches it.
    splitter_mid: Option<f64>,
    arcs: Vec<(f64, f64)>,
}

/// A point of a flow line: `(t, φ, station index, lane mid angle)`.
type LineParam = (f64, f64, usize, f64);

/// One lane: a free arc followed over a run of stations.
#[derive(Debug, Clone)]
struct Lane {
    /// `(t, φ_L, φ_R)` per station.
    rows: Vec<(f64, f64, f64)>,
}

/// A planned location with its clearance and the turning steps it took.
#[derive(Debug, Clone, Copy)]
struct Posture {
    cl: CutterLocation,
    /// Clearance of the whole tool to the design (the ball touches the hub: ≈ hub allowance).
    clearance: f64,
    /// Clearance of the whole tool to the blades alone.
    blade_clearance: f64,
    steps: usize,
    rotation: f64,
}

/// What one flow line produced.
#[derive(Debug, Default)]
struct LineResult {
    runs: Vec<Vec<Posture>>,
    skipped: usize,
    split: usize,
    steps: usize,
    max_rotation: f64,
    min_blade_clearance: f64,
    max_overcut: f64,
    max_offset_error: f64,
    /// Split motions by cause: ball into hub, ball into blades, tool above the ball.
    split_causes: [usize; 3],
    /// The axis smoothing of the line's runs.
    smoothing: cam_plan::SmoothingSummary,
}

impl LineResult {
    /// Adds another line's counts and extremes to these (the axis smoothing summary apart).
    fn absorb(&mut self, res: &LineResult) {
        self.skipped += res.skipped;
        self.split += res.split;
        self.steps += res.steps;
        self.max_rotation = self.max_rotation.max(res.max_rotation);
        self.min_blade_clearance = self.min_blade_clearance.min(res.min_blade_clearance);
        self.max_overcut = self.max_overcut.max(res.max_overcut);
        self.max_offset_error = self.max_offset_error.max(res.max_offset_error);
        for (acc, c) in self.split_causes.iter_mut().zip(res.split_causes) {
            *acc += c;
        }
    }
}

/// Shared planning data of the reference channel.
struct Planner<'a> {
    ctx: &'a PlanContext<'a>,
    op: &'a HubFinishing,
    r: f64,
    rho_h: f64,
    rho_b: f64,
    tol: f64,
    left: RulingTable,
    right: RulingTable,
    splitter: Option<(RulingTable, RulingTable)>,
    /// The tool from twice the ball radius up against hub and blades (the ball is placed
    /// exactly; the samples just above the ball are spheres that would dip into the hub the
    /// ball touches, and the flutes there clear the hub by `r(1 − sin θ)` at tilt `θ`).
    upper: cam_plan::DesignClearance<'a>,
    /// The tool above its ball against the blades alone.
    blades_only: cam_plan::DesignClearance<'a>,
}

impl Planner<'_> {
    fn centre(&self, t: f64, phi: f64) -> Vector3<f64> {
        let hub = self.ctx.impeller.hub();
        hub.point(t, phi) + hub.normal(t, phi) * self.rho_h
    }

    /// The first axis at `(t, φ)` of a station whose root angles are `st` (module docs).
    fn first_axis(&self, t: f64, phi: f64, st: &Station) -> Vector3<f64> {
        let n = self.ctx.impeller.hub().normal(t, phi);
        let lerp = |a: Option<Vector3<f64>>, b: Option<Vector3<f64>>, lo: f64, hi: f64| {
            let f = if hi > lo {
                ((phi - lo) / (hi - lo)).clamp(0.0, 1.0)
            } else {
                0.5
            };
            match (a, b) {
                (Some(a), Some(b)) => (a * (1.0 - f) + b * f).try_normalize(1e-12),
                _ => None,
            }
        };
        let a = match (&self.splitter, st.splitter_mid) {
            (Some((minus, _)), Some(mid)) if phi < mid => {
                lerp(self.left.at(t), minus.at(t), st.left, mid)
            }
            (Some((_, plus)), Some(mid)) => lerp(plus.at(t), self.right.at(t), mid, st.right),
            _ => lerp(self.left.at(t), self.right.at(t), st.left, st.right),
        };
        let mut a = a.unwrap_or(n);
        if a.dot(&n) < 0.0 {
            a = -a;
        }
        limit_tilt(a, &n, self.op.params.max_tilt_deg.to_radians())
    }

    fn location(&self, centre: &Vector3<f64>, axis: &Vector3<f64>) -> Option<CutterLocation> {
        CutterLocation::new(Point3::from(centre - axis * self.r), *axis).ok()
    }

    /// A clear posture at `(t, φ)` (module docs: first axis, turns about the impeller axis,
    /// hub normal) whose axis the job's machine can take ([`PlanContext::reaches`]), or
    /// `None`.
    fn posture(&self, t: f64, phi: f64, st: &Station, hint: f64) -> Option<Posture> {
        let c = self.centre(t, phi);
        let n = self.ctx.impeller.hub().normal(t, phi);
        let a0 = self.first_axis(t, phi, st);
        let min = -0.5 * self.tol;
        let step = self.op.params.step_deg.to_radians();
        let max_tilt = self.op.params.max_tilt_deg.to_radians();
        let turns = (self.op.params.max_turn_deg.to_radians() / step).floor() as i64;
        // Turns about the impeller axis, nearest to the previous point's turn first (keeps
        // the axis continuous along the line), then the smaller turn.
        let mut rots: Vec<i64> = (-turns..=turns).collect();
        let h = hint / step;
        rots.sort_by(|x, y| {
            ((*x as f64 - h).abs(), x.abs())
                .partial_cmp(&((*y as f64 - h).abs(), y.abs()))
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        let mut tries: Vec<(Vector3<f64>, usize, f64)> = rots
            .iter()
            .map(|&k| {
                let rot = step * k as f64;
                let a = Rotation3::from_axis_angle(&Vector3::z_axis(), rot) * a0;
                (limit_tilt(a, &n, max_tilt), k.unsigned_abs() as usize, rot)
            })
            .collect();
        tries.push((n, turns as usize + 1, 0.0));
        // Prefer a posture with room (≥ tol) so that the motions between postures can be
        // certified; else the first one that is clear at all. The early-exit query rejects
        // the others cheaply.
        let mut fallback: Option<Posture> = None;
        for (a, steps, rotation) in tries {
            if !self.ctx.reaches(&a) {
                continue;
            }
            let Some(cl) = self.location(&c, &a) else {
                continue;
            };
            let want = if fallback.is_none() { min } else { self.tol };
            // One query per part set: stops below `want`, else the clearance itself.
            let Some(upper) = self.upper.clearance_if_clear(&cl, want) else {
                continue;
            };
            let Some(blades) = self.blades_only.clearance_if_clear(&cl, want) else {
                continue;
            };
            let (clearance, blade_clearance) = (upper.distance_mm, blades.distance_mm);
            let p = Posture {
                cl,
                clearance,
                blade_clearance,
                steps,
                rotation,
            };
            if clearance.min(blade_clearance) >= self.tol {
                return Some(p);
            }
            if clearance.min(blade_clearance) >= min && fallback.is_none() {
                fallback = Some(p);
            }
        }
        fallback
    }

    /// Connects `a` (parameters `pa`) to `b` (`pb`): `Ok` with the planned midpoints to insert
    /// (in order, into `out`) when the motion, or its halves through planned midpoint
    /// postures (up to `depth` levels), are clear; else the cause of the first failure.
    #[allow(clippy::too_many_arguments)]
    fn bridge(
        &self,
        a: &Posture,
        pa: LineParam,
        b: &Posture,
        pb: LineParam,
        stations: &[Station],
        depth: usize,
        out: &mut Vec<Posture>,
    ) -> Result<(), usize> {
        let cause = match self.motion_check(a, b) {
            Ok(()) => return Ok(()),
            Err(c) => c,
        };
        if depth == 0 {
            return Err(cause);
        }
        let t = 0.5 * (pa.0 + pb.0);
        let mid = 0.5 * (pa.3 + pb.3);
        let phi = self
            .keep_from_blades(t, 0.5 * (pa.1 + pb.1), mid)
            .ok_or(cause)?;
        let pm = (t, phi, pa.2.min(pb.2), mid);
        let m = self
            .posture(t, phi, &stations[pm.2], 0.5 * (a.rotation + b.rotation))
            .ok_or(cause)?;
        self.bridge(a, pa, &m, pm, stations, depth - 1, out)?;
        out.push(m);
        self.bridge(&m, pm, b, pb, stations, depth - 1, out)
    }

    /// `φ` moved toward the lane's mid angle `mid` until the ball centre keeps `ρ_b` from the
    /// blades (the free arc's end between stations, bisection to 2⁻⁴⁰ of the gap); `None`
    /// when even `mid` does not.
    fn keep_from_blades(&self, t: f64, phi: f64, mid: f64) -> Option<f64> {
        let g = |x: f64| {
            self.ctx
                .clearance
                .blade_signed_distance(&Point3::from(self.centre(t, x)))
                .0
                - self.rho_b
        };
        if g(phi) >= 0.0 {
            return Some(phi);
        }
        if g(mid) < 0.0 {
            return None;
        }
        let (mut bad, mut good) = (phi, mid);
        for _ in 0..40 {
            let m = 0.5 * (bad + good);
            if g(m) >= 0.0 {
                good = m;
            } else {
                bad = m;
            }
        }
        Some(good)
    }

    /// The parameters `(t, φ, station, lane mid angle)` of flow line `f` of `lane`,
    /// subdivided between stations.
    fn line_params(&self, lane: &Lane, f: f64) -> Vec<LineParam> {
        let mut out = Vec::new();
        for (k, w) in lane.rows.windows(2).enumerate() {
            let a = (
                w[0].0,
                w[0].1 + f * (w[0].2 - w[0].1),
                0.5 * (w[0].1 + w[0].2),
            );
            let b = (
                w[1].0,
                w[1].1 + f * (w[1].2 - w[1].1),
                0.5 * (w[1].1 + w[1].2),
            );
            out.push((a.0, a.1, k, a.2));
            self.subdivide(a, b, MAX_SUBDIVISION, k, &mut out);
        }
        if let Some(l) = lane.rows.last() {
            out.push((
                l.0,
                l.1 + f * (l.2 - l.1),
                lane.rows.len() - 1,
                0.5 * (l.1 + l.2),
            ));
        }
        out
    }

    fn subdivide(
        &self,
        a: (f64, f64, f64),
        b: (f64, f64, f64),
        depth: usize,
        k: usize,
        out: &mut Vec<LineParam>,
    ) {
        if depth == 0 {
            return;
        }
        let m = (0.5 * (a.0 + b.0), 0.5 * (a.1 + b.1), 0.5 * (a.2 + b.2));
        let (ca, cb, cm) = (
            self.centre(a.0, a.1),
            self.centre(b.0, b.1),
            self.centre(m.0, m.1),
        );
        if (cm - 0.5 * (ca + cb)).norm() <= 0.25 * self.tol {
            return;
        }
        self.subdivide(a, m, depth - 1, k, out);
        out.push((m.0, m.1, k, m.2));
        self.subdivide(m, b, depth - 1, k, out);
    }

    /// Appends `runs` to `path` (in reverse order, each run reversed, when `reverse`: the
    /// zig-zag's odd lines): the step from the path's last location to a run's first is a
    /// feed move when it is at most `near` mm long and the certified motion check passes,
    /// else a link over the safety surface. Returns the number of steps made at feed.
    fn join(
        &self,
        ctx: &PlanContext<'_>,
        path: &mut ToolPath,
        mut runs: Vec<Vec<Posture>>,
        reverse: bool,
        near: f64,
    ) -> Result<usize, PlanError> {
        if reverse {
            runs.reverse();
            for run in &mut runs {
                run.reverse();
            }
        }
        let mut at_feed = 0;
        for run in runs {
            let Some(first) = run.first() else { continue };
            match path.moves.last().copied() {
                None => path.moves.push(Move::feed(first.cl)),
                Some(last) => {
                    let prev = self.posture_of(last.cl);
                    if (last.cl.tip - first.cl.tip).norm() <= near
                        && self.motion_clear(&prev, first)
                    {
                        path.moves.push(Move::link(first.cl));
                        at_feed += 1;
                    } else {
                        path.moves
                            .extend(ctx.link(&last.cl, &first.cl, APPROACH_MM)?);
                    }
                }
            }
            path.moves
                .extend(run.iter().skip(1).map(|p| Move::feed(p.cl)));
        }
        Ok(at_feed)
    }

    /// Plans flow line `f` of `lane` (stations of the lane: `stations`).
    fn plan_line(&self, lane: &Lane, stations: &[Station], f: f64) -> LineResult {
        self.plan_params(&self.line_params(lane, f), stations)
    }

    /// Plans the cross line along free arc `arc` of station `st` (constant `t`, `φ` from the
    /// arc's left end to its right), subdivided like a flow line ([`Self::subdivide`]).
    fn plan_cross_line(&self, st: &Station, arc: usize) -> LineResult {
        let (a, b) = st.arcs[arc];
        let mid = 0.5 * (a + b);
        let mut params = vec![(st.t, a, 0, mid)];
        self.subdivide(
            (st.t, a, mid),
            (st.t, b, mid),
            MAX_SUBDIVISION,
            0,
            &mut params,
        );
        params.push((st.t, b, 0, mid));
        self.plan_params(&params, std::slice::from_ref(st))
    }

    /// Plans the locations `params` (`(t, φ, index into stations, mid angle)`) as one line:
    /// postures, certified motions (split where one fails), exactness figures, smoothed axes.
    fn plan_params(&self, params: &[LineParam], stations: &[Station]) -> LineResult {
        let mut res = LineResult {
            min_blade_clearance: f64::INFINITY,
            ..LineResult::default()
        };
        let hub = self.ctx.impeller.hub();
        let mut hint = 0.0;
        let postures: Vec<Option<(Posture, LineParam)>> = params
            .iter()
            .map(|&(t, phi, k, mid)| {
                let phi = self.keep_from_blades(t, phi, mid)?;
                let p = self.posture(t, phi, &stations[k], hint)?;
                hint = p.rotation;
                Some((p, (t, phi, k, mid)))
            })
            .collect();
        let mut run: Vec<Posture> = Vec::new();
        let mut prev_par: Option<LineParam> = None;
        let mut accepted: Vec<Posture> = Vec::new();
        for item in postures {
            let Some((p, par)) = item else {
                res.skipped += 1;
                if !run.is_empty() {
                    res.runs.push(std::mem::take(&mut run));
                }
                prev_par = None;
                continue;
            };
            accepted.clear();
            if let (Some(prev), Some(pp)) = (run.last().copied(), prev_par) {
                if let Err(cause) =
                    self.bridge(&prev, pp, &p, par, stations, MIDPOINT_DEPTH, &mut accepted)
                {
                    res.split += 1;
                    res.split_causes[cause] += 1;
                    res.runs.push(std::mem::take(&mut run));
                    accepted.clear();
                }
            }
            accepted.push(p);
            prev_par = Some(par);
            for p in accepted.drain(..) {
                // Exactness of the offset and the ball's penetration, from exact distances.
                let c = p.cl.tip.coords + p.cl.axis.into_inner() * self.r;
                let dh = hub.signed_distance(&c);
                res.max_offset_error = res.max_offset_error.max((dh - self.rho_h).abs());
                let cp = Point3::from(c);
                let db = self.ctx.clearance.blade_signed_distance(&cp).0;
                let dhub = self.ctx.clearance.hub_signed_distance(&cp);
                res.max_overcut = res.max_overcut.max(self.r - dh.min(db).min(dhub));
                res.min_blade_clearance = res
                    .min_blade_clearance
                    .min(p.blade_clearance)
                    .min(db - self.r);
                res.steps += p.steps;
                res.max_rotation = res.max_rotation.max(p.rotation.abs());
                run.push(p);
            }
        }
        if !run.is_empty() {
            res.runs.push(run);
        }
        res.max_overcut = res.max_overcut.max(0.0);
        self.smooth_axes(&mut res);
        res
    }

    /// The shared axis smoothing ([`cam_plan::axis_smoothing`]) of every run of a line: turns
    /// about the ball centres (the hub contact and every figure measured from the centres stay
    /// exact), checked with this planner's posture and motion checks.
    fn smooth_axes(&self, res: &mut LineResult) {
        let opts = cam_plan::AxisSmoothing::ball_end(self.r);
        for run in &mut res.runs {
            let cls: Vec<CutterLocation> = run.iter().map(|p| p.cl).collect();
            let out = cam_plan::axis_smoothing::smooth_run(&cls, &opts, self);
            res.smoothing.add(&out);
            for (p, cl) in run.iter_mut().zip(out.postures) {
                if p.cl != cl {
                    let q = self.posture_of(cl);
                    res.min_blade_clearance = res.min_blade_clearance.min(q.blade_clearance);
                    *p = Posture {
                        steps: p.steps,
                        rotation: p.rotation,
                        ..q
                    };
                }
            }
        }
    }

    /// Whether the motion from `a` to `b` is clear (module docs): the tool above its ball
    /// against hub and blades by certified bisection; the ball against the blades by
    /// certified bisection of its centre's (1-Lipschitz) blade distance along the motion,
    /// against the hub by the hub distance of its centre at the quarter points of the motion
    /// (the chord sag that the subdivision keeps within `tol/4`).
    fn motion_clear(&self, a: &Posture, b: &Posture) -> bool {
        self.motion_check(a, b).is_ok()
    }

    /// [`Self::motion_clear`] with the failing check: 0 ball–hub, 1 ball–blades, 2 the tool
    /// above the ball.
    fn motion_check(&self, a: &Posture, b: &Posture) -> Result<(), usize> {
        let min = -0.5 * self.tol;
        let hub = self.ctx.impeller.hub();
        let (ca, cb) = (self.centre_of(&a.cl), self.centre_of(&b.cl));
        let hub_ok = [0.25, 0.5, 0.75]
            .iter()
            .all(|&s| hub.signed_distance(&(ca + (cb - ca) * s)) - self.r >= min);
        let ball = |c: &Vector3<f64>| {
            self.ctx
                .clearance
                .blade_signed_distance(&Point3::from(*c))
                .0
                - self.r
        };
        if !hub_ok {
            return Err(0);
        }
        let ball_ok = certify_line(&ball, &ca, &cb, ball(&ca), ball(&cb), min, BALL_BISECTIONS);
        if !ball_ok {
            return Err(1);
        }
        for (q, ca, cb) in [
            (&self.upper, a.clearance, b.clearance),
            (&self.blades_only, a.blade_clearance, b.blade_clearance),
        ] {
            q.segment_clearance_between(
                (&a.cl, ca),
                (&b.cl, cb),
                min,
                0.25 * self.tol,
                SEGMENT_QUERIES,
            )
            .map_err(|_| 2usize)?;
        }
        Ok(())
    }

    fn centre_of(&self, cl: &CutterLocation) -> Vector3<f64> {
        cl.tip.coords + cl.axis.into_inner() * self.r
    }

    /// A posture for `cl` already planned (its clearances measured again).
    fn posture_of(&self, cl: CutterLocation) -> Posture {
        Posture {
            cl,
            clearance: self.upper.clearance(&cl).distance_mm,
            blade_clearance: self.blades_only.clearance(&cl).distance_mm,
            steps: 0,
            rotation: 0.0,
        }
    }
}

/// The checks a smoothed posture and motion must pass: the planner's own (module docs,
/// "Tool axis and accessibility"; the ball is not moved by a turn about its centre), and an
/// axis the machine can take.
/// The measure of a posture is its pair of clearances (tool above the ball against hub and
/// blades, against the blades alone), the ends of the motion check's bisections.
impl cam_plan::PostureCheck for Planner<'_> {
    type Clear = (f64, f64);
    fn posture_clear(&self, _: usize, cl: &CutterLocation) -> Option<(f64, f64)> {
        let min = -0.5 * self.tol;
        if !self.ctx.reaches(&cl.axis.into_inner()) {
            return None;
        }
        let upper = self.upper.clearance_if_clear(cl, min)?;
        let blades = self.blades_only.clearance_if_clear(cl, min)?;
        Some((upper.distance_mm, blades.distance_mm))
    }
    fn planned_clear(&self, _: usize, cl: &CutterLocation) -> Option<(f64, f64)> {
        let p = self.posture_of(*cl);
        Some((p.clearance, p.blade_clearance))
    }
    fn motion_clear(
        &self,
        _: usize,
        (a, ca): (&CutterLocation, &(f64, f64)),
        (b, cb): (&CutterLocation, &(f64, f64)),
    ) -> bool {
        let posture = |cl: &CutterLocation, c: &(f64, f64)| Posture {
            cl: *cl,
            clearance: c.0,
            blade_clearance: c.1,
            steps: 0,
            rotation: 0.0,
        };
        self.motion_clear(&posture(a, ca), &posture(b, cb))
    }
}

/// Whether the 1-Lipschitz `f` stays `≥ min` on the segment `a`–`b` (ends `fa`, `fb`): an
/// interval of length `L` is accepted when `(f₀ + f₁ − L)/2 ≥ min`, else split at its
/// midpoint, at most `depth` times.
fn certify_line(
    f: &dyn Fn(&Vector3<f64>) -> f64,
    a: &Vector3<f64>,
    b: &Vector3<f64>,
    fa: f64,
    fb: f64,
    min: f64,
    depth: usize,
) -> bool {
    if fa < min || fb < min {
        return false;
    }
    if 0.5 * (fa + fb - (b - a).norm()) >= min {
        return true;
    }
    if depth == 0 {
        return false;
    }
    let m = 0.5 * (a + b);
    let fm = f(&m);
    certify_line(f, a, &m, fa, fm, min, depth - 1) && certify_line(f, &m, b, fm, fb, min, depth - 1)
}

/// The free arcs at station `t` (module docs): `None` where the channel's bounding sides do
/// not both reach the hub at `t`.
fn station(p: &Planner<'_>, t: f64) -> Option<Station> {
    let imp = p.ctx.impeller;
    let ch = imp.channel(0);
    // Beyond the blades' ends there is no station: a normal answer here.
    let sec = ch.section(imp.hub(), t).ok()?;
    let g = |phi: f64| {
        let c = p.centre(t, phi);
        p.ctx.clearance.blade_signed_distance(&Point3::from(c)).0 - p.rho_b
    };
    let (l, r) = (sec.left, sec.right);
    let phis: Vec<f64> = (0..=ARC_SAMPLES)
        .map(|k| l + (r - l) * k as f64 / ARC_SAMPLES as f64)
        .collect();
    let gs: Vec<f64> = phis.iter().map(|&x| g(x)).collect();
    let refine = |a: f64, b: f64, ga: f64| {
        // Bisection of the sign change between a and b (g(a) has sign of ga).
        let (mut lo, mut hi) = (a, b);
        for _ in 0..ARC_BISECTIONS {
            let m = 0.5 * (lo + hi);
            if (g(m) >= 0.0) == (ga >= 0.0) {
                lo = m;
            } else {
                hi = m;
            }
        }
        // The end on the free side.
        if ga >= 0.0 {
            lo
        } else {
            hi
        }
    };
    let mut arcs = Vec::new();
    let mut start: Option<f64> = if gs[0] >= 0.0 { Some(phis[0]) } else { None };
    for k in 1..phis.len() {
        let (ga, gb) = (gs[k - 1], gs[k]);
        if ga < 0.0 && gb >= 0.0 {
            start = Some(refine(phis[k - 1], phis[k], ga));
        } else if ga >= 0.0 && gb < 0.0 {
            if let Some(s) = start.take() {
                let e = refine(phis[k - 1], phis[k], ga);
                if e > s {
                    arcs.push((s, e));
                }
            }
        }
    }
    if let Some(s) = start {
        arcs.push((s, r));
    }
    Some(Station {
        t,
        left: l,
        right: r,
        splitter_mid: sec.splitter.map(|(a, b)| 0.5 * (a + b)),
        arcs,
    })
}

/// The main blades' hub extent `[t_lo, t_hi]` of channel 0 (where both bounding sides reach
/// the hub), by 200 samples and 40 bisections at each end.
fn blade_extent(imp: &Impeller) -> Option<(f64, f64)> {
    let ch = imp.channel(0);
    let hub = imp.hub();
    let (a, b) = hub.meridional().domain();
    let ok = |t: f64| ch.section(hub, t).is_ok();
    let n = 200;
    let ts: Vec<f64> = (0..=n).map(|k| a + (b - a) * k as f64 / n as f64).collect();
    let first = ts.iter().position(|&t| ok(t))?;
    let last = ts.iter().rposition(|&t| ok(t))?;
    let edge = |inside: f64, outside: f64| {
        let (mut i, mut o) = (inside, outside);
        for _ in 0..40 {
            let m = 0.5 * (i + o);
            if ok(m) {
                i = m;
            } else {
                o = m;
            }
        }
        i
    };
    let lo = if first > 0 {
        edge(ts[first], ts[first - 1])
    } else {
        ts[first]
    };
    let hi = if last < n {
        edge(ts[last], ts[last + 1])
    } else {
        ts[last]
    };
    (hi > lo).then_some((lo, hi))
}

/// Bisection steps locating where the number of free arcs changes between two stations.
const BOUNDARY_BISECTIONS: usize = 30;

/// Runs of stations with the same non-zero number of free arcs, in `t` order, and the gaps
/// between them, where the count changes from one non-zero count to another (at the
/// splitter's leading edge: one arc upstream, two beside it). The station where the count
/// changes is found by bisection of `t` between the two stations, to `2⁻³⁰` of their
/// spacing: the last station with the smaller count ends (or starts) the run with fewer arcs,
/// whose arcs still span the channel whole there. The *gap* is what is left: from the first
/// station with the larger count (where the splitter nose's keep-out just divides the
/// channel) to the nearest station of the run with more arcs, returned as that pair of
/// stations; the plan crosses it with cross lines ([`cross_stations`]). Without the boundary
/// stations and the cross lines, the hub between the last station of one run and the first of
/// the next belonged to no lane and was never machined (the default job left a ring up to
/// 0.47 mm high all around the hub just upstream of the splitters). Flow lines there instead
/// (a short lane from the boundary to the next station) would wrap around the nose: on the
/// AutoGrid design they cost 36 more flow lines per channel, most of them linked over the
/// safety surface, and twice the split motions. Cost: `BOUNDARY_BISECTIONS` stations per
/// change of count.
#[allow(clippy::type_complexity)]
fn runs(p: &Planner<'_>, stations: &[Station]) -> (Vec<Vec<Station>>, Vec<(Station, Station)>) {
    let mut runs: Vec<Vec<Station>> = Vec::new();
    for st in stations {
        match runs.last_mut() {
            Some(run) if run[0].arcs.len() == st.arcs.len() => run.push(st.clone()),
            _ => runs.push(vec![st.clone()]),
        }
    }
    let bounds: Vec<Option<(Station, Station)>> = runs
        .windows(2)
        .map(|w| boundary(p, &w[0][w[0].len() - 1], &w[1][0]))
        .collect();
    let mut gaps = Vec::new();
    for (k, b) in bounds.into_iter().enumerate() {
        let Some((lo, hi)) = b else { continue };
        if lo.arcs.len() < hi.arcs.len() {
            // Fewer arcs upstream: extend that run down to the boundary.
            gaps.push((hi, runs[k + 1][0].clone()));
            runs[k].push(lo);
        } else {
            let last = runs[k][runs[k].len() - 1].clone();
            gaps.push((lo, last));
            runs[k + 1].insert(0, hi);
        }
    }
    runs.retain(|r| !r[0].arcs.is_empty());
    (runs, gaps)
}

/// The stations of the cross lines over a gap `(g, s)` of [`runs`]: `g`, `s` and stations
/// between them, evenly spaced in meridional arc length at most `step` apart, each with the
/// same number of free arcs as `g` (one where the count differs is left out). Consecutive
/// cross lines are then no farther apart than the flow lines, so the gap is left with at
/// most the scallop the flow lines leave between them.
fn cross_stations(p: &Planner<'_>, gap: &(Station, Station), step: f64) -> Vec<Station> {
    let m = p.ctx.impeller.hub().meridional();
    let (g, s) = gap;
    let w = (m.arc_length_at(s.t) - m.arc_length_at(g.t)).abs();
    let n = (w / step).ceil().max(1.0) as usize;
    let mut out = vec![g.clone()];
    out.extend((1..n).filter_map(|k| {
        let st = station(p, g.t + (s.t - g.t) * k as f64 / n as f64)?;
        (st.arcs.len() == g.arcs.len()).then_some(st)
    }));
    out.push(s.clone());
    out
}

/// Where the number of free arcs changes between stations `a` and `b` (both with arcs, in
/// different numbers): the last station with `a`'s count and the first with `b`'s, by
/// bisection of `t` ([`BOUNDARY_BISECTIONS`] steps); `None` when the counts agree, either is
/// zero, or a station between them cannot be made.
fn boundary(p: &Planner<'_>, a: &Station, b: &Station) -> Option<(Station, Station)> {
    let (na, nb) = (a.arcs.len(), b.arcs.len());
    if na == 0 || nb == 0 || na == nb {
        return None;
    }
    let (mut lo, mut hi) = (a.clone(), b.clone());
    for _ in 0..BOUNDARY_BISECTIONS {
        let mid = station(p, 0.5 * (lo.t + hi.t))?;
        if mid.arcs.len() == na {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    // Only the counts of the two stations found may differ from their runs'.
    (lo.t > a.t && hi.t < b.t && lo.arcs.len() == na && hi.arcs.len() == nb).then_some((lo, hi))
}

/// Lanes: one per free arc of every run of two or more stations (the runs of [`runs`]).
fn lanes(runs: &[Vec<Station>]) -> Vec<(Lane, Vec<Station>)> {
    let mut out = Vec::new();
    for run in runs.iter().filter(|r| r.len() > 1) {
        for a in 0..run[0].arcs.len() {
            out.push((
                Lane {
                    rows: run
                        .iter()
                        .map(|s| (s.t, s.arcs[a].0, s.arcs[a].1))
                        .collect(),
                },
                run.clone(),
            ));
        }
    }
    out
}

/// Largest residual height along the hub normal over the lane's scallop grid (module docs).
fn measure_scallop(
    p: &Planner<'_>,
    lane: &Lane,
    fractions: &[f64],
    lines: &[Vec<Vector3<f64>>],
    heat: &mut Vec<Vec<f64>>,
) -> f64 {
    let hub = p.ctx.impeller.hub();
    let r = p.r;
    let cap = r;
    let n = fractions.len();
    let mut worst: f64 = 0.0;
    let rows = &lane.rows;
    if rows.len() < 2 {
        return 0.0;
    }
    for i in 0..=SCALLOP_ALONG {
        let x = i as f64 / SCALLOP_ALONG as f64 * (rows.len() - 1) as f64;
        let k = (x.floor() as usize).min(rows.len() - 2);
        let w = x - k as f64;
        let (t, l, rr) = (
            rows[k].0 * (1.0 - w) + rows[k + 1].0 * w,
            rows[k].1 * (1.0 - w) + rows[k + 1].1 * w,
            rows[k].2 * (1.0 - w) + rows[k + 1].2 * w,
        );
        let mut row = Vec::new();
        let samples = if n > 1 {
            (n - 1) * SCALLOP_BETWEEN + 1
        } else {
            1
        };
        for j in 0..samples {
            let f = if n > 1 {
                fractions[0] + (fractions[n - 1] - fractions[0]) * j as f64 / (samples - 1) as f64
            } else {
                fractions[0]
            };
            let phi = l + f * (rr - l);
            // Hub a ball kept ρ_b from the blades cannot touch is blade-root finishing's.
            let reach = p
                .ctx
                .clearance
                .blade_signed_distance(&Point3::from(p.centre(t, phi)))
                .0
                - p.rho_b;
            if reach < 0.0 {
                row.push(f64::NAN);
                continue;
            }
            let (q, nn) = (hub.point(t, phi), hub.normal(t, phi));
            // Lines next to the sample.
            let jl = if n > 1 {
                (j / SCALLOP_BETWEEN).min(n - 2)
            } else {
                0
            };
            let mut h = cap;
            for line in lines
                .iter()
                .take((jl + 3).min(lines.len()))
                .skip(jl.saturating_sub(1))
            {
                for c in line {
                    let d = c - q;
                    let b = nn.dot(&d);
                    let disc = b * b - d.norm_squared() + r * r;
                    if disc < 0.0 {
                        continue;
                    }
                    // Entry of the ray q + s·n into the ball: s = b − √disc (≤ 0: inside).
                    let s = b - disc.sqrt();
                    let exit = b + disc.sqrt();
                    if exit < 0.0 {
                        continue;
                    }
                    h = h.min(s.max(0.0));
                }
            }
            worst = worst.max(h);
            row.push(h);
        }
        heat.push(row);
    }
    worst
}

/// Densifies ball centres of consecutive postures of each run to spacing ≤ `step`.
fn dense_centres(runs: &[Vec<Posture>], r: f64, step: f64) -> Vec<Vector3<f64>> {
    let mut out = Vec::new();
    let centre = |p: &Posture| p.cl.tip.coords + p.cl.axis.into_inner() * r;
    for run in runs {
        for w in run.windows(2) {
            let (a, b) = (centre(&w[0]), centre(&w[1]));
            let k = (((b - a).norm() / step).ceil() as usize).clamp(1, 256);
            for i in 0..k {
                out.push(a + (b - a) * (i as f64 / k as f64));
            }
        }
        if let Some(l) = run.last() {
            out.push(centre(l));
        }
    }
    out
}

impl Operation for HubFinishing {
    fn kind(&self) -> &'static str {
        HUB_FINISHING
    }
    fn name(&self) -> &str {
        &self.name
    }
    fn tool(&self) -> &str {
        &self.tool
    }
    fn plan(&self, ctx: &PlanContext<'_>) -> Result<PlannedOperation, PlanError> {
        let r = ball_radius(ctx, &self.name, "hub finishing")?;
        let imp = ctx.impeller;
        let tol = ctx.tolerances.machining_tol;
        let rf = imp.fillet_radius_mm();
        let ch = imp.channel(0);
        let splitter = ch.splitter.as_ref().map(|s| {
            (
                RulingTable::new(imp, s, s.plus_theta_side().other()),
                RulingTable::new(imp, s, s.plus_theta_side()),
            )
        });
        let planner = Planner {
            ctx,
            op: self,
            r,
            rho_h: r + ctx.process.hub_allowance_mm,
            rho_b: r.max(2.0 * rf - r) + ctx.process.blade_allowance_mm + 0.5 * tol,
            tol,
            left: RulingTable::new(imp, &ch.left, ch.left_side()),
            right: RulingTable::new(imp, &ch.right, ch.right_side()),
            splitter,
            upper: ctx.clearance.with_options(ClearanceOptions {
                parts: PartSet::MATERIAL,
                above_mm: 2.0 * r,
                ..ClearanceOptions::default()
            }),
            blades_only: ctx.clearance.with_options(ClearanceOptions {
                parts: PartSet::BLADES,
                above_mm: r,
                ..ClearanceOptions::default()
            }),
        };
        let (t_lo, t_hi) = blade_extent(imp).ok_or_else(|| {
            PlanError::geometry(
                &self.name,
                "channel 0",
                "the bounding main blades do not both reach the hub anywhere",
            )
        })?;
        // Stations uniform in meridional arc length, inset by 1e-6 of the extent.
        let m = imp.hub().meridional();
        let (s_lo, s_hi) = (m.arc_length_at(t_lo), m.arc_length_at(t_hi));
        let len = m.length_mm().max(1e-300);
        let inset = 1e-6 * (s_hi - s_lo);
        let n_st = self.params.stations;
        let stations: Vec<Station> = (0..n_st)
            .into_par_iter()
            .filter_map(|k| {
                let s = s_lo + inset + (s_hi - s_lo - 2.0 * inset) * k as f64 / (n_st - 1) as f64;
                station(&planner, m.param_at_fraction(s / len))
            })
            .collect();
        let (runs, gaps) = runs(&planner, &stations);
        let lanes = lanes(&runs);
        if lanes.is_empty() {
            return Err(PlanError::geometry(
                &self.name,
                "channel 0",
                format!(
                    "no room on the hub for a ball of radius {r} mm kept {:.3} mm from the blades",
                    planner.rho_b
                ),
            ));
        }
        // Step-over from the scallop target at the hub's largest convex cross curvature.
        let mut kappa: f64 = 0.0;
        for i in 0..=64 {
            let t = t_lo + (t_hi - t_lo) * i as f64 / 64.0;
            let (nz, rad) = (m.normal(t), m.point(t)[1]);
            if rad > 1e-9 {
                kappa = kappa.max(nz[1] / rad);
            }
        }
        let mut step = cam_core::ball_step_over(r, kappa, self.params.scallop_mm)
            .map_err(|e| PlanError::param(&self.name, "scallop_mm", e.to_string()))?;
        if let Some(w) = ctx.process.width_of_cut_mm.filter(|w| *w > 0.0) {
            step = step.min(w);
        }
        // Plan every lane's lines (in parallel), then join them zig-zag.
        let mut path = ToolPath::new(format!("{} channel", self.name), &self.tool);
        let mut metrics_acc = LineResult {
            min_blade_clearance: f64::INFINITY,
            ..LineResult::default()
        };
        let mut max_scallop: f64 = 0.0;
        let mut n_lines = 0usize;
        let mut series = Vec::new();
        let mut heat = Vec::new();
        let mut cross_links = 0usize;
        let mut smoothing = cam_plan::SmoothingSummary::default();
        for (li, (lane, lane_st)) in lanes.iter().enumerate() {
            let w_max = lane
                .rows
                .iter()
                .map(|&(t, a, b)| m.point(t)[1] * (b - a))
                .fold(0.0, f64::max);
            let n = ((w_max / step).ceil() as usize + 1).max(2);
            let fractions: Vec<f64> = (0..n).map(|j| j as f64 / (n - 1) as f64).collect();
            let results: Vec<LineResult> = fractions
                .par_iter()
                .map(|&f| planner.plan_line(lane, lane_st, f))
                .collect();
            let lines: Vec<Vec<Vector3<f64>>> = results
                .iter()
                .map(|res| dense_centres(&res.runs, r, 0.25 * r))
                .collect();
            let mut lane_heat = Vec::new();
            max_scallop = max_scallop.max(measure_scallop(
                &planner,
                lane,
                &fractions,
                &lines,
                &mut lane_heat,
            ));
            if li == 0 {
                heat = lane_heat;
            }
            for (j, res) in results.into_iter().enumerate() {
                metrics_acc.absorb(&res);
                smoothing.merge(&res.smoothing);
                n_lines += 1;
                if j == 0 || j + 1 == n || j % 4 == 0 {
                    series.push(PlotSeries {
                        label: format!("lane {li} line {j}"),
                        points: res
                            .runs
                            .iter()
                            .flatten()
                            .map(|p| {
                                let c = p.cl.tip.coords + p.cl.axis.into_inner() * r;
                                let (t, phi, _) = imp.hub().closest(&c);
                                [m.arc_length_at(t), phi.to_degrees()]
                            })
                            .collect(),
                    });
                }
                cross_links +=
                    planner.join(ctx, &mut path, res.runs, j % 2 == 1, 2.0 * step + r)?;
            }
        }
        // Cross lines over the gaps where the number of lanes changes ([`runs`]): per gap and
        // free arc, the arc at each cross station in turn, zig-zag.
        let mut crossings: Vec<(Station, usize)> = Vec::new();
        for gap in &gaps {
            let sts = cross_stations(&planner, gap, step);
            for a in 0..gap.0.arcs.len() {
                crossings.extend(sts.iter().map(|st| (st.clone(), a)));
            }
        }
        let cross: Vec<LineResult> = crossings
            .par_iter()
            .map(|(st, a)| planner.plan_cross_line(st, *a))
            .collect();
        let n_cross = cross.len();
        for (j, res) in cross.into_iter().enumerate() {
            metrics_acc.absorb(&res);
            smoothing.merge(&res.smoothing);
            cross_links += planner.join(ctx, &mut path, res.runs, j % 2 == 1, 2.0 * step + r)?;
        }
        if metrics_acc.max_offset_error > 1e-6 {
            return Err(PlanError::geometry(
                &self.name,
                "channel 0",
                format!(
                    "the hub's offset by {:.3} mm is not exact here (error {:.2e} mm): a concave hub radius is smaller than the ball",
                    planner.rho_h, metrics_acc.max_offset_error
                ),
            ));
        }
        ctx.close(&mut path, APPROACH_MM)?;
        let count = imp.main().count();
        let pitch = std::f64::consts::TAU / count.max(1) as f64;
        let order = cam_plan::order::angular_sequence(count, 0);
        let paths = pattern::copy_to(&path, pitch, &order);
        let mut metrics = Metrics::new();
        metrics
            .number("max_scallop_mm", max_scallop)
            .number("scallop_target_mm", self.params.scallop_mm)
            .number("step_over_mm", step)
            .number("max_overcut_mm", metrics_acc.max_overcut)
            .number("min_blade_clearance_mm", metrics_acc.min_blade_clearance)
            .count("paths", (n_lines + n_cross) * count)
            .count("lanes", lanes.len())
            .count("skipped_locations", metrics_acc.skipped * count)
            .count("split_motions", metrics_acc.split * count)
            .count("accessibility_steps", metrics_acc.steps * count)
            .number(
                "max_axis_rotation_deg",
                metrics_acc.max_rotation.to_degrees(),
            );
        let smoothing = smoothing.times(count);
        smoothing.add_metrics(&mut metrics);
        let mut notes = vec![format!(
            "{} lanes, {n_lines} flow lines and {n_cross} cross lines (where the number of lanes changes) per channel at ≤ {step:.3} mm; ball centres kept {:.3} mm from the blades (the strip to the root is blade-root finishing's); {cross_links} line-to-line steps at feed",
            lanes.len(),
            planner.rho_b
        )];
        if metrics_acc.split > 0 {
            let [h, b, u] = metrics_acc.split_causes;
            notes.push(format!(
                "{} motions per channel not clear as a whole, split there: {h} ball into hub, {b} ball into blades, {u} flutes/shank/holder",
                metrics_acc.split
            ));
        }
        notes.push(smoothing.note());
        if metrics_acc.skipped > 0 {
            notes.push(format!(
                "{} points per channel have no collision-free axis within ±{}° and are left uncut (see max_scallop_mm)",
                metrics_acc.skipped, self.params.max_turn_deg
            ));
        }
        let mut plots = vec![
                Plot {
                    title: "Hub finishing flow lines of channel 0 (every fourth line)".into(),
                    kind: PlotKind::Lines {
                        x_label: "meridional length from the inlet (mm)".into(),
                        y_label: "polar angle (deg)".into(),
                        series,
                        equal_aspect: false,
                    },
                },
                Plot {
                    title: "Measured hub residual of the first lane (rows: inlet → outlet; columns: across the lane)".into(),
                    kind: PlotKind::HeatMap {
                        values: heat,
                        unit: "mm".into(),
                    },
                },
            ];
        plots.extend(smoothing.plot());
        Ok(PlannedOperation {
            paths,
            metrics,
            plots,
            notes,
        })
    }
}
