//! Degree-specialised evaluation kernels. The public `point`/`derivs2` methods dispatch
//! here for degrees 1–3 in each direction (the common CAD cases), so loops over basis
//! functions have compile-time bounds and unroll; other degrees use the general code.
//! Same algorithms as the general path (A2.2, A2.3, A3.5/A4.3, A3.6/A4.4 to order 2).

use nalgebra::{SVector, Vector3};

use crate::knots::{find_span, KnotVector};
use crate::surface::SurfaceDerivs2;

/// A2.2 with the order `O = p + 1` fixed at compile time and the knot-difference
/// denominators taken from the precomputed reciprocals.
#[inline(always)]
pub(crate) fn basis<const O: usize>(kv: &KnotVector, span: usize, u: f64) -> [f64; O] {
    let knots = kv.knots();
    let mut n = [0.0; O];
    let mut left = [0.0; O];
    let mut right = [0.0; O];
    n[0] = 1.0;
    for j in 1..O {
        left[j] = u - knots[span + 1 - j];
        right[j] = knots[span + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            // right[r+1] + left[j-r] = u_{span+r+1} − u_{span+1−j+r}
            let temp = n[r] * kv.inv_diff(j, span + 1 - j + r);
            n[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        n[j] = saved;
    }
    n
}

/// Basis functions and their first and second derivatives for order `O = p + 1`:
/// `d[k][jj]` is the `k`-th derivative of `N_{span−p+jj, p}`. Same values as A2.3, written
/// with the textbook derivative formula (NURBS Book eq. 2.9 applied twice) on the
/// lower-degree functions of the A2.2 triangle and precomputed reciprocal knot differences
/// (no division).
#[inline(always)]
pub(crate) fn ders2_basis<const O: usize>(kv: &KnotVector, span: usize, u: f64) -> [[f64; O]; 3] {
    let knots = kv.knots();
    let p = O - 1;
    // ndu[r][j] = N_{span−j+r, j}(u)
    let mut ndu = [[0.0; O]; O];
    let mut left = [0.0; O];
    let mut right = [0.0; O];
    ndu[0][0] = 1.0;
    for j in 1..O {
        left[j] = u - knots[span + 1 - j];
        right[j] = knots[span + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            let temp = ndu[r][j - 1] * kv.inv_diff(j, span + 1 - j + r);
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    let mut d = [[0.0; O]; 3];
    let first = span - p;
    // n1[jj] = N_{first+jj, p−1}, n2[jj] = N_{first+jj, p−2} (zero outside the triangle)
    const PAD: usize = crate::MAX_ORDER + 3;
    let mut n1 = [0.0; PAD];
    let mut n2 = [0.0; PAD];
    for jj in 1..O {
        n1[jj] = ndu[jj - 1][p - 1];
    }
    if p >= 2 {
        for jj in 2..O {
            n2[jj] = ndu[jj - 2][p - 2];
        }
    }
    // e[jj] = N'_{first+jj, p−1}
    let mut e = [0.0; PAD];
    if p >= 2 {
        let q = (p - 1) as f64;
        for jj in 0..=O {
            e[jj] = q
                * (n2[jj] * kv.inv_diff(p - 1, first + jj)
                    - n2[jj + 1] * kv.inv_diff(p - 1, first + jj + 1));
        }
    }
    let pf = p as f64;
    for jj in 0..O {
        d[0][jj] = ndu[jj][p];
        let a0 = kv.inv_diff(p, first + jj);
        let a1 = kv.inv_diff(p, first + jj + 1);
        d[1][jj] = pf * (n1[jj] * a0 - n1[jj + 1] * a1);
        d[2][jj] = pf * (e[jj] * a0 - e[jj + 1] * a1);
    }
    d
}

/// Control data of a surface as the kernels see it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SurfaceView<'a> {
    pub ku: &'a KnotVector,
    pub kv: &'a KnotVector,
    pub n_v: usize,
    pub ctrl: &'a [Vector3<f64>],
    pub weights: Option<&'a [f64]>,
}

/// `S(u, v)` for orders `OU = p + 1`, `OV = q + 1` (parameters already clamped).
#[inline(always)]
pub(crate) fn surface_point<const OU: usize, const OV: usize>(
    s: SurfaceView<'_>,
    u: f64,
    v: f64,
) -> Vector3<f64> {
    let su = find_span(s.ku.knots(), OU - 1, u);
    let sv = find_span(s.kv.knots(), OV - 1, v);
    let nu = basis::<OU>(s.ku, su, u);
    let nv = basis::<OV>(s.kv, sv, v);
    let base = (su + 1 - OU) * s.n_v + (sv + 1 - OV);
    match s.weights {
        None => {
            let mut acc = Vector3::zeros();
            for i in 0..OU {
                let row = &s.ctrl[base + i * s.n_v..base + i * s.n_v + OV];
                let mut t = Vector3::zeros();
                for j in 0..OV {
                    t += row[j] * nv[j];
                }
                acc += t * nu[i];
            }
            acc
        }
        Some(w) => {
            let mut acc = Vector3::zeros();
            let mut wacc = 0.0;
            for i in 0..OU {
                let start = base + i * s.n_v;
                let row = &s.ctrl[start..start + OV];
                let wrow = &w[start..start + OV];
                let mut t = Vector3::zeros();
                let mut tw = 0.0;
                for j in 0..OV {
                    let bw = nv[j] * wrow[j];
                    t += row[j] * bw;
                    tw += bw;
                }
                acc += t * nu[i];
                wacc += tw * nu[i];
            }
            acc / wacc
        }
    }
}

/// Point and derivatives to order 2 for orders `OU`, `OV` (parameters already clamped).
#[inline(always)]
pub(crate) fn surface_derivs2<const OU: usize, const OV: usize>(
    s: SurfaceView<'_>,
    u: f64,
    v: f64,
) -> SurfaceDerivs2 {
    let (pu, pv) = (OU - 1, OV - 1);
    let su = find_span(s.ku.knots(), pu, u);
    let sv = find_span(s.kv.knots(), pv, v);
    let nu = ders2_basis::<OU>(s.ku, su, u);
    let nv = ders2_basis::<OV>(s.kv, sv, v);
    let base = (su - pu) * s.n_v + (sv - pv);
    let mut a = [[Vector3::<f64>::zeros(); 3]; 3];
    let Some(ws) = s.weights else {
        for i in 0..OU {
            let start = base + i * s.n_v;
            let row = &s.ctrl[start..start + OV];
            let (mut t0, mut t1, mut t2) = (Vector3::zeros(), Vector3::zeros(), Vector3::zeros());
            for j in 0..OV {
                t0 += row[j] * nv[0][j];
                t1 += row[j] * nv[1][j];
                t2 += row[j] * nv[2][j];
            }
            a[0][0] += t0 * nu[0][i];
            a[0][1] += t1 * nu[0][i];
            a[0][2] += t2 * nu[0][i];
            a[1][0] += t0 * nu[1][i];
            a[1][1] += t1 * nu[1][i];
            a[2][0] += t0 * nu[2][i];
        }
        return SurfaceDerivs2 {
            p: a[0][0],
            su: a[1][0],
            sv: a[0][1],
            suu: a[2][0],
            suv: a[1][1],
            svv: a[0][2],
        };
    };
    let mut w = [[0.0f64; 3]; 3];
    for i in 0..OU {
        let start = base + i * s.n_v;
        let row = &s.ctrl[start..start + OV];
        let wrow = &ws[start..start + OV];
        let mut t = [Vector3::<f64>::zeros(); 3];
        let mut tw = [0.0; 3];
        for j in 0..OV {
            let pw = row[j] * wrow[j];
            for l in 0..3 {
                t[l] += pw * nv[l][j];
                tw[l] += wrow[j] * nv[l][j];
            }
        }
        for k in 0..3 {
            let c = nu[k][i];
            for l in 0..(3 - k) {
                a[k][l] += t[l] * c;
                w[k][l] += tw[l] * c;
            }
        }
    }
    rational_correction(&a, &w)
}

/// A4.4 restricted to `k + l <= 2`: Euclidean derivatives from homogeneous ones.
#[inline(always)]
pub(crate) fn rational_correction(a: &[[Vector3<f64>; 3]; 3], w: &[[f64; 3]; 3]) -> SurfaceDerivs2 {
    let inv = 1.0 / w[0][0];
    let s00 = a[0][0] * inv;
    let s10 = (a[1][0] - s00 * w[1][0]) * inv;
    let s01 = (a[0][1] - s00 * w[0][1]) * inv;
    let s20 = (a[2][0] - s10 * (2.0 * w[1][0]) - s00 * w[2][0]) * inv;
    let s02 = (a[0][2] - s01 * (2.0 * w[0][1]) - s00 * w[0][2]) * inv;
    let s11 = (a[1][1] - s01 * w[1][0] - s10 * w[0][1] - s00 * w[1][1]) * inv;
    SurfaceDerivs2 {
        p: s00,
        su: s10,
        sv: s01,
        suu: s20,
        suv: s11,
        svv: s02,
    }
}

/// `C(u)` for order `O = p + 1` (parameter already clamped).
#[inline(always)]
pub(crate) fn curve_point<const D: usize, const O: usize>(
    kv: &KnotVector,
    ctrl: &[SVector<f64, D>],
    weights: Option<&[f64]>,
    u: f64,
) -> SVector<f64, D> {
    let span = find_span(kv.knots(), O - 1, u);
    let n = basis::<O>(kv, span, u);
    let first = span + 1 - O;
    let pts = &ctrl[first..first + O];
    match weights {
        None => {
            let mut c = SVector::<f64, D>::zeros();
            for j in 0..O {
                c += pts[j] * n[j];
            }
            c
        }
        Some(w) => {
            let ws = &w[first..first + O];
            let mut c = SVector::<f64, D>::zeros();
            let mut wsum = 0.0;
            for j in 0..O {
                let nw = n[j] * ws[j];
                c += pts[j] * nw;
                wsum += nw;
            }
            c / wsum
        }
    }
}

/// `[C, C', C'']` for order `O = p + 1` (parameter already clamped; A3.2 + A4.2 to order 2).
#[inline(always)]
pub(crate) fn curve_derivs2<const D: usize, const O: usize>(
    kv: &KnotVector,
    ctrl: &[SVector<f64, D>],
    weights: Option<&[f64]>,
    u: f64,
) -> [SVector<f64, D>; 3] {
    let span = find_span(kv.knots(), O - 1, u);
    let nd = ders2_basis::<O>(kv, span, u);
    let first = span + 1 - O;
    let pts = &ctrl[first..first + O];
    let mut a = [SVector::<f64, D>::zeros(); 3];
    match weights {
        None => {
            for j in 0..O {
                for k in 0..3 {
                    a[k] += pts[j] * nd[k][j];
                }
            }
            a
        }
        Some(w) => {
            let ws = &w[first..first + O];
            let mut wd = [0.0; 3];
            for j in 0..O {
                let pw = pts[j] * ws[j];
                for k in 0..3 {
                    a[k] += pw * nd[k][j];
                    wd[k] += ws[j] * nd[k][j];
                }
            }
            let inv = 1.0 / wd[0];
            let c0 = a[0] * inv;
            let c1 = (a[1] - c0 * wd[1]) * inv;
            let c2 = (a[2] - c1 * (2.0 * wd[1]) - c0 * wd[2]) * inv;
            [c0, c1, c2]
        }
    }
}
