//! The flank-milling optimisation model (paper 002, "Optimization model"): variables, the
//! three constraints written with the signed distance to the swept envelope, the stiffness
//! objective, all with closed-form first derivatives.
//!
//! Variables `x = [r, θ, Q0₀ … Q0ₙ₋₁, Q1₀ … Q1ₙ₋₁]` (ball radius, half angle in radians, the
//! control points of the ball-centre guide `P0` and of the upper guide `P1`). With the
//! envelope's guide height equal to `r` (`P0` is the ball centre), `d_i(x)` is the signed
//! distance of design sample `i` to the envelope:
//!
//! 1. accuracy: `d_i + overcut_tol >= 0`, `undercut_tol − d_i >= 0` (shape optimisation) or
//!    the minimax rows `d_i` (path optimisation) for the samples at least
//!    `min_sample_height` above the hub; for the samples of the fillet band below it (still
//!    above the hub) only the overcut row `d_i + overcut_tol >= 0` in both modes: the ball
//!    end leaves the fillet there (undercut is expected), but it must not cut into the blade
//!    (issue 13);
//! 2. hub tangency at each cutter location `s_j`: `ε ± (h(P0(s_j)) − r) >= 0` with `h` the
//!    signed distance from the hub body ([`FlankSide::hub_body_distance`], continuous beyond
//!    the ends of the hub contour);
//! 3. clearance: `d(q_k) − c_min >= 0` for the adjacent-blade samples `q_k` within
//!    `CLEARANCE_BAND_MM` of the bound (the others cannot become active inside a trust region).
//!
//! Derivatives: `∂d/∂Q` and `∂d/∂r|_{h_g}`, `∂d/∂θ` from [`cam_core::SweptEnvelope::gradient`]
//! (envelope theorem); since the guide height is `r` too, `∂d/∂r = ∂d/∂r|_{h_g} + G_v·a`
//! (`∂F/∂h_g = −∂F/∂c`). Stiffness `k(r, θ)` and its gradient from
//! [`cutter_stiffness::ConicalCutter`] (same parameters, radians). The hub distance gradient
//! is the hub's unit normal, taken by central differences of the exact closed-form hub
//! distance (step `HUB_FD_STEP_MM`).

use crate::geometry::FlankSide;
use crate::slp::{Evaluation, Model, Row};
use crate::FlankError;
use cam_core::{
    CutterShape, EnvelopeOptions, EnvelopeParam, GuideCurve, Point3, SphereFamily, SweptEnvelope,
    Vector3,
};
use cutter_stiffness::{ConicalCutter, RitzOptions};
use rayon::prelude::*;

/// Adjacent-blade samples farther than this beyond the clearance bound are left out of the
/// LP (the trust region moves the cutter far less in one step).
pub const CLEARANCE_BAND_MM: f64 = 2.0;
/// Central-difference step of the hub-distance gradient: the hub is a smooth surface of
/// revolution of radius ≥ tens of mm, so the truncation error is ~1e-9.
pub const HUB_FD_STEP_MM: f64 = 1e-4;

/// What the model optimises.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Mode {
    /// Maximise stiffness over shape and path under accuracy, hub and clearance constraints.
    Shape,
    /// Minimise the largest |deviation| over the path (shape fixed) under hub and clearance.
    Minimax,
}

/// The cutter family optimised.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Family {
    /// Tapered ball end (r, θ).
    TaperedBall,
    /// Cylindrical ball end (r; θ ≡ 0).
    Ball,
}

/// One row of the convergence history.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HistoryRow {
    /// SLP iteration (0 = start).
    pub iteration: usize,
    /// Largest |deviation| over the design samples (mm).
    pub max_deviation_mm: f64,
    /// Ball radius (mm).
    pub ball_radius_mm: f64,
    /// Half angle (rad).
    pub half_angle: f64,
    /// Smallest signed distance of the adjacent blade's samples to the envelope (mm).
    pub min_clearance_mm: f64,
    /// Stiffness (N/mm).
    pub stiffness_n_per_mm: f64,
    /// Trust radius.
    pub trust_radius: f64,
}

/// Settings of the model.
#[derive(Debug, Clone, Copy)]
pub struct ProblemSettings {
    /// Allowed overcut (mm).
    pub overcut_tol: f64,
    /// Allowed undercut (mm).
    pub undercut_tol: f64,
    /// Hub tangency tolerance ε (mm).
    pub hub_tol: f64,
    /// Smallest clearance to the adjacent blade (mm).
    pub min_clearance: f64,
    /// Flute length of the cutter (mm).
    pub flute_length: f64,
    /// Tip-to-chuck length of the stiffness model (mm).
    pub stick_out: f64,
    /// Young's modulus (N/mm²).
    pub youngs: f64,
    /// Design samples lower than this above the hub are not accuracy samples (the ball end
    /// and the fillet meet there).
    pub min_sample_height: f64,
}

/// The model: a blade side, the guide-curve template, the CL parameters and the settings.
#[derive(Debug)]
pub struct FlankProblem<'a> {
    side: &'a FlankSide,
    g0: GuideCurve,
    g1: GuideCurve,
    cl_params: Vec<f64>,
    samples: Vec<usize>,
    /// Samples of the fillet band (above the hub, below `min_sample_height`): overcut rows.
    band: Vec<usize>,
    family: Family,
    mode: Mode,
    settings: ProblemSettings,
    hints: Vec<Option<EnvelopeParam>>,
    /// Convergence history (one row per recorded iteration).
    pub history: Vec<HistoryRow>,
    /// Signed deviation of every design sample (NaN where not an accuracy sample) at the last
    /// evaluation.
    pub deviations: Vec<f64>,
    last_clearance: f64,
    /// Stiffness of the first evaluated shape: the objective is `−k/k_ref` (order 1).
    k_ref: Option<f64>,
}

impl<'a> FlankProblem<'a> {
    /// A model over `side` with the initial guides `g0` (ball centres) and `g1`.
    pub fn new(
        side: &'a FlankSide,
        g0: GuideCurve,
        g1: GuideCurve,
        family: Family,
        mode: Mode,
        settings: ProblemSettings,
    ) -> Self {
        let n = g0.control_points().len();
        let (lo, hi) = g0.domain();
        let cl_params = (0..n)
            .map(|i| lo + (hi - lo) * i as f64 / (n - 1).max(1) as f64)
            .collect();
        let height = |i: usize| side.hub_distance(&side.samples[i].coords);
        let samples = (0..side.samples.len())
            .filter(|&i| height(i) >= settings.min_sample_height)
            .collect();
        let band = (0..side.samples.len())
            .filter(|&i| (0.0..settings.min_sample_height).contains(&height(i)))
            .collect();
        Self {
            side,
            g0,
            g1,
            cl_params,
            samples,
            band,
            family,
            mode,
            settings,
            hints: vec![None; side.samples.len() + side.adjacent.len()],
            history: Vec::new(),
            deviations: Vec::new(),
            last_clearance: f64::NAN,
            k_ref: None,
        }
    }

    /// Number of control points per guide.
    pub fn n_ctrl(&self) -> usize {
        self.g0.control_points().len()
    }

    /// The variable vector of a shape and the current guides.
    pub fn pack(&self, r: f64, theta: f64) -> Vec<f64> {
        let mut x = vec![r, theta];
        for g in [&self.g0, &self.g1] {
            for q in g.control_points() {
                x.extend([q.x, q.y, q.z]);
            }
        }
        x
    }

    /// Shape and guides of `x`.
    pub fn unpack(&self, x: &[f64]) -> (CutterShape, GuideCurve, GuideCurve) {
        let n = self.n_ctrl();
        let mut g0 = self.g0.clone();
        let mut g1 = self.g1.clone();
        for (g, off) in [(&mut g0, 2), (&mut g1, 2 + 3 * n)] {
            for (k, q) in g.control_points_mut().iter_mut().enumerate() {
                let b = off + 3 * k;
                *q = Vector3::new(x[b], x[b + 1], x[b + 2]);
            }
        }
        (self.shape(x), g0, g1)
    }

    fn shape(&self, x: &[f64]) -> CutterShape {
        match self.family {
            Family::TaperedBall => CutterShape::TaperedBallEnd {
                ball_radius: x[0],
                half_angle: x[1],
            },
            Family::Ball => CutterShape::BallEnd { radius: x[0] },
        }
    }

    /// The envelope of `x`.
    pub fn envelope(&self, x: &[f64]) -> Result<SweptEnvelope, FlankError> {
        let (shape, g0, g1) = self.unpack(x);
        let fam = SphereFamily::from_shape(&shape, self.settings.flute_length)?;
        Ok(SweptEnvelope::new(
            fam,
            g0,
            g1,
            x[0],
            EnvelopeOptions::default(),
        )?)
    }

    /// Stiffness and its gradient `(∂k/∂r, ∂k/∂θ)` of the shape of `x`.
    pub fn stiffness(&self, x: &[f64]) -> Result<(f64, [f64; 2]), FlankError> {
        let theta = match self.family {
            Family::TaperedBall => x[1],
            Family::Ball => 0.0,
        };
        let c = ConicalCutter::new(x[0], theta, self.settings.stick_out, self.settings.youngs)
            .map_err(|e| FlankError::Param(format!("stiffness model: {e}")))?;
        let rep = c
            .report(&RitzOptions::default())
            .map_err(|e| FlankError::Param(format!("stiffness model: {e}")))?;
        Ok((
            rep.stiffness_n_per_mm,
            [rep.d_stiffness_d_ball_radius, rep.d_stiffness_d_half_angle],
        ))
    }

    /// Distance row of point `p` (sample index `hint_slot` for the warm start).
    fn distance_row(
        &mut self,
        env: &SweptEnvelope,
        p: &Point3,
        hint_slot: usize,
        gradients: bool,
    ) -> Result<Row, FlankError> {
        let (row, param) = self.row_from(env, p, self.hints[hint_slot], gradients)?;
        self.hints[hint_slot] = Some(param);
        Ok(row)
    }

    /// Distance rows of the samples `slots` (each warm-started from its own hint), computed
    /// in parallel; their hints are updated and the rows returned in the order of `slots`,
    /// exactly as [`Self::distance_row`] one after another would give them.
    fn distance_rows(
        &mut self,
        env: &SweptEnvelope,
        slots: &[usize],
        gradients: bool,
    ) -> Result<Vec<Row>, FlankError> {
        let this = &*self;
        let found: Vec<Result<(Row, EnvelopeParam), FlankError>> = slots
            .par_iter()
            .map(|&i| this.row_from(env, &this.side.samples[i], this.hints[i], gradients))
            .collect();
        let mut rows = Vec::with_capacity(slots.len());
        for (&i, r) in slots.iter().zip(found) {
            let (row, param) = r?;
            self.hints[i] = Some(param);
            rows.push(row);
        }
        Ok(rows)
    }

    /// The distance row of `p` from the warm start `hint`, and the parameter found.
    fn row_from(
        &self,
        env: &SweptEnvelope,
        p: &Point3,
        hint: Option<EnvelopeParam>,
        gradients: bool,
    ) -> Result<(Row, EnvelopeParam), FlankError> {
        let d = env.signed_distance(p, hint)?;
        let mut row = Row {
            value: d.distance,
            grad: Vec::new(),
        };
        if gradients {
            let g = env.gradient(p, &d)?;
            let axis = env.cutter_location(d.param.s)?.axis;
            row.grad.push((0, g.shape[0] + g.point.dot(&axis)));
            if self.family == Family::TaperedBall {
                row.grad.push((1, g.shape[1]));
            }
            let n = self.n_ctrl();
            for (cg, off) in [(&g.guide0, 2), (&g.guide1, 2 + 3 * n)] {
                for i in 0..cg.count {
                    let v = cg.get(cg.first + i);
                    let b = off + 3 * (cg.first + i);
                    row.grad.extend([(b, v.x), (b + 1, v.y), (b + 2, v.z)]);
                }
            }
        }
        Ok((row, d.param))
    }

    /// The hub rows of location `j`: value `h − r` and its gradient.
    fn hub_gap(&self, g0: &GuideCurve, j: usize, r: f64) -> Row {
        let s = self.cl_params[j];
        let e = g0.eval2(s);
        let c = e.d[0];
        let h = HUB_FD_STEP_MM;
        let mut grad_c = Vector3::zeros();
        for k in 0..3 {
            let mut dp = Vector3::zeros();
            dp[k] = h;
            grad_c[k] = (self.side.hub_body_distance(&(c + dp))
                - self.side.hub_body_distance(&(c - dp)))
                / (2.0 * h);
        }
        let mut grad = vec![(0, -1.0)];
        for i in 0..e.count {
            let b = 2 + 3 * (e.first + i);
            let w = e.basis[i];
            grad.extend([
                (b, w * grad_c.x),
                (b + 1, w * grad_c.y),
                (b + 2, w * grad_c.z),
            ]);
        }
        Row {
            value: self.side.hub_body_distance(&c) - r,
            grad,
        }
    }

    /// Largest |hub gap| over the cutter locations of `x` (mm).
    pub fn hub_tangency_error(&self, x: &[f64]) -> f64 {
        let (_, g0, _) = self.unpack(x);
        (0..self.cl_params.len())
            .map(|j| self.hub_gap(&g0, j, x[0]).value.abs())
            .fold(0.0, f64::max)
    }

    /// Smallest clearance at the last evaluation (mm).
    pub fn last_min_clearance(&self) -> f64 {
        self.last_clearance
    }

    /// Indices of the accuracy samples.
    pub fn accuracy_samples(&self) -> &[usize] {
        &self.samples
    }

    /// Indices of the fillet-band samples (overcut rows only).
    pub fn fillet_band_samples(&self) -> &[usize] {
        &self.band
    }
}

impl Model for FlankProblem<'_> {
    fn dimension(&self) -> usize {
        2 + 6 * self.n_ctrl()
    }

    fn evaluate(&mut self, x: &[f64], gradients: bool) -> Result<Evaluation, FlankError> {
        let env = self.envelope(x)?;
        let st = self.settings;
        let mut eval = Evaluation::default();
        let mut deviations = vec![f64::NAN; self.side.samples.len()];
        let samples = self.samples.clone();
        let rows = self.distance_rows(&env, &samples, gradients)?;
        for (&i, row) in samples.iter().zip(rows) {
            deviations[i] = row.value;
            match self.mode {
                Mode::Minimax => eval.minimax.push(row),
                Mode::Shape => {
                    let mut low = row.clone();
                    low.value += st.overcut_tol;
                    let mut high = row;
                    high.value = st.undercut_tol - high.value;
                    for g in &mut high.grad {
                        g.1 = -g.1;
                    }
                    eval.constraints.push(low);
                    eval.constraints.push(high);
                }
            }
        }
        let band = self.band.clone();
        for mut row in self.distance_rows(&env, &band, gradients)? {
            row.value += st.overcut_tol;
            eval.constraints.push(row);
        }
        self.deviations = deviations;
        let (_, g0, _) = self.unpack(x);
        for j in 0..self.cl_params.len() {
            let gap = self.hub_gap(&g0, j, x[0]);
            let mut up = gap.clone();
            up.value += st.hub_tol;
            let mut down = gap;
            down.value = st.hub_tol - down.value;
            for g in &mut down.grad {
                g.1 = -g.1;
            }
            eval.constraints.push(up);
            eval.constraints.push(down);
        }
        let n_s = self.side.samples.len();
        let mut min_clear = f64::INFINITY;
        for k in 0..self.side.adjacent.len() {
            let q = self.side.adjacent[k];
            let d = env.signed_distance(&q, self.hints[n_s + k])?;
            self.hints[n_s + k] = Some(d.param);
            min_clear = min_clear.min(d.distance);
            if d.distance - st.min_clearance < CLEARANCE_BAND_MM {
                let mut row = self.distance_row(&env, &q, n_s + k, gradients)?;
                row.value -= st.min_clearance;
                eval.constraints.push(row);
            }
        }
        self.last_clearance = min_clear;
        let max_dev = deviations_max(&self.deviations);
        eval.info = vec![max_dev, min_clear];
        if self.mode == Mode::Shape {
            let (k, dk) = self.stiffness(x)?;
            let k0 = *self.k_ref.get_or_insert(k);
            eval.objective = Row {
                value: -k / k0,
                grad: if gradients {
                    let mut g = vec![(0, -dk[0] / k0)];
                    if self.family == Family::TaperedBall {
                        g.push((1, -dk[1] / k0));
                    }
                    g
                } else {
                    Vec::new()
                },
            };
        }
        Ok(eval)
    }

    fn record(&mut self, iteration: usize, x: &[f64], eval: &Evaluation, radius: f64) {
        let max_dev = eval.info.first().copied().unwrap_or(f64::NAN);
        let clearance = eval.info.get(1).copied().unwrap_or(f64::NAN);
        let k = self.stiffness(x).map_or(f64::NAN, |s| s.0);
        self.history.push(HistoryRow {
            iteration,
            max_deviation_mm: max_dev,
            ball_radius_mm: x[0],
            half_angle: if self.family == Family::TaperedBall {
                x[1]
            } else {
                0.0
            },
            min_clearance_mm: clearance,
            stiffness_n_per_mm: k,
            trust_radius: radius,
        });
    }
}

/// Largest |value| of the finite entries.
pub fn deviations_max(d: &[f64]) -> f64 {
    d.iter()
        .filter(|v| v.is_finite())
        .map(|v| v.abs())
        .fold(0.0, f64::max)
}
