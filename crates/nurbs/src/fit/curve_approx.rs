//! Least-squares curve approximation with fixed end points (NURBS Book §9.4.1) and its
//! smoothing (penalised) variant.

use faer::Mat;
use nalgebra::SVector;

use super::curve_interp::{basis_row, interpolate_curve};
use super::params::{approximation_knots, parameters};
use super::solve::solve_lstsq;
use super::{FitError, Parametrisation};
use crate::discretise::{GL8_W, GL8_X};
use crate::{KnotVector, NurbsCurve};

/// Result of a least-squares fit.
#[derive(Debug, Clone)]
pub struct CurveFit<const D: usize> {
    /// The fitted curve, parameter domain [0, 1], clamped, non-rational.
    pub curve: NurbsCurve<D>,
    /// Largest deviation `max_k |C(ū_k) − Q_k|` at the data parameters. This is an upper
    /// bound of the largest point-to-curve distance of the data.
    pub max_error: f64,
    /// The data parameters ū_k used.
    pub params: Vec<f64>,
}

/// The derivative whose squared norm is integrated as the smoothing energy.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Energy {
    /// `∫ |C'(u)|² du` — penalises length (a membrane); pulls towards the chord.
    FirstDerivative,
    /// `∫ |C''(u)|² du` — penalises bending (a thin beam); the usual smoothing spline.
    SecondDerivative,
}

impl Energy {
    fn order(self) -> usize {
        match self {
            Energy::FirstDerivative => 1,
            Energy::SecondDerivative => 2,
        }
    }
}

fn check_counts(len: usize, degree: usize, n_ctrl: usize) -> Result<(), FitError> {
    if degree == 0 {
        return Err(FitError::InvalidDegree { degree });
    }
    if len < degree + 1 {
        return Err(FitError::TooFewPoints {
            what: "points",
            needed: degree + 1,
            got: len,
        });
    }
    if n_ctrl < degree + 1 || n_ctrl > len {
        return Err(FitError::InvalidControlCount {
            n_ctrl,
            min: degree + 1,
            max: len,
        });
    }
    Ok(())
}

/// Core of the (penalised) least-squares fit with fixed end points.
fn fit_fixed_ends<const D: usize>(
    points: &[SVector<f64, D>],
    params: Vec<f64>,
    degree: usize,
    n_ctrl: usize,
    energy: Option<(Energy, f64)>,
) -> Result<CurveFit<D>, FitError> {
    let p = degree;
    let m = points.len() - 1;
    let n = n_ctrl - 1;
    let knots = approximation_knots(&params, p, n_ctrl);
    let kv = KnotVector::new(p, knots.clone())?;
    let (q0, qm) = (points[0], points[m]);
    let unknowns = n - 1;

    // Energy rows: Gauss nodes in each non-empty span, sqrt(λ w_g) N^{(r)}(u_g).
    let mut energy_rows: Vec<(f64, f64, usize)> = Vec::new();
    if let Some((e, lambda)) = energy {
        if lambda > 0.0 {
            let r = e.order();
            // 8-point Gauss–Legendre integrates the energy (degree 2(p−r)) exactly for p ≤ 8.
            let (xs, ws) = (&GL8_X, &GL8_W);
            for w in knots.windows(2) {
                let (a, b) = (w[0], w[1]);
                if b <= a {
                    continue;
                }
                let half = 0.5 * (b - a);
                for (x, wt) in xs.iter().zip(ws) {
                    let u = 0.5 * (a + b) + half * x;
                    energy_rows.push((u, (lambda * wt * half).sqrt(), r));
                }
            }
        }
    }

    let n_rows = m.saturating_sub(1) + energy_rows.len();
    let mut a = Mat::<f64>::zeros(n_rows, unknowns);
    let mut rhs = Mat::<f64>::zeros(n_rows, D);
    let mut row = vec![0.0; n_ctrl];
    let mut fill = |r: usize, u: f64, order: usize, scale: f64, target: SVector<f64, D>| {
        basis_row(&kv, u, order, &mut row);
        for c in 0..unknowns {
            a[(r, c)] = scale * row[c + 1];
        }
        let fixed = target * scale - (q0 * row[0] + qm * row[n]) * scale;
        for d in 0..D {
            rhs[(r, d)] = fixed[d];
        }
    };
    for k in 1..m {
        fill(k - 1, params[k], 0, 1.0, points[k]);
    }
    for (g, &(u, s, order)) in energy_rows.iter().enumerate() {
        fill(m.saturating_sub(1) + g, u, order, s, SVector::zeros());
    }
    let x = solve_lstsq(&a, &rhs)?;
    let mut ctrl = Vec::with_capacity(n_ctrl);
    ctrl.push(q0);
    for i in 0..unknowns {
        ctrl.push(SVector::<f64, D>::from_fn(|d, _| x[(i, d)]));
    }
    ctrl.push(qm);
    let curve = NurbsCurve::new(p, knots, ctrl, None)?;
    let max_error = params
        .iter()
        .zip(points)
        .map(|(&u, q)| (curve.point(u) - q).norm())
        .fold(0.0, f64::max);
    Ok(CurveFit {
        curve,
        max_error,
        params,
    })
}

/// Least-squares approximation of `points` by a clamped B-spline of `degree` with `n_ctrl`
/// control points that passes exactly through the first and last point (NURBS Book §9.4.1,
/// eqs. 9.63–9.69).
///
/// Minimises `Σ_{k=1}^{m-1} |Q_k − C(ū_k)|²` over the interior control points, with ū_k from
/// `parametrisation` and knots from eq. 9.69 (each span holds data). Solved by column-pivoted
/// QR on the `(m−1) × (n−1)` collocation matrix (better conditioned than the normal
/// equations of A9.7). `n_ctrl = points.len()` gives the interpolant. O(m·n²).
///
/// Errors: degree 0, too few points, `n_ctrl ∉ [degree+1, points.len()]`, non-finite or
/// coincident data.
pub fn approximate_curve<const D: usize>(
    points: &[SVector<f64, D>],
    degree: usize,
    n_ctrl: usize,
    parametrisation: Parametrisation,
) -> Result<CurveFit<D>, FitError> {
    check_counts(points.len(), degree, n_ctrl)?;
    let params = parameters(points, parametrisation)?;
    if n_ctrl == points.len() {
        let curve = interpolate_curve(points, degree, parametrisation, None)?;
        let max_error = params
            .iter()
            .zip(points)
            .map(|(&u, q)| (curve.point(u) - q).norm())
            .fold(0.0, f64::max);
        return Ok(CurveFit {
            curve,
            max_error,
            params,
        });
    }
    fit_fixed_ends(points, params, degree, n_ctrl, None)
}

/// Smoothing least squares: like [`approximate_curve`] but minimises
/// `Σ_{k=1}^{m-1} |Q_k − C(ū_k)|² + weight · ∫_0^1 |C^{(r)}(u)|² du` with `r` from `energy`
/// (a penalised spline). The integral is evaluated exactly (degree ≤ 8) by 8-point Gauss–Legendre per
/// knot span and appended as extra least-squares rows, so the same QR solve applies.
///
/// `weight ≥ 0` (mm² per unit energy; the parameter runs over [0, 1], so a curve of length
/// `L` has `∫|C'|² ≈ L²`): 0 reproduces [`approximate_curve`], large values give the
/// straightest / least-bent curve through the fixed ends. Data at end points is interpolated.
///
/// Errors: those of [`approximate_curve`], and a negative or non-finite `weight`.
pub fn smooth_curve<const D: usize>(
    points: &[SVector<f64, D>],
    degree: usize,
    n_ctrl: usize,
    parametrisation: Parametrisation,
    energy: Energy,
    weight: f64,
) -> Result<CurveFit<D>, FitError> {
    if !(weight.is_finite() && weight >= 0.0) {
        return Err(FitError::InvalidValue {
            field: "weight",
            value: weight,
            reason: "must be finite and >= 0",
        });
    }
    check_counts(points.len(), degree, n_ctrl)?;
    let params = parameters(points, parametrisation)?;
    fit_fixed_ends(points, params, degree, n_ctrl, Some((energy, weight)))
}

/// Least-squares approximation with the fewest control points whose deviation
/// `max_k |C(ū_k) − Q_k|` is at most `tol` (§9.4.1 with the control-point count searched).
///
/// The count is found by doubling from `degree + 1` and then bisection, assuming the error
/// decreases with the count (true in practice for dense data). `points.len()` control points
/// interpolate, so the tolerance is always met unless it lies below the interpolant's
/// round-off (~1e-12 relative), in which case the interpolant is returned. O(log m) fits.
///
/// Errors: `tol` not finite and positive, plus those of [`approximate_curve`].
pub fn approximate_curve_to_tolerance<const D: usize>(
    points: &[SVector<f64, D>],
    degree: usize,
    tol: f64,
    parametrisation: Parametrisation,
) -> Result<CurveFit<D>, FitError> {
    if !(tol.is_finite() && tol > 0.0) {
        return Err(FitError::InvalidValue {
            field: "tol",
            value: tol,
            reason: "must be finite and > 0",
        });
    }
    let max = points.len();
    let min = degree + 1;
    check_counts(max, degree, min.min(max))?;
    let first = approximate_curve(points, degree, min, parametrisation)?;
    if first.max_error <= tol {
        return Ok(first);
    }
    // Exponential search for a passing count.
    let mut lo = min;
    let mut hi = (2 * min).min(max);
    let mut best = loop {
        let fit = approximate_curve(points, degree, hi, parametrisation)?;
        if fit.max_error <= tol || hi == max {
            break fit;
        }
        lo = hi;
        hi = (2 * hi).min(max);
    };
    // Bisection on (lo, hi]: lo fails, hi passes.
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        let fit = approximate_curve(points, degree, mid, parametrisation)?;
        if fit.max_error <= tol {
            hi = mid;
            best = fit;
        } else {
            lo = mid;
        }
    }
    Ok(best)
}
