//! Banded elimination for B-spline interpolation (collocation at increasing sites).
//!
//! The collocation matrix `A_rk = N_k(ū_r)` of a degree-`p` B-spline basis at sites
//! `ū_0 ≤ … ≤ ū_{n−1}` has at most `p + 1` non-zeros per row, in columns
//! `span(ū_r) − p … span(ū_r)`, which never move left from one row to the next. When the
//! sites satisfy the Schoenberg–Whitney conditions (`N_r(ū_r) > 0`, which averaged knots,
//! NURBS Book eq. 9.8, guarantee) the matrix is totally positive, and Gaussian elimination
//! without pivoting is stable on it (de Boor, *A Practical Guide to Splines*, ch. XIII; The
//! NURBS Book §9.2.1 notes the band). Fill-in stays inside a window of `2p + 1` columns per
//! row. Cost O(n·p²) time and O(n·p) memory, against O(n³) and O(n²) for the dense QR it
//! replaces (4097 points: milliseconds instead of tens of seconds).

use nalgebra::SVector;

use crate::KnotVector;

/// A pivot smaller than this fraction of its row's largest entry sends the solve back to
/// the dense QR (the sites do not satisfy Schoenberg–Whitney to working precision).
const PIVOT_TOL: f64 = 1e-12;

/// Solves `Σ_k N_k(ū_r) P_k = Q_r` for the `n = sites.len()` control points `P_k` of the
/// basis `kv` (which must have exactly `n` basis functions), with `sites` non-decreasing.
/// `None` when a pivot is too small (see [`PIVOT_TOL`]) or the sites are out of order: the
/// caller then solves densely.
pub(crate) fn solve_collocation<const D: usize>(
    kv: &KnotVector,
    sites: &[f64],
    values: &[SVector<f64, D>],
) -> Option<Vec<SVector<f64, D>>> {
    let n = sites.len();
    let p = kv.degree();
    if n == 0 || values.len() != n || sites.windows(2).any(|w| w[1] < w[0]) {
        return None;
    }
    let w = 2 * p + 1;
    let mut band = vec![0.0; n * w];
    let mut lo = vec![0usize; n];
    let mut funs = vec![0.0; p + 1];
    for (r, &u) in sites.iter().enumerate() {
        let span = kv.find_span(u);
        let first = span.checked_sub(p)?;
        if span >= n {
            return None;
        }
        kv.basis_funs(span, u, &mut funs);
        lo[r] = first;
        band[r * w..r * w + p + 1].copy_from_slice(&funs);
    }
    if lo.windows(2).any(|l| l[1] < l[0]) {
        return None;
    }
    let mut b: Vec<SVector<f64, D>> = values.to_vec();
    for k in 0..n {
        let ok = k.checked_sub(lo[k]).filter(|&c| c < w)?;
        let row_k = &band[k * w..(k + 1) * w];
        let scale = row_k.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let piv = row_k[ok];
        if piv.is_nan() || piv.abs() <= PIVOT_TOL * scale {
            return None;
        }
        let pivot_row: Vec<f64> = row_k.to_vec();
        let last = (lo[k] + w).min(n);
        for i in k + 1..n {
            if lo[i] > k {
                break;
            }
            let base = i * w;
            let f = band[base + k - lo[i]] / piv;
            if f == 0.0 {
                continue;
            }
            // lo[i] ≥ lo[k], so column c of row k (c < lo[k] + w) lies in row i's window.
            for c in k..last {
                band[base + c - lo[i]] -= f * pivot_row[c - lo[k]];
            }
            let bk = b[k];
            b[i] -= bk * f;
        }
    }
    let mut x = vec![SVector::<f64, D>::zeros(); n];
    for k in (0..n).rev() {
        let row = &band[k * w..(k + 1) * w];
        let mut s = b[k];
        for c in k + 1..(lo[k] + w).min(n) {
            s -= x[c] * row[c - lo[k]];
        }
        x[k] = s / row[k - lo[k]];
    }
    x.iter()
        .all(|v| v.iter().all(|c| c.is_finite()))
        .then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::params::{averaged_knots, parameters};
    use crate::fit::solve::solve_lstsq;
    use crate::fit::Parametrisation;
    use faer::Mat;
    use proptest::prelude::*;

    /// The dense column-pivoted QR solve of the same collocation system.
    fn dense(kv: &KnotVector, sites: &[f64], values: &[SVector<f64, 3>]) -> Vec<SVector<f64, 3>> {
        let n = sites.len();
        let p = kv.degree();
        let mut a = Mat::<f64>::zeros(n, n);
        let mut b = Mat::<f64>::zeros(n, 3);
        let mut funs = vec![0.0; p + 1];
        for (r, &u) in sites.iter().enumerate() {
            let span = kv.find_span(u);
            kv.basis_funs(span, u, &mut funs);
            for (j, v) in funs.iter().enumerate() {
                a[(r, span - p + j)] = *v;
            }
            for d in 0..3 {
                b[(r, d)] = values[r][d];
            }
        }
        let x = solve_lstsq(&a, &b).unwrap();
        (0..n)
            .map(|i| SVector::<f64, 3>::new(x[(i, 0)], x[(i, 1)], x[(i, 2)]))
            .collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        /// The banded elimination gives the dense QR's control points (1e-9 of the data's
        /// size) for random data, degrees 1-5 and every parametrisation, and the curve
        /// passes through the points.
        #[test]
        fn banded_equals_dense_qr(
            pts in proptest::collection::vec((-50.0..50.0f64, -50.0..50.0f64, -50.0..50.0f64), 6..120),
            degree in 1usize..6,
            par in 0usize..3,
        ) {
            let points: Vec<SVector<f64, 3>> =
                pts.iter().map(|&(x, y, z)| SVector::<f64, 3>::new(x, y, z)).collect();
            prop_assume!(points.windows(2).all(|w| (w[1] - w[0]).norm() > 1e-3));
            let par = [Parametrisation::Uniform, Parametrisation::ChordLength, Parametrisation::Centripetal][par];
            let sites = parameters(&points, par).unwrap();
            let kv = KnotVector::new(degree, averaged_knots(&sites, degree, false)).unwrap();
            let banded = solve_collocation(&kv, &sites, &points).unwrap();
            let qr = dense(&kv, &sites, &points);
            let scale = points.iter().map(|p| p.amax()).fold(1.0, f64::max);
            for (a, b) in banded.iter().zip(&qr) {
                prop_assert!((a - b).amax() <= 1e-9 * scale, "{a:?} vs {b:?}");
            }
            let curve = crate::NurbsCurve::new(degree, kv.knots().to_vec(), banded, None).unwrap();
            for (u, q) in sites.iter().zip(&points) {
                prop_assert!((curve.point(*u) - q).amax() <= 1e-9 * scale);
            }
        }
    }

    /// The public interpolation takes the banded path from `BANDED_MIN_POINTS` points on: a
    /// helix of 1100 points is interpolated through every point (1e-9 mm) and agrees with
    /// the dense QR's control points (1e-9 of its size).
    #[test]
    fn large_interpolation_is_banded_and_exact() {
        let n = 1100;
        assert!(n >= crate::fit::BANDED_MIN_POINTS);
        let points: Vec<SVector<f64, 3>> = (0..n)
            .map(|k| {
                let t = k as f64 * 0.03;
                SVector::<f64, 3>::new(20.0 * t.cos(), 20.0 * t.sin(), 3.0 * t)
            })
            .collect();
        let curve =
            crate::fit::interpolate_curve(&points, 3, Parametrisation::ChordLength, None).unwrap();
        let sites = parameters(&points, Parametrisation::ChordLength).unwrap();
        for (u, q) in sites.iter().zip(&points) {
            assert!((curve.point(*u) - q).amax() <= 1e-9);
        }
        let kv = curve.knots().clone();
        let qr = dense(&kv, &sites, &points);
        for (a, b) in curve.control_points().iter().zip(&qr) {
            assert!((a - b).amax() <= 1e-9 * 100.0, "{a:?} vs {b:?}");
        }
    }

    /// Sites out of order are declined (the caller solves densely).
    #[test]
    fn unordered_sites_are_declined() {
        let kv = KnotVector::new(1, vec![0.0, 0.0, 0.5, 1.0, 1.0]).unwrap();
        let v = [SVector::<f64, 1>::new(0.0); 3];
        assert!(solve_collocation(&kv, &[0.0, 0.5, 1.0], &v).is_some());
        assert!(solve_collocation(&kv, &[0.5, 0.0, 1.0], &v).is_none());
    }
}
