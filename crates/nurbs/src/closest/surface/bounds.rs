//! Interval bounds of a leaf's derivatives (polynomial: hodograph boxes; rational: the
//! quotient rule on the homogeneous net) and the Hessian (convexity) certificate.

use nalgebra::Vector3;

use super::tree::Obb;
use crate::closest::bezier::BezierPatch;

/// Closed interval.
#[derive(Debug, Clone, Copy)]
pub(super) struct Iv {
    pub(super) lo: f64,
    pub(super) hi: f64,
}

impl Iv {
    pub(super) fn add(self, o: Iv) -> Iv {
        Iv {
            lo: self.lo + o.lo,
            hi: self.hi + o.hi,
        }
    }
    pub(super) fn mul(self, o: Iv) -> Iv {
        let c = [
            self.lo * o.lo,
            self.lo * o.hi,
            self.hi * o.lo,
            self.hi * o.hi,
        ];
        Iv {
            lo: c.iter().copied().fold(f64::INFINITY, f64::min),
            hi: c.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        }
    }
}

/// Box (per-component intervals) of a vector quantity over a leaf.
#[derive(Debug, Clone, Copy)]
pub(super) struct VBox(pub(super) [Iv; 3]);

impl VBox {
    pub(super) fn of(vs: &[Vector3<f64>]) -> VBox {
        let mut b = [Iv {
            lo: f64::INFINITY,
            hi: f64::NEG_INFINITY,
        }; 3];
        for v in vs {
            for k in 0..3 {
                b[k].lo = b[k].lo.min(v[k]);
                b[k].hi = b[k].hi.max(v[k]);
            }
        }
        if vs.is_empty() {
            b = [Iv { lo: 0.0, hi: 0.0 }; 3];
        }
        VBox(b)
    }
    /// Widens every interval by `rel` of its width plus `rel` of its magnitude.
    pub(super) fn widen(mut self, rel: f64) -> VBox {
        for iv in &mut self.0 {
            let pad = rel * ((iv.hi - iv.lo) + iv.lo.abs().max(iv.hi.abs()));
            iv.lo -= pad;
            iv.hi += pad;
        }
        self
    }
    /// Componentwise difference of two boxes.
    pub(super) fn sub(&self, o: &VBox) -> VBox {
        VBox([0, 1, 2].map(|k| Iv {
            lo: self.0[k].lo - o.0[k].hi,
            hi: self.0[k].hi - o.0[k].lo,
        }))
    }
    /// Every component times an interval.
    pub(super) fn scale(&self, s: Iv) -> VBox {
        VBox([0, 1, 2].map(|k| self.0[k].mul(s)))
    }
    pub(super) fn dot(&self, o: &VBox) -> Iv {
        let mut acc = Iv { lo: 0.0, hi: 0.0 };
        for k in 0..3 {
            acc = acc.add(self.0[k].mul(o.0[k]));
        }
        acc
    }
    /// `{x·x}` (tighter than `dot` with itself: squares are non-negative).
    pub(super) fn sq(&self) -> Iv {
        let mut acc = Iv { lo: 0.0, hi: 0.0 };
        for iv in &self.0 {
            let (a, b) = (iv.lo * iv.lo, iv.hi * iv.hi);
            let lo = if iv.lo <= 0.0 && iv.hi >= 0.0 {
                0.0
            } else {
                a.min(b)
            };
            acc = acc.add(Iv { lo, hi: a.max(b) });
        }
        acc
    }
}

/// Interval bounds over a leaf of the first fundamental form `JᵀJ` and of the second
/// derivatives, for the query-time test that the Hessian of `½|S − q|²`,
/// `H = JᵀJ + [r·S_uu, r·S_uv; r·S_uv, r·S_vv]` with `r ∈ box(leaf) − q`, is positive definite
/// on the whole leaf (then the distance is strictly convex there and Newton's minimum is the
/// leaf's only one). Polynomial leaves: rigorous boxes of the hodograph control vectors.
/// Rational leaves: rigorous interval bounds from the homogeneous net
/// (`rational_derivative_boxes`).
#[derive(Debug, Clone, Copy)]
pub(super) struct HessianBounds {
    pub(super) a: Iv,
    pub(super) b: Iv,
    pub(super) c: Iv,
    pub(super) suu: VBox,
    pub(super) suv: VBox,
    pub(super) svv: VBox,
}

impl HessianBounds {
    /// The test for a query `q`, with `r = S − q` bounded by the leaf's oriented box (the
    /// vector boxes are stored in the same frame).
    #[inline]
    pub(super) fn certifies(&self, obb: &Obb, q: &Vector3<f64>) -> bool {
        let cq = obb.c - q;
        let r = VBox([0, 1, 2].map(|k| {
            let m = cq.dot(&obb.axes[k]);
            Iv {
                lo: m - obb.h[k],
                hi: m + obb.h[k],
            }
        }));
        let huu = self.a.add(r.dot(&self.suu));
        let hvv = self.c.add(r.dot(&self.svv));
        let huv = self.b.add(r.dot(&self.suv));
        let m = huv.lo.abs().max(huv.hi.abs());
        huu.lo > 0.0 && hvv.lo > 0.0 && huu.lo * hvv.lo > m * m
    }

    pub(super) fn of(
        sub: &BezierPatch,
        pts: &[Vector3<f64>],
        axes: &[Vector3<f64>; 3],
    ) -> HessianBounds {
        let frame =
            |v: Vector3<f64>| Vector3::new(v.dot(&axes[0]), v.dot(&axes[1]), v.dot(&axes[2]));
        let (p, q) = (sub.p, sub.q);
        let (du, dv) = (sub.u1 - sub.u0, sub.v1 - sub.v0);
        let (su, sv, suu, suv, svv) = if sub.rational {
            rational_derivative_boxes(sub, pts, &frame)
        } else {
            let at = |i: usize, j: usize| pts[i * (q + 1) + j];
            let (pf, qf) = (p as f64, q as f64);
            let mut d = (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
            for i in 0..=p {
                for j in 0..=q {
                    if i < p {
                        d.0.push(frame((at(i + 1, j) - at(i, j)) * (pf / du)));
                    }
                    if j < q {
                        d.1.push(frame((at(i, j + 1) - at(i, j)) * (qf / dv)));
                    }
                    if i + 2 <= p {
                        d.2.push(frame(
                            (at(i + 2, j) - at(i + 1, j) * 2.0 + at(i, j))
                                * (pf * (pf - 1.0) / (du * du)),
                        ));
                    }
                    if i < p && j < q {
                        d.3.push(frame(
                            (at(i + 1, j + 1) - at(i + 1, j) - at(i, j + 1) + at(i, j))
                                * (pf * qf / (du * dv)),
                        ));
                    }
                    if j + 2 <= q {
                        d.4.push(frame(
                            (at(i, j + 2) - at(i, j + 1) * 2.0 + at(i, j))
                                * (qf * (qf - 1.0) / (dv * dv)),
                        ));
                    }
                }
            }
            // Round-off guard.
            (
                VBox::of(&d.0).widen(1e-12),
                VBox::of(&d.1).widen(1e-12),
                VBox::of(&d.2).widen(1e-12),
                VBox::of(&d.3).widen(1e-12),
                VBox::of(&d.4).widen(1e-12),
            )
        };
        HessianBounds {
            a: su.sq(),
            b: su.dot(&sv),
            c: sv.sq(),
            suu,
            suv,
            svv,
        }
    }
}

/// Rigorous boxes of `S_u, S_v, S_uu, S_uv, S_vv` over a rational leaf (in the leaf's frame),
/// from its homogeneous control net: with `X = w (P − c)` (`c` the centre of the control
/// points' box) and `W` polynomials, `Y = S − c = X / W` and
///
/// ```text
/// Y_u  = (X_u − Y W_u) / W                      Y_v = (X_v − Y W_v) / W
/// Y_uu = (X_uu − 2 Y_u W_u − Y W_uu) / W
/// Y_uv = (X_uv − Y_u W_v − Y_v W_u − Y W_uv) / W
/// Y_vv = (X_vv − 2 Y_v W_v − Y W_vv) / W
/// ```
///
/// evaluated in interval arithmetic: the derivatives of the polynomials `X`, `W` lie in the
/// boxes of their hodographs' Bernstein coefficients, `W` in `[min w, max w]` (positive
/// weights), `Y` in the box of the control points (convex hull). Widened by 1e-12 for
/// round-off. O((p+1)(q+1)).
pub(super) fn rational_derivative_boxes(
    sub: &BezierPatch,
    pts: &[Vector3<f64>],
    frame: &dyn Fn(Vector3<f64>) -> Vector3<f64>,
) -> (VBox, VBox, VBox, VBox, VBox) {
    let (p, q) = (sub.p, sub.q);
    let q1 = q + 1;
    let (du, dv) = (sub.u1 - sub.u0, sub.v1 - sub.v0);
    let local: Vec<Vector3<f64>> = pts.iter().map(|x| frame(*x)).collect();
    let y = VBox::of(&local);
    let c = Vector3::from_fn(|k, _| 0.5 * (y.0[k].lo + y.0[k].hi));
    let y = VBox::of(&local.iter().map(|x| x - c).collect::<Vec<_>>());
    let w: Vec<f64> = sub.pw.iter().map(|h| h[3]).collect();
    let x: Vec<Vector3<f64>> = local
        .iter()
        .zip(&w)
        .map(|(pt, wi)| (pt - c) * *wi)
        .collect();
    let (pf, qf) = (p as f64, q as f64);
    // Hodograph coefficients of (X, W): first, second and mixed differences, scaled to the
    // global parameters.
    let mut d: [(Vec<Vector3<f64>>, Vec<f64>); 5] = Default::default();
    let scales = [
        pf / du,
        qf / dv,
        pf * (pf - 1.0) / (du * du),
        pf * qf / (du * dv),
        qf * (qf - 1.0) / (dv * dv),
    ];
    for i in 0..=p {
        for j in 0..=q {
            let k = i * q1 + j;
            if i < p {
                let k1 = k + q1;
                d[0].0.push((x[k1] - x[k]) * scales[0]);
                d[0].1.push((w[k1] - w[k]) * scales[0]);
            }
            if j < q {
                d[1].0.push((x[k + 1] - x[k]) * scales[1]);
                d[1].1.push((w[k + 1] - w[k]) * scales[1]);
            }
            if i + 2 <= p {
                let (k1, k2) = (k + q1, k + 2 * q1);
                d[2].0.push((x[k2] - x[k1] * 2.0 + x[k]) * scales[2]);
                d[2].1.push((w[k2] - w[k1] * 2.0 + w[k]) * scales[2]);
            }
            if i < p && j < q {
                let (k10, k01, k11) = (k + q1, k + 1, k + q1 + 1);
                d[3].0.push((x[k11] - x[k10] - x[k01] + x[k]) * scales[3]);
                d[3].1.push((w[k11] - w[k10] - w[k01] + w[k]) * scales[3]);
            }
            if j + 2 <= q {
                d[4].0.push((x[k + 2] - x[k + 1] * 2.0 + x[k]) * scales[4]);
                d[4].1.push((w[k + 2] - w[k + 1] * 2.0 + w[k]) * scales[4]);
            }
        }
    }
    let iv = |v: &[f64]| {
        if v.is_empty() {
            return Iv { lo: 0.0, hi: 0.0 };
        }
        Iv {
            lo: v.iter().copied().fold(f64::INFINITY, f64::min),
            hi: v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        }
    };
    let wr = iv(&w);
    let inv_w = Iv {
        lo: 1.0 / wr.hi,
        hi: 1.0 / wr.lo,
    };
    let [xu, xv, xuu, xuv, xvv] = [0, 1, 2, 3, 4].map(|k| VBox::of(&d[k].0));
    let [wu, wv, wuu, wuv, wvv] = [0, 1, 2, 3, 4].map(|k| iv(&d[k].1));
    let two = Iv { lo: 2.0, hi: 2.0 };
    let yu = xu.sub(&y.scale(wu)).scale(inv_w);
    let yv = xv.sub(&y.scale(wv)).scale(inv_w);
    let yuu = xuu
        .sub(&yu.scale(wu.mul(two)))
        .sub(&y.scale(wuu))
        .scale(inv_w);
    let yuv = xuv
        .sub(&yu.scale(wv))
        .sub(&yv.scale(wu))
        .sub(&y.scale(wuv))
        .scale(inv_w);
    let yvv = xvv
        .sub(&yv.scale(wv.mul(two)))
        .sub(&y.scale(wvv))
        .scale(inv_w);
    (
        yu.widen(1e-12),
        yv.widen(1e-12),
        yuu.widen(1e-12),
        yuv.widen(1e-12),
        yvv.widen(1e-12),
    )
}
