//! The `flank_finishing` operation (paper 002).
//!
//! For each blade side asked for (one blade; the paths are copied to every blade):
//!
//! 1. [`FlankSide`]: accuracy samples on the design side, clearance samples on the facing side
//!    of the adjacent blade.
//! 2. Shape study (first side): from the job tool's ball radius (and half angle, 1° for a
//!    cylindrical tool) and its two-point-tangency path, SLP maximises the stiffness over
//!    `(r, θ, guide control points)` under accuracy, hub tangency and clearance
//!    ([`crate::problem`]). The catalogue cutter just below the optimum is reported.
//! 3. The path of the job's tool (ball end or tapered ball end): its initial path
//!    ([`InitialPath`]), then minimax SLP (largest |deviation|) under hub tangency and
//!    clearance, shape fixed. The written locations follow the optimised envelope within a
//!    quarter of the tolerance ([`output_locations`]). The written pass is then measured
//!    densely against the design side ([`crate::measure`], issue 13); while it is outside
//!    the tolerance, the points outside become samples and the SLP continues from the
//!    current path (at most `REFINE_ROUNDS` rounds, cutting planes). The operation's
//!    `max_overcut_mm`, `max_undercut_mm` and `max_deviation_mm` are that dense measurement
//!    (`sample_max_*` keep the optimiser's own figures); a pass still outside after the
//!    rounds is refused ([`FlankError::NotAccurate`]). The pass's tool axes are then made
//!    monotone about the impeller axis within its accuracy slack ([`crate::axis_smoothing`]:
//!    turned about the ball centres, clearance re-checked, the smoothed pass measured densely
//!    again); every direction change left is reported with its reason (`axis_reversals_*`).
//! 4. Comparison: the largest catalogue cylindrical ball end whose initial path keeps the
//!    clearance, with its own minimax path, refined and measured densely by the same route
//!    ([`minimax_measured`]); `stiffness_ratio_vs_cylindrical` is the job tool's stiffness
//!    over that cylinder's, `cylinder_max_overcut_mm` / `cylinder_max_undercut_mm` its dense
//!    figures.
//! 5. Optionally (`second_initial_path`), the job tool's minimax path from a second initial
//!    path, by the same route: `second_start_max_deviation_mm` and
//!    `two_start_deviation_ratio` (larger over smaller largest |deviation|; issue 13 expects
//!    at most 1.1).
//!
//! Complexity per SLP iteration: (samples + adjacent samples) certified envelope distance
//! queries with gradients (a few µs each) and one sparse LP of `2 + 6n` variables plus one
//! slack per constraint row. Iteration counts are bounded by `max_slp_iterations`.

use crate::catalogue::Catalogue;
use crate::geometry::{ball_radius, guides_through, FlankSide, InitialPath};
use crate::measure::{measure_written_path, DenseGrid, WrittenDeviation};
use crate::problem::{deviations_max, Family, FlankProblem, HistoryRow, Mode, ProblemSettings};
use crate::rows::{self, RowName};
use crate::slp::{self, SlpOptions, Termination};
use crate::{FlankError, FLANK_FINISHING};
use cam_core::{CutterShape, Move, ToolPath};
use cam_plan::{
    Metrics, Operation, OperationSpec, PassCheck, PassFloors, PlanContext, PlanError,
    PlannedOperation, Plot, PlotKind, PlotSeries, Row,
};
use impeller_model::Side;
use rayon::prelude::*;
use serde::Deserialize;

/// Which sides of the blade are finished.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Sides {
    /// Pressure and suction side.
    Both,
    /// Pressure side only.
    Pressure,
    /// Suction side only.
    Suction,
}

fn default_locations() -> usize {
    30
}
fn default_along() -> usize {
    60
}
fn default_across() -> usize {
    8
}
fn default_hub_tol() -> f64 {
    0.01
}
fn default_clearance() -> f64 {
    0.1
}
fn default_youngs() -> f64 {
    600.0
}
fn default_iterations() -> usize {
    12
}
fn default_trust() -> f64 {
    0.5
}
fn default_output() -> usize {
    60
}
fn default_true() -> bool {
    true
}
fn default_sides() -> Sides {
    Sides::Both
}
fn default_initial() -> InitialPath {
    InitialPath::TwoPoint
}

/// The kind's own keys (job file, `[[operations]]` of kind `flank_finishing`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FinishingParams {
    /// Cutter locations of the initial path = control points per guide (default 30).
    #[serde(default = "default_locations")]
    pub cutter_locations: usize,
    /// `both` (default), `pressure` or `suction`.
    #[serde(default = "default_sides")]
    pub sides: Sides,
    /// Accuracy samples along the blade (default 60: two per guide control point of the
    /// default 30, so the minimax path cannot swing between sample columns; issue 13).
    #[serde(default = "default_along")]
    pub samples_along: usize,
    /// Accuracy samples across (hub to shroud, default 8).
    #[serde(default = "default_across")]
    pub samples_across: usize,
    /// Allowed overcut (mm); default the job's `machining_tol`.
    pub overcut_tol_mm: Option<f64>,
    /// Allowed undercut (mm); default the job's `machining_tol`.
    pub undercut_tol_mm: Option<f64>,
    /// Hub tangency tolerance ε (mm, default 0.01).
    #[serde(default = "default_hub_tol")]
    pub hub_tangency_tol_mm: f64,
    /// Smallest clearance to the adjacent blade (mm, default 0.1).
    #[serde(default = "default_clearance")]
    pub min_blade_clearance_mm: f64,
    /// Young's modulus of the cutter (GPa, default 600: cemented carbide).
    #[serde(default = "default_youngs")]
    pub youngs_gpa: f64,
    /// Iteration limit of each SLP run (default 12).
    #[serde(default = "default_iterations")]
    pub max_slp_iterations: usize,
    /// Initial and largest trust radius (mm of control-point motion; default 0.5).
    #[serde(default = "default_trust")]
    pub trust_radius_mm: f64,
    /// `two_point` (default) or `mid_normal`.
    #[serde(default = "default_initial")]
    pub initial_path: InitialPath,
    /// A second initial path (`two_point` or `mid_normal`) from which the job tool's minimax
    /// path is also optimised, refined and measured on the first side (issue 13's two-start
    /// convergence check); reported as `second_start_max_deviation_mm` and
    /// `two_start_deviation_ratio`, not written. Default: none.
    #[serde(default)]
    pub second_initial_path: Option<InitialPath>,
    /// Run the shape study (default true).
    #[serde(default = "default_true")]
    pub optimise_shape: bool,
    /// Plan the best cylindrical ball end for comparison (default true).
    #[serde(default = "default_true")]
    pub compare_cylindrical: bool,
    /// Cutter locations written per side (default 60).
    #[serde(default = "default_output")]
    pub output_locations: usize,
    /// The catalogue (default: 1–6 mm by 0.25 mm, 0–8° by 0.5°).
    #[serde(default)]
    pub catalogue: Option<Catalogue>,
    /// Blade rows finished: `["main", "splitter"]` (default: both rows the impeller has).
    #[serde(default)]
    pub rows: Option<Vec<RowName>>,
}

impl FinishingParams {
    fn validate(&self) -> Result<(), FlankError> {
        let bad = |m: &str| Err(FlankError::Param(m.into()));
        if !(4..=200).contains(&self.cutter_locations) {
            return bad("cutter_locations must be in 4..=200");
        }
        if self.samples_along < 2 || self.samples_across < 2 {
            return bad("samples_along and samples_across must be >= 2");
        }
        if self.output_locations < 2 {
            return bad("output_locations must be >= 2");
        }
        for (k, v) in [
            ("hub_tangency_tol_mm", self.hub_tangency_tol_mm),
            ("youngs_gpa", self.youngs_gpa),
            ("trust_radius_mm", self.trust_radius_mm),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(FlankError::Param(format!("{k} must be > 0")));
            }
        }
        for v in [self.overcut_tol_mm, self.undercut_tol_mm]
            .into_iter()
            .flatten()
        {
            if !(v.is_finite() && v > 0.0) {
                return bad("overcut_tol_mm and undercut_tol_mm must be > 0");
            }
        }
        if !self.min_blade_clearance_mm.is_finite() {
            return bad("min_blade_clearance_mm must be finite");
        }
        if let Some(c) = &self.catalogue {
            c.validate()?;
        }
        Ok(())
    }
}

/// The operation.
#[derive(Debug, Clone)]
pub struct FlankFinishing {
    name: String,
    tool: String,
    params: FinishingParams,
}

/// Builds a `flank_finishing` operation from its job table.
pub fn build_flank_finishing(spec: &OperationSpec) -> Result<Box<dyn Operation>, PlanError> {
    let params: FinishingParams = cam_plan::params::parse(spec)?;
    params.validate().map_err(|e| e.plan(&spec.name))?;
    Ok(Box::new(FlankFinishing {
        name: spec.name.clone(),
        tool: spec.tool.clone(),
        params,
    }))
}

/// One optimised path: its problem data and result.
#[derive(Debug, Clone)]
pub struct PathResult {
    /// Final variables.
    pub x: Vec<f64>,
    /// Largest |deviation| of the initial path (mm).
    pub initial_max_deviation_mm: f64,
    /// Signed deviations of the design samples (NaN: not an accuracy sample).
    pub deviations: Vec<f64>,
    /// Largest overcut over the optimiser's accuracy samples (mm, >= 0); the written pass
    /// itself is measured by [`crate::measure::measure_written_path`].
    pub max_overcut_mm: f64,
    /// Largest undercut over the optimiser's accuracy samples (mm, >= 0).
    pub max_undercut_mm: f64,
    /// Smallest clearance to the adjacent blade (mm).
    pub min_clearance_mm: f64,
    /// Largest |hub gap| (mm).
    pub hub_error_mm: f64,
    /// Stiffness of the cutter (N/mm).
    pub stiffness_n_per_mm: f64,
    /// SLP iterations.
    pub iterations: usize,
    /// Why the SLP stopped.
    pub termination: Termination,
    /// Convergence history.
    pub history: Vec<HistoryRow>,
    /// SLP merit after each iteration (the accepted point's), initial merit first.
    pub merit_history: Vec<f64>,
    /// Cutter locations along the final path (tip + axis).
    pub locations: Vec<cam_core::CutterLocation>,
}

/// Settings shared by every run on one side.
#[derive(Debug, Clone, Copy)]
pub struct RunSettings {
    /// Problem settings (tolerances, cutter lengths).
    pub problem: ProblemSettings,
    /// Cutter locations of the initial path.
    pub locations: usize,
    /// SLP iteration limit.
    pub max_iterations: usize,
    /// Initial and largest trust radius (mm).
    pub trust_radius: f64,
    /// Cutter locations written.
    pub output_locations: usize,
}

/// Trust scale of the half angle per mm of trust radius (rad/mm): 0.02 rad ≈ 1.1° for a
/// 1 mm radius, comparable in effect on the flank to a millimetre of radius over ~50 mm.
const ANGLE_TRUST_SCALE: f64 = 0.02;
/// SLP stops when the trust radius shrinks below this (mm).
const MIN_TRUST_MM: f64 = 1e-4;
/// Penalty weight of constraint violations (per mm) in the merit: large against the
/// normalised stiffness objective (order 1) so that feasibility comes first.
const PENALTY_PER_MM: f64 = 100.0;
/// Smallest ball radius the shape study may reach (mm).
const MIN_BALL_RADIUS_MM: f64 = 0.5;
/// Largest half angle of the shape study (rad): 15°, beyond any catalogue taper.
const MAX_HALF_ANGLE: f64 = 0.26;

/// Optimises one path on `side` for `shape` (shape fixed, minimax) or the shape and path
/// together (`mode = Shape`, `shape` the start). Returns the result with the final
/// cutter locations.
pub fn optimise(
    side: &FlankSide,
    shape: CutterShape,
    how: InitialPath,
    mode: Mode,
    run: &RunSettings,
) -> Result<PathResult, FlankError> {
    optimise_from(side, shape, how, mode, run, None)
}

/// [`optimise`] started from the variables `start` (a previous result's `x` on the same side
/// with the same `run.locations`) instead of the initial path; `None`: from the initial path.
/// Errors as [`optimise`], and [`FlankError::Param`] when `start` has the wrong length.
pub fn optimise_from(
    side: &FlankSide,
    shape: CutterShape,
    how: InitialPath,
    mode: Mode,
    run: &RunSettings,
    start: Option<&[f64]>,
) -> Result<PathResult, FlankError> {
    let (family, r, theta) = match shape {
        CutterShape::BallEnd { radius } => (Family::Ball, radius, 0.0),
        CutterShape::TaperedBallEnd {
            ball_radius,
            half_angle,
        } => (Family::TaperedBall, ball_radius, half_angle),
        other => {
            return Err(FlankError::Param(format!(
                "flank finishing needs a ball or tapered ball end, not {other:?}"
            )))
        }
    };
    let (p0, p1) = side.initial_locations(&shape, run.locations, how)?;
    let (g0, g1) = guides_through(&p0, &p1)?;
    let mut settings = run.problem;
    settings.min_sample_height = settings.min_sample_height.max(r);
    let mut prob = FlankProblem::new(side, g0, g1, family, mode, settings);
    let mut x0 = prob.pack(r, theta);
    let n = x0.len();
    if let Some(x) = start {
        if x.len() != n {
            return Err(FlankError::Param(format!(
                "start vector has {} variables, the problem {n}",
                x.len()
            )));
        }
        x0 = x.to_vec();
    }
    let mut scale = vec![1.0; n];
    let mut lower = vec![f64::NEG_INFINITY; n];
    let mut upper = vec![f64::INFINITY; n];
    match (mode, family) {
        (Mode::Shape, Family::TaperedBall) => {
            scale[1] = ANGLE_TRUST_SCALE;
            lower[0] = MIN_BALL_RADIUS_MM;
            lower[1] = 0.0;
            upper[1] = MAX_HALF_ANGLE;
        }
        (Mode::Shape, Family::Ball) => {
            scale[1] = 0.0;
            lower[0] = MIN_BALL_RADIUS_MM;
        }
        (Mode::Minimax, _) => {
            scale[0] = 0.0;
            scale[1] = 0.0;
        }
    }
    let opts = SlpOptions {
        max_iterations: run.max_iterations,
        radius: run.trust_radius,
        min_radius: MIN_TRUST_MM,
        tol: 1e-7,
        penalty: PENALTY_PER_MM,
        feas_tol: 1e-3,
        scale,
        lower,
        upper,
    };
    use crate::slp::Model;
    let first = prob.evaluate(&x0, false)?;
    let initial_max = first.info.first().copied().unwrap_or(f64::NAN);
    prob.history.clear();
    let res = slp::solve(&mut prob, x0, &opts)?;
    // Final figures at the accepted point.
    let fin = prob.evaluate(&res.x, false)?;
    let deviations = prob.deviations.clone();
    let (mut over, mut under) = (0.0f64, 0.0f64);
    for d in deviations.iter().filter(|d| d.is_finite()) {
        over = over.max(-d);
        under = under.max(*d);
    }
    let env = prob.envelope(&res.x)?;
    let chord = (OUTPUT_CHORD_FRACTION * run.problem.overcut_tol.min(run.problem.undercut_tol))
        .max(OUTPUT_CHORD_FLOOR_MM);
    let locations = output_locations(&env, run.output_locations, run.problem.flute_length, chord)?;
    Ok(PathResult {
        initial_max_deviation_mm: initial_max,
        max_overcut_mm: over,
        max_undercut_mm: under,
        min_clearance_mm: fin.info.get(1).copied().unwrap_or(f64::NAN),
        hub_error_mm: prob.hub_tangency_error(&res.x),
        stiffness_n_per_mm: prob.stiffness(&res.x)?.0,
        deviations,
        iterations: res.iterations,
        termination: res.termination,
        history: prob.history.clone(),
        merit_history: res.merit_history.clone(),
        locations,
        x: res.x,
    })
}

/// Fraction of the accuracy tolerance allowed to the chord error of the written pass: the
/// written motion (linear between locations) strays from the optimised envelope by at most
/// this much at the tip and the flute top, so by at most this much anywhere on the cutter.
const OUTPUT_CHORD_FRACTION: f64 = 0.25;
/// Smallest chord tolerance of the written pass (mm): tighter accuracy requests would
/// multiply the locations for no machining gain (the post linearises to a few µm anyway);
/// the dense measurement still measures the pass as written.
const OUTPUT_CHORD_FLOOR_MM: f64 = 1e-3;
/// Bisections of one output interval (2¹⁰ = 1024 sub-intervals at most per initial one).
const OUTPUT_MAX_DEPTH: usize = 10;

/// The written cutter locations of `env`: `m` evenly in the path parameter, then each
/// interval bisected while the cutter location at its middle lies farther than `chord` (mm)
/// from the chord of its ends, measured at the tip and at the flute top (`flute_length`
/// above it), which bounds how far any point of the cutter's axis segment strays from the
/// written linear motion there (the ends of a segment move linearly, so every point in
/// between stays within the larger of the two). At the rounded leading edge, where the axis
/// turns fastest, this inserts locations that 60 even ones lacked (issue 13: 0.019 mm of
/// linearisation overcut at the nose). O(final count · depth) guide evaluations.
pub fn output_locations(
    env: &cam_core::SweptEnvelope,
    m: usize,
    flute_length: f64,
    chord: f64,
) -> Result<Vec<cam_core::CutterLocation>, FlankError> {
    let (lo, hi) = env.domain();
    let m = m.max(2);
    let at = |s: f64| env.cutter_location(s);
    let ends = |c: &cam_core::CutterLocation| {
        (
            c.tip.coords,
            c.tip.coords + c.axis.into_inner() * flute_length,
        )
    };
    let mut out = vec![at(lo)?];
    for i in 1..m {
        let (a, b) = (
            lo + (hi - lo) * (i - 1) as f64 / (m - 1) as f64,
            lo + (hi - lo) * i as f64 / (m - 1) as f64,
        );
        // Depth-first bisection, left to right.
        let mut stack = vec![(a, b, 0usize)];
        while let Some((a, b, depth)) = stack.pop() {
            let (ca, cb) = (at(a)?, at(b)?);
            let mid = 0.5 * (a + b);
            let cm = at(mid)?;
            let ((ta, pa), (tb, pb), (tm, pm)) = (ends(&ca), ends(&cb), ends(&cm));
            let err = (tm - 0.5 * (ta + tb))
                .norm()
                .max((pm - 0.5 * (pa + pb)).norm());
            if err > chord && depth < OUTPUT_MAX_DEPTH {
                stack.push((mid, b, depth + 1));
                stack.push((a, mid, depth + 1));
            } else {
                out.push(cb);
            }
        }
    }
    Ok(out)
}

/// The largest cylindrical ball end of the catalogue whose initial path keeps the
/// clearance, with its minimax path refined and measured densely exactly as the job tool's
/// ([`minimax_measured`], on a copy of `side`). `None` when no catalogue radius fits.
/// Cost: one zero-iteration probe per radius tried, then one [`minimax_measured`].
pub fn best_cylinder(
    side: &FlankSide,
    catalogue: &Catalogue,
    how: InitialPath,
    run: &RunSettings,
) -> Result<Option<MeasuredPath>, FlankError> {
    for r in catalogue.ball_radius_mm.descending() {
        let shape = CutterShape::BallEnd { radius: r };
        let probe = RunSettings {
            max_iterations: 0,
            ..*run
        };
        let Ok(res) = optimise(side, shape, how, Mode::Minimax, &probe) else {
            continue;
        };
        if res.min_clearance_mm >= run.problem.min_clearance {
            let mut own = side.clone();
            return minimax_measured(&mut own, shape, how, run).map(Some);
        }
    }
    Ok(None)
}

/// A minimax path whose written pass was measured densely and refined (issue 13).
#[derive(Debug, Clone)]
pub struct MeasuredPath {
    /// The last optimised path (its written locations are `path.locations`;
    /// `initial_max_deviation_mm` is the initial path's, before the first run).
    pub path: PathResult,
    /// Dense measurement of that written pass ([`measure_written_path`]).
    pub dense: WrittenDeviation,
    /// Refinement rounds run (0 when the first pass already held the tolerance).
    pub refine_rounds: usize,
    /// SLP iterations of every run (first and refinements).
    pub iterations: usize,
    /// The worst termination of those runs.
    pub termination: Termination,
}

impl MeasuredPath {
    /// The dense overcut and undercut are within `settings`' tolerances, and no uncertified
    /// query could hide an overcut beyond it.
    pub fn holds(&self, settings: &ProblemSettings) -> bool {
        self.dense.max_overcut_mm <= settings.overcut_tol
            && self.dense.max_undercut_mm <= settings.undercut_tol
            && self.dense.uncertified_max_overcut_mm <= settings.overcut_tol
    }
}

/// The minimax path of `shape` on `side` from the initial path `how` (shape fixed,
/// [`optimise`]), its written pass measured densely against the design side
/// ([`measure_written_path`], default grid), and while that pass is outside the overcut or
/// undercut tolerance, up to `REFINE_ROUNDS` = 4 cutting-plane rounds: the (at most
/// `REFINE_POINTS` = 300 worst) dense points outside `REFINE_FRACTION` = ½ of the tolerance
/// become samples of `side` and the SLP continues from the current path with a tenth of the
/// trust radius and the hub rows planned to 95 % of ε (the linearised hub rows then keep ε
/// after the last step). Used for the job tool, the second initial path and the best
/// cylindrical ball end alike, so their reported accuracies are measured the same way.
/// `side` keeps the added samples. Cost: (1 + rounds) SLP runs and dense measurements.
pub fn minimax_measured(
    side: &mut FlankSide,
    shape: CutterShape,
    how: InitialPath,
    run: &RunSettings,
) -> Result<MeasuredPath, FlankError> {
    let pr = &run.problem;
    let root = pr.min_sample_height.max(ball_radius(&shape));
    let report_mm = REFINE_FRACTION * pr.overcut_tol.min(pr.undercut_tol);
    let measure = |fs: &FlankSide, res: &PathResult| {
        measure_written_path(
            fs,
            &shape,
            pr.flute_length,
            &res.locations,
            root,
            DenseGrid::default(),
            report_mm,
        )
    };
    let mut res = optimise(side, shape, how, Mode::Minimax, run)?;
    // The initial path's largest deviation (a refinement run's own "initial" is its warm
    // start).
    let initial_max = res.initial_max_deviation_mm;
    let mut iterations = res.iterations;
    let mut termination = res.termination;
    let mut dense = measure(side, &res)?;
    let refine_run = RunSettings {
        trust_radius: REFINE_TRUST_FRACTION * run.trust_radius,
        problem: ProblemSettings {
            hub_tol: REFINE_HUB_MARGIN * pr.hub_tol,
            ..*pr
        },
        ..*run
    };
    let mut rounds = 0;
    // A run that stops at its iteration limit may end a hair outside the hub tangency band
    // (0.0100x mm against 0.01 on impeller-8+8 without its fillet, whose accuracy was met):
    // the refinement's narrower band (REFINE_HUB_MARGIN) brings it back inside.
    while (dense.max_overcut_mm > pr.overcut_tol
        || dense.max_undercut_mm > pr.undercut_tol
        || exceeds(res.hub_error_mm, pr.hub_tol))
        && rounds < REFINE_ROUNDS
    {
        rounds += 1;
        side.add_samples(
            dense
                .outside_points
                .iter()
                .take(REFINE_POINTS)
                .map(|q| q.uv),
        );
        res = optimise_from(side, shape, how, Mode::Minimax, &refine_run, Some(&res.x))?;
        iterations += res.iterations;
        termination = worse(termination, res.termination);
        dense = measure(side, &res)?;
    }
    res.initial_max_deviation_mm = initial_max;
    Ok(MeasuredPath {
        path: res,
        dense,
        refine_rounds: rounds,
        iterations,
        termination,
    })
}

fn series(label: &str, rows: &[HistoryRow], f: impl Fn(&HistoryRow) -> f64) -> PlotSeries {
    PlotSeries {
        label: label.into(),
        points: rows
            .iter()
            .enumerate()
            .map(|(i, h)| [i as f64, f(h)])
            .collect(),
    }
}

fn lines(title: &str, y: &str, series: Vec<PlotSeries>) -> Plot {
    Plot {
        title: title.into(),
        kind: PlotKind::Lines {
            x_label: "SLP iteration".into(),
            y_label: y.into(),
            series,
            equal_aspect: false,
        },
    }
}

/// Convergence plots of the runs `(label, history)`.
pub fn history_plots(runs: &[(&str, &[HistoryRow])]) -> Vec<Plot> {
    type Getter = fn(&HistoryRow) -> f64;
    let figs: [(&str, &str, Getter); 6] = [
        ("largest deviation", "mm", |h| h.max_deviation_mm),
        ("smallest clearance to the adjacent blade", "mm", |h| {
            h.min_clearance_mm
        }),
        ("stiffness", "N/mm", |h| h.stiffness_n_per_mm),
        ("ball radius", "mm", |h| h.ball_radius_mm),
        ("half angle", "deg", |h| h.half_angle.to_degrees()),
        ("trust radius", "mm", |h| h.trust_radius),
    ];
    figs.iter()
        .map(|(t, y, f)| {
            lines(
                &format!("flank finishing: {t} per SLP iteration"),
                y,
                runs.iter().map(|(l, h)| series(l, h, f)).collect(),
            )
        })
        .collect()
}

/// Heat map of the signed deviation over the side (rows: across, hub first).
pub fn deviation_map(side: &FlankSide, deviations: &[f64], title: &str) -> Plot {
    let (nu, nv) = side.grid;
    let values = (0..nv)
        .map(|j| (0..nu).map(|i| deviations[i * nv + j]).collect())
        .collect();
    Plot {
        title: title.into(),
        kind: PlotKind::HeatMap {
            values,
            unit: "mm".into(),
        },
    }
}

impl Operation for FlankFinishing {
    fn kind(&self) -> &'static str {
        FLANK_FINISHING
    }
    fn name(&self) -> &str {
        &self.name
    }
    fn tool(&self) -> &str {
        &self.tool
    }
    fn plan(&self, ctx: &PlanContext<'_>) -> Result<PlannedOperation, PlanError> {
        self.plan_inner(ctx).map_err(|e| e.plan(&self.name))
    }
}

fn worse(a: Termination, b: Termination) -> Termination {
    let rank = |t: Termination| match t {
        Termination::Converged => 0,
        Termination::IterationLimit => 1,
        Termination::Infeasible => 2,
    };
    if rank(b) > rank(a) {
        b
    } else {
        a
    }
}

impl FlankFinishing {
    fn plan_inner(&self, ctx: &PlanContext<'_>) -> Result<PlannedOperation, FlankError> {
        let p = &self.params;
        let cutter = &ctx.tool.cutter;
        let tol = ctx.tolerances.machining_tol;
        let run = RunSettings {
            problem: ProblemSettings {
                overcut_tol: p.overcut_tol_mm.unwrap_or(tol),
                undercut_tol: p.undercut_tol_mm.unwrap_or(tol),
                hub_tol: p.hub_tangency_tol_mm,
                min_clearance: p.min_blade_clearance_mm,
                flute_length: cutter.flute_length,
                stick_out: cutter.overall_length,
                youngs: p.youngs_gpa * 1000.0,
                min_sample_height: ctx.impeller.fillet_radius_mm(),
            },
            locations: p.cutter_locations,
            max_iterations: p.max_slp_iterations,
            trust_radius: p.trust_radius_mm,
            output_locations: p.output_locations,
        };
        let catalogue = p.catalogue.unwrap_or_default();
        let side_list: &[Side] = match p.sides {
            Sides::Both => &[Side::Pressure, Side::Suction],
            Sides::Pressure => &[Side::Pressure],
            Sides::Suction => &[Side::Suction],
        };
        let row_list = match &p.rows {
            Some(names) => rows::rows_of(ctx.impeller, names, true)?,
            None => rows::rows_of(ctx.impeller, &rows::default_rows(), false)?,
        };
        let sides: Vec<(Row, Side)> = row_list
            .iter()
            .flat_map(|&r| side_list.iter().map(move |&s| (r, s)))
            .collect();
        let mut out = PlannedOperation::default();
        let mut metrics = Metrics::new();
        let mut over = 0.0f64;
        let mut under = 0.0f64;
        let mut sample_over = 0.0f64;
        let mut sample_under = 0.0f64;
        let mut refine_rounds = 0usize;
        let mut dense_points = 0usize;
        let mut uncertified = 0usize;
        let mut uncertified_over = 0.0f64;
        let mut worst_at: Option<(Row, Side, crate::measure::DensePoint)> = None;
        let mut whole_tool_misses: Vec<String> = Vec::new();
        let mut hub_lifts = 0usize;
        let mut hub_lift_max = 0.0f64;
        let mut clear = f64::INFINITY;
        let mut hub = 0.0f64;
        let mut iterations = 0;
        let mut termination = Termination::Converged;
        let mut stiffness = f64::NAN;
        let mut cylinder_k = f64::NAN;
        let mut initial_dev = 0.0f64;
        let mut final_dev = 0.0f64;
        let mut row_paths: Vec<(Row, ToolPath)> = Vec::new();
        let mut smoothing = cam_plan::SmoothingSummary::default();
        // The SLP runs are independent of each other (each side's job path; on the first
        // side also the shape study, the best cylinder and the second start): run them in
        // parallel, then report them in the order of the sides.
        let study_start = match cutter.shape {
            CutterShape::TaperedBallEnd { .. } => cutter.shape,
            other => CutterShape::TaperedBallEnd {
                ball_radius: ball_radius(&other),
                half_angle: 1f64.to_radians(),
            },
        };
        let side_runs: Vec<Result<SideRuns, FlankError>> = sides
            .par_iter()
            .enumerate()
            .map(|(k, &(row, side))| {
                let fresh =
                    FlankSide::of_row(ctx.impeller, row, side, p.samples_along, p.samples_across)?;
                let first = k == 0;
                let job = || {
                    let mut fs = fresh.clone();
                    minimax_measured(&mut fs, cutter.shape, p.initial_path, &run).map(|m| (fs, m))
                };
                let study = || {
                    (first && p.optimise_shape)
                        .then(|| optimise(&fresh, study_start, p.initial_path, Mode::Shape, &run))
                };
                let cylinder = || {
                    (first && p.compare_cylindrical)
                        .then(|| best_cylinder(&fresh, &catalogue, p.initial_path, &run))
                };
                let second = || {
                    p.second_initial_path.filter(|_| first).map(|how| {
                        let mut second_side = fresh.clone();
                        minimax_measured(&mut second_side, cutter.shape, how, &run)
                    })
                };
                // The cylinder comparison is the longest chain (its minimax runs after a
                // probe per catalogue radius): this thread starts it, the others are left
                // for idle threads to take.
                let ((cylinder, second), (job, study)) =
                    rayon::join(|| rayon::join(cylinder, second), || rayon::join(job, study));
                Ok(SideRuns {
                    fresh,
                    job,
                    study,
                    cylinder,
                    second,
                })
            })
            .collect();
        for (&(row, side), runs_of_side) in sides.iter().zip(side_runs) {
            let SideRuns {
                fresh: job_side,
                job,
                study,
                cylinder,
                second,
            } = runs_of_side?;
            let mut runs: Vec<(String, Vec<HistoryRow>)> = Vec::new();
            if let Some(study) = study {
                let study = study?;
                iterations += study.iterations;
                let (r_opt, t_opt) = (study.x[0], study.x[1]);
                metrics.number("optimal_ball_radius_mm", r_opt);
                metrics.number("optimal_half_angle_deg", t_opt.to_degrees());
                metrics.number("optimal_stiffness_n_per_mm", study.stiffness_n_per_mm);
                metrics.text("shape_slp_termination", study.termination.as_str());
                match catalogue.below(r_opt, t_opt) {
                    Some((rc, tc)) => {
                        metrics.number("catalogue_ball_radius_mm", rc);
                        metrics.number("catalogue_half_angle_deg", tc.to_degrees());
                        let job = match cutter.shape {
                            CutterShape::TaperedBallEnd {
                                ball_radius,
                                half_angle,
                            } => (ball_radius, half_angle),
                            other => (ball_radius(&other), 0.0),
                        };
                        if (job.0 - rc).abs() > 1e-9 || (job.1 - tc).abs() > 1e-9 {
                            out.notes.push(format!(
                                "the job's tool {} (r = {:.3} mm, θ = {:.2}°) is not the \
                                 catalogue cutter just below the optimum (r = {rc:.2} mm, \
                                 θ = {:.1}°); the path is planned for the job's tool",
                                self.tool,
                                job.0,
                                job.1.to_degrees(),
                                tc.to_degrees()
                            ));
                        }
                    }
                    None => out.notes.push(format!(
                        "the optimum (r = {r_opt:.3} mm) is below the smallest catalogue cutter"
                    )),
                }
                runs.push(("shape and path".into(), study.history));
            }
            let (fs, measured) = job?;
            iterations += measured.iterations;
            termination = worse(termination, measured.termination);
            let res = &measured.path;
            // The written locations between the optimiser's hub-tangency samples may hang the
            // ball over the hub body's edge (the inlet corner of impeller-8+8's hub: 0.03 mm
            // into it): each such location is lifted along its axis until the ball keeps the
            // hub tangency tolerance.
            let (locations, lifted, lift_max) = lift_off_hub(
                ctx,
                &res.locations,
                ball_radius(&cutter.shape),
                run.problem.hub_tol,
            );
            hub_lifts += lifted;
            hub_lift_max = hub_lift_max.max(lift_max);
            // The whole tool along the written pass against the whole design: a finishing
            // pass may touch its side within the overcut tolerance (its accuracy there is the
            // dense measurement's; this check is for the rest of the design), its motions
            // within the chord tolerance more, nothing else nearer.
            let floor = -(run.problem.overcut_tol + ctx.tolerances.chord_tol);
            let check = PassCheck::new(
                ctx.clearance,
                PassFloors {
                    blades_mm: floor,
                    hub_mm: floor - run.problem.hub_tol,
                    motion_tol_mm: ctx.tolerances.chord_tol,
                },
                cutter.flute_length,
            );
            // The axes made monotone within the pass's accuracy slack (issue 37), the
            // smoothed pass measured densely again: its figures are the side's when accepted.
            let pr = &run.problem;
            let smoothed = crate::axis_smoothing::smooth_pass(
                &crate::axis_smoothing::PlannedPass {
                    locations: &locations,
                    side: &fs,
                    shape: cutter.shape,
                    flute_length: pr.flute_length,
                    root: pr.min_sample_height.max(ball_radius(&cutter.shape)),
                    tol_mm: (pr.overcut_tol, pr.undercut_tol),
                    measured_mm: (
                        measured.dense.max_overcut_mm,
                        measured.dense.max_undercut_mm,
                    ),
                    report_mm: REFINE_FRACTION * pr.overcut_tol.min(pr.undercut_tol),
                },
                &check,
            )?;
            let (_, copies) = rows::pitch_and_count(ctx.impeller, row)?;
            let mut one = cam_plan::SmoothingSummary::default();
            one.add(&smoothed.run);
            smoothing.merge(&one.times(copies));
            let dense = smoothed.dense.as_ref().unwrap_or(&measured.dense);
            let locations = smoothed.run.postures;
            refine_rounds += measured.refine_rounds;
            dense_points += dense.points;
            uncertified += dense.uncertified;
            uncertified_over = uncertified_over.max(dense.uncertified_max_overcut_mm);
            if let Some(w) = dense.worst_overcut {
                if dense.max_overcut_mm > over {
                    worst_at = Some((row, side, w));
                }
            }
            over = over.max(dense.max_overcut_mm);
            under = under.max(dense.max_undercut_mm);
            sample_over = sample_over.max(res.max_overcut_mm);
            sample_under = sample_under.max(res.max_undercut_mm);
            clear = clear.min(res.min_clearance_mm);
            hub = hub.max(res.hub_error_mm);
            stiffness = res.stiffness_n_per_mm;
            initial_dev = initial_dev.max(res.initial_max_deviation_mm);
            let side_dev = dense.max_overcut_mm.max(dense.max_undercut_mm);
            final_dev = final_dev.max(side_dev);
            out.plots.push(deviation_map(
                &fs,
                &res.deviations,
                &format!(
                    "flank finishing: signed deviation over the {} blade's {side:?} side (mm)",
                    rows::label(row)
                ),
            ));
            runs.push(("job tool path (minimax)".into(), res.history.clone()));
            if let Some(cylinder) = cylinder {
                match cylinder? {
                    Some(cyl) => {
                        let (cp, cd) = (&cyl.path, &cyl.dense);
                        cylinder_k = cp.stiffness_n_per_mm;
                        metrics.number("cylinder_radius_mm", ball_radius_of(cp));
                        metrics.number("cylinder_stiffness_n_per_mm", cp.stiffness_n_per_mm);
                        // Dense measurement of the cylinder's written pass (the same route
                        // and refinement as the job tool's); the optimiser's own figure as
                        // `cylinder_sample_max_deviation_mm`.
                        metrics.number(
                            "cylinder_max_deviation_mm",
                            cd.max_overcut_mm.max(cd.max_undercut_mm),
                        );
                        metrics.number("cylinder_max_overcut_mm", cd.max_overcut_mm);
                        metrics.number("cylinder_max_undercut_mm", cd.max_undercut_mm);
                        metrics.number(
                            "cylinder_sample_max_deviation_mm",
                            deviations_max(&cp.deviations),
                        );
                        metrics.count("cylinder_dense_points", cd.points);
                        metrics.count("cylinder_dense_uncertified_points", cd.uncertified);
                        metrics.number(
                            "cylinder_dense_uncertified_max_overcut_mm",
                            cd.uncertified_max_overcut_mm,
                        );
                        metrics.count("cylinder_refine_rounds", cyl.refine_rounds);
                        metrics.count("cylinder_slp_iterations", cyl.iterations);
                        metrics.text("cylinder_slp_termination", cyl.termination.as_str());
                        if !cyl.holds(&run.problem) {
                            out.notes.push(format!(
                                "the best cylindrical ball end (r = {:.2} mm) misses the \
                                 tolerance on its written pass after {} refinement round(s): \
                                 overcut {:.4} mm, undercut {:.4} mm",
                                ball_radius_of(cp),
                                cyl.refine_rounds,
                                cd.max_overcut_mm,
                                cd.max_undercut_mm
                            ));
                        }
                        out.plots.push(deviation_map(
                            &job_side,
                            &cp.deviations,
                            &format!(
                                "flank finishing, best cylindrical ball end: signed deviation \
                                 over the {side:?} side (mm)"
                            ),
                        ));
                        runs.push((
                            "cylindrical ball end path (minimax)".into(),
                            cp.history.clone(),
                        ));
                    }
                    None => out
                        .notes
                        .push("no catalogue cylindrical ball end keeps the clearance".into()),
                }
            }
            if let (Some(how), Some(second)) = (p.second_initial_path, second) {
                // Issue 13: the minimax from a second initial path, measured the same way;
                // both largest deviations and their ratio (larger over smaller) are reported.
                let second = second?;
                let d2 = second
                    .dense
                    .max_overcut_mm
                    .max(second.dense.max_undercut_mm);
                metrics.text("second_start_initial_path", how.as_str());
                metrics.number("first_start_max_deviation_mm", side_dev);
                metrics.number("second_start_max_deviation_mm", d2);
                metrics.number(
                    "second_start_initial_max_deviation_mm",
                    second.path.initial_max_deviation_mm,
                );
                metrics.number(
                    "two_start_deviation_ratio",
                    side_dev.max(d2) / side_dev.min(d2),
                );
                metrics.count("second_start_slp_iterations", second.iterations);
                metrics.count("second_start_refine_rounds", second.refine_rounds);
                metrics.count(
                    "second_start_dense_uncertified_points",
                    second.dense.uncertified,
                );
                metrics.text("second_start_slp_termination", second.termination.as_str());
                runs.push((
                    format!("job tool path from {} (minimax)", how.as_str()),
                    second.path.history.clone(),
                ));
            }
            let refs: Vec<(&str, &[HistoryRow])> = runs
                .iter()
                .map(|(l, h)| (l.as_str(), h.as_slice()))
                .collect();
            out.plots.extend(history_plots(&refs));
            let violations = check.check(&locations);
            let worst_violation = violations
                .iter()
                .max_by(|a, b| a.depth_mm().total_cmp(&b.depth_mm()));
            if let Some(v) = worst_violation {
                whole_tool_misses.push(format!(
                    "{} blade {side:?} side: {} of {} postures and motions of the pass come \
                     below their floor; worst: {}",
                    rows::label(row),
                    violations.len(),
                    2 * locations.len() - 1,
                    v.describe()
                ));
            }
            // The side's pass, linked to the previous one of its row.
            let moves: Vec<Move> = locations.iter().map(|cl| Move::feed(*cl)).collect();
            if row_paths.last().is_none_or(|(r, _)| *r != row) {
                row_paths.push((row, ToolPath::new(&self.name, &self.tool)));
            }
            if let Some((_, one_path)) = row_paths.last_mut() {
                if let (Some(last), Some(first)) = (one_path.moves.last(), moves.first()) {
                    let link = ctx
                        .link(&last.cl, &first.cl, APPROACH_MM)
                        .map_err(|e| FlankError::Geometry(e.to_string()))?;
                    one_path.moves.extend(link);
                }
                one_path.moves.extend(moves);
            }
        }
        for (_, one_path) in &mut row_paths {
            ctx.close(one_path, APPROACH_MM)
                .map_err(|e| FlankError::Geometry(e.to_string()))?;
        }
        // The accuracy gate: a finishing pass that misses its tolerances is not emitted.
        let pr = &run.problem;
        let misses: Vec<String> = [
            ("overcut", over, pr.overcut_tol, "mm"),
            ("undercut", under, pr.undercut_tol, "mm"),
            ("hub tangency error", hub, pr.hub_tol, "mm"),
        ]
        .iter()
        .filter(|(_, v, t, _)| v.is_nan() || exceeds(*v, *t))
        .map(|(what, v, t, u)| match (*what, worst_at) {
            ("overcut", Some((_, side, w))) => format!(
                "{what} {} {u} > {t} {u} (dense measurement of the written pass, {side:?} \
                 side at ({:.3}, {:.3}, {:.3}), {:.3} mm above the hub)",
                digits_above(*v, *t),
                w.point.x,
                w.point.y,
                w.point.z,
                w.hub_height_mm
            ),
            _ => format!("{what} {} {u} > {t} {u}", digits_above(*v, *t)),
        })
        .chain(
            (uncertified_over > pr.overcut_tol * (1.0 + 1e-9) + 1e-12).then(|| {
                format!(
                    "{uncertified} dense distance queries are uncertified and could hide an \
                     overcut of up to {uncertified_over:.4} mm > {} mm",
                    pr.overcut_tol
                )
            }),
        )
        .chain((clear < pr.min_clearance - 1e-9).then(|| {
            format!(
                "clearance to the next blade {clear:.4} mm < {} mm",
                pr.min_clearance
            )
        }))
        .chain(whole_tool_misses.iter().map(|m| format!("whole tool: {m}")))
        .collect();
        if !misses.is_empty() {
            return Err(FlankError::NotAccurate(format!(
                "the optimised path misses its tolerances after {iterations} SLP iteration(s) \
                 ({}): {}; {}try more iterations (max_slp_iterations), a larger trust region \
                 (trust_radius_mm) or another initial path (initial_path), or finish the \
                 blades with blade_point_finishing (method = \"auto\": one flank pass where a \
                 side is ruled within the strip tolerance, sub-ruled strips or point milling \
                 elsewhere)",
                termination.as_str(),
                misses.join(", "),
                worst_at
                    .and_then(|(row, side, _)| ruled_deviation_note(ctx, row, side, pr))
                    .unwrap_or_default()
            )));
        }
        for (row, one_path) in &row_paths {
            let (pitch, count) = rows::pitch_and_count(ctx.impeller, *row)?;
            let order: Vec<usize> = (0..count).collect();
            out.paths
                .extend(cam_plan::pattern::copy_to(one_path, pitch, &order));
        }
        metrics.text(
            "rows",
            row_paths
                .iter()
                .map(|(r, _)| rows::label(*r))
                .collect::<Vec<_>>()
                .join(", "),
        );
        metrics.number("max_overcut_mm", over);
        metrics.number("max_undercut_mm", under);
        smoothing.add_metrics(&mut metrics);
        out.notes.push(format!(
            "{} (about the ball centre, within each pass's accuracy slack, the smoothed pass \
             measured densely again)",
            smoothing.note()
        ));
        out.plots.extend(smoothing.plot());
        metrics.count("hub_lifted_locations", hub_lifts);
        metrics.number("max_hub_lift_mm", hub_lift_max);
        metrics.number("sample_max_overcut_mm", sample_over);
        metrics.number("sample_max_undercut_mm", sample_under);
        metrics.count("dense_points", dense_points);
        metrics.count("dense_uncertified_points", uncertified);
        metrics.number("dense_uncertified_max_overcut_mm", uncertified_over);
        metrics.count("refine_rounds", refine_rounds);
        metrics.number("min_blade_clearance_mm", clear);
        metrics.number("hub_tangency_error_mm", hub);
        metrics.number("stiffness_n_per_mm", stiffness);
        metrics.number("stiffness_ratio_vs_cylindrical", stiffness / cylinder_k);
        metrics.count("slp_iterations", iterations);
        metrics.text("slp_termination", termination.as_str());
        metrics.number("initial_max_deviation_mm", initial_dev);
        metrics.number("max_deviation_mm", final_dev);
        out.metrics = metrics;
        Ok(out)
    }
}

/// Bisection steps of a location's lift off the hub (the bracket is the ball radius).
const HUB_LIFT_BISECTIONS: usize = 40;

/// `locations` with every ball (radius `r`) that reaches deeper than `hub_tol` into the hub
/// body (exact distance of its centre, [`cam_plan::DesignClearance::hub_signed_distance`],
/// the body capped by the inlet face and the outlet cylinder) lifted along its axis until it
/// keeps `hub_tol` (bisection); with the number of locations lifted and the largest lift.
/// O(locations · bisections) hub distances.
pub fn lift_off_hub(
    ctx: &PlanContext<'_>,
    locations: &[cam_core::CutterLocation],
    r: f64,
    hub_tol: f64,
) -> (Vec<cam_core::CutterLocation>, usize, f64) {
    let gap = |cl: &cam_core::CutterLocation, lift: f64| {
        let c = cl.tip + cl.axis.into_inner() * (r + lift);
        ctx.clearance.hub_signed_distance(&c) - r + hub_tol
    };
    let mut lifted = 0;
    let mut largest = 0.0f64;
    let out = locations
        .iter()
        .map(|cl| {
            if gap(cl, 0.0) >= 0.0 || gap(cl, r) < 0.0 {
                return *cl;
            }
            let (mut lo, mut hi) = (0.0, r);
            for _ in 0..HUB_LIFT_BISECTIONS {
                let mid = 0.5 * (lo + hi);
                if gap(cl, mid) >= 0.0 {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            lifted += 1;
            largest = largest.max(hi);
            cam_core::CutterLocation {
                tip: cl.tip + cl.axis.into_inner() * hi,
                axis: cl.axis,
            }
        })
        .collect();
    (out, lifted, largest)
}

/// The SLP runs of one blade side, computed in parallel before they are reported.
struct SideRuns {
    /// The side as built, before the job path's refinement added samples to it.
    fresh: FlankSide,
    /// The job tool's measured minimax path and the side with its refinement samples.
    job: Result<(FlankSide, MeasuredPath), FlankError>,
    /// The cutter-shape study (first side, `optimise_shape`).
    study: Option<Result<PathResult, FlankError>>,
    /// The best cylindrical ball end (first side, `compare_cylindrical`).
    cylinder: Option<Result<Option<MeasuredPath>, FlankError>>,
    /// The job tool from the second initial path (first side, `second_initial_path`).
    second: Option<Result<MeasuredPath, FlankError>>,
}

/// Refinement rounds (dense measurement, overcut points added as samples, re-optimisation)
/// before the operation gives up with [`FlankError::NotAccurate`].
const REFINE_ROUNDS: usize = 4;
/// Dense points outside by more than this fraction of the tolerance are added.
const REFINE_FRACTION: f64 = 0.5;
/// Hub tangency tolerance of a refinement run as a fraction of `hub_tangency_tol_mm`.
const REFINE_HUB_MARGIN: f64 = 0.95;
/// Trust radius of a refinement run as a fraction of `trust_radius_mm` (warm start).
const REFINE_TRUST_FRACTION: f64 = 0.1;
/// At most this many points (the worst) are added per round (LP rows stay below ~2000).
const REFINE_POINTS: usize = 300;

/// Approach distance above the first cutter location of a pass (mm).
const APPROACH_MM: f64 = 5.0;

fn ball_radius_of(r: &PathResult) -> f64 {
    r.x[0]
}

/// Whether `v` misses its tolerance `t` (beyond rounding: a relative 1e-9 and 1e-12 mm).
fn exceeds(v: f64, t: f64) -> bool {
    v > t * (1.0 + 1e-9) + 1e-12
}

/// `v` with four decimals, or as many more (up to nine) as it takes to read above `limit`:
/// a value a hair over its tolerance must not print as the tolerance itself ("0.0100 mm >
/// 0.01 mm").
fn digits_above(v: f64, limit: f64) -> String {
    (4..=9)
        .map(|d| format!("{v:.d$}"))
        .find(|s| s.parse::<f64>().is_ok_and(|x| x > limit))
        .unwrap_or_else(|| format!("{v:e}"))
}

/// Why a side may be beyond one flank pass: its largest distance from the ruled surface
/// between its hub and shroud edges ([`impeller_model::ruled::ruled_approximation`]), said
/// when it exceeds the overcut and undercut tolerances together (the band a pass's envelope
/// may lie in). A conical cutter's envelope is not a ruled surface, so this is a diagnosis,
/// not a proof. `None` when within that band or when the approximation cannot be built.
fn ruled_deviation_note(
    ctx: &PlanContext<'_>,
    row: Row,
    side: Side,
    pr: &ProblemSettings,
) -> Option<String> {
    let set = rows::blade_set(ctx.impeller, row).ok()?;
    let blade = set.blade();
    let v_range = crate::regions::side_v_range(ctx, blade, side).ok()?;
    let ruled = impeller_model::ruled::ruled_approximation(blade, side, v_range).ok()?;
    let band = pr.overcut_tol + pr.undercut_tol;
    (ruled.max_deviation_mm > band).then(|| {
        format!(
            "the {} blade's {side:?} side lies up to {:.4} mm from the ruled surface between \
             its hub and shroud edges, more than the {band} mm band the tolerances allow a \
             pass: a single flank pass is unlikely to follow it; ",
            rows::label(row),
            ruled.max_deviation_mm
        )
    })
}

#[cfg(test)]
mod tests {
    use super::digits_above;

    /// A value a hair above its tolerance prints above it; one well above keeps four decimals.
    #[test]
    fn a_miss_prints_above_its_tolerance() {
        assert_eq!(digits_above(0.010_003, 0.01), "0.010003");
        assert_eq!(digits_above(0.0227, 0.01), "0.0227");
        assert_eq!(digits_above(0.012_34, 0.01), "0.0123");
    }
}
