//! Surface–surface intersection by marching from certified start points, and the offset of a
//! curve lying on a surface.
//!
//! # Intersection ([`intersect_surfaces`])
//! The classic subdivision + marching scheme (Barnhill & Kersey 1990; Patrikalakis &
//! Maekawa, *Shape Interrogation for Computer Aided Design and Manufacturing*, §5.8):
//!
//! 1. **Seeding (certified).** Both surfaces are cut, inside the caller's parameter boxes, into
//!    sub-surfaces by knot insertion (A5.3); the control points of a sub-surface bound it
//!    (convex-hull property, positive weights), so two sub-surfaces whose control-point boxes
//!    are disjoint cannot intersect. Overlapping pairs are split (the one with the larger box,
//!    across its longer parameter side) until both boxes are smaller than
//!    [`SsiOptions::seed_size`]. Every intersection point lies in some surviving leaf pair.
//! 2. **Refinement.** From the centres of each leaf pair, a Gauss–Newton iteration on
//!    `S_a(u_a, v_a) − S_b(u_b, v_b) = 0` (3 equations, 4 unknowns; minimum-norm step from the
//!    SVD) converges to a point of the intersection — quadratically where the surfaces cross,
//!    linearly where they touch.
//! 3. **Marching.** From each start point not already on a traced branch, the branch is traced
//!    in both directions: predictor along the tangent `t = n_a × n_b`, corrector by Newton on
//!    the three equations plus the plane `(X − X_pred)·t = 0`. The step is `h = √(8 ε / κ)`
//!    (`ε` = [`SsiOptions::chord_tol`], κ the curvature of the intersection curve from the two
//!    normal curvatures, Patrikalakis & Maekawa eq. 5.83), clamped to
//!    `[min_step, max_step]`, and halved when the corrector fails or the tangent turns by more
//!    than [`MAX_TURN_RAD`]. Near tangency (`|n_a × n_b| <` [`TANGENT_SIN`]) the tangent is the
//!    direction of second-order contact: the null direction of the difference of the two
//!    second fundamental forms (a tangential intersection curve, e.g. two touching cylinders);
//!    an elliptic difference means an isolated touching point, reported as such.
//! 4. **Termination.** A branch ends where it leaves either parameter box (the last point is
//!    put on the box side by Newton with that parameter fixed), where it closes on its start
//!    point (a loop), or where the step falls below `min_step` (reported).
//! 5. **Result.** Each branch's marched points (every one within [`SsiOptions::point_tol`] of
//!    both surfaces: `|S_a − S_b| ≤ point_tol`) and a cubic NURBS curve fitted through them
//!    by least squares (§9.4.1, at most half as many control points as points, so it cannot
//!    oscillate between them, else the interpolant) within [`SsiOptions::fit_tol`] at
//!    the points; between points the curve deviates from the true intersection by at most
//!    `fit_tol + chord_tol` (the chord sagitta is bounded by the step rule).
//!
//! Cost: seeding O(L / seed_size) leaf pairs for a branch of length L (plus the subdivision
//! tree above them); marching O(L / h) steps of a few Newton iterations, each two surface
//! evaluations with second derivatives.
//!
//! # Offset of a curve on a surface ([`offset_curve_on_surface`])
//! See its docs.

mod march;
mod offset_curve;
mod seed;

pub use march::{BranchEnd, IntersectionBranch, IntersectionPoint};
pub use offset_curve::{offset_curve_on_surface, OffsetCurve, OffsetCurveError};

use crate::fit::FitError;
use crate::{NurbsError, NurbsSurface};

/// Near-tangency threshold on `|n_a × n_b|` (sine of the angle between the unit normals).
/// Below it the cross product no longer gives a reliable tangent (a converged point on a
/// tangential intersection has normals parallel to ~√(residual·κ) ≈ 1e-6), so the
/// second-order contact direction is used instead.
pub const TANGENT_SIN: f64 = 1e-4;

/// Largest turn of the curve tangent accepted in one marching step (radians); a larger turn
/// means the step jumped or cut a corner, so it is halved.
pub const MAX_TURN_RAD: f64 = 0.35;

/// Largest number of overlapping leaf pairs the seeding keeps. More means the surfaces
/// coincide over an area, or `seed_size` is far too small for the boxes.
pub const MAX_LEAF_PAIRS: usize = 200_000;

/// A rectangle of parameters `[u0, u1] × [v0, v1]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamBox {
    /// `(u0, u1)`, `u0 < u1`.
    pub u: (f64, f64),
    /// `(v0, v1)`, `v0 < v1`.
    pub v: (f64, f64),
}

impl ParamBox {
    /// The whole domain of `s`.
    pub fn of(s: &NurbsSurface) -> Self {
        let (u, v) = s.domain();
        Self { u, v }
    }

    /// Whether `(u, v)` lies in the box (with a relative slack of 1e-12 of its size).
    pub fn contains(&self, u: f64, v: f64) -> bool {
        let eu = 1e-12 * (self.u.1 - self.u.0);
        let ev = 1e-12 * (self.v.1 - self.v.0);
        u >= self.u.0 - eu && u <= self.u.1 + eu && v >= self.v.0 - ev && v <= self.v.1 + ev
    }

    fn centre(&self) -> (f64, f64) {
        (0.5 * (self.u.0 + self.u.1), 0.5 * (self.v.0 + self.v.1))
    }
}

/// Tolerances and step limits of [`intersect_surfaces`] (lengths in the surfaces' units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SsiOptions {
    /// Largest `|S_a − S_b|` of an accepted intersection point.
    pub point_tol: f64,
    /// Chordal deviation of the marching polyline from the curve (sets the step from the
    /// curvature).
    pub chord_tol: f64,
    /// Largest deviation of the fitted NURBS curve from the marched points.
    pub fit_tol: f64,
    /// Smallest marching step; a branch that needs less ends there ([`BranchEnd::StepFailure`]).
    pub min_step: f64,
    /// Largest marching step.
    pub max_step: f64,
    /// Size of the leaf boxes of the seeding subdivision. Closed branches smaller than about
    /// this may be missed only if Newton from the leaf does not reach them.
    pub seed_size: f64,
    /// Largest number of points of one branch.
    pub max_points: usize,
}

impl Default for SsiOptions {
    fn default() -> Self {
        Self {
            point_tol: 1e-9,
            chord_tol: 1e-3,
            fit_tol: 1e-4,
            min_step: 1e-6,
            max_step: 2.0,
            seed_size: 2.0,
            max_points: 100_000,
        }
    }
}

/// Why an intersection could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IntersectError {
    /// A parameter box or option is invalid.
    #[error("invalid {what}: {reason}")]
    Invalid {
        /// Which input.
        what: &'static str,
        /// Why.
        reason: String,
    },
    /// The seeding found too many overlapping pairs (the surfaces coincide over an area).
    #[error("more than {limit} overlapping sub-surface pairs: the surfaces probably coincide over an area")]
    TooManyPairs {
        /// [`MAX_LEAF_PAIRS`].
        limit: usize,
    },
    /// Knot insertion failed.
    #[error(transparent)]
    Nurbs(#[from] NurbsError),
    /// The curve fit failed.
    #[error("fitting intersection branch {branch}: {source}")]
    Fit {
        /// Index of the branch.
        branch: usize,
        /// The fit error.
        source: FitError,
    },
}

/// The intersection of two surfaces inside their parameter boxes.
#[derive(Debug, Clone)]
pub struct Intersection {
    /// The curve branches.
    pub branches: Vec<IntersectionBranch>,
    /// Isolated touching points (elliptic tangency), not on any branch.
    pub touch_points: Vec<IntersectionPoint>,
}

fn check_box(s: &NurbsSurface, b: &ParamBox, what: &'static str) -> Result<(), IntersectError> {
    let ((u0, u1), (v0, v1)) = s.domain();
    let ok = b.u.0.is_finite()
        && b.u.1.is_finite()
        && b.v.0.is_finite()
        && b.v.1.is_finite()
        && b.u.0 < b.u.1
        && b.v.0 < b.v.1
        && b.u.0 >= u0 - 1e-12
        && b.u.1 <= u1 + 1e-12
        && b.v.0 >= v0 - 1e-12
        && b.v.1 <= v1 + 1e-12;
    if ok {
        Ok(())
    } else {
        Err(IntersectError::Invalid {
            what,
            reason: format!(
                "box u {:?} v {:?} must be non-empty and inside the domain u ({u0}, {u1}) v ({v0}, {v1})",
                b.u, b.v
            ),
        })
    }
}

fn check_options(o: &SsiOptions) -> Result<(), IntersectError> {
    let pos = |x: f64| x.is_finite() && x > 0.0;
    let ok = pos(o.point_tol)
        && pos(o.chord_tol)
        && pos(o.fit_tol)
        && pos(o.min_step)
        && pos(o.max_step)
        && pos(o.seed_size)
        && o.min_step <= o.max_step
        && o.max_points >= 2;
    if ok {
        Ok(())
    } else {
        Err(IntersectError::Invalid {
            what: "options",
            reason: format!(
                "tolerances, steps and seed size must be finite and > 0, min_step <= max_step, max_points >= 2: {o:?}"
            ),
        })
    }
}

/// Every branch of the intersection of `a` (inside `box_a`) and `b` (inside `box_b`); see the
/// module docs for the method, its tolerances and its cost.
///
/// Errors: invalid boxes or options; [`IntersectError::TooManyPairs`] where the surfaces
/// coincide over an area; a failed fit.
pub fn intersect_surfaces(
    a: &NurbsSurface,
    box_a: ParamBox,
    b: &NurbsSurface,
    box_b: ParamBox,
    opts: &SsiOptions,
) -> Result<Intersection, IntersectError> {
    check_box(a, &box_a, "box_a")?;
    check_box(b, &box_b, "box_b")?;
    check_options(opts)?;
    let seeds = seed::seeds(a, box_a, b, box_b, opts)?;
    march::trace_all(a, box_a, b, box_b, opts, seeds)
}

/// Cubic least-squares fit of dense, ordered `points` with the fewest control points (at most
/// half the points, so every knot span holds at least two data points and the fit cannot
/// oscillate between them) whose deviation at the points is at most `tol`; when even that
/// count misses `tol`, the cubic interpolant. Fewer than 4 points: the interpolant of degree
/// `len − 1`. O(log m) fits of O(m·n²) each.
pub(crate) fn fit_dense(
    points: &[nalgebra::Vector3<f64>],
    tol: f64,
) -> Result<crate::fit::CurveFit<3>, FitError> {
    use crate::fit::{approximate_curve, Parametrisation::ChordLength};
    let m = points.len();
    if m < 4 {
        return approximate_curve(points, m.saturating_sub(1).max(1), m, ChordLength);
    }
    let cap = (m / 2).max(4);
    let mut lo = 3; // fails (below the minimum count)
    let mut hi = 4;
    let mut best = loop {
        let fit = approximate_curve(points, 3, hi, ChordLength)?;
        if fit.max_error <= tol {
            break Some(fit);
        }
        if hi >= cap {
            break None;
        }
        lo = hi;
        hi = (2 * hi).min(cap);
    };
    let Some(mut fit) = best.take() else {
        return approximate_curve(points, 3, m, ChordLength);
    };
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        let f = approximate_curve(points, 3, mid, ChordLength)?;
        if f.max_error <= tol {
            hi = mid;
            fit = f;
        } else {
            lo = mid;
        }
    }
    Ok(fit)
}
