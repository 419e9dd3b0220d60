//! Signed distance from a point to the envelope swept by a cutter moving along a tool-axis
//! trajectory surface, and its first-order change with respect to the tool path and the
//! cutter shape — without building the swept surface.
//!
//! # The two-parameter sphere family
//!
//! The tool axis at path parameter `s` runs through `P0(s)` toward `P1(s)` (two guiding
//! B-spline/NURBS curves): `D = P1 − P0`, `ℓ = |D|`, `a(s) = D/ℓ`. `P0` is the axis point at
//! height `h_g` (the *guide height*, 0 when `P0` is the tool tip) above the tip. The cutter is
//! a [`SphereFamily`]: member `t` is centred on the axis at height `c(t)` above the tip, with
//! disc radius `e(t)` (0 for a plain sphere) and sphere radius `ρ(t)`. Moving the cutter gives
//! the two-parameter family with centres
//!
//! `o(s, t) = P0(s) + (c(t) − h_g)·a(s)`,
//!
//! and the swept volume is the union of all members (paper 002, §"Representation of cutter
//! swept envelope as sphere-swept surface"; Zhu et al.'s sphere congruence). With `v = p − o`,
//! `z = v·a`, `w = √(|v|² − z²)`:
//!
//! `F(s, t) = √(z² + max(w − e, 0)²) − ρ`  (`= |p − o| − ρ` for a plain sphere),
//! `d(p) = min_{s ∈ [s₀, s₁], t ∈ [0, n]} F(s, t)`.
//!
//! `d > 0`: `p` is outside the swept volume and `d` is its exact Euclidean distance (distance
//! to a union = smallest distance to a member). `d < 0`: `p` is inside; `−d` is the depth of
//! `p` inside the deepest single member — a lower bound of the depth below the swept envelope
//! (exact when the deepest member's surface normal through `p` reaches the envelope, which is
//! the usual case for small overcuts of ball and tapered ball ends). `d = 0` on the envelope.
//!
//! # Computation
//!
//! Stationarity: `∂F/∂s = 0`, `∂F/∂t = 0` (with bounds). At fixed `s` the `t`-equation has a
//! closed-form solution over the whole family ([`crate::SpherePiece::min_over_tau`]: the function is
//! convex in `t` on each piece), so the 2×2 Newton system is reduced exactly to its Schur
//! complement in `s`:
//!
//! `g(s) = F(s, t*(s))`, `g' = F_s`, `g'' = F_ss − F_st²/F_tt` (`t*` interior, `F_tt > 0`;
//! else `g'' = F_ss` because `t*` sits on a bound or on a kink of the family),
//!
//! and Newton steps in `s` are projected onto `[s₀, s₁]` and safeguarded by Armijo
//! backtracking on `g` (a gradient step when `g'' <= 0`). Derivatives of `F` come from the
//! guides' first and second derivatives (`a' = (D' − a ℓ')/ℓ`, `ℓ' = a·D'`,
//! `a'' = (D'' − 2a'ℓ' − aℓ'')/ℓ`, `ℓ'' = a'·D' + a·D''`) through `z` and `w`.
//!
//! *Cold* queries seed globally: at construction both guides are sampled
//! `samples_per_span` times per knot span (union of both curves' breakpoints) and the tip and
//! axis are cached; a query evaluates the closed-form `min_t F` at every sample (no curve
//! evaluation), keeps the best `newton_starts` discrete local minima in `s` and polishes each.
//! *Warm* queries start Newton from a hint (typically the previous point's result).
//! Iterations stop when the Newton step moves the centre less than `step_tol` (mm).
//!
//! # Certificate
//!
//! Newton finds a local minimum of `g(s) = min_t F(s, t)`; an optimiser that trusts a local
//! minimum would miss a gouge elsewhere along the path. So every query (cold or warm) ends
//! with a certification pass that proves, for every part of the path Newton did not search,
//! a lower bound of the distance (the envelope analogue of the `nurbs` closest-point
//! hierarchy's box bounds):
//!
//! - each member is a rigid body carried by the frame, so `|g(s₁) − g(s₂)|` is at most the
//!   largest displacement of a point of a member's centre disc, and `|g'| <= L =
//!   max|P0'| + (max|m| + max e)·max|D'|/min ℓ` on a seed interval; `max|P0'|` and `max|D'|`
//!   are the largest hodograph control points of the span (a B-spline derivative is a convex
//!   combination of them), `min ℓ >= min(ℓ at the ends) − max|D'|·h/2`. Bounds are built once.
//! - the cone bound `(g_a + g_b − L·h)/2` (Piyavskii) bounds `g` below on an interval from
//!   its end values; blocks of seed intervals are first excluded with one evaluation at their
//!   middle seed (`g_mid − L·half width`).
//! - second order, for sphere families (ball and tapered ball ends, every member a sphere of
//!   radius `ρ(t) >= ρ_min`): at fixed `t`, `F = |p − o| − ρ` has `F_ss <= |o_s|²/|p − o| +
//!   |o_ss|`, and on an interval where `g >= lb` (the cone bound) `|p − o| >= ρ_min + lb`, so
//!   `F_ss <= M = L²/(ρ_min + lb) + A` (`A` bounds `|o_ss|` from the second hodographs);
//!   then `F(s, t) >= chord − M·h²/8 >= min(g_a, g_b) − M·h²/8` for every `t`, which bounds
//!   `g` below. The cone bound's deficit `L·h/2` is first order in the interval width, this
//!   one's second order: on densely sampled paths (a written pass of thousands of short
//!   linear moves) the intervals beside the minimiser, where `g` rises by less than `L·h/2`,
//!   are excluded without a Newton run each (issue 13: they exhausted the run budget);
//! - an interval whose bound is below `answer − certify_tol` and that no Newton run has
//!   searched (started in or ended in) is searched by Newton from its lower end; the answer
//!   only decreases, so earlier exclusions stay valid.
//!
//! The result carries `certified = true` when every unsearched interval is excluded. What is
//! *not* proven: a second, deeper minimum inside a searched seed interval (a quarter of a knot
//! span by default) — that would take a convexity certificate of `g` there. `certified` is
//! false for rational guides (no hodograph bound is kept) and when `max_certify_runs` Newton
//! runs did not suffice.
//!
//! Cost: cold O(samples · pieces) + a few Newton runs, warm one Newton run plus the pass
//! (one closed-form evaluation per block of far seeds, per seed near the point), each Newton
//! iteration O(p²) for degree-p guides; no allocation.
//!
//! Measured (`cargo bench -p cam-core --bench envelope`, on-CPU time per query on a shared
//! 2-core machine): warm 9.7 µs, cold 13.0 µs, against 0.61 µs and 2.5 µs before the
//! certificate. The bench's points lie on a flank, about 23 Newton iterations per query: the
//! seed intervals next to the minimiser fail the cone bound (the distance rises there by
//! less than `L·h/2`) and are searched. A convexity certificate of `g` on those intervals
//! (as `nurbs` keeps for surface leaves) would remove most of that cost;
//! `max_certify_runs = 0` gives the uncertified cost back with `certified = false`.
//!
//! # First-order change (envelope theorem)
//!
//! At the minimiser `(s*, t*)` (bounds fixed: `s ∈ [s₀, s₁]`, `τ ∈ [0, 1]` per piece), the
//! derivative of `d` with respect to any data `q` is `∂F/∂q` at fixed `(s*, t*)` (Danskin; the
//! terms through `∂s*/∂q`, `∂t*/∂q` vanish by stationarity or by the bound). With
//! `G_v = ∂F/∂v`, `G_a = ∂F/∂a|_v` and `m = c − h_g`:
//!
//! - plain sphere: `G_v = v/|v|` (the unit normal `n`), `G_a = 0`;
//! - beyond a disc rim (`w > e`, `g = w − e`, `Q = √(z² + g²)`):
//!   `G_v = (z·a + g·(v − z a)/w)/Q`, `G_a = z(1 − g/w)·v/Q`, `∂F/∂e = −g/Q`;
//! - over a disc (`w <= e`): `G_v = σ·a`, `G_a = σ·v`, `∂F/∂e = 0`, with `σ = sign(z)`, except
//!   at the kink `z = 0` where the minimising member's centre plane passes through `p`: there
//!   the value is `−ρ(t*)` with `c(t*) = z`, which gives `σ = −ρ'/c'` (0 for a bull nose);
//! - point: `∂d/∂p = G_v` (the unit outward normal of the envelope at the foot point);
//! - axis: `∂F/∂a = G_a − m·G_v`, projected on the sphere of unit vectors,
//!   `∂F/∂D = (I − a aᵀ)·∂F/∂a / ℓ`;
//! - guides: `∂d/∂P1 = ∂F/∂D`, `∂d/∂P0 = −G_v − ∂F/∂D`, and for control points
//!   `∂d/∂Q0_i = R⁰_i(s*)·∂d/∂P0`, `∂d/∂Q1_j = R¹_j(s*)·∂d/∂P1` (rational basis, weights fixed;
//!   only `degree + 1` control points of each curve are non-zero);
//! - shape parameter `q_k`: `∂d/∂q_k = −(G_v·a)·∂c/∂q_k + ∂F/∂e·∂e/∂q_k − ∂ρ/∂q_k`, with the
//!   closed-form coefficient derivatives of the family at fixed `τ*` (for a tapered ball:
//!   ball radius and half angle).
//!
//! The derivative is exact where the minimiser is unique; where several `(s, t)` attain the
//! minimum (e.g. a point below a flat bottom, equidistant from several members) it is one
//! valid one-sided derivative.

//!
//! # Example
//!
//! ```
//! use cam_core::{CutterShape, EnvelopeOptions, GuideCurve, Point3, SphereFamily,
//!                SweptEnvelope, Vector3};
//! // A 3 mm ball, 3° taper, moving 50 mm along +x with a vertical axis.
//! let shape = CutterShape::TaperedBallEnd { ball_radius: 3.0, half_angle: 3f64.to_radians() };
//! let family = SphereFamily::from_shape(&shape, 25.0)?;
//! let line = |z: f64| GuideCurve::new(1, vec![0.0, 0.0, 1.0, 1.0],
//!     vec![Vector3::new(0.0, 0.0, z), Vector3::new(50.0, 0.0, z)], None);
//! let env = SweptEnvelope::new(family, line(0.0)?, line(10.0)?, 0.0,
//!                              EnvelopeOptions::default())?;
//! // 1 mm below the tip line: outside, 1 mm away.
//! let (d, grad) = env.signed_distance_with_gradient(&Point3::new(25.0, 0.0, -1.0), None)?;
//! assert!((d.distance - 1.0).abs() < 1e-12);
//! assert!((grad.point - Vector3::new(0.0, 0.0, -1.0)).norm() < 1e-9);
//! // ∂d/∂(ball radius) = 0 here: the tip (lowest point) stays on the guide when r grows.
//! assert!(grad.shape[0].abs() < 1e-9);
//! // Warm start for the next point along the path.
//! let next = env.signed_distance(&Point3::new(26.0, 0.0, -1.0), Some(d.param))?;
//! assert!((next.distance - 1.0).abs() < 1e-12);
//! # Ok::<(), cam_core::CamError>(())
//! ```

use crate::guide::GuideEval;
use crate::{CamError, CutterLocation, GuideCurve, Point3, SphereFamily, Vector3};

const NB: usize = crate::guide::MAX_GUIDE_DEGREE + 1;

/// A point whose height above a disc member's centre plane is below this (mm) is treated as
/// lying in that plane (the kink of `|z − c(t)|` where the exact `t`-minimisation puts it).
pub const KINK_TOL_MM: f64 = 1e-9;

/// Default certification slack (mm): far below any machining tolerance, above the rounding
/// noise of a distance of a few hundred mm.
pub const DEFAULT_CERTIFY_TOL_MM: f64 = 1e-9;

/// Default budget of certification Newton runs per query: a query point is normally near the
/// envelope at one or two places along the path; 16 leaves room for a blade point that several
/// sweeps of a zig-zag path pass near, and bounds the worst case.
pub const DEFAULT_MAX_CERTIFY_RUNS: usize = 16;

/// Seed intervals grouped under one coarse lower bound (one distance evaluation at the
/// group's middle seed excludes the whole group when the point is far from it).
const CERTIFY_BLOCK: usize = 8;

/// Named numerical settings of [`SweptEnvelope`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnvelopeOptions {
    /// Seed samples per knot span of the guides (cold queries).
    pub samples_per_span: usize,
    /// Number of best discrete local minima polished by Newton on a cold query.
    pub newton_starts: usize,
    /// Newton stops when a step moves the sphere centre less than this (mm).
    pub step_tol: f64,
    /// Iteration cap per Newton run.
    pub max_iterations: usize,
    /// Smallest allowed `|P1 − P0|` (mm); below it the axis is undefined.
    pub min_axis_length: f64,
    /// Certification slack (mm): a seed interval whose lower bound is at least the answer
    /// minus this is certified not to hold a nearer member (module docs, "Certificate").
    pub certify_tol: f64,
    /// Most Newton runs the certification may start per query (each searches one seed
    /// interval whose lower bound is below the answer); beyond it the answer is returned
    /// with `certified = false`.
    pub max_certify_runs: usize,
}

impl Default for EnvelopeOptions {
    fn default() -> Self {
        Self {
            samples_per_span: 4,
            newton_starts: 2,
            step_tol: 1e-10,
            max_iterations: 40,
            min_axis_length: 1e-9,
            certify_tol: DEFAULT_CERTIFY_TOL_MM,
            max_certify_runs: DEFAULT_MAX_CERTIFY_RUNS,
        }
    }
}

/// Parameters of the minimising member: path parameter `s` and global family parameter `t`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnvelopeParam {
    /// Path (guide-curve) parameter.
    pub s: f64,
    /// Family parameter in `[0, number of pieces]`.
    pub t: f64,
}

/// Result of a signed-distance query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnvelopeDistance {
    /// Signed distance (mm): positive outside the swept volume, negative inside.
    pub distance: f64,
    /// Minimiser; pass it as the hint of the next query on a neighbouring point.
    pub param: EnvelopeParam,
    /// Newton iterations used (all starts).
    pub iterations: usize,
    /// True when every part of the path not searched by Newton is proven (Lipschitz lower
    /// bound, module docs) to hold no member nearer than `distance − certify_tol`. False for
    /// rational guides (no derivative bound is kept for them) or when the run budget ran out.
    pub certified: bool,
    /// A lower bound of the distance from the certification pass: `distance − certify_tol`
    /// when certified; when the run budget ran out, the smaller of that and the cone or
    /// second-order bounds of the seed intervals left unsearched (so an uncertified answer
    /// still bounds how much nearer the envelope could be); `−∞` for rational guides.
    pub lower_bound: f64,
}

/// Sensitivity of the distance to one guide's control points: `∂d/∂Q_{first+i} =
/// basis[i]·direction` for `i < count`, zero for the others.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlPointGradient {
    /// First control point with a non-zero sensitivity.
    pub first: usize,
    /// Number of control points with a non-zero sensitivity (`degree + 1`).
    pub count: usize,
    /// Rational basis values `R_{first+i}(s*)`.
    pub basis: [f64; NB],
    /// `∂d/∂P(s*)`: gradient with respect to the guide's point.
    pub direction: Vector3,
}

impl ControlPointGradient {
    /// `∂d/∂Q_i` (zero vector outside the support).
    pub fn get(&self, i: usize) -> Vector3 {
        if i >= self.first && i < self.first + self.count {
            self.direction * self.basis[i - self.first]
        } else {
            Vector3::zeros()
        }
    }

    /// Adds `scale·∂d/∂Q_i` into `out[i]` for every control point in the support
    /// (`out` indexed like the guide's control points).
    pub fn add_to(&self, out: &mut [Vector3], scale: f64) {
        for i in 0..self.count {
            if let Some(o) = out.get_mut(self.first + i) {
                *o += self.direction * (scale * self.basis[i]);
            }
        }
    }
}

/// First-order change of the signed distance (envelope theorem; see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnvelopeGradient {
    /// `∂d/∂p`: outside the swept volume the unit normal of the envelope at the foot point
    /// (pointing toward `p`); inside, the gradient of the deepest-member depth (a unit vector
    /// too, except at the kink over a disc, see the module docs).
    pub point: Vector3,
    /// Sensitivity to the control points of `P0` (the lower guide).
    pub guide0: ControlPointGradient,
    /// Sensitivity to the control points of `P1` (the upper guide).
    pub guide1: ControlPointGradient,
    /// `∂d/∂q_k` for the family's shape parameters
    /// ([`SphereFamily::shape_param_names`]); unused slots are 0.
    pub shape: [f64; 2],
}

/// Cached tip and axis at a seed parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Seed {
    s: f64,
    tip: Vector3,
    axis: Vector3,
}

/// Tool axis frame at `s` with derivatives.
#[derive(Debug, Clone, Copy)]
struct Frame {
    p0: [Vector3; 3],
    a: Vector3,
    a_s: Vector3,
    a_ss: Vector3,
    ell: f64,
    e0: GuideEval,
    e1: GuideEval,
}

/// `F` and its first and second derivatives in `(s, τ)`, plus the pieces needed later.
#[derive(Debug, Clone, Copy)]
struct Local {
    /// `F` itself (the Newton loop takes it from the exact `t`-minimisation instead).
    #[cfg_attr(not(test), allow(dead_code))]
    f: f64,
    g: [f64; 2],
    h: [[f64; 2]; 2],
    /// |∂o/∂s|, |∂o/∂τ| (mm per unit parameter), for the step test.
    speed: [f64; 2],
}

/// The envelope swept by a sphere-family cutter along a two-guide tool-axis trajectory.
#[derive(Debug, Clone, PartialEq)]
pub struct SweptEnvelope {
    family: SphereFamily,
    guide0: GuideCurve,
    guide1: GuideCurve,
    guide_height: f64,
    domain: (f64, f64),
    seeds: Vec<Seed>,
    opts: EnvelopeOptions,
    /// Both guides have the same degree and knots: one basis evaluation per frame.
    shared_basis: bool,
    /// Per seed interval `[seeds[k].s, seeds[k+1].s]`: an upper bound of `|g'(s)|` (mm per
    /// unit parameter); `INFINITY` where none is known (rational guides, axis may vanish).
    lipschitz: Vec<f64>,
    /// Per seed interval: an upper bound of `|∂²o/∂s²|` over every member centre (mm per unit
    /// parameter²) for the second-order bound (module docs); `INFINITY` where none is known.
    curvature: Vec<f64>,
    /// Smallest member sphere radius when every member is a sphere (ball and tapered ball
    /// ends); `None` for families with discs (no second-order bound is used for them).
    sphere_radius_min: Option<f64>,
    /// Every seed interval has a finite bound (non-rational guides, axis bounded away from 0).
    certifiable: bool,
}

impl SweptEnvelope {
    /// Builds the envelope of `family` moving with its axis through `guide0(s)` (at height
    /// `guide_height` above the tip) toward `guide1(s)`. Samples and caches the seed frames.
    ///
    /// Errors: [`CamError::InvalidGuide`] if the guides' domains differ or an option is out of
    /// range; [`CamError::DegenerateAxis`] if the guides meet at a seed parameter;
    /// [`CamError::NonPositive`] for a non-finite guide height or non-positive tolerances.
    pub fn new(
        family: SphereFamily,
        guide0: GuideCurve,
        guide1: GuideCurve,
        guide_height: f64,
        opts: EnvelopeOptions,
    ) -> Result<Self, CamError> {
        let (d0, d1) = (guide0.domain(), guide1.domain());
        let scale = 1.0 + d0.0.abs().max(d0.1.abs());
        if (d0.0 - d1.0).abs() > 1e-12 * scale || (d0.1 - d1.1).abs() > 1e-12 * scale {
            return Err(CamError::InvalidGuide {
                reason: "the two guides must share one parameter domain",
            });
        }
        if opts.samples_per_span == 0 || opts.newton_starts == 0 || opts.max_iterations == 0 {
            return Err(CamError::InvalidGuide {
                reason: "samples_per_span, newton_starts and max_iterations must be >= 1",
            });
        }
        for (field, value) in [
            ("step_tol", opts.step_tol),
            ("min_axis_length", opts.min_axis_length),
            ("certify_tol", opts.certify_tol),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(CamError::NonPositive { field, value });
            }
        }
        if !guide_height.is_finite() {
            return Err(CamError::NonPositive {
                field: "guide_height",
                value: guide_height,
            });
        }
        let mut breaks = guide0.breakpoints();
        breaks.extend(guide1.breakpoints());
        breaks.sort_by(f64::total_cmp);
        breaks.dedup_by(|a, b| (*a - *b).abs() <= 1e-14 * scale);
        let shared_basis = guide0.shares_basis_with(&guide1);
        let mut env = Self {
            shared_basis,
            family,
            guide0,
            guide1,
            guide_height,
            domain: d0,
            seeds: Vec::new(),
            opts,
            lipschitz: Vec::new(),
            curvature: Vec::new(),
            sphere_radius_min: None,
            certifiable: false,
        };
        let mut seeds = Vec::with_capacity(breaks.len() * opts.samples_per_span + 1);
        for w in breaks.windows(2) {
            for k in 0..opts.samples_per_span {
                let s = w[0] + (w[1] - w[0]) * k as f64 / opts.samples_per_span as f64;
                seeds.push(env.seed_at(s)?);
            }
        }
        seeds.push(env.seed_at(d0.1)?);
        (env.lipschitz, env.curvature) = env.interval_bounds(&seeds);
        env.certifiable = env.lipschitz.iter().all(|l| l.is_finite());
        env.sphere_radius_min = env
            .family
            .pieces()
            .iter()
            .all(|piece| piece.is_sphere())
            .then(|| {
                env.family
                    .pieces()
                    .iter()
                    .fold(f64::INFINITY, |acc, piece| {
                        acc.min(piece.radius[0])
                            .min(piece.radius[0] + piece.radius[1])
                    })
            })
            .filter(|r| r.is_finite() && *r > 0.0);
        env.seeds = seeds;
        Ok(env)
    }

    /// Convenience: the envelope of `cutter`'s fluted part moving along two `nurbs` guides.
    pub fn for_cutter(
        cutter: &crate::Cutter,
        guide0: &nurbs::Curve3,
        guide1: &nurbs::Curve3,
        guide_height: f64,
        opts: EnvelopeOptions,
    ) -> Result<Self, CamError> {
        Self::new(
            SphereFamily::from_cutter(cutter)?,
            GuideCurve::from_curve(guide0)?,
            GuideCurve::from_curve(guide1)?,
            guide_height,
            opts,
        )
    }

    /// Per seed interval, an upper bound `L` of `|g'(s)|`, `g(s) = min_t F(s, t)` (module docs,
    /// "Certificate"): every member moves rigidly with the frame, so `g` changes no faster
    /// than the fastest point of any member's centre disc, `|P0'| + (|m|max + e_max)·|a'|`, with
    /// `|a'| <= |D'|/ℓ` and `ℓ >= min(ℓ at the ends) − |D'|max·h/2`; and an upper bound `A` of
    /// `|o_ss| <= |P0''| + |m|max·|a''|` with `|a''| <= (2|D''| + 3|a'|·|D'|)/ℓ` (from
    /// `D'' = ℓ''a + 2ℓ'a' + ℓa''`, `|ℓ'| <= |D'|`, `|ℓ''| <= |a'|·|D'| + |D''|`). The
    /// hodograph bounds come from [`GuideCurve::derivative_bound`] and
    /// [`GuideCurve::second_derivative_bound`]. O(seeds · p).
    fn interval_bounds(&self, seeds: &[Seed]) -> (Vec<f64>, Vec<f64>) {
        let mut m_max: f64 = 0.0;
        let mut e_max: f64 = 0.0;
        for piece in self.family.pieces() {
            for tau in [0.0, 1.0] {
                let member = piece.at(tau);
                m_max = m_max.max((member.height - self.guide_height).abs());
                e_max = e_max.max(member.disc_radius);
            }
        }
        let ell = |s: f64| (self.guide1.point(s) - self.guide0.point(s)).norm();
        seeds
            .windows(2)
            .map(|w| {
                let (a, b) = (w[0].s, w[1].s);
                let mid = 0.5 * (a + b);
                let (sp0, sp1) = (self.guide0.find_span(mid), self.guide1.find_span(mid));
                // A hodograph bound of `P0` and of `D = P1 − P0` on this interval (`|D^(k)|`
                // from the shared basis, else `|P1^(k)| + |P0^(k)|`).
                let bounds = |bound: fn(&GuideCurve, usize, Option<&GuideCurve>) -> Option<f64>| {
                    let b0 = bound(&self.guide0, sp0, None);
                    let bd = if self.shared_basis {
                        bound(&self.guide1, sp1, Some(&self.guide0))
                    } else {
                        bound(&self.guide1, sp1, None).zip(b0).map(|(x, y)| x + y)
                    };
                    (b0, bd)
                };
                let (dp0, dd) = bounds(GuideCurve::derivative_bound);
                let (Some(dp0), Some(dd)) = (dp0, dd) else {
                    return (f64::INFINITY, f64::INFINITY);
                };
                let ell_min = ell(a).min(ell(b)) - dd * 0.5 * (b - a);
                if ell_min.is_nan() || ell_min < self.opts.min_axis_length {
                    return (f64::INFINITY, f64::INFINITY);
                }
                let (d2p0, d2d) = bounds(GuideCurve::second_derivative_bound);
                let curvature = match (d2p0, d2d) {
                    (Some(d2p0), Some(d2d)) => {
                        let a_s = dd / ell_min;
                        let a_ss = (2.0 * d2d + 3.0 * a_s * dd) / ell_min;
                        (d2p0 + m_max * a_ss) * (1.0 + 1e-12)
                    }
                    _ => f64::INFINITY,
                };
                // Relative slack for the rounding of the bound itself.
                (
                    (dp0 + (m_max + e_max) * dd / ell_min) * (1.0 + 1e-12),
                    curvature,
                )
            })
            .unzip()
    }

    /// Second-order lower bound of `g` on seed interval `k` of parameter width `h` (module
    /// docs, "Certificate"): `min(g_a, g_b) − M·h²/8` with `M = L²/(ρ_min + lb) + A`, valid
    /// when every member is a sphere and `ρ_min + lb > 0` (`lb`: a lower bound of `g` on the
    /// interval, here the cone bound); `−∞` where it does not apply. O(1).
    fn second_order_bound(&self, k: usize, g_a: f64, g_b: f64, lb: f64, h: f64) -> f64 {
        let Some(rho_min) = self.sphere_radius_min else {
            return f64::NEG_INFINITY;
        };
        let (l, a) = (self.lipschitz[k], self.curvature[k]);
        let near = rho_min + lb;
        if !(near > 0.0 && l.is_finite() && a.is_finite()) {
            return f64::NEG_INFINITY;
        }
        let m = (l * l / near + a) * (1.0 + 1e-12);
        g_a.min(g_b) - m * h * h / 8.0
    }

    fn seed_at(&self, s: f64) -> Result<Seed, CamError> {
        let (tip, axis) = self.tip_axis(s)?;
        Ok(Seed { s, tip, axis })
    }

    /// The cutter family.
    pub fn family(&self) -> &SphereFamily {
        &self.family
    }
    /// The lower guide `P0`.
    pub fn guide0(&self) -> &GuideCurve {
        &self.guide0
    }
    /// The upper guide `P1`.
    pub fn guide1(&self) -> &GuideCurve {
        &self.guide1
    }
    /// Height of `P0` above the tool tip (mm).
    pub fn guide_height(&self) -> f64 {
        self.guide_height
    }
    /// Path parameter domain.
    pub fn domain(&self) -> (f64, f64) {
        self.domain
    }

    /// Tool tip and unit axis at path parameter `s` (clamped to the domain).
    fn tip_axis(&self, s: f64) -> Result<(Vector3, Vector3), CamError> {
        let p0 = self.guide0.point(s);
        let d = self.guide1.point(s) - p0;
        let ell = d.norm();
        if ell.is_nan() || ell < self.opts.min_axis_length {
            return Err(CamError::DegenerateAxis { s });
        }
        let a = d / ell;
        Ok((p0 - a * self.guide_height, a))
    }

    /// The cutter location (tip + axis) at path parameter `s`.
    pub fn cutter_location(&self, s: f64) -> Result<CutterLocation, CamError> {
        let (tip, axis) = self.tip_axis(s)?;
        CutterLocation::new(Point3::from(tip), axis)
    }

    fn frame(&self, s: f64) -> Result<Frame, CamError> {
        let (e0, e1) = if self.shared_basis {
            let (span, n) = self.guide0.basis2(s);
            (
                self.guide0.combine2(span, &n),
                self.guide1.combine2(span, &n),
            )
        } else {
            (self.guide0.eval2(s), self.guide1.eval2(s))
        };
        let d = e1.d[0] - e0.d[0];
        let d1 = e1.d[1] - e0.d[1];
        let d2 = e1.d[2] - e0.d[2];
        let ell = d.norm();
        if ell.is_nan() || ell < self.opts.min_axis_length {
            return Err(CamError::DegenerateAxis { s });
        }
        let a = d / ell;
        let ell_s = a.dot(&d1);
        let a_s = (d1 - a * ell_s) / ell;
        let ell_ss = a_s.dot(&d1) + a.dot(&d2);
        let a_ss = (d2 - a_s * (2.0 * ell_s) - a * ell_ss) / ell;
        Ok(Frame {
            p0: e0.d,
            a,
            a_s,
            a_ss,
            ell,
            e0,
            e1,
        })
    }

    /// `F`, gradient and Hessian in `(s, τ)` of the member `t` at the frame.
    fn local(&self, p: &Vector3, fr: &Frame, t: f64) -> Local {
        let (k, tau) = self.family.split(t);
        let piece = &self.family.pieces()[k];
        let m = piece.height[0] + tau * piece.height[1] - self.guide_height;
        let dc = piece.height[1];
        let a = fr.a;
        let o_s = fr.p0[1] + fr.a_s * m;
        let o_ss = fr.p0[2] + fr.a_ss * m;
        let o_t = a * dc;
        let o_st = fr.a_s * dc;
        let v = p - (fr.p0[0] + a * m);
        let (v_s, v_t, v_ss, v_st) = (-o_s, -o_t, -o_ss, -o_st);
        let n = v.norm_squared();
        let n_i = [2.0 * v.dot(&v_s), 2.0 * v.dot(&v_t)];
        let n_ij = [
            [
                2.0 * (v_s.dot(&v_s) + v.dot(&v_ss)),
                2.0 * (v_s.dot(&v_t) + v.dot(&v_st)),
            ],
            [0.0, 2.0 * v_t.dot(&v_t)],
        ];
        let tiny = 1e-300;
        let (q, q_i, q_ij);
        if piece.is_sphere() {
            let qq = n.sqrt().max(tiny);
            let qi = [n_i[0] / (2.0 * qq), n_i[1] / (2.0 * qq)];
            let h = |i: usize, j: usize| (0.5 * n_ij[i.min(j)][i.max(j)] - qi[i] * qi[j]) / qq;
            q = qq;
            q_i = qi;
            q_ij = [[h(0, 0), h(0, 1)], [h(0, 1), h(1, 1)]];
        } else {
            let e = piece.disc_radius[0] + tau * piece.disc_radius[1];
            let de = piece.disc_radius[1];
            let z = v.dot(&a);
            let z_i = [v_s.dot(&a) + v.dot(&fr.a_s), v_t.dot(&a)];
            let z_ij = [
                [
                    v_ss.dot(&a) + 2.0 * v_s.dot(&fr.a_s) + v.dot(&fr.a_ss),
                    v_st.dot(&a) + v_t.dot(&fr.a_s),
                ],
                [0.0, 0.0],
            ];
            let zz = |i: usize, j: usize| z_ij[i.min(j)][i.max(j)];
            let ww = n - z * z;
            let w = ww.max(0.0).sqrt();
            if w > e && w > 1e-12 * (1.0 + e) {
                let w_cap_i = [n_i[0] - 2.0 * z * z_i[0], n_i[1] - 2.0 * z * z_i[1]];
                let w_i = [w_cap_i[0] / (2.0 * w), w_cap_i[1] / (2.0 * w)];
                let w_ij = |i: usize, j: usize| {
                    let wc = n_ij[i.min(j)][i.max(j)] - 2.0 * (z_i[i] * z_i[j] + z * zz(i, j));
                    (0.5 * wc - w_i[i] * w_i[j]) / w
                };
                let g = w - e;
                let g_i = [w_i[0], w_i[1] - de];
                let qq = (z * z + g * g).sqrt().max(tiny);
                let qi = [
                    (z * z_i[0] + g * g_i[0]) / qq,
                    (z * z_i[1] + g * g_i[1]) / qq,
                ];
                let h = |i: usize, j: usize| {
                    (z_i[i] * z_i[j] + z * zz(i, j) + g_i[i] * g_i[j] + g * w_ij(i, j)
                        - qi[i] * qi[j])
                        / qq
                };
                q = qq;
                q_i = qi;
                q_ij = [[h(0, 0), h(0, 1)], [h(0, 1), h(1, 1)]];
            } else {
                let sg = flat_sign(z, piece);
                q = z.abs();
                q_i = [sg * z_i[0], sg * z_i[1]];
                q_ij = [[sg * zz(0, 0), sg * zz(0, 1)], [sg * zz(0, 1), 0.0]];
            }
        }
        let rho = piece.radius[0] + tau * piece.radius[1];
        Local {
            f: q - rho,
            g: [q_i[0], q_i[1] - piece.radius[1]],
            h: q_ij,
            speed: [o_s.norm(), o_t.norm()],
        }
    }

    /// `min_t F(s, t)` at a frame: (value, global t).
    fn g_frame(&self, p: &Vector3, fr: &Frame) -> (f64, f64) {
        let v = p - (fr.p0[0] - fr.a * self.guide_height);
        let z = v.dot(&fr.a);
        let w = (v.norm_squared() - z * z).max(0.0).sqrt();
        self.family.signed_distance(w, z)
    }

    /// Newton on `g(s) = min_t F(s, t)` from `s`; returns (value, s, t, iterations).
    /// Each iteration evaluates both guides once (with two derivatives) at the trial point,
    /// which is reused as the next iterate when the full step is accepted.
    fn polish(&self, p: &Vector3, s_start: f64) -> Result<(f64, f64, f64, usize), CamError> {
        let (lo, hi) = self.domain;
        let mut s = s_start.clamp(lo, hi);
        let mut fr = self.frame(s)?;
        let (mut f, mut t) = self.g_frame(p, &fr);
        let n_pieces = self.family.pieces().len() as f64;
        let mut iters = 0;
        while iters < self.opts.max_iterations {
            iters += 1;
            let loc = self.local(p, &fr, t);
            let gs = loc.g[0];
            if (s <= lo && gs >= 0.0) || (s >= hi && gs <= 0.0) {
                break; // minimum on the domain end
            }
            // Schur complement of the 2×2 Newton system (t solved exactly).
            let tau = t - self.family.split(t).0 as f64;
            let t_interior = tau > 0.0 && tau < 1.0 && t > 0.0 && t < n_pieces;
            let mut gss = loc.h[0][0];
            if t_interior && loc.h[1][1] > 1e-12 * (loc.h[0][0].abs() + 1.0) {
                gss -= loc.h[0][1] * loc.h[0][1] / loc.h[1][1];
            }
            let step = if gss > 0.0 {
                -gs / gss
            } else {
                -gs.signum() * 0.05 * (hi - lo)
            };
            // Converged when the (projected) Newton step would move the centre less than
            // step_tol, or would lower F by less than its rounding noise (the line search
            // could not see the decrease; the remaining error is below that noise).
            if gss > 0.0 {
                let ds = (s + step).clamp(lo, hi) - s;
                let noise = 64.0 * f64::EPSILON * (1.0 + p.amax() + fr.p0[0].amax());
                if ds.abs() * loc.speed[0] < self.opts.step_tol || -gs * ds < noise {
                    break;
                }
            }
            let mut alpha = 1.0;
            let mut accepted = None;
            while alpha > 1e-12 {
                let s_new = (s + alpha * step).clamp(lo, hi);
                let fr_new = self.frame(s_new)?;
                let (f_new, t_new) = self.g_frame(p, &fr_new);
                if f_new <= f + 1e-4 * gs * (s_new - s) {
                    accepted = Some((s_new, fr_new, f_new, t_new));
                    break;
                }
                alpha *= 0.5;
            }
            let Some((s_new, fr_new, f_new, t_new)) = accepted else {
                break; // no decrease possible at this resolution: converged
            };
            let moved = (s_new - s).abs() * loc.speed[0];
            s = s_new;
            fr = fr_new;
            f = f_new;
            t = t_new;
            if moved < self.opts.step_tol {
                break;
            }
        }
        Ok((f, s, t, iters))
    }

    /// `min_t F` at a cached seed (no curve evaluation).
    fn seed_value(&self, pv: &Vector3, sd: &Seed) -> f64 {
        let v = pv - sd.tip;
        let z = v.dot(&sd.axis);
        let w = (v.norm_squared() - z * z).max(0.0).sqrt();
        self.family.signed_distance(w, z).0
    }

    /// Signed distance from `p` to the swept envelope (module docs), globally seeded when
    /// `hint` is `None`, else Newton from `hint.s` (the family parameter is recomputed
    /// exactly); either way followed by the certification pass ("Certificate" in the module
    /// docs), which searches every seed interval whose lower bound is below the answer.
    /// No allocation.
    ///
    /// Errors: [`CamError::NonFinitePoint`]; [`CamError::DegenerateAxis`] if the guides meet
    /// where the search goes.
    pub fn signed_distance(
        &self,
        p: &Point3,
        hint: Option<EnvelopeParam>,
    ) -> Result<EnvelopeDistance, CamError> {
        if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
            return Err(CamError::NonFinitePoint(p.x, p.y, p.z));
        }
        let pv = p.coords;
        let mut out = match hint {
            Some(h) => {
                let (f, s, t, iterations) = self.polish(&pv, h.s)?;
                EnvelopeDistance {
                    distance: f,
                    param: EnvelopeParam { s, t },
                    iterations,
                    certified: false,
                    lower_bound: f64::NEG_INFINITY,
                }
            }
            None => self.cold_start(&pv)?,
        };
        self.certify(&pv, &mut out)?;
        Ok(out)
    }

    /// Cold seeding: polishes the best `newton_starts` discrete local minima of `min_t F` over
    /// the cached seeds.
    fn cold_start(&self, pv: &Vector3) -> Result<EnvelopeDistance, CamError> {
        const MAX_STARTS: usize = 8;
        let k_starts = self.opts.newton_starts.min(MAX_STARTS);
        let mut best = [(f64::INFINITY, 0.0f64); MAX_STARTS];
        let n = self.seeds.len();
        let mut prev = f64::INFINITY;
        let mut cur = self.seed_value(pv, &self.seeds[0]);
        for i in 0..n {
            let next = if i + 1 < n {
                self.seed_value(pv, &self.seeds[i + 1])
            } else {
                f64::INFINITY
            };
            if cur <= prev && cur <= next {
                // Insert into the sorted list of the best local minima.
                let mut item = (cur, self.seeds[i].s);
                for slot in best.iter_mut().take(k_starts) {
                    if item.0 < slot.0 {
                        std::mem::swap(slot, &mut item);
                    }
                }
            }
            prev = cur;
            cur = next;
        }
        let mut out: Option<EnvelopeDistance> = None;
        let mut iterations = 0;
        for &(v, s0) in best.iter().take(k_starts) {
            if !v.is_finite() {
                break;
            }
            let (f, s, t, it) = self.polish(pv, s0)?;
            iterations += it;
            if out.is_none_or(|o| f < o.distance) {
                out = Some(EnvelopeDistance {
                    distance: f,
                    param: EnvelopeParam { s, t },
                    iterations: 0,
                    certified: false,
                    lower_bound: f64::NEG_INFINITY,
                });
            }
        }
        let mut out = match out {
            Some(o) => o,
            None => {
                // Every seed value was NaN/infinite: cannot happen for finite data, but stay
                // total: polish from the domain start.
                let (f, s, t, it) = self.polish(pv, self.domain.0)?;
                iterations += it;
                EnvelopeDistance {
                    distance: f,
                    param: EnvelopeParam { s, t },
                    iterations: 0,
                    certified: false,
                    lower_bound: f64::NEG_INFINITY,
                }
            }
        };
        out.iterations = iterations;
        Ok(out)
    }

    /// The certification pass (module docs, "Certificate"): one sweep over the seed
    /// intervals in blocks of [`CERTIFY_BLOCK`]. A block whose middle-seed value minus
    /// `L_block·(half width)` is at least `best − certify_tol` is excluded with one
    /// evaluation; otherwise each interval's cone bound `(g_a + g_b − L·h)/2` is tested and a
    /// failing interval not yet searched is searched by Newton from its lower end, which can
    /// only lower `best` (so every earlier exclusion stays valid). Sets `certified`.
    /// O(seeds) evaluations of the closed-form `min_t F` plus the Newton runs; no allocation.
    fn certify(&self, pv: &Vector3, out: &mut EnvelopeDistance) -> Result<(), CamError> {
        const MAX_RUNS: usize = 64;
        let max_runs = self.opts.max_certify_runs.min(MAX_RUNS);
        let tol = self.opts.certify_tol;
        if !self.certifiable {
            out.certified = false;
            out.lower_bound = f64::NEG_INFINITY;
            return Ok(());
        }
        // Smallest bound of an interval left unsearched for want of runs.
        let mut unsearched = f64::INFINITY;
        // Parameters where a Newton run ended: their seed intervals count as searched.
        let mut found = [out.param.s; 2 * MAX_RUNS + 1];
        let mut n_found = 1;
        let mut runs = 0;
        let mut certified = true;
        let n_int = self.seeds.len() - 1;
        let mut k0 = 0;
        while k0 < n_int {
            let k1 = (k0 + CERTIFY_BLOCK).min(n_int);
            let mid = (k0 + k1) / 2;
            let l_block = self.lipschitz[k0..k1]
                .iter()
                .fold(0.0f64, |acc, &l| acc.max(l));
            let half =
                (self.seeds[mid].s - self.seeds[k0].s).max(self.seeds[k1].s - self.seeds[mid].s);
            let g_mid = self.seed_value(pv, &self.seeds[mid]);
            if g_mid - l_block * half >= out.distance - tol {
                k0 = k1;
                continue;
            }
            let mut g_a = self.seed_value(pv, &self.seeds[k0]);
            for k in k0..k1 {
                let (sa, sb) = (self.seeds[k].s, self.seeds[k + 1].s);
                let g_b = if k + 1 == mid {
                    g_mid
                } else {
                    self.seed_value(pv, &self.seeds[k + 1])
                };
                let mut lb = (0.5 * (g_a + g_b - self.lipschitz[k] * (sb - sa))).min(g_a.min(g_b));
                let searched = found[..n_found].iter().any(|&s| s >= sa && s <= sb);
                if lb < out.distance - tol && !searched {
                    lb = lb.max(self.second_order_bound(k, g_a, g_b, lb, sb - sa));
                }
                if lb < out.distance - tol && !searched {
                    if runs >= max_runs {
                        certified = false;
                        unsearched = unsearched.min(lb);
                    } else {
                        runs += 1;
                        let start = if g_a <= g_b { sa } else { sb };
                        let (f, s, t, it) = self.polish(pv, start)?;
                        out.iterations += it;
                        // Where Newton ended, and the interval itself (searched even
                        // when Newton left it): two entries per run, so `found` holds
                        // `1 + 2·MAX_RUNS`.
                        found[n_found] = s;
                        found[n_found + 1] = 0.5 * (sa + sb);
                        n_found += 2;
                        if f < out.distance {
                            out.distance = f;
                            out.param = EnvelopeParam { s, t };
                        }
                    }
                }
                g_a = g_b;
            }
            k0 = k1;
        }
        out.certified = certified;
        out.lower_bound = (out.distance - tol).min(unsearched);
        Ok(())
    }

    /// First-order change of the distance at a query's minimiser (envelope theorem, module
    /// docs): with respect to the point, both guides' control points and the shape
    /// parameters. O(p²), no allocation.
    pub fn gradient(
        &self,
        p: &Point3,
        at: &EnvelopeDistance,
    ) -> Result<EnvelopeGradient, CamError> {
        let s = at.param.s;
        let fr = self.frame(s)?;
        let (k, tau) = self.family.split(at.param.t);
        let piece = &self.family.pieces()[k];
        let member = piece.at(tau);
        let m = member.height - self.guide_height;
        let a = fr.a;
        let v = p.coords - (fr.p0[0] + a * m);
        let (g_v, g_a, f_e) = if piece.is_sphere() {
            let q = v.norm();
            let g_v = if q > 0.0 { v / q } else { a };
            (g_v, Vector3::zeros(), 0.0)
        } else {
            let z = v.dot(&a);
            let w = (v.norm_squared() - z * z).max(0.0).sqrt();
            let e = member.disc_radius;
            if w > e && w > 0.0 {
                let g = w - e;
                let q = (z * z + g * g).sqrt();
                if q > 0.0 {
                    let radial = (v - a * z) / w;
                    (
                        (a * z + radial * g) / q,
                        v * (z * (1.0 - g / w) / q),
                        -g / q,
                    )
                } else {
                    (radial_or_axis(&v, &a, w), Vector3::zeros(), -1.0)
                }
            } else {
                let sg = flat_sign(z, piece);
                (a * sg, v * sg, 0.0)
            }
        };
        let df_da = g_a - g_v * m;
        let df_dd = (df_da - a * a.dot(&df_da)) / fr.ell;
        let dp1 = df_dd;
        let dp0 = -g_v - df_dd;
        let mut shape = [0.0; 2];
        let f_c = -g_v.dot(&a);
        for (k_param, out) in shape
            .iter_mut()
            .enumerate()
            .take(self.family.shape_param_names().len())
        {
            let d = &piece.d_shape[k_param];
            let dc = d[0] + tau * d[1];
            let de = d[2] + tau * d[3];
            let drho = d[4] + tau * d[5];
            *out = f_c * dc + f_e * de - drho;
        }
        let cp = |e: &GuideEval, direction: Vector3| ControlPointGradient {
            first: e.first,
            count: e.count,
            basis: e.basis,
            direction,
        };
        Ok(EnvelopeGradient {
            point: g_v,
            guide0: cp(&fr.e0, dp0),
            guide1: cp(&fr.e1, dp1),
            shape,
        })
    }

    /// [`Self::signed_distance`] followed by [`Self::gradient`].
    pub fn signed_distance_with_gradient(
        &self,
        p: &Point3,
        hint: Option<EnvelopeParam>,
    ) -> Result<(EnvelopeDistance, EnvelopeGradient), CamError> {
        let d = self.signed_distance(p, hint)?;
        let g = self.gradient(p, &d)?;
        Ok((d, g))
    }
}

/// `∂|z|/∂z` over a disc, where `z` is the height of `p` above the member's centre plane. At
/// the kink `z = 0` reached by the exact `t`-minimisation (p lies in the centre plane of a
/// member containing it) the value is `min_t (|z − c(t)| − ρ(t)) = −ρ(t*)` with `c(t*) = z`, so
/// its derivative follows `t*`: the effective slope is `−ρ'/c'` (0 for a bull nose: the depth
/// `−ρ` is locally constant).
fn flat_sign(z: f64, piece: &crate::SpherePiece) -> f64 {
    if z.abs() <= KINK_TOL_MM && piece.height[1] != 0.0 {
        -piece.radius[1] / piece.height[1]
    } else if z < 0.0 {
        -1.0
    } else {
        1.0
    }
}

/// Unit radial direction of `v` (or the axis when `v` is on it).
fn radial_or_axis(v: &Vector3, a: &Vector3, w: f64) -> Vector3 {
    if w > 0.0 {
        (v - a * v.dot(a)) / w
    } else {
        *a
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CutterShape;

    fn guide(pts: &[[f64; 3]]) -> GuideCurve {
        let n = pts.len();
        let p = 3;
        let mut knots = vec![0.0; p + 1];
        for i in 1..(n - p) {
            knots.push(i as f64 / (n - p) as f64);
        }
        knots.extend([1.0; 4]);
        GuideCurve::new(
            p,
            knots,
            pts.iter().map(|q| Vector3::new(q[0], q[1], q[2])).collect(),
            None,
        )
        .unwrap()
    }

    /// `local` derivatives against central differences of `F`, for sphere and disc pieces.
    #[test]
    #[allow(clippy::needless_range_loop)]
    fn local_derivatives_match_finite_differences() {
        let g0 = guide(&[
            [0.0, 0.0, 0.0],
            [10.0, 5.0, 1.0],
            [20.0, -3.0, 2.0],
            [30.0, 2.0, 0.0],
            [40.0, 0.0, 1.0],
        ]);
        let g1 = guide(&[
            [0.0, 3.0, 20.0],
            [12.0, 6.0, 19.0],
            [19.0, 1.0, 21.0],
            [33.0, 5.0, 20.0],
            [41.0, 4.0, 18.0],
        ]);
        let shapes = [
            CutterShape::TaperedBallEnd {
                ball_radius: 3.0,
                half_angle: 0.05,
            },
            CutterShape::BullNose {
                radius: 5.0,
                corner_radius: 1.0,
            },
            CutterShape::TaperedFlatEnd {
                tip_radius: 4.0,
                half_angle: 0.1,
            },
        ];
        let p = Vector3::new(17.0, 9.0, 4.0);
        for shape in shapes {
            let fam = SphereFamily::from_shape(&shape, 25.0).unwrap();
            let env =
                SweptEnvelope::new(fam, g0.clone(), g1.clone(), 1.5, EnvelopeOptions::default())
                    .unwrap();
            for &(s, t) in &[(0.3, 0.4), (0.55, 0.7), (0.42, 0.2)] {
                let h = 1e-6;
                let f = |s: f64, t: f64| env.local(&p, &env.frame(s).unwrap(), t);
                let l = f(s, t);
                let (sp, sm) = (f(s + h, t), f(s - h, t));
                let (tp, tm) = (f(s, t + h), f(s, t - h));
                let fd_g = [(sp.f - sm.f) / (2.0 * h), (tp.f - tm.f) / (2.0 * h)];
                let fd_h = [
                    [
                        (sp.g[0] - sm.g[0]) / (2.0 * h),
                        (tp.g[0] - tm.g[0]) / (2.0 * h),
                    ],
                    [
                        (sp.g[1] - sm.g[1]) / (2.0 * h),
                        (tp.g[1] - tm.g[1]) / (2.0 * h),
                    ],
                ];
                let scale = 1.0 + l.g[0].abs() + l.g[1].abs();
                for i in 0..2 {
                    assert!(
                        (l.g[i] - fd_g[i]).abs() < 1e-6 * scale,
                        "{shape:?} g{i}: {} vs {}",
                        l.g[i],
                        fd_g[i]
                    );
                    for j in 0..2 {
                        let hs = 1.0 + l.h[i][j].abs();
                        assert!(
                            (l.h[i][j] - fd_h[i][j]).abs() < 1e-5 * hs * scale,
                            "{shape:?} h{i}{j}: {} vs {}",
                            l.h[i][j],
                            fd_h[i][j]
                        );
                    }
                }
            }
        }
    }
}
