//! Dense least-squares / square solves with rank detection (faer column-pivoted QR).

use faer::linalg::solvers::SolveLstsq;
use faer::Mat;

use super::FitError;

/// Relative threshold on the diagonal of the column-pivoted `R` below which a column is
/// considered dependent.
const RANK_TOL: f64 = 1e-13;

/// Solves `A X = B` in the least-squares sense (exactly when `A` is square and regular).
///
/// Column-pivoted QR makes `|R_kk|` non-increasing, so the numerical rank is the number of
/// diagonal entries above `RANK_TOL · |R_00| · max(rows, cols)`. Cost O(rows · cols²).
pub(crate) fn solve_lstsq(a: &Mat<f64>, b: &Mat<f64>) -> Result<Mat<f64>, FitError> {
    let cols = a.ncols();
    if cols == 0 {
        return Ok(Mat::zeros(0, b.ncols()));
    }
    if a.nrows() < cols {
        return Err(FitError::SingularSystem {
            rank: a.nrows(),
            cols,
        });
    }
    let qr = a.col_piv_qr();
    let r = qr.R();
    let r00 = r[(0, 0)].abs();
    let thresh = RANK_TOL * r00 * (a.nrows().max(cols) as f64);
    let mut rank = 0;
    for k in 0..cols {
        let d = r[(k, k)].abs();
        if d.is_finite() && d > thresh && r00 > 0.0 {
            rank += 1;
        }
    }
    if rank < cols {
        return Err(FitError::SingularSystem { rank, cols });
    }
    let x = qr.solve_lstsq(b);
    if x.col_iter().any(|c| c.iter().any(|v| !v.is_finite())) {
        return Err(FitError::SingularSystem { rank: 0, cols });
    }
    Ok(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rank_deficiency_is_reported() {
        // Second column zero: rank 1 of 2.
        let a = Mat::from_fn(3, 2, |i, j| if j == 0 { 1.0 + i as f64 } else { 0.0 });
        let b = Mat::from_fn(3, 1, |i, _| i as f64);
        assert_eq!(
            solve_lstsq(&a, &b).unwrap_err(),
            FitError::SingularSystem { rank: 1, cols: 2 }
        );
        // Fewer rows than unknowns.
        let a = Mat::from_fn(1, 2, |_, j| 1.0 + j as f64);
        let b = Mat::from_fn(1, 1, |_, _| 1.0);
        assert!(matches!(
            solve_lstsq(&a, &b),
            Err(FitError::SingularSystem { .. })
        ));
        // A regular system is solved.
        let a = Mat::from_fn(2, 2, |i, j| if i == j { 2.0 } else { 0.0 });
        let b = Mat::from_fn(2, 1, |i, _| 4.0 * (i + 1) as f64);
        let x = solve_lstsq(&a, &b).unwrap();
        assert!((x[(0, 0)] - 2.0).abs() < 1e-15 && (x[(1, 0)] - 4.0).abs() < 1e-15);
    }
}
