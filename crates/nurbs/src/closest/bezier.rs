//! Bézier pieces in homogeneous form: fast evaluation of point and derivatives up to second
//! order (Bernstein basis, no allocation), de Casteljau subdivision and control-net bounds.
//! These are the working representation of the closest-point, projection and tessellation
//! engines (each knot span of a NURBS is one Bézier piece, NURBS Book A5.6/A5.7).

use nalgebra::{SVector, Vector3};

use crate::{SurfaceDerivs2, MAX_ORDER};

/// Bernstein polynomials of degree `n` at `t` with first and second derivatives (in `t`).
/// Uses the triangular recurrence `B_{i,k} = (1−t) B_{i,k−1} + t B_{i−1,k−1}` and
/// `B'_{i,n} = n (B_{i−1,n−1} − B_{i,n−1})`, `B''_{i,n} = n(n−1)(B_{i−2,n−2} − 2B_{i−1,n−2} + B_{i,n−2})`.
#[inline]
pub(crate) fn bernstein2(
    n: usize,
    t: f64,
    b0: &mut [f64; MAX_ORDER],
    b1: &mut [f64; MAX_ORDER],
    b2: &mut [f64; MAX_ORDER],
) {
    let s = 1.0 - t;
    let mut lvl = [0.0; MAX_ORDER];
    let mut lvl_n1 = [0.0; MAX_ORDER];
    let mut lvl_n2 = [0.0; MAX_ORDER];
    lvl[0] = 1.0;
    if n >= 2 && n - 2 == 0 {
        lvl_n2[0] = 1.0;
    }
    if n >= 1 && n - 1 == 0 {
        lvl_n1[0] = 1.0;
    }
    for k in 1..=n {
        let mut prev = 0.0;
        for i in 0..=k {
            let cur = lvl[i];
            lvl[i] = s * cur + t * prev;
            prev = cur;
        }
        if k + 2 == n {
            lvl_n2[..=k].copy_from_slice(&lvl[..=k]);
        }
        if k + 1 == n {
            lvl_n1[..=k].copy_from_slice(&lvl[..=k]);
        }
    }
    b0[..=n].copy_from_slice(&lvl[..=n]);
    let nf = n as f64;
    for i in 0..=n {
        let a = if i >= 1 { lvl_n1[i - 1] } else { 0.0 };
        let b = if i < n { lvl_n1[i] } else { 0.0 };
        b1[i] = nf * (a - b);
    }
    if n >= 2 {
        let c = nf * (nf - 1.0);
        for i in 0..=n {
            let a = if i >= 2 { lvl_n2[i - 2] } else { 0.0 };
            let b = if i >= 1 && i - 1 <= n - 2 {
                lvl_n2[i - 1]
            } else {
                0.0
            };
            let d = if i <= n - 2 { lvl_n2[i] } else { 0.0 };
            b2[i] = c * (a - 2.0 * b + d);
        }
    } else {
        b2[..=n].iter_mut().for_each(|x| *x = 0.0);
    }
}

/// Bernstein polynomials of degree `n` at `t` (values only).
#[inline]
pub(crate) fn bernstein0(n: usize, t: f64, b0: &mut [f64; MAX_ORDER]) {
    let s = 1.0 - t;
    b0[0] = 1.0;
    for k in 1..=n {
        let mut prev = 0.0;
        for i in 0..=k {
            let cur = if i < k { b0[i] } else { 0.0 };
            b0[i] = s * cur + t * prev;
            prev = cur;
        }
    }
}

/// Bernstein polynomials of order `N` (degree `N − 1`) with first and second derivatives,
/// for compile-time `N` (the loops unroll).
#[inline(always)]
fn bernstein2_fixed<const N: usize>(t: f64) -> ([f64; N], [f64; N], [f64; N]) {
    let s = 1.0 - t;
    // Closed forms of degrees 1 to 3 (ruled and bicubic patches): fewer operations than the
    // triangle below, same values to round-off.
    let (mut b0, mut b1, mut b2) = ([0.0; N], [0.0; N], [0.0; N]);
    match N {
        2 => {
            (b0[0], b0[1]) = (s, t);
            (b1[0], b1[1]) = (-1.0, 1.0);
            return (b0, b1, b2);
        }
        3 => {
            (b0[0], b0[1], b0[2]) = (s * s, 2.0 * s * t, t * t);
            (b1[0], b1[1], b1[2]) = (-2.0 * s, 2.0 * (s - t), 2.0 * t);
            (b2[0], b2[1], b2[2]) = (2.0, -4.0, 2.0);
            return (b0, b1, b2);
        }
        4 => {
            let (ss, st, tt) = (s * s, s * t, t * t);
            (b0[0], b0[1], b0[2], b0[3]) = (ss * s, 3.0 * ss * t, 3.0 * s * tt, tt * t);
            (b1[0], b1[1], b1[2], b1[3]) = (
                -3.0 * ss,
                3.0 * (ss - 2.0 * st),
                3.0 * (2.0 * st - tt),
                3.0 * tt,
            );
            (b2[0], b2[1], b2[2], b2[3]) =
                (6.0 * s, 6.0 * (t - 2.0 * s), 6.0 * (s - 2.0 * t), 6.0 * t);
            return (b0, b1, b2);
        }
        _ => {}
    }
    bernstein2_triangle::<N>(t)
}

/// [`bernstein2_fixed`] by the de Casteljau triangle, for any order.
#[inline(always)]
fn bernstein2_triangle<const N: usize>(t: f64) -> ([f64; N], [f64; N], [f64; N]) {
    let s = 1.0 - t;
    let n = N - 1;
    // Levels of the triangle: keep degree n-2, n-1, n.
    let mut lvl = [0.0; N];
    let mut l1 = [0.0; N];
    let mut l2 = [0.0; N];
    lvl[0] = 1.0;
    if n == 1 {
        l1[0] = 1.0;
    }
    if n == 2 {
        l2[0] = 1.0;
    }
    for k in 1..N {
        let mut prev = 0.0;
        for i in 0..N {
            if i <= k {
                let cur = lvl[i];
                lvl[i] = s * cur + t * prev;
                prev = cur;
            }
        }
        if k + 2 == n {
            l2 = lvl;
        }
        if k + 1 == n {
            l1 = lvl;
        }
    }
    let nf = n as f64;
    let mut b1 = [0.0; N];
    let mut b2 = [0.0; N];
    for i in 0..N {
        let a = if i >= 1 { l1[i - 1] } else { 0.0 };
        let b = if i < n { l1[i] } else { 0.0 };
        b1[i] = nf * (a - b);
        if n >= 2 {
            let a = if i >= 2 { l2[i - 2] } else { 0.0 };
            let b = if i >= 1 && i < n { l2[i - 1] } else { 0.0 };
            let d = if i + 2 <= n { l2[i] } else { 0.0 };
            b2[i] = nf * (nf - 1.0) * (a - 2.0 * b + d);
        }
    }
    (lvl, b1, b2)
}

/// Turns the homogeneous tensor sums `a = [A, A_t, A_s, A_tt, A_ts, A_ss]` into Euclidean
/// derivatives (quotient rule, NURBS Book eq. 4.20) scaled from local to global parameters.
#[inline(always)]
fn finish_derivs(a: &[[f64; 4]; 6], rational: bool, du: f64, dv: f64) -> SurfaceDerivs2 {
    let v3 = |x: &[f64; 4]| Vector3::new(x[0], x[1], x[2]);
    let (p, su, sv, suu, suv, svv) = if rational {
        let wt = a[0][3];
        let (wu, wv, wuu, wuv, wvv) = (a[1][3], a[2][3], a[3][3], a[4][3], a[5][3]);
        let inv = 1.0 / wt;
        let p = v3(&a[0]) * inv;
        let su = (v3(&a[1]) - p * wu) * inv;
        let sv = (v3(&a[2]) - p * wv) * inv;
        let suu = (v3(&a[3]) - su * (2.0 * wu) - p * wuu) * inv;
        let suv = (v3(&a[4]) - su * wv - sv * wu - p * wuv) * inv;
        let svv = (v3(&a[5]) - sv * (2.0 * wv) - p * wvv) * inv;
        (p, su, sv, suu, suv, svv)
    } else {
        (
            v3(&a[0]),
            v3(&a[1]),
            v3(&a[2]),
            v3(&a[3]),
            v3(&a[4]),
            v3(&a[5]),
        )
    };
    SurfaceDerivs2 {
        p,
        su: su * du,
        sv: sv * dv,
        suu: suu * (du * du),
        suv: suv * (du * dv),
        svv: svv * (dv * dv),
    }
}

/// One rational (or polynomial) Bézier patch on the parameter box `[u0,u1]×[v0,v1]`.
#[derive(Debug, Clone)]
pub(crate) struct BezierPatch {
    pub p: usize,
    pub q: usize,
    pub u0: f64,
    pub u1: f64,
    pub v0: f64,
    pub v1: f64,
    /// Homogeneous control points `(w·x, w·y, w·z, w)`, index `i·(q+1) + j`.
    pub pw: Vec<[f64; 4]>,
    pub rational: bool,
}

impl BezierPatch {
    /// Euclidean control points.
    pub fn points(&self) -> impl Iterator<Item = Vector3<f64>> + '_ {
        self.pw
            .iter()
            .map(|c| Vector3::new(c[0] / c[3], c[1] / c[3], c[2] / c[3]))
    }

    /// Point and derivatives up to order two at global parameters `(u, v)` (extrapolates
    /// polynomially outside the box). O((p+1)(q+1)), no allocation. Degrees up to 3 run a
    /// kernel specialised at compile time (fully unrolled).
    #[inline]
    pub fn derivs2(&self, u: f64, v: f64) -> SurfaceDerivs2 {
        macro_rules! fixed {
            ($($p:literal, $q:literal);*) => {
                match (self.p, self.q, self.rational) {
                    $(($p, $q, false) => return self.derivs2_fixed::<{ $p + 1 }, { $q + 1 }, false>(u, v),
                      ($p, $q, true) => return self.derivs2_fixed::<{ $p + 1 }, { $q + 1 }, true>(u, v),)*
                    _ => {}
                }
            };
        }
        fixed!(1, 1; 1, 2; 1, 3; 2, 1; 2, 2; 2, 3; 3, 1; 3, 2; 3, 3);
        self.derivs2_generic(u, v)
    }

    /// [`Self::derivs2`] for compile-time orders `PU = p + 1`, `QV = q + 1`.
    #[inline(always)]
    fn derivs2_fixed<const PU: usize, const QV: usize, const R: bool>(
        &self,
        u: f64,
        v: f64,
    ) -> SurfaceDerivs2 {
        let du = 1.0 / (self.u1 - self.u0);
        let dv = 1.0 / (self.v1 - self.v0);
        let (bu0, bu1, bu2) = bernstein2_fixed::<PU>((u - self.u0) * du);
        let (bv0, bv1, bv2) = bernstein2_fixed::<QV>((v - self.v0) * dv);
        let mut a = [[0.0f64; 4]; 6];
        let pw = &self.pw[..PU * QV];
        // All four homogeneous lanes are summed even for a polynomial patch (its weight lane
        // is then unused): whole-lane sums vectorise, a masked lane does not.
        for i in 0..PU {
            let mut t0 = [0.0f64; 4];
            let mut t1 = [0.0f64; 4];
            let mut t2 = [0.0f64; 4];
            for j in 0..QV {
                let c = &pw[i * QV + j];
                for k in 0..4 {
                    t0[k] += bv0[j] * c[k];
                    t1[k] += bv1[j] * c[k];
                    if QV > 2 {
                        t2[k] += bv2[j] * c[k];
                    }
                }
            }
            for k in 0..4 {
                a[0][k] += bu0[i] * t0[k];
                a[1][k] += bu1[i] * t0[k];
                a[2][k] += bu0[i] * t1[k];
                a[3][k] += bu2[i] * t0[k];
                a[4][k] += bu1[i] * t1[k];
                if QV > 2 {
                    a[5][k] += bu0[i] * t2[k];
                }
            }
        }
        finish_derivs(&a, R, du, dv)
    }

    /// Generic-degree version of [`Self::derivs2`].
    fn derivs2_generic(&self, u: f64, v: f64) -> SurfaceDerivs2 {
        let du = 1.0 / (self.u1 - self.u0);
        let dv = 1.0 / (self.v1 - self.v0);
        let t = (u - self.u0) * du;
        let s = (v - self.v0) * dv;
        let (mut bu0, mut bu1, mut bu2) = ([0.0; MAX_ORDER], [0.0; MAX_ORDER], [0.0; MAX_ORDER]);
        let (mut bv0, mut bv1, mut bv2) = ([0.0; MAX_ORDER], [0.0; MAX_ORDER], [0.0; MAX_ORDER]);
        bernstein2(self.p, t, &mut bu0, &mut bu1, &mut bu2);
        bernstein2(self.q, s, &mut bv0, &mut bv1, &mut bv2);
        let q1 = self.q + 1;
        // a[k] = Σ_ij (B_u^(a) B_v^(b)) Pw_ij for (a,b) in [(0,0),(1,0),(0,1),(2,0),(1,1),(0,2)]
        let mut a = [[0.0f64; 4]; 6];
        let w = if self.rational { 4 } else { 3 };
        for i in 0..=self.p {
            let row = &self.pw[i * q1..i * q1 + q1];
            let mut t0 = [0.0f64; 4];
            let mut t1 = [0.0f64; 4];
            let mut t2 = [0.0f64; 4];
            for (j, c) in row.iter().enumerate() {
                for k in 0..w {
                    t0[k] += bv0[j] * c[k];
                    t1[k] += bv1[j] * c[k];
                    t2[k] += bv2[j] * c[k];
                }
            }
            for k in 0..w {
                a[0][k] += bu0[i] * t0[k];
                a[1][k] += bu1[i] * t0[k];
                a[2][k] += bu0[i] * t1[k];
                a[3][k] += bu2[i] * t0[k];
                a[4][k] += bu1[i] * t1[k];
                a[5][k] += bu0[i] * t2[k];
            }
        }
        finish_derivs(&a, self.rational, du, dv)
    }

    /// Point at global parameters `(u, v)`.
    #[inline]
    pub fn point(&self, u: f64, v: f64) -> Vector3<f64> {
        let t = (u - self.u0) / (self.u1 - self.u0);
        let s = (v - self.v0) / (self.v1 - self.v0);
        let (mut bu, mut bv) = ([0.0; MAX_ORDER], [0.0; MAX_ORDER]);
        bernstein0(self.p, t, &mut bu);
        bernstein0(self.q, s, &mut bv);
        let q1 = self.q + 1;
        let mut acc = [0.0f64; 4];
        for i in 0..=self.p {
            let mut t0 = [0.0f64; 4];
            for (j, c) in self.pw[i * q1..i * q1 + q1].iter().enumerate() {
                for k in 0..4 {
                    t0[k] += bv[j] * c[k];
                }
            }
            for k in 0..4 {
                acc[k] += bu[i] * t0[k];
            }
        }
        Vector3::new(acc[0], acc[1], acc[2]) / acc[3]
    }

    /// The same surface restricted to the sub-box `[ua,ub]×[va,vb]` (global parameters), as
    /// a Bézier patch (de Casteljau subdivision in homogeneous space, NURBS Book §5.2).
    pub fn sub_patch(&self, ua: f64, ub: f64, va: f64, vb: f64) -> BezierPatch {
        let q1 = self.q + 1;
        let p1 = self.p + 1;
        let ta = (ua - self.u0) / (self.u1 - self.u0);
        let tb = (ub - self.u0) / (self.u1 - self.u0);
        let sa = (va - self.v0) / (self.v1 - self.v0);
        let sb = (vb - self.v0) / (self.v1 - self.v0);
        let mut pw = self.pw.clone();
        // u direction: for each column j
        // One column of control points at a time, on the stack (degree ≤ MAX_DEGREE).
        let mut col = [[0.0; 4]; MAX_ORDER];
        let mut heap = Vec::new();
        let buf: &mut [[f64; 4]] = if p1 <= MAX_ORDER {
            &mut col[..p1]
        } else {
            heap.resize(p1, [0.0; 4]);
            &mut heap
        };
        for j in 0..q1 {
            for i in 0..p1 {
                buf[i] = pw[i * q1 + j];
            }
            restrict(buf, ta, tb);
            for i in 0..p1 {
                pw[i * q1 + j] = buf[i];
            }
        }
        for i in 0..p1 {
            restrict(&mut pw[i * q1..i * q1 + q1], sa, sb);
        }
        BezierPatch {
            p: self.p,
            q: self.q,
            u0: ua,
            u1: ub,
            v0: va,
            v1: vb,
            pw,
            rational: self.rational,
        }
    }
}

/// Replaces a Bézier control polygon on [0,1] by its right part after the split at `t`
/// (de Casteljau, NURBS Book §5.2; reparametrised to [0,1]), in place: after level `k` of the
/// triangle, entry `n-1-k` holds `P_{n-1-k}^k`, which is the right part's entry `n-1-k` and is
/// not touched by later levels. O(n²·W), no allocation.
#[inline]
fn split_right_in_place<const W: usize>(c: &mut [[f64; W]], t: f64) {
    let n = c.len();
    for k in 1..n {
        for i in 0..n - k {
            for d in 0..W {
                c[i][d] = (1.0 - t) * c[i][d] + t * c[i + 1][d];
            }
        }
    }
}

/// Replaces a Bézier control polygon on [0,1] by its left part after the split at `t`, in
/// place: level `k` of the de Casteljau triangle is stored shifted by `k` (entry `i` holds
/// `P_{i-k}^k`, updated from the top down so that `P_{i-k}^{k-1}` is still at `i-1`), so entry
/// `k` ends as `P_0^k`, the left part's entry `k`. The same products and sums as the textbook
/// triangle, in the same order: bit-identical results. O(n²·W), no allocation.
#[inline]
fn split_left_in_place<const W: usize>(c: &mut [[f64; W]], t: f64) {
    let n = c.len();
    for k in 1..n {
        for i in (k..n).rev() {
            for d in 0..W {
                c[i][d] = (1.0 - t) * c[i - 1][d] + t * c[i][d];
            }
        }
    }
}

/// Restricts a Bézier control polygon on [0,1] to its piece over `[a, b]` (in place): the
/// right part of the split at `a`, reparametrised to [0,1], then the left part of that at
/// `(b-a)/(1-a)`. O(n²·W), no allocation (it runs inside the projector's branch and bound).
pub(crate) fn restrict<const W: usize>(c: &mut [[f64; W]], a: f64, b: f64) {
    if c.is_empty() {
        return;
    }
    if a > 0.0 {
        split_right_in_place(c, a);
    }
    let rest = 1.0 - a;
    let tb = if rest > 0.0 { (b - a) / rest } else { 1.0 };
    if tb < 1.0 {
        split_left_in_place(c, tb);
    }
}

/// One rational (or polynomial) Bézier segment of a curve in `D` dimensions on `[u0, u1]`,
/// homogeneous control points stored as `D + 1` components (`w·P`, `w`) in a flat vector.
#[derive(Debug, Clone)]
pub(crate) struct BezierSegment<const D: usize> {
    pub p: usize,
    pub u0: f64,
    pub u1: f64,
    /// Homogeneous control points, `(w·P, w)`.
    pub pw: Vec<(SVector<f64, D>, f64)>,
    pub rational: bool,
}

impl<const D: usize> BezierSegment<D> {
    /// Euclidean control points.
    pub fn points(&self) -> impl Iterator<Item = SVector<f64, D>> + '_ {
        self.pw.iter().map(|(p, w)| p / *w)
    }

    /// `[C, C', C'']` at global parameter `u`. No allocation.
    #[inline]
    pub fn derivs2(&self, u: f64) -> [SVector<f64, D>; 3] {
        let du = 1.0 / (self.u1 - self.u0);
        let t = (u - self.u0) * du;
        let (mut b0, mut b1, mut b2) = ([0.0; MAX_ORDER], [0.0; MAX_ORDER], [0.0; MAX_ORDER]);
        bernstein2(self.p, t, &mut b0, &mut b1, &mut b2);
        let mut a = [SVector::<f64, D>::zeros(); 3];
        let mut w = [0.0; 3];
        for (i, (pt, wt)) in self.pw.iter().enumerate() {
            a[0] += pt * b0[i];
            a[1] += pt * b1[i];
            a[2] += pt * b2[i];
            w[0] += wt * b0[i];
            w[1] += wt * b1[i];
            w[2] += wt * b2[i];
        }
        let (c, c1, c2) = if self.rational {
            let inv = 1.0 / w[0];
            let c = a[0] * inv;
            let c1 = (a[1] - c * w[1]) * inv;
            let c2 = (a[2] - c1 * (2.0 * w[1]) - c * w[2]) * inv;
            (c, c1, c2)
        } else {
            (a[0], a[1], a[2])
        };
        [c, c1 * du, c2 * (du * du)]
    }

    /// The same curve restricted to `[ua, ub]` as a Bézier segment.
    pub fn sub_segment(&self, ua: f64, ub: f64) -> BezierSegment<D> {
        let ta = (ua - self.u0) / (self.u1 - self.u0);
        let tb = (ub - self.u0) / (self.u1 - self.u0);
        // Work with flat arrays of D+1 components through a Vec<Vec<f64>> detour.
        let mut flat: Vec<Vec<f64>> = self
            .pw
            .iter()
            .map(|(p, w)| p.iter().copied().chain(std::iter::once(*w)).collect())
            .collect();
        restrict_dyn(&mut flat, ta, tb);
        let pw = flat
            .iter()
            .map(|c| (SVector::<f64, D>::from_fn(|d, _| c[d]), c[D]))
            .collect();
        BezierSegment {
            p: self.p,
            u0: ua,
            u1: ub,
            pw,
            rational: self.rational,
        }
    }
}

/// [`restrict`] for control points of runtime dimension.
fn restrict_dyn(c: &mut [Vec<f64>], a: f64, b: f64) {
    let split_dyn = |c: &[Vec<f64>], t: f64| -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
        let n = c.len();
        let mut work = c.to_vec();
        let mut left = Vec::with_capacity(n);
        let mut right = c.to_vec();
        left.push(work[0].clone());
        right[n - 1] = work[n - 1].clone();
        for k in 1..n {
            for i in 0..n - k {
                let next = work[i + 1].clone();
                for (x, y) in work[i].iter_mut().zip(next) {
                    *x = (1.0 - t) * *x + t * y;
                }
            }
            left.push(work[0].clone());
            right[n - 1 - k] = work[n - 1 - k].clone();
        }
        (left, right)
    };
    if c.is_empty() {
        return;
    }
    let right = if a > 0.0 {
        split_dyn(c, a).1
    } else {
        c.to_vec()
    };
    let rest = 1.0 - a;
    let tb = if rest > 0.0 { (b - a) / rest } else { 1.0 };
    let out = if tb < 1.0 {
        split_dyn(&right, tb).0
    } else {
        right
    };
    for (dst, src) in c.iter_mut().zip(out) {
        *dst = src;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed-form Bernstein values and derivatives of degrees 1–3 equal the de Casteljau
    /// triangle's within 1e-12.
    #[test]
    fn closed_form_bernstein_matches_the_triangle() {
        fn check<const N: usize>() {
            for k in 0..=20 {
                let t = k as f64 / 20.0;
                let a = bernstein2_fixed::<N>(t);
                let b = bernstein2_triangle::<N>(t);
                for i in 0..N {
                    assert!((a.0[i] - b.0[i]).abs() < 1e-14, "N {N} t {t} B{i}");
                    assert!((a.1[i] - b.1[i]).abs() < 1e-13, "N {N} t {t} B'{i}");
                    assert!((a.2[i] - b.2[i]).abs() < 1e-12, "N {N} t {t} B''{i}");
                }
            }
        }
        check::<2>();
        check::<3>();
        check::<4>();
    }

    /// The textbook de Casteljau split (allocating the triangle's two sides), as `restrict`
    /// computed it before it ran in place.
    fn split_reference<const W: usize>(c: &[[f64; W]], t: f64) -> (Vec<[f64; W]>, Vec<[f64; W]>) {
        let n = c.len();
        let mut work = c.to_vec();
        let mut left = Vec::with_capacity(n);
        let mut right = vec![[0.0; W]; n];
        left.push(work[0]);
        right[n - 1] = work[n - 1];
        for k in 1..n {
            for i in 0..n - k {
                for d in 0..W {
                    work[i][d] = (1.0 - t) * work[i][d] + t * work[i + 1][d];
                }
            }
            left.push(work[0]);
            right[n - 1 - k] = work[n - 1 - k];
        }
        (left, right)
    }

    fn restrict_reference<const W: usize>(c: &[[f64; W]], a: f64, b: f64) -> Vec<[f64; W]> {
        let right = if a > 0.0 {
            split_reference(c, a).1
        } else {
            c.to_vec()
        };
        let rest = 1.0 - a;
        let tb = if rest > 0.0 { (b - a) / rest } else { 1.0 };
        if tb < 1.0 {
            split_reference(&right, tb).0
        } else {
            right
        }
    }

    /// The in-place restriction gives bit-for-bit the control points of the textbook
    /// (allocating) de Casteljau triangle, on random polygons of degree 0–12 and random
    /// sub-intervals (including the ends 0 and 1), so the projector's answers do not move.
    #[test]
    fn in_place_restrict_is_bit_identical_to_the_textbook_triangle() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(31);
        for case in 0..2000 {
            let n = 1 + case % crate::MAX_ORDER;
            let c: Vec<[f64; 4]> = (0..n)
                .map(|_| {
                    let w = rng.random_range(0.2..3.0);
                    [
                        rng.random_range(-100.0..100.0),
                        rng.random_range(-100.0..100.0),
                        rng.random_range(-100.0..100.0),
                        w,
                    ]
                })
                .collect();
            let (mut a, mut b): (f64, f64) =
                (rng.random_range(0.0..1.0), rng.random_range(0.0..1.0));
            match case % 5 {
                0 => a = 0.0,
                1 => b = 1.0,
                _ => {}
            }
            if a > b {
                std::mem::swap(&mut a, &mut b);
            }
            let want = restrict_reference(&c, a, b);
            let mut got = c.clone();
            restrict(&mut got, a, b);
            for (g, w) in got.iter().zip(&want) {
                for d in 0..4 {
                    assert_eq!(
                        g[d].to_bits(),
                        w[d].to_bits(),
                        "case {case} n {n} [{a}, {b}]"
                    );
                }
            }
        }
    }
}
