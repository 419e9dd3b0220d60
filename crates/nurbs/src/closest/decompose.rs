//! Bézier pieces of curves and surfaces by blossoming (polar forms).
//!
//! On the knot span `[a, b] = [u_k, u_{k+1}]` the piece of a degree-`p` B-spline has Bézier
//! control points `f(a^{p−j}, b^j)`, `j = 0..=p`, where `f` is its blossom, evaluated by de
//! Boor's algorithm with argument `t_r` at level `r` (NURBS Book §5.1 / Ramshaw). Working per
//! span, this needs no knot insertion and accepts clamped and unclamped knot vectors alike.
//! Rational pieces are decomposed in homogeneous space `(wP, w)`. O(p²) per control point.

use nalgebra::SVector;

use super::bezier::{BezierPatch, BezierSegment};
use crate::{KnotVector, NurbsCurve, NurbsSurface};

/// Blossom of the span `k` piece at arguments `args` (length `p`) for control data `d`
/// (the `p + 1` homogeneous points `P_{k−p..=k}`, each of `W` components).
fn blossom<const W: usize>(
    knots: &[f64],
    p: usize,
    k: usize,
    d: &[[f64; W]],
    args: &[f64],
) -> [f64; W] {
    let mut work = [[0.0; W]; crate::MAX_ORDER];
    work[..=p].copy_from_slice(&d[..=p]);
    for (r, &t) in args.iter().enumerate() {
        let r = r + 1;
        for i in (r..=p).rev() {
            let lo = knots[k - p + i];
            let hi = knots[k + i - r + 1];
            let alpha = if hi > lo { (t - lo) / (hi - lo) } else { 0.0 };
            for c in 0..W {
                work[i][c] = (1.0 - alpha) * work[i - 1][c] + alpha * work[i][c];
            }
        }
    }
    work[p]
}

/// Bézier control points of span `k` (`[knots[k], knots[k+1]]`) from the `p + 1`
/// homogeneous points `d = P_{k−p..=k}`.
fn span_bezier<const W: usize>(knots: &[f64], p: usize, k: usize, d: &[[f64; W]]) -> Vec<[f64; W]> {
    let (a, b) = (knots[k], knots[k + 1]);
    (0..=p)
        .map(|j| {
            let mut args = [0.0; crate::MAX_ORDER];
            for (r, x) in args.iter_mut().take(p).enumerate() {
                *x = if r < j { b } else { a };
            }
            blossom(knots, p, k, d, &args[..p])
        })
        .collect()
}

/// Non-empty spans inside the domain: knot indices `k` with `u_k < u_{k+1}`.
fn spans(kv: &KnotVector) -> Vec<usize> {
    let p = kv.degree();
    let n_ctrl = kv.n_ctrl();
    let t = kv.knots();
    (p..n_ctrl).filter(|&k| t[k] < t[k + 1]).collect()
}

/// Bézier patches of a surface in row-major patch order `(a, b)` → `a·n_v_spans + b`,
/// with the span boundaries in u and v.
pub(crate) fn decompose_surface(s: &NurbsSurface) -> (Vec<BezierPatch>, Vec<f64>, Vec<f64>) {
    let (ku, kv) = (s.knots_u(), s.knots_v());
    let (p, q) = (ku.degree(), kv.degree());
    let (tu, tv) = (ku.knots(), kv.knots());
    let su = spans(ku);
    let sv = spans(kv);
    let nv_ctrl = s.n_v();
    let ctrl = s.control_points();
    let w = s.weights();
    let hom = |i: usize, j: usize| -> [f64; 4] {
        let idx = i * nv_ctrl + j;
        let wt = w.map_or(1.0, |w| w[idx]);
        let c = ctrl[idx];
        [c.x * wt, c.y * wt, c.z * wt, wt]
    };
    let mut patches = Vec::with_capacity(su.len() * sv.len());
    for &a in &su {
        for &b in &sv {
            // u-direction first: for each column j of the span's support.
            let mut tmp = vec![[0.0; 4]; (p + 1) * (q + 1)]; // [i'][j']
            for jj in 0..=q {
                let j = b - q + jj;
                let d: Vec<[f64; 4]> = (0..=p).map(|ii| hom(a - p + ii, j)).collect();
                let bez = span_bezier(tu, p, a, &d);
                for (ii, x) in bez.into_iter().enumerate() {
                    tmp[ii * (q + 1) + jj] = x;
                }
            }
            let mut pw = vec![[0.0; 4]; (p + 1) * (q + 1)];
            for ii in 0..=p {
                let d = &tmp[ii * (q + 1)..(ii + 1) * (q + 1)];
                let bez = span_bezier(tv, q, b, d);
                pw[ii * (q + 1)..(ii + 1) * (q + 1)].copy_from_slice(&bez);
            }
            patches.push(BezierPatch {
                p,
                q,
                u0: tu[a],
                u1: tu[a + 1],
                v0: tv[b],
                v1: tv[b + 1],
                pw,
                rational: s.is_rational(),
            });
        }
    }
    let mut ub: Vec<f64> = su.iter().map(|&a| tu[a]).collect();
    ub.push(ku.domain().1);
    let mut vb: Vec<f64> = sv.iter().map(|&b| tv[b]).collect();
    vb.push(kv.domain().1);
    (patches, ub, vb)
}

/// Bézier segments of a curve with the span boundaries.
pub(crate) fn decompose_curve<const D: usize>(
    c: &NurbsCurve<D>,
) -> (Vec<BezierSegment<D>>, Vec<f64>) {
    let kv = c.knots();
    let p = kv.degree();
    let t = kv.knots();
    let ctrl = c.control_points();
    let w = c.weights();
    let mut segs = Vec::new();
    let sp = spans(kv);
    for &k in &sp {
        // Work on D+1 components through fixed chunks of 4 (D ≤ 3) or generic via Vec.
        let d: Vec<Vec<f64>> = (0..=p)
            .map(|ii| {
                let idx = k - p + ii;
                let wt = w.map_or(1.0, |w| w[idx]);
                ctrl[idx]
                    .iter()
                    .map(|x| x * wt)
                    .chain(std::iter::once(wt))
                    .collect()
            })
            .collect();
        let bez: Vec<Vec<f64>> = (0..=p)
            .map(|j| {
                let args: Vec<f64> = (0..p)
                    .map(|r| if r < j { t[k + 1] } else { t[k] })
                    .collect();
                blossom_dyn(t, p, k, &d, &args)
            })
            .collect();
        segs.push(BezierSegment {
            p,
            u0: t[k],
            u1: t[k + 1],
            pw: bez
                .iter()
                .map(|x| (SVector::<f64, D>::from_fn(|i, _| x[i]), x[D]))
                .collect(),
            rational: c.is_rational(),
        });
    }
    let mut breaks: Vec<f64> = sp.iter().map(|&k| t[k]).collect();
    breaks.push(kv.domain().1);
    (segs, breaks)
}

/// [`blossom`] for points of runtime dimension.
fn blossom_dyn(knots: &[f64], p: usize, k: usize, d: &[Vec<f64>], args: &[f64]) -> Vec<f64> {
    let mut work: Vec<Vec<f64>> = d.to_vec();
    for (r, &t) in args.iter().enumerate() {
        let r = r + 1;
        for i in (r..=p).rev() {
            let lo = knots[k - p + i];
            let hi = knots[k + i - r + 1];
            let alpha = if hi > lo { (t - lo) / (hi - lo) } else { 0.0 };
            let prev = work[i - 1].clone();
            for (x, y) in work[i].iter_mut().zip(prev) {
                *x = (1.0 - alpha) * y + alpha * *x;
            }
        }
    }
    work.swap_remove(p)
}
