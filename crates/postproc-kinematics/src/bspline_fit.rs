//! Least-squares fitting of a scalar sequence by a clamped uniform cubic B-spline (the
//! smoothing step of paper 004's reverse-motion removal, which uses four cubic B-spline basis
//! functions), with evaluation and a monotone projection of the control points.
//!
//! Basis by the Cox–de Boor recursion (NURBS Book A2.2); the normal equations are replaced by
//! an SVD-based least-squares solve of the `m × n` collocation matrix (nalgebra, `n` small),
//! cost O(m·n²). Reverse-motion smoothing, which refits many long runs, factors the banded
//! collocation matrix by Givens rotations instead ([`crate::banded_lsq`]).

use crate::banded_lsq::BandRow;
use nalgebra::{DMatrix, DVector};

/// A scalar clamped uniform B-spline on `[0, 1]`.
#[derive(Debug, Clone, PartialEq)]
pub struct ScalarBSpline {
    degree: usize,
    knots: Vec<f64>,
    ctrl: Vec<f64>,
}

impl ScalarBSpline {
    /// Degree.
    pub fn degree(&self) -> usize {
        self.degree
    }
    /// Control values.
    pub fn control_points(&self) -> &[f64] {
        &self.ctrl
    }
    /// Replaces the control values (same count).
    pub fn with_control_points(&self, ctrl: Vec<f64>) -> Option<Self> {
        (ctrl.len() == self.ctrl.len()).then(|| Self {
            degree: self.degree,
            knots: self.knots.clone(),
            ctrl,
        })
    }

    /// Value at `t ∈ [0, 1]` (clamped).
    pub fn eval(&self, t: f64) -> f64 {
        let mut n = [0.0; 4];
        let span = find_span(&self.knots, self.degree, self.ctrl.len(), t);
        basis(&self.knots, self.degree, span, t.clamp(0.0, 1.0), &mut n);
        (0..=self.degree)
            .map(|i| n[i] * self.ctrl[span - self.degree + i])
            .sum()
    }

    /// Projects the control values onto a monotone sequence (running maximum for
    /// `direction > 0`, running minimum otherwise). By the variation-diminishing property the
    /// spline is then monotone in that direction.
    pub fn monotone(&self, direction: f64) -> Self {
        let mut c = self.ctrl.clone();
        for i in 1..c.len() {
            c[i] = if direction > 0.0 {
                c[i].max(c[i - 1])
            } else {
                c[i].min(c[i - 1])
            };
        }
        Self {
            degree: self.degree,
            knots: self.knots.clone(),
            ctrl: c,
        }
    }
}

fn find_span(knots: &[f64], p: usize, n_ctrl: usize, t: f64) -> usize {
    let n = n_ctrl - 1;
    if t >= knots[n + 1] {
        return n;
    }
    if t <= knots[p] {
        return p;
    }
    let (mut lo, mut hi) = (p, n + 1);
    let mut mid = (lo + hi) / 2;
    while t < knots[mid] || t >= knots[mid + 1] {
        if t < knots[mid] {
            hi = mid;
        } else {
            lo = mid;
        }
        mid = (lo + hi) / 2;
    }
    mid
}

fn basis(knots: &[f64], p: usize, span: usize, t: f64, n: &mut [f64; 4]) {
    let mut left = [0.0; 4];
    let mut right = [0.0; 4];
    n[0] = 1.0;
    for j in 1..=p {
        left[j] = t - knots[span + 1 - j];
        right[j] = knots[span + j] - t;
        let mut saved = 0.0;
        for r in 0..j {
            let den = right[r + 1] + left[j - r];
            let temp = if den != 0.0 { n[r] / den } else { 0.0 };
            n[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        n[j] = saved;
    }
}

/// The clamped uniform B-spline of [`fit_least_squares`] for `m` samples and `n_ctrl`
/// control values (all zero) and its collocation matrix at `t` (`m × n`,
/// `A[i][j] = N_j(t_i)`, banded: p + 1 non-zeros per row). `None` without samples.
/// Cost O(m·p²) plus the O(m·n) zeroed matrix.
pub(crate) fn collocation(t: &[f64], n_ctrl: usize) -> Option<(ScalarBSpline, DMatrix<f64>)> {
    let (spline, rows) = collocation_rows(t, n_ctrl)?;
    let (n, p) = (spline.ctrl.len(), spline.degree);
    let mut a = DMatrix::<f64>::zeros(t.len(), n);
    for (row, (first, nb)) in rows.iter().enumerate() {
        for i in 0..=p {
            a[(row, first + i)] = nb[i];
        }
    }
    Some((spline, a))
}

/// [`collocation`] by rows: for each parameter, the first column of its `p + 1` non-zeros
/// and their values (the rest of the row is zero). O(m·p²).
pub(crate) fn collocation_rows(t: &[f64], n_ctrl: usize) -> Option<(ScalarBSpline, Vec<BandRow>)> {
    let m = t.len();
    let n = n_ctrl.min(m).max(1);
    if m == 0 {
        return None;
    }
    let p = 3.min(n - 1);
    let inner = n - p - 1;
    let mut knots = vec![0.0; p + 1];
    knots.extend((1..=inner).map(|i| i as f64 / (inner + 1) as f64));
    knots.extend(std::iter::repeat_n(1.0, p + 1));
    let rows = t
        .iter()
        .map(|&ti| {
            let span = find_span(&knots, p, n, ti);
            let mut nb = [0.0; 4];
            basis(&knots, p, span, ti.clamp(0.0, 1.0), &mut nb);
            (span - p, nb)
        })
        .collect();
    let spline = ScalarBSpline {
        degree: p,
        knots,
        ctrl: vec![0.0; n],
    };
    Some((spline, rows))
}

/// Least-squares fit of values `y` at parameters `t ∈ [0,1]` by a clamped uniform B-spline of
/// degree `min(3, n_ctrl − 1)` with `n_ctrl` control values (`n_ctrl` is reduced to the
/// number of samples). `None` when there are no samples or the system is rank deficient
/// (smallest singular value of the collocation matrix below 10⁻¹⁰ of the largest).
pub fn fit_least_squares(t: &[f64], y: &[f64], n_ctrl: usize) -> Option<ScalarBSpline> {
    let m = t.len().min(y.len());
    let (mut spline, a) = collocation(&t[..m], n_ctrl)?;
    let b = DVector::from_column_slice(&y[..m]);
    let svd = a.svd(true, true);
    let smax = svd.singular_values.max();
    if smax.is_nan() || smax <= 0.0 || svd.singular_values.min() < 1e-10 * smax {
        return None;
    }
    let x = svd.solve(&b, 1e-12 * smax).ok()?;
    spline.ctrl = x.iter().copied().collect();
    Some(spline)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reproduces_a_cubic_exactly() {
        // a cubic polynomial lies in the span of any clamped cubic B-spline basis
        let f = |t: f64| 2.0 - 3.0 * t + 5.0 * t * t - 4.0 * t * t * t;
        let t: Vec<f64> = (0..40).map(|i| (i as f64 / 39.0).powf(1.3)).collect();
        let y: Vec<f64> = t.iter().map(|&x| f(x)).collect();
        for n in [4, 6, 9] {
            let s = fit_least_squares(&t, &y, n).unwrap();
            assert_eq!(s.degree(), 3);
            for k in 0..=100 {
                let x = k as f64 / 100.0;
                assert!((s.eval(x) - f(x)).abs() < 1e-10, "n={n} x={x}");
            }
        }
    }

    #[test]
    fn monotone_projection_gives_monotone_curve() {
        let t: Vec<f64> = (0..50).map(|i| i as f64 / 49.0).collect();
        let y: Vec<f64> = t.iter().map(|&x| x + 0.3 * (9.0 * x).sin()).collect();
        let s = fit_least_squares(&t, &y, 8).unwrap().monotone(1.0);
        let v: Vec<f64> = (0..=500).map(|k| s.eval(k as f64 / 500.0)).collect();
        assert!(v.windows(2).all(|w| w[1] >= w[0] - 1e-12));
        let s = fit_least_squares(&t, &y, 8).unwrap().monotone(-1.0);
        let v: Vec<f64> = (0..=500).map(|k| s.eval(k as f64 / 500.0)).collect();
        assert!(v.windows(2).all(|w| w[1] <= w[0] + 1e-12));
    }

    #[test]
    fn rank_deficient_fit_is_refused() {
        // all samples at one parameter cannot determine four control values
        let t = vec![0.5; 10];
        let y = vec![1.0; 10];
        assert!(fit_least_squares(&t, &y, 4).is_none());
        assert!(fit_least_squares(&[], &[], 4).is_none());
    }
}
