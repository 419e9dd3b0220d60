//! Sequential linear programming with a box trust region and an ℓ1 (exact penalty) merit,
//! each subproblem an LP solved by clarabel (paper 002, "Optimization algorithm": the
//! constraints and the objective are linearised with their closed-form derivatives and the
//! step is bounded).
//!
//! The model at `x`: an objective `f(x)`, optionally plus `max_i |a_i(x)|` (minimax rows),
//! and constraints `g_j(x) >= 0`. Merit `φ(x) = f + max_i |a_i| + μ Σ_j max(0, −g_j)`. The
//! LP in the step `Δ`, the bound `t` of the minimax rows and one elastic slack `σ_j >= 0` per
//! constraint (so it is always feasible):
//!
//! `min ∇f·Δ + t + μ Σσ  s.t.  ±(a_i + ∇a_i·Δ) <= t,  g_j + ∇g_j·Δ + σ_j >= 0,
//!  |Δ_k| <= ρ·scale_k,  lo_k <= x_k + Δ_k <= hi_k`.
//!
//! The step is accepted only when the true merit decreases by at least `ACCEPT_RATIO` of the
//! predicted decrease (so an iterate that raises the merit is never accepted); the trust
//! radius doubles after a very good step, up to its initial value, and halves after a
//! rejected one. A step that fails the test while raising the constraint violation gets a
//! second-order correction first: one more LP, linearised at the trial point, from there,
//! and the corrected point is judged by the same test against the first step's predicted
//! decrease (it counts as an LP solve of the iteration limit). Without it the curvature of
//! the constraints (e.g. the hub-tangency band of width 2ε, met at its edge by the LP) turns
//! a good step into a merit rise through the penalty, and the radius shrinks until that
//! curvature no longer shows (the Maratos effect: the minimax from impeller-30-narrow's
//! mid-normal start crept at ~8 µm steps, issue 13). Termination, with
//! its reason: predicted decrease below `tol` or trust radius below `min_radius`
//! (converged; `infeasible` instead when the constraints are still violated by more than
//! `feas_tol`), or the iteration limit.
//!
//! Cost per iteration: one model evaluation with derivatives, one LP (interior point, sparse
//! KKT of size O(variables + rows)) and one merit evaluation per trial, twice with a
//! correction.

use crate::FlankError;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT, SolverStatus,
};

/// A step is accepted when the actual merit decrease is at least this fraction of the
/// predicted one (classic trust-region value; > 0 so the merit never rises).
const ACCEPT_RATIO: f64 = 0.1;
/// Above this ratio the trust radius grows.
const GROW_RATIO: f64 = 0.75;

/// One linearised function: value and sparse gradient `(variable, ∂/∂x)`.
#[derive(Debug, Clone, Default)]
pub struct Row {
    /// Value at the current point.
    pub value: f64,
    /// Sparse gradient.
    pub grad: Vec<(usize, f64)>,
}

/// The model evaluated at one point.
#[derive(Debug, Clone, Default)]
pub struct Evaluation {
    /// Smooth objective `f` and its gradient.
    pub objective: Row,
    /// Minimax rows `a_i` (the merit adds `max |a_i|`); empty for none.
    pub minimax: Vec<Row>,
    /// Constraints `g_j >= 0`.
    pub constraints: Vec<Row>,
    /// Model-specific figures carried with the evaluation for its history (not used by the
    /// solver).
    pub info: Vec<f64>,
}

impl Evaluation {
    /// `f + max|a_i|` (no penalty).
    pub fn objective_value(&self) -> f64 {
        self.objective.value
            + self
                .minimax
                .iter()
                .map(|r| r.value.abs())
                .fold(0.0, f64::max)
    }
    /// `Σ max(0, −g_j)`.
    pub fn violation(&self) -> f64 {
        self.constraints.iter().map(|r| (-r.value).max(0.0)).sum()
    }
    /// Largest single violation `max(0, −g_j)`.
    pub fn max_violation(&self) -> f64 {
        self.constraints
            .iter()
            .map(|r| (-r.value).max(0.0))
            .fold(0.0, f64::max)
    }
}

/// A problem SLP can solve.
pub trait Model {
    /// Number of variables.
    fn dimension(&self) -> usize;
    /// Values (and, with `gradients`, the sparse gradients) at `x`.
    fn evaluate(&mut self, x: &[f64], gradients: bool) -> Result<Evaluation, FlankError>;
    /// Called after every accepted or rejected iteration (history, plots).
    fn record(&mut self, _iteration: usize, _x: &[f64], _eval: &Evaluation, _radius: f64) {}
}

/// Settings of [`solve`].
#[derive(Debug, Clone)]
pub struct SlpOptions {
    /// Iteration limit (LP solves).
    pub max_iterations: usize,
    /// Initial and largest trust radius (in units of `scale`).
    pub radius: f64,
    /// Converged when the radius falls below this.
    pub min_radius: f64,
    /// Converged when the predicted merit decrease is below this.
    pub tol: f64,
    /// Penalty weight μ of constraint violations in the merit.
    pub penalty: f64,
    /// Constraint violation (largest single one) above which the end is `infeasible`.
    pub feas_tol: f64,
    /// Per-variable trust scale (0 fixes the variable).
    pub scale: Vec<f64>,
    /// Per-variable bounds.
    pub lower: Vec<f64>,
    /// Per-variable bounds.
    pub upper: Vec<f64>,
}

/// Why the SLP stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Termination {
    /// No useful step left (small predicted decrease or trust radius) and feasible.
    Converged,
    /// The iteration limit was reached.
    IterationLimit,
    /// Stopped with a constraint still violated beyond `feas_tol`.
    Infeasible,
}

impl Termination {
    /// The metric text (`slp_termination`).
    pub fn as_str(self) -> &'static str {
        match self {
            Termination::Converged => "converged",
            Termination::IterationLimit => "iteration_limit",
            Termination::Infeasible => "infeasible",
        }
    }
}

/// Result of [`solve`].
#[derive(Debug, Clone)]
pub struct SlpResult {
    /// Final (best accepted) point.
    pub x: Vec<f64>,
    /// Its evaluation.
    pub eval: Evaluation,
    /// LP iterations done.
    pub iterations: usize,
    /// Merit after each iteration (accepted point), starting with the initial merit.
    pub merit_history: Vec<f64>,
    /// Why it stopped.
    pub termination: Termination,
}

fn merit(e: &Evaluation, mu: f64) -> f64 {
    e.objective_value() + mu * e.violation()
}

/// Runs SLP from `x0` (module docs).
pub fn solve<M: Model>(
    model: &mut M,
    x0: Vec<f64>,
    opts: &SlpOptions,
) -> Result<SlpResult, FlankError> {
    let n = model.dimension();
    if x0.len() != n || opts.scale.len() != n || opts.lower.len() != n || opts.upper.len() != n {
        return Err(FlankError::Param(
            "SLP vectors must match the dimension".into(),
        ));
    }
    let mut x = x0;
    let mut eval = model.evaluate(&x, true)?;
    let mut phi = merit(&eval, opts.penalty);
    let mut radius = opts.radius;
    let mut history = vec![phi];
    model.record(0, &x, &eval, radius);
    let mut termination = Termination::IterationLimit;
    let mut iterations = 0;
    while iterations < opts.max_iterations {
        iterations += 1;
        let (step, predicted) = lp_step(&eval, &x, radius, opts)?;
        let pred_red = phi - predicted;
        if pred_red <= opts.tol {
            termination = Termination::Converged;
            model.record(iterations, &x, &eval, radius);
            break;
        }
        let trial = take_step(&x, &step, opts);
        let trial_eval = model.evaluate(&trial, true)?;
        let trial_phi = merit(&trial_eval, opts.penalty);
        let mut ratio = (phi - trial_phi) / pred_red;
        let mut cand = (trial, trial_eval, trial_phi);
        if !(ratio >= ACCEPT_RATIO && cand.2 < phi)
            && cand.1.violation() > eval.violation()
            && iterations < opts.max_iterations
        {
            // Second-order correction (module docs): one more LP from the trial point,
            // linearised there; the corrected point is judged against the first step's
            // predicted decrease, so the merit still never rises.
            iterations += 1;
            let (corr, _) = lp_step(&cand.1, &cand.0, radius, opts)?;
            let x2 = take_step(&cand.0, &corr, opts);
            let e2 = model.evaluate(&x2, true)?;
            let phi2 = merit(&e2, opts.penalty);
            let r2 = (phi - phi2) / pred_red;
            if r2 > ratio {
                ratio = r2;
                cand = (x2, e2, phi2);
            }
        }
        if ratio >= ACCEPT_RATIO && cand.2 < phi {
            (x, eval, phi) = cand;
            if ratio >= GROW_RATIO {
                radius = (2.0 * radius).min(opts.radius);
            }
        } else {
            radius *= 0.5;
        }
        history.push(phi);
        model.record(iterations, &x, &eval, radius);
        if radius < opts.min_radius {
            termination = Termination::Converged;
            break;
        }
    }
    if termination == Termination::Converged && eval.max_violation() > opts.feas_tol {
        termination = Termination::Infeasible;
    }
    Ok(SlpResult {
        x,
        eval,
        iterations,
        merit_history: history,
        termination,
    })
}

/// `x + step` kept exactly inside the variable bounds, with the variables of zero trust
/// scale left where they are. The LP meets its bounds only to the interior-point tolerance
/// (about 1e-10): without this projection a variable at its bound (a half angle of 0, say)
/// could step to −1e-10 and leave the model's domain.
fn take_step(x: &[f64], step: &[f64], opts: &SlpOptions) -> Vec<f64> {
    x.iter()
        .zip(step)
        .enumerate()
        .map(|(k, (a, d))| {
            if opts.scale[k] == 0.0 {
                *a
            } else {
                (a + d).max(opts.lower[k]).min(opts.upper[k])
            }
        })
        .collect()
}

/// Sparse matrix assembly by columns (CSC) from (row, col, value) triplets.
fn csc(m: usize, n: usize, mut trip: Vec<(usize, usize, f64)>) -> CscMatrix<f64> {
    trip.sort_by_key(|t| (t.1, t.0));
    let mut colptr = vec![0usize; n + 1];
    let mut rowval = Vec::with_capacity(trip.len());
    let mut nzval = Vec::with_capacity(trip.len());
    let mut last: Option<(usize, usize)> = None;
    for (r, c, v) in trip {
        if last == Some((r, c)) {
            if let Some(z) = nzval.last_mut() {
                *z += v;
            }
            continue;
        }
        last = Some((r, c));
        colptr[c + 1] += 1;
        rowval.push(r);
        nzval.push(v);
    }
    for c in 0..n {
        colptr[c + 1] += colptr[c];
    }
    CscMatrix::new(m, n, colptr, rowval, nzval)
}

/// Solves the LP of the module docs: returns the step and the model merit at it. The LP is
/// solved by the specialised interior-point method of [`crate::lp`]; should it fail, by
/// clarabel.
fn lp_step(
    e: &Evaluation,
    x: &[f64],
    radius: f64,
    opts: &SlpOptions,
) -> Result<(Vec<f64>, f64), FlankError> {
    let step = match lp_step_ipm(e, x, radius, opts) {
        Ok(step) => step,
        Err(_) => lp_step_clarabel(e, x, radius, opts)?,
    };
    let mut predicted = e.objective.value;
    for &(k, g) in &e.objective.grad {
        predicted += g * step[k];
    }
    // Model merit from the step itself (not the LP's t and σ, which may be loose).
    let lin = |r: &Row| r.value + r.grad.iter().map(|&(k, g)| g * step[k]).sum::<f64>();
    predicted += e.minimax.iter().map(|r| lin(r).abs()).fold(0.0, f64::max);
    predicted += opts.penalty
        * e.constraints
            .iter()
            .map(|r| (-lin(r)).max(0.0))
            .sum::<f64>();
    Ok((step, predicted))
}

/// Step bounds of variable `k`: the trust box intersected with the variable bounds, always
/// containing 0.
fn step_bounds(x: &[f64], k: usize, radius: f64, opts: &SlpOptions) -> (f64, f64) {
    let tr = radius * opts.scale[k];
    let hi = tr.min(opts.upper[k] - x[k]).max(0.0);
    let lo = (-tr).max(opts.lower[k] - x[k]).min(0.0);
    (lo, hi)
}

/// The LP by [`crate::lp`]: variables of an empty step range (zero trust scale, or both
/// bounds at the point) are left out; the minimax bound `t` is a free variable.
fn lp_step_ipm(
    e: &Evaluation,
    x: &[f64],
    radius: f64,
    opts: &SlpOptions,
) -> Result<Vec<f64>, crate::lp::LpFailure> {
    use crate::lp::{ElasticLp, SparseRows};
    let n = x.len();
    let mut map = vec![usize::MAX; n];
    let mut lower = Vec::with_capacity(n + 1);
    let mut upper = Vec::with_capacity(n + 1);
    for (k, slot) in map.iter_mut().enumerate() {
        let (lo, hi) = step_bounds(x, k, radius, opts);
        if hi > lo {
            *slot = lower.len();
            lower.push(lo);
            upper.push(hi);
        }
    }
    let has_t = !e.minimax.is_empty();
    let it = lower.len();
    if has_t {
        lower.push(f64::NEG_INFINITY);
        upper.push(f64::INFINITY);
    }
    let p = lower.len();
    let mut cost = vec![0.0; p];
    for &(k, g) in &e.objective.grad {
        if map[k] != usize::MAX {
            cost[map[k]] += g;
        }
    }
    if has_t {
        cost[it] = 1.0;
    }
    let map_ref = &map;
    let free = |grad: &[(usize, f64)], sign: f64| {
        grad.iter()
            .filter(|(k, _)| map_ref[*k] != usize::MAX)
            .map(|&(k, g)| (map_ref[k], sign * g))
            .collect::<Vec<_>>()
    };
    let mut rows = SparseRows::new();
    let mut rhs = Vec::with_capacity(2 * e.minimax.len());
    for r in &e.minimax {
        // ±(a + ∇a·Δ) − t <= 0
        for sign in [1.0, -1.0] {
            let mut entries = free(&r.grad, sign);
            entries.push((it, -1.0));
            rows.push(entries);
            rhs.push(-sign * r.value);
        }
    }
    let mut elastic = SparseRows::new();
    let mut elastic_rhs = Vec::with_capacity(e.constraints.len());
    for r in &e.constraints {
        // g + ∇g·Δ + σ >= 0  ⇔  −∇g·Δ − σ <= g
        elastic.push(free(&r.grad, -1.0));
        elastic_rhs.push(r.value);
    }
    let sol = crate::lp::solve(&ElasticLp {
        cost,
        lower,
        upper,
        rows,
        rhs,
        elastic,
        elastic_rhs,
        penalty: opts.penalty,
    })?;
    Ok((0..n)
        .map(|k| {
            if map[k] == usize::MAX {
                0.0
            } else {
                // The interior point meets its bounds only to its tolerance.
                let (lo, hi) = step_bounds(x, k, radius, opts);
                sol.y[map[k]].max(lo).min(hi)
            }
        })
        .collect())
}

/// The LP by clarabel (the fallback of [`lp_step`]): the step.
fn lp_step_clarabel(
    e: &Evaluation,
    x: &[f64],
    radius: f64,
    opts: &SlpOptions,
) -> Result<Vec<f64>, FlankError> {
    let n = x.len();
    let has_t = !e.minimax.is_empty();
    let it = n; // index of t
    let s0 = n + usize::from(has_t); // first slack
    let m_c = e.constraints.len();
    let nv = s0 + m_c;
    let mut q = vec![0.0; nv];
    for &(k, g) in &e.objective.grad {
        q[k] += g;
    }
    if has_t {
        q[it] = 1.0;
    }
    for qs in &mut q[s0..] {
        *qs = opts.penalty;
    }
    // Rows A z <= b (nonnegative cone on b − A z).
    let mut trip = Vec::new();
    let mut b = Vec::new();
    let mut row = 0;
    for r in &e.minimax {
        // a + ∇a·Δ − t <= 0  and  −a − ∇a·Δ − t <= 0
        for sign in [1.0, -1.0] {
            for &(k, g) in &r.grad {
                trip.push((row, k, sign * g));
            }
            trip.push((row, it, -1.0));
            b.push(-sign * r.value);
            row += 1;
        }
    }
    for (j, r) in e.constraints.iter().enumerate() {
        // −∇g·Δ − σ <= g
        for &(k, g) in &r.grad {
            trip.push((row, k, -g));
        }
        trip.push((row, s0 + j, -1.0));
        b.push(r.value);
        row += 1;
        trip.push((row, s0 + j, -1.0));
        b.push(0.0);
        row += 1;
    }
    #[allow(clippy::needless_range_loop)] // four parallel per-variable vectors
    for k in 0..n {
        let (lo, hi) = step_bounds(x, k, radius, opts);
        trip.push((row, k, 1.0));
        b.push(hi);
        row += 1;
        trip.push((row, k, -1.0));
        b.push(-lo);
        row += 1;
    }
    let a = csc(row, nv, trip);
    let p = CscMatrix::zeros((nv, nv));
    let cones = [NonnegativeConeT(row)];
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .build()
        .map_err(|e| FlankError::Solver(format!("settings: {e:?}")))?;
    let mut solver = DefaultSolver::new(&p, &q, &a, &b, &cones, settings)
        .map_err(|e| FlankError::Solver(format!("{e:?}")))?;
    solver.solve();
    match solver.solution.status {
        SolverStatus::Solved | SolverStatus::AlmostSolved => {}
        other => return Err(FlankError::Solver(format!("LP status {other:?}"))),
    }
    Ok(solver.solution.x[..n].to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Maximise x + y on the unit disc (linearised as half-planes): optimum (1/√2, 1/√2).
    struct Disc;
    impl Model for Disc {
        fn dimension(&self) -> usize {
            2
        }
        fn evaluate(&mut self, x: &[f64], _: bool) -> Result<Evaluation, FlankError> {
            Ok(Evaluation {
                objective: Row {
                    value: -(x[0] + x[1]),
                    grad: vec![(0, -1.0), (1, -1.0)],
                },
                minimax: Vec::new(),
                constraints: vec![Row {
                    value: 1.0 - x[0] * x[0] - x[1] * x[1],
                    grad: vec![(0, -2.0 * x[0]), (1, -2.0 * x[1])],
                }],
                info: Vec::new(),
            })
        }
    }

    /// Options of the two-variable tests: trust radius 0.5, penalty 10, box ±10.
    fn plane_options(max_iterations: usize, tol: f64) -> SlpOptions {
        SlpOptions {
            max_iterations,
            radius: 0.5,
            min_radius: 1e-9,
            tol,
            penalty: 10.0,
            feas_tol: 1e-6,
            scale: vec![1.0; 2],
            lower: vec![-10.0; 2],
            upper: vec![10.0; 2],
        }
    }

    #[test]
    fn converges_on_a_disc_with_monotone_merit() {
        // The LPs are solved to a relative 1e-8: a tolerance on the predicted decrease far
        // below that asks SLP to resolve decreases finer than its LPs; 1e-10 is met after
        // 53 LP solves (the steps zig-zag along the curved constraint).
        let opts = plane_options(60, 1e-10);
        let r = solve(&mut Disc, vec![0.1, -0.3], &opts).unwrap();
        assert_eq!(r.termination, Termination::Converged);
        let h = std::f64::consts::FRAC_1_SQRT_2;
        assert!(
            (r.x[0] - h).abs() < 1e-4 && (r.x[1] - h).abs() < 1e-4,
            "{:?}",
            r.x
        );
        assert!(r.merit_history.windows(2).all(|w| w[1] <= w[0]));
    }

    /// Minimise x on the band 1 − ε <= x² + y² <= 1 + ε (ε = 1e-4), from (0.6, 0.8): the way
    /// to (−1, 0) follows the curved band, which a full step along its tangent leaves by
    /// ρ²/2 ≫ ε (the Maratos effect). Measured with 30 LP solves: x = −1.0001 with the
    /// second-order correction, −0.770 without it (the radius shrinks to ~√(2ε)).
    struct Band;
    impl Model for Band {
        fn dimension(&self) -> usize {
            2
        }
        fn evaluate(&mut self, x: &[f64], _: bool) -> Result<Evaluation, FlankError> {
            let q = x[0] * x[0] + x[1] * x[1];
            let g = vec![(0, 2.0 * x[0]), (1, 2.0 * x[1])];
            Ok(Evaluation {
                objective: Row {
                    value: x[0],
                    grad: vec![(0, 1.0)],
                },
                minimax: Vec::new(),
                constraints: vec![
                    Row {
                        value: q - (1.0 - 1e-4),
                        grad: g.clone(),
                    },
                    Row {
                        value: 1.0 + 1e-4 - q,
                        grad: g.into_iter().map(|(k, v)| (k, -v)).collect(),
                    },
                ],
                info: Vec::new(),
            })
        }
    }

    #[test]
    fn a_curved_constraint_band_does_not_stall_the_steps() {
        let opts = plane_options(30, 1e-10);
        let r = solve(&mut Band, vec![0.6, 0.8], &opts).unwrap();
        assert!(r.x[0] < -0.99 && r.x[1].abs() < 0.1, "{:?}", r.x);
        assert!(r.eval.max_violation() < 1e-2, "{}", r.eval.max_violation());
        assert!(r.merit_history.windows(2).all(|w| w[1] <= w[0]));
    }

    /// Infeasible constraints (x >= 1 and x <= −1): the end says so.
    struct Clash;
    impl Model for Clash {
        fn dimension(&self) -> usize {
            1
        }
        fn evaluate(&mut self, x: &[f64], _: bool) -> Result<Evaluation, FlankError> {
            Ok(Evaluation {
                objective: Row::default(),
                minimax: Vec::new(),
                constraints: vec![
                    Row {
                        value: x[0] - 1.0,
                        grad: vec![(0, 1.0)],
                    },
                    Row {
                        value: -1.0 - x[0],
                        grad: vec![(0, -1.0)],
                    },
                ],
                info: Vec::new(),
            })
        }
    }

    #[test]
    fn infeasible_problems_say_so() {
        let opts = SlpOptions {
            max_iterations: 30,
            radius: 1.0,
            min_radius: 1e-8,
            tol: 1e-10,
            penalty: 1.0,
            feas_tol: 1e-6,
            scale: vec![1.0],
            lower: vec![-5.0],
            upper: vec![5.0],
        };
        let r = solve(&mut Clash, vec![3.0], &opts).unwrap();
        assert_eq!(r.termination, Termination::Infeasible);
        assert!(r.merit_history.windows(2).all(|w| w[1] <= w[0]));
    }

    /// Minimise `x0 + (x1 − 0.3)²` over `x0 >= 0` (the bound) with `x2` fixed (trust scale
    /// 0): the optimum sits on the bound, where the LP lands only within its tolerance. The
    /// model refuses to evaluate outside its domain, as a cutter model refuses a negative
    /// half angle (issue found on an imported 12+12 impeller: θ = −1.1e-10).
    struct OnBound;
    impl Model for OnBound {
        fn dimension(&self) -> usize {
            3
        }
        fn evaluate(&mut self, x: &[f64], _: bool) -> Result<Evaluation, FlankError> {
            if x[0] < 0.0 || x[2] != 0.25 {
                return Err(FlankError::Param(format!("outside the domain: {x:?}")));
            }
            Ok(Evaluation {
                objective: Row {
                    value: x[0] + (x[1] - 0.3) * (x[1] - 0.3),
                    grad: vec![(0, 1.0), (1, 2.0 * (x[1] - 0.3)), (2, 1.0)],
                },
                minimax: Vec::new(),
                constraints: Vec::new(),
                info: Vec::new(),
            })
        }
    }

    #[test]
    fn steps_stay_inside_the_bounds_and_keep_fixed_variables() {
        let opts = SlpOptions {
            max_iterations: 40,
            radius: 0.5,
            min_radius: 1e-12,
            tol: 1e-14,
            penalty: 10.0,
            feas_tol: 1e-6,
            scale: vec![1.0, 1.0, 0.0],
            lower: vec![0.0, -1.0, -1.0],
            upper: vec![1.0, 1.0, 1.0],
        };
        // Every start walks onto the bound x0 = 0; none may step past it.
        for start in [0.7, 0.31, 0.05, 1e-9] {
            let r = solve(&mut OnBound, vec![start, -0.4, 0.25], &opts).unwrap();
            assert!(r.x[0] >= 0.0 && r.x[0] < 1e-9, "{start}: {:?}", r.x);
            assert_eq!(r.x[2], 0.25, "{start}: the fixed variable moved");
            assert!((r.x[1] - 0.3).abs() < 1e-3, "{start}: {:?}", r.x);
        }
    }
}
