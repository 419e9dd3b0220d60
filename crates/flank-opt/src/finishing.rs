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
//!    clearance, shape fixed. This is the path written.
//! 4. Comparison: the largest catalogue cylindrical ball end whose initial path keeps the
//!    clearance, with its own minimax path; `stiffness_ratio_vs_cylindrical` is the job
//!    tool's stiffness over that cylinder's.
//!
//! Complexity per SLP iteration: (samples + adjacent samples) certified envelope distance
//! queries with gradients (a few µs each) and one sparse LP of `2 + 6n` variables plus one
//! slack per constraint row. Iteration counts are bounded by `max_slp_iterations`.

use crate::catalogue::Catalogue;
use crate::geometry::{ball_radius, guides_through, FlankSide, InitialPath};
use crate::problem::{deviations_max, Family, FlankProblem, HistoryRow, Mode, ProblemSettings};
use crate::slp::{self, SlpOptions, Termination};
use crate::{FlankError, FLANK_FINISHING};
use cam_core::{CutterShape, Move, ToolPath};
use cam_plan::{
    Metrics, Operation, OperationSpec, PlanContext, PlanError, PlannedOperation, Plot, PlotKind,
    PlotSeries,
};
use impeller_model::Side;
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
    24
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
    /// Accuracy samples along the blade (default 24).
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
    /// Initial trust radius (mm of control-point motion; default 0.5).
    #[serde(default = "default_trust")]
    pub trust_radius_mm: f64,
    /// `two_point` (default) or `mid_normal`.
    #[serde(default = "default_initial")]
    pub initial_path: InitialPath,
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
    /// Largest overcut (mm, >= 0).
    pub max_overcut_mm: f64,
    /// Largest undercut (mm, >= 0).
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
    /// Initial trust radius (mm).
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
    let x0 = prob.pack(r, theta);
    let n = x0.len();
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
    let (lo, hi) = env.domain();
    let m = run.output_locations;
    let locations = (0..m)
        .map(|i| env.cutter_location(lo + (hi - lo) * i as f64 / (m - 1) as f64))
        .collect::<Result<Vec<_>, _>>()?;
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

/// The largest cylindrical ball end of the catalogue whose initial path keeps the
/// clearance, and its minimax path. `None` when no catalogue radius fits.
pub fn best_cylinder(
    side: &FlankSide,
    catalogue: &Catalogue,
    how: InitialPath,
    run: &RunSettings,
) -> Result<Option<PathResult>, FlankError> {
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
            return optimise(side, shape, how, Mode::Minimax, run).map(Some);
        }
    }
    Ok(None)
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
        let sides: &[Side] = match p.sides {
            Sides::Both => &[Side::Pressure, Side::Suction],
            Sides::Pressure => &[Side::Pressure],
            Sides::Suction => &[Side::Suction],
        };
        let mut out = PlannedOperation::default();
        let mut metrics = Metrics::new();
        let mut over = 0.0f64;
        let mut under = 0.0f64;
        let mut clear = f64::INFINITY;
        let mut hub = 0.0f64;
        let mut iterations = 0;
        let mut termination = Termination::Converged;
        let mut stiffness = f64::NAN;
        let mut cylinder_k = f64::NAN;
        let mut initial_dev = 0.0f64;
        let mut final_dev = 0.0f64;
        let mut one_path = ToolPath::new(&self.name, &self.tool);
        let count = ctx.impeller.main().count();
        for (k, &side) in sides.iter().enumerate() {
            let fs = FlankSide::new(ctx.impeller, side, p.samples_along, p.samples_across)?;
            let mut runs: Vec<(String, Vec<HistoryRow>)> = Vec::new();
            if k == 0 && p.optimise_shape {
                let start = match cutter.shape {
                    CutterShape::TaperedBallEnd { .. } => cutter.shape,
                    other => CutterShape::TaperedBallEnd {
                        ball_radius: ball_radius(&other),
                        half_angle: 1f64.to_radians(),
                    },
                };
                let study = optimise(&fs, start, p.initial_path, Mode::Shape, &run)?;
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
            let res = optimise(&fs, cutter.shape, p.initial_path, Mode::Minimax, &run)?;
            iterations += res.iterations;
            termination = worse(termination, res.termination);
            over = over.max(res.max_overcut_mm);
            under = under.max(res.max_undercut_mm);
            clear = clear.min(res.min_clearance_mm);
            hub = hub.max(res.hub_error_mm);
            stiffness = res.stiffness_n_per_mm;
            initial_dev = initial_dev.max(res.initial_max_deviation_mm);
            final_dev = final_dev.max(deviations_max(&res.deviations));
            out.plots.push(deviation_map(
                &fs,
                &res.deviations,
                &format!("flank finishing: signed deviation over the {side:?} side (mm)"),
            ));
            runs.push(("job tool path (minimax)".into(), res.history.clone()));
            if k == 0 && p.compare_cylindrical {
                match best_cylinder(&fs, &catalogue, p.initial_path, &run)? {
                    Some(cyl) => {
                        cylinder_k = cyl.stiffness_n_per_mm;
                        metrics.number("cylinder_radius_mm", ball_radius_of(&cyl));
                        metrics.number("cylinder_stiffness_n_per_mm", cyl.stiffness_n_per_mm);
                        metrics
                            .number("cylinder_max_deviation_mm", deviations_max(&cyl.deviations));
                        metrics.number("cylinder_max_overcut_mm", cyl.max_overcut_mm);
                        metrics.number("cylinder_max_undercut_mm", cyl.max_undercut_mm);
                        metrics.text("cylinder_slp_termination", cyl.termination.as_str());
                        out.plots.push(deviation_map(
                            &fs,
                            &cyl.deviations,
                            &format!(
                                "flank finishing, best cylindrical ball end: signed deviation \
                                 over the {side:?} side (mm)"
                            ),
                        ));
                        runs.push(("cylindrical ball end path (minimax)".into(), cyl.history));
                    }
                    None => out
                        .notes
                        .push("no catalogue cylindrical ball end keeps the clearance".into()),
                }
            }
            let refs: Vec<(&str, &[HistoryRow])> = runs
                .iter()
                .map(|(l, h)| (l.as_str(), h.as_slice()))
                .collect();
            out.plots.extend(history_plots(&refs));
            // The side's pass, linked to the previous one.
            let moves: Vec<Move> = res.locations.iter().map(|cl| Move::feed(*cl)).collect();
            if let (Some(last), Some(first)) = (one_path.moves.last(), moves.first()) {
                let link = ctx
                    .link(&last.cl, &first.cl, APPROACH_MM)
                    .map_err(|e| FlankError::Geometry(e.to_string()))?;
                one_path.moves.extend(link);
            }
            one_path.moves.extend(moves);
        }
        ctx.close(&mut one_path, APPROACH_MM)
            .map_err(|e| FlankError::Geometry(e.to_string()))?;
        // The accuracy gate: a finishing pass that misses its tolerances is not emitted.
        let pr = &run.problem;
        let misses: Vec<String> = [
            ("overcut", over, pr.overcut_tol, "mm"),
            ("undercut", under, pr.undercut_tol, "mm"),
            ("hub tangency error", hub, pr.hub_tol, "mm"),
        ]
        .iter()
        .filter(|(_, v, t, _)| v.is_nan() || *v > t * (1.0 + 1e-9) + 1e-12)
        .map(|(what, v, t, u)| format!("{what} {v:.4} {u} > {t} {u}"))
        .chain((clear < pr.min_clearance - 1e-9).then(|| {
            format!(
                "clearance to the next blade {clear:.4} mm < {} mm",
                pr.min_clearance
            )
        }))
        .collect();
        if !misses.is_empty() {
            return Err(FlankError::NotAccurate(format!(
                "the optimised path misses its tolerances after {iterations} SLP iteration(s) \
                 ({}): {}; try more iterations (max_slp_iterations), a larger trust region \
                 (trust_radius_mm) or another initial path (initial_path)",
                termination.as_str(),
                misses.join(", ")
            )));
        }
        let order: Vec<usize> = (0..count).collect();
        out.paths = cam_plan::pattern::copy_to(&one_path, ctx.impeller.main().pitch_rad(), &order);
        metrics.number("max_overcut_mm", over);
        metrics.number("max_undercut_mm", under);
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

/// Approach distance above the first cutter location of a pass (mm).
const APPROACH_MM: f64 = 5.0;

fn ball_radius_of(r: &PathResult) -> f64 {
    r.x[0]
}
