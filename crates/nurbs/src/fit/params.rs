//! Parameter values for data points and knot vectors derived from them (NURBS Book §9.2.1,
//! eqs. 9.4–9.8, and §9.4.1, eq. 9.69).

use nalgebra::SVector;

use super::FitError;

/// How parameter values are assigned to data points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Parametrisation {
    /// Equally spaced parameters (eq. 9.3). Ignores the point spacing.
    Uniform,
    /// Parameters proportional to accumulated chord length (eq. 9.5). The usual choice.
    #[default]
    ChordLength,
    /// Parameters proportional to accumulated square roots of chord lengths (eq. 9.6, Lee's
    /// centripetal method); better for data with sharp turns.
    Centripetal,
}

/// Checks that every point is finite.
pub(crate) fn check_finite<const D: usize>(points: &[SVector<f64, D>]) -> Result<(), FitError> {
    match points.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
        Some(index) => Err(FitError::NonFinitePoint { index }),
        None => Ok(()),
    }
}

/// Parameter values `ū_0 = 0 < … < ū_m = 1` for `points` (NURBS Book eqs. 9.3, 9.5, 9.6).
///
/// Errors: fewer than two points, a non-finite point, or (for chord-length and centripetal
/// parameters) two consecutive coincident points. O(m).
pub fn parameters<const D: usize>(
    points: &[SVector<f64, D>],
    method: Parametrisation,
) -> Result<Vec<f64>, FitError> {
    if points.len() < 2 {
        return Err(FitError::TooFewPoints {
            what: "points",
            needed: 2,
            got: points.len(),
        });
    }
    check_finite(points)?;
    let m = points.len() - 1;
    if method == Parametrisation::Uniform {
        return Ok((0..=m).map(|k| k as f64 / m as f64).collect());
    }
    let mut acc = Vec::with_capacity(m + 1);
    acc.push(0.0);
    let mut total = 0.0;
    for (k, w) in points.windows(2).enumerate() {
        let chord = (w[1] - w[0]).norm();
        if chord <= 0.0 {
            return Err(FitError::CoincidentPoints { index: k });
        }
        total += match method {
            Parametrisation::Centripetal => chord.sqrt(),
            _ => chord,
        };
        acc.push(total);
    }
    for a in acc.iter_mut() {
        *a /= total;
    }
    acc[m] = 1.0;
    Ok(acc)
}

/// Clamped knot vector on [0, 1] for global interpolation, by averaging `degree`
/// consecutive parameters.
///
/// Without end derivatives (`n_ctrl = params.len()`, NURBS Book eq. 9.8):
/// `u_{j+p} = (1/p) Σ_{i=j}^{j+p-1} ū_i`, `j = 1..=n-p`.
/// With both end derivatives (`n_ctrl = params.len() + 2`, eq. 9.22):
/// `u_{j+p+1} = (1/p) Σ_{i=j}^{j+p-1} ū_i`, `j = 0..=n-p+1`.
/// Averaging makes every basis function's support contain a parameter (Schoenberg–Whitney),
/// so the interpolation matrix is regular and banded. Requires `params.len() >= degree`.
pub fn averaged_knots(params: &[f64], degree: usize, end_derivatives: bool) -> Vec<f64> {
    let p = degree;
    let n_ctrl = if end_derivatives {
        params.len() + 2
    } else {
        params.len()
    };
    let first = usize::from(!end_derivatives);
    let mut knots = Vec::with_capacity(n_ctrl + p + 1);
    knots.extend(std::iter::repeat_n(0.0, p + 1));
    for j in 0..n_ctrl.saturating_sub(p + 1) {
        let start = j + first;
        let s: f64 = params[start..start + p].iter().sum();
        knots.push(s / p as f64);
    }
    knots.extend(std::iter::repeat_n(1.0, p + 1));
    knots
}

/// Clamped knot vector on [0, 1] for least-squares approximation with `n_ctrl` control
/// points of the data with parameters `params` (NURBS Book eq. 9.69): with `d = (m+1)/(n-p+1)`,
/// `u_{p+j} = (1-α) ū_{i-1} + α ū_i`, `i = ⌊j d⌋`, `α = j d - i`. Every knot span then
/// contains at least one parameter, which keeps the normal matrix regular.
pub(crate) fn approximation_knots(params: &[f64], degree: usize, n_ctrl: usize) -> Vec<f64> {
    let p = degree;
    let n = n_ctrl - 1;
    let m = params.len() - 1;
    let mut knots = Vec::with_capacity(n_ctrl + p + 1);
    knots.extend(std::iter::repeat_n(0.0, p + 1));
    let d = (m + 1) as f64 / (n - p + 1) as f64;
    for j in 1..=(n - p) {
        let jd = j as f64 * d;
        let i = (jd.floor() as usize).clamp(1, m);
        let alpha = jd - i as f64;
        knots.push((1.0 - alpha) * params[i - 1] + alpha * params[i]);
    }
    knots.extend(std::iter::repeat_n(1.0, p + 1));
    knots
}
