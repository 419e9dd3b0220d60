//! Least squares with a banded matrix by Givens QR: the projection onto a B-spline space
//! that reverse-motion smoothing repeats for every shift-and-smooth iteration.
//!
//! A B-spline collocation matrix `A` (`m × k`, `A[i][j] = N_j(t_i)`) has at most `w = p + 1`
//! non-zeros per row, in consecutive columns. Its QR factorisation by Givens rotations,
//! taking the rows one at a time, keeps `R` (`k × k`, upper triangular) within the same
//! band: eliminating a row's leading entry against row `j` of `R` leaves the row's other
//! entries in columns `j + 1 … j + w − 1`, which row `j + 1` of `R` covers (Golub & Van Loan,
//! *Matrix Computations*, §5.2.5 and the banded case of §5.3). The rotations are recorded, so
//! a right-hand side is reduced in O(m·w) and the least-squares solution follows by
//! back substitution in O(k·w): the same solution as an SVD or dense QR of `A` when `A` has
//! full column rank (backward stable like them), at O(m·w²) to factor instead of O(m·k²).
//!
//! The rank test of the callers (smallest singular value at least 10⁻¹⁰ of the largest) reads
//! the singular values of `R`, which are those of `A` (`A = QR`, `Q` orthogonal): O(k³)
//! for the `k × k` triangle instead of O(m·k²) for `A`.

use nalgebra::DMatrix;

/// Widest band handled (cubic B-splines have 4 non-zeros per row).
pub const MAX_BAND: usize = 4;

/// A row of a banded matrix: its first non-zero column and the values from there (entries
/// past the band are zero).
pub type BandRow = (usize, [f64; MAX_BAND]);

/// One step of the reduction of a right-hand-side entry (see [`BandedQr::reduce`]).
#[derive(Debug, Clone, Copy)]
enum Step {
    /// Rotate the entry against row `j` of `R` (`c`, `s`: the Givens pair).
    Rotate { j: usize, c: f64, s: f64 },
    /// The entry becomes row `j`'s (the row of `A` filled an empty row of `R`).
    Place { j: usize },
    /// The entry is done (what is left is residual).
    End,
}

/// The Givens QR of a banded `m × k` matrix (rows given as their first column and `w`
/// values), with the rotations kept to reduce right-hand sides.
#[derive(Debug, Clone)]
pub struct BandedQr {
    k: usize,
    w: usize,
    /// `r[j·w + d] = R(j, j + d)`.
    r: Vec<f64>,
    filled: Vec<bool>,
    steps: Vec<Step>,
}

impl BandedQr {
    /// Factors the matrix whose row `i` has the values `rows[i].1[..w]` in columns
    /// `rows[i].0 …` (entries at columns `≥ k` must be zero and are ignored). `w` must be
    /// at most [`MAX_BAND`]. O(m·w²).
    pub fn new(k: usize, w: usize, rows: impl IntoIterator<Item = BandRow>) -> Self {
        let w = w.clamp(1, MAX_BAND);
        let mut qr = Self {
            k,
            w,
            r: vec![0.0; k * w],
            filled: vec![false; k],
            steps: Vec::new(),
        };
        for (first, values) in rows {
            qr.add_row(first, values);
        }
        qr
    }

    fn add_row(&mut self, first: usize, values: [f64; MAX_BAND]) {
        let w = self.w;
        let mut row = values;
        let mut j = first;
        while j < self.k {
            if row[0] != 0.0 {
                let base = j * w;
                if !self.filled[j] {
                    self.r[base..base + w].copy_from_slice(&row[..w]);
                    self.filled[j] = true;
                    self.steps.push(Step::Place { j });
                    self.steps.push(Step::End);
                    return;
                }
                let (a, b) = (self.r[base], row[0]);
                let h = a.hypot(b);
                let (c, s) = (a / h, b / h);
                for (rv, xv) in self.r[base..base + w].iter_mut().zip(row.iter_mut()) {
                    let (x, y) = (*rv, *xv);
                    *rv = c * x + s * y;
                    *xv = -s * x + c * y;
                }
                self.steps.push(Step::Rotate { j, c, s });
            } else if row[..w].iter().all(|v| *v == 0.0) {
                break;
            }
            // The leading entry is zero now: the row starts one column further.
            row.copy_within(1..w, 0);
            row[w - 1] = 0.0;
            j += 1;
        }
        self.steps.push(Step::End);
    }

    /// Whether every row of `R` holds a pivot (else `A` is rank deficient).
    pub fn is_complete(&self) -> bool {
        self.filled.iter().all(|f| *f)
    }

    /// `R` as a dense `k × k` matrix.
    pub fn r_dense(&self) -> DMatrix<f64> {
        DMatrix::from_fn(self.k, self.k, |i, j| {
            if j >= i && j - i < self.w {
                self.r[i * self.w + (j - i)]
            } else {
                0.0
            }
        })
    }

    /// The least-squares solution `x` of `A x ≈ y` (`y` one value per row of `A`, in the
    /// order given to [`BandedQr::new`]); `None` when `R` has a zero pivot or `y` has the
    /// wrong length. O(m·w + k·w).
    pub fn solve(&self, y: &[f64]) -> Option<Vec<f64>> {
        let mut z = vec![0.0; self.k];
        let mut rows = y.iter();
        let mut cur = *rows.next()?;
        let mut left = y.len();
        for step in &self.steps {
            match *step {
                Step::Rotate { j, c, s } => {
                    let zj = z[j];
                    z[j] = c * zj + s * cur;
                    cur = -s * zj + c * cur;
                }
                Step::Place { j } => z[j] = cur,
                Step::End => {
                    left -= 1;
                    if left > 0 {
                        cur = *rows.next()?;
                    }
                }
            }
        }
        if left != 0 {
            return None;
        }
        let w = self.w;
        let mut x = vec![0.0; self.k];
        for j in (0..self.k).rev() {
            let mut v = z[j];
            for d in 1..w.min(self.k - j) {
                v -= self.r[j * w + d] * x[j + d];
            }
            let pivot = self.r[j * w];
            if pivot == 0.0 || !pivot.is_finite() {
                return None;
            }
            x[j] = v / pivot;
        }
        Some(x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DVector;

    /// A banded test matrix: row `i` has `w` values from column `first(i)`.
    fn banded(m: usize, k: usize, w: usize) -> Vec<BandRow> {
        (0..m)
            .map(|i| {
                let first = (i * (k - w + 1)) / m;
                let mut v = [0.0; MAX_BAND];
                for (d, x) in v.iter_mut().enumerate().take(w) {
                    *x = 1.0 + ((i * 7 + d * 3) % 11) as f64 / 5.0 - d as f64 * 0.3;
                }
                (first, v)
            })
            .collect()
    }

    fn dense(rows: &[BandRow], k: usize, w: usize) -> DMatrix<f64> {
        let mut a = DMatrix::zeros(rows.len(), k);
        for (i, (first, v)) in rows.iter().enumerate() {
            for d in 0..w {
                if first + d < k {
                    a[(i, first + d)] = v[d];
                }
            }
        }
        a
    }

    #[test]
    fn solution_and_singular_values_match_the_dense_svd() {
        for (m, k, w) in [(40, 12, 4), (9, 9, 4), (25, 6, 3), (17, 5, 2)] {
            let rows = banded(m, k, w);
            let a = dense(&rows, k, w);
            let y: Vec<f64> = (0..m)
                .map(|i| (i as f64 * 0.37).sin() + 0.1 * i as f64)
                .collect();
            let qr = BandedQr::new(k, w, rows.iter().copied());
            assert!(qr.is_complete());
            let x = qr.solve(&y).unwrap();
            let svd = a.clone().svd(true, true);
            let want = svd.solve(&DVector::from_column_slice(&y), 1e-14).unwrap();
            for (p, q) in x.iter().zip(want.iter()) {
                assert!(
                    (p - q).abs() <= 1e-10 * (1.0 + q.abs()),
                    "{m}×{k}: {p} vs {q}"
                );
            }
            let mut s1: Vec<f64> = qr.r_dense().singular_values().iter().copied().collect();
            let mut s2: Vec<f64> = a.singular_values().iter().copied().collect();
            s1.sort_by(f64::total_cmp);
            s2.sort_by(f64::total_cmp);
            for (p, q) in s1.iter().zip(&s2) {
                assert!((p - q).abs() <= 1e-12 * s2[s2.len() - 1], "{p} vs {q}");
            }
        }
    }

    #[test]
    fn a_column_without_entries_is_rank_deficient() {
        // Column 3 of 6 is never touched.
        let rows: Vec<BandRow> = (0..12)
            .map(|i| {
                (
                    if i < 6 { 0 } else { 4 },
                    [1.0, 0.5 + i as f64 * 0.1, 0.0, 0.0],
                )
            })
            .collect();
        let qr = BandedQr::new(6, 2, rows);
        assert!(!qr.is_complete());
    }
}
