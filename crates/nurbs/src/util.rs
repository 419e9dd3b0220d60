//! Small shared helpers: binomial coefficients and homogeneous-coordinate packing.

use nalgebra::SVector;

/// Binomial coefficient `C(n, k)` as `f64` (exact for the small orders used here).
#[inline]
pub(crate) fn binomial(n: usize, k: usize) -> f64 {
    if k > n {
        return 0.0;
    }
    let k = k.min(n - k);
    let mut r = 1.0;
    for i in 0..k {
        r = r * (n - i) as f64 / (i + 1) as f64;
    }
    r.round()
}

/// Packs control points (and weights) into a flat array: `(w P, w)` with stride `D + 1`
/// when weights are given, plain `P` with stride `D` otherwise.
pub(crate) fn to_homogeneous<const D: usize>(
    ctrl: &[SVector<f64, D>],
    weights: Option<&[f64]>,
) -> Vec<f64> {
    match weights {
        None => ctrl.iter().flat_map(|p| p.iter().copied()).collect(),
        Some(w) => {
            let mut out = Vec::with_capacity(ctrl.len() * (D + 1));
            for (p, &wi) in ctrl.iter().zip(w) {
                out.extend(p.iter().map(|c| c * wi));
                out.push(wi);
            }
            out
        }
    }
}

/// Inverse of [`to_homogeneous`].
pub(crate) fn split_homogeneous<const D: usize>(
    data: &[f64],
    rational: bool,
) -> (Vec<SVector<f64, D>>, Option<Vec<f64>>) {
    if rational {
        let mut ctrl = Vec::with_capacity(data.len() / (D + 1));
        let mut w = Vec::with_capacity(data.len() / (D + 1));
        for chunk in data.chunks_exact(D + 1) {
            let wi = chunk[D];
            ctrl.push(SVector::<f64, D>::from_fn(|r, _| chunk[r] / wi));
            w.push(wi);
        }
        (ctrl, Some(w))
    } else {
        let ctrl = data
            .chunks_exact(D)
            .map(|chunk| SVector::<f64, D>::from_fn(|r, _| chunk[r]))
            .collect();
        (ctrl, None)
    }
}
