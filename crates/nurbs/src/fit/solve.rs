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
