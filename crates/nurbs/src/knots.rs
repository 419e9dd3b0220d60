//! Knot vectors and B-spline basis functions (The NURBS Book, Piegl & Tiller, 2nd ed.,
//! chapter 2: algorithms A2.1 `FindSpan`, A2.2 `BasisFuns`, A2.3 `DersBasisFuns`).

use crate::error::NurbsError;
use crate::{MAX_DEGREE, MAX_ORDER};

/// A validated knot vector `U = {u_0, ..., u_m}` of a degree-`p` B-spline.
///
/// Invariants (checked by [`KnotVector::new`] and on deserialisation):
/// - `1 <= p <= MAX_DEGREE`;
/// - at least `2 (p + 1)` knots (so at least `p + 1` control points);
/// - every knot finite and the sequence non-decreasing;
/// - a knot value repeated at most `p + 1` times if the run touches either end of the
///   vector, at most `p` times in the interior (so the spline is at least C⁰ inside);
/// - non-empty parameter domain `[u_p, u_{m-p}]`.
///
/// Knot vectors need not be clamped (end multiplicity `p + 1`) for evaluation; operations
/// that need a clamped vector clamp internally.
#[derive(Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "KnotVectorData", into = "KnotVectorData")]
pub struct KnotVector {
    degree: usize,
    knots: Vec<f64>,
    /// `inv_diff[(g - 1) * len + k] = 1 / (u_{k+g} − u_k)` for gaps `g = 1..=p` (0 where
    /// the difference vanishes or `k + g` is past the end): the denominators of A2.2/A2.3,
    /// precomputed so evaluation multiplies instead of dividing.
    inv_diff: Vec<f64>,
}

impl std::fmt::Debug for KnotVector {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("KnotVector")
            .field("degree", &self.degree)
            .field("knots", &self.knots)
            .finish()
    }
}

/// Serialised form of a [`KnotVector`] (validated when converted back).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct KnotVectorData {
    /// Degree `p`.
    pub degree: usize,
    /// The knots `u_0..=u_m`.
    pub knots: Vec<f64>,
}

impl TryFrom<KnotVectorData> for KnotVector {
    type Error = NurbsError;
    fn try_from(d: KnotVectorData) -> Result<Self, NurbsError> {
        KnotVector::new(d.degree, d.knots)
    }
}

impl From<KnotVector> for KnotVectorData {
    fn from(k: KnotVector) -> Self {
        KnotVectorData {
            degree: k.degree,
            knots: k.knots,
        }
    }
}

impl KnotVector {
    /// Validates `knots` for degree `degree` (see the type-level invariants). Each
    /// violation is a typed [`NurbsError`] naming the offending index. O(m).
    pub fn new(degree: usize, knots: Vec<f64>) -> Result<Self, NurbsError> {
        if degree == 0 || degree > MAX_DEGREE {
            return Err(NurbsError::DegreeOutOfRange {
                degree,
                max: MAX_DEGREE,
            });
        }
        let min = 2 * (degree + 1);
        if knots.len() < min {
            return Err(NurbsError::TooFewKnots {
                len: knots.len(),
                degree,
                min,
            });
        }
        for (index, &value) in knots.iter().enumerate() {
            if !value.is_finite() {
                return Err(NurbsError::NonFiniteKnot { index, value });
            }
        }
        for index in 1..knots.len() {
            if knots[index] < knots[index - 1] {
                return Err(NurbsError::DecreasingKnot {
                    index,
                    value: knots[index],
                    previous: knots[index - 1],
                });
            }
        }
        let last = knots.len() - 1;
        let mut start = 0;
        while start <= last {
            let mut end = start;
            while end < last && knots[end + 1] == knots[start] {
                end += 1;
            }
            let multiplicity = end - start + 1;
            let at_end = start == 0 || end == last;
            let max = if at_end { degree + 1 } else { degree };
            if multiplicity > max {
                return Err(NurbsError::KnotMultiplicity {
                    index: start,
                    value: knots[start],
                    multiplicity,
                    max,
                });
            }
            start = end + 1;
        }
        let (a, b) = (knots[degree], knots[last - degree]);
        if a >= b {
            return Err(NurbsError::EmptyDomain { start: a, end: b });
        }
        let len = knots.len();
        let mut inv_diff = vec![0.0; degree * len];
        for g in 1..=degree {
            for k in 0..len - g {
                let d = knots[k + g] - knots[k];
                if d > 0.0 {
                    inv_diff[(g - 1) * len + k] = 1.0 / d;
                }
            }
        }
        Ok(KnotVector {
            degree,
            knots,
            inv_diff,
        })
    }

    /// `1 / (u_{k+g} − u_k)`, 0 for an empty interval (`1 <= g <= p`, `k + g <= m`).
    #[inline(always)]
    pub(crate) fn inv_diff(&self, g: usize, k: usize) -> f64 {
        self.inv_diff[(g - 1) * self.knots.len() + k]
    }

    /// Clamped uniform knot vector on `[0, 1]` for `n_ctrl` control points: `p + 1` zeros,
    /// `n_ctrl - p - 1` equally spaced interior knots, `p + 1` ones.
    pub fn clamped_uniform(degree: usize, n_ctrl: usize) -> Result<Self, NurbsError> {
        if degree == 0 || degree > MAX_DEGREE {
            return Err(NurbsError::DegreeOutOfRange {
                degree,
                max: MAX_DEGREE,
            });
        }
        if n_ctrl < degree + 1 {
            return Err(NurbsError::TooFewKnots {
                len: n_ctrl + degree + 1,
                degree,
                min: 2 * (degree + 1),
            });
        }
        let n_spans = n_ctrl - degree;
        let mut knots = Vec::with_capacity(n_ctrl + degree + 1);
        knots.extend(std::iter::repeat_n(0.0, degree + 1));
        for k in 1..n_spans {
            knots.push(k as f64 / n_spans as f64);
        }
        knots.extend(std::iter::repeat_n(1.0, degree + 1));
        KnotVector::new(degree, knots)
    }

    /// Degree `p`.
    #[inline]
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// The knots `u_0..=u_m`.
    #[inline]
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// Number of control points this knot vector carries: `m - p`.
    #[inline]
    pub fn n_ctrl(&self) -> usize {
        self.knots.len() - self.degree - 1
    }

    /// Parameter domain `[u_p, u_{m-p}]`.
    #[inline]
    pub fn domain(&self) -> (f64, f64) {
        (
            self.knots[self.degree],
            self.knots[self.knots.len() - 1 - self.degree],
        )
    }

    /// True when the first and last `p + 1` knots are equal (the curve interpolates its
    /// end control points).
    pub fn is_clamped(&self) -> bool {
        let p = self.degree;
        let m = self.knots.len() - 1;
        self.knots[..=p].iter().all(|&k| k == self.knots[0])
            && self.knots[m - p..].iter().all(|&k| k == self.knots[m])
    }

    /// Multiplicity of the value `u` in the knot vector (exact comparison).
    pub fn multiplicity(&self, u: f64) -> usize {
        self.knots.iter().filter(|&&k| k == u).count()
    }

    /// Distinct knot values inside the open domain `(u_p, u_{m-p})` with their
    /// multiplicities, in increasing order.
    pub fn interior_breaks(&self) -> Vec<(f64, usize)> {
        let (a, b) = self.domain();
        let mut out: Vec<(f64, usize)> = Vec::new();
        for &k in &self.knots {
            if k <= a || k >= b {
                continue;
            }
            match out.last_mut() {
                Some((v, m)) if *v == k => *m += 1,
                _ => out.push((k, 1)),
            }
        }
        out
    }

    /// Knot span index `i` with `u_i <= u < u_{i+1}` and `p <= i <= n` (NURBS Book A2.1,
    /// binary search, O(log m)). Parameters outside the domain are clamped to it; at the
    /// domain end the last non-empty span is returned. NaN maps to the first span.
    #[inline]
    pub fn find_span(&self, u: f64) -> usize {
        find_span(&self.knots, self.degree, u)
    }

    /// The `p + 1` non-vanishing basis functions `N_{span-p,p}(u) ..= N_{span,p}(u)` into
    /// `out[0..=p]` (NURBS Book A2.2; O(p²), no allocation). They are non-negative and sum
    /// to one to rounding (partition of unity).
    ///
    /// `span` must come from [`KnotVector::find_span`] and `out.len() >= p + 1`
    /// (otherwise this panics: a caller bug, not an input error).
    #[inline]
    pub fn basis_funs(&self, span: usize, u: f64, out: &mut [f64]) {
        let n = basis_funs_fixed(&self.knots, self.degree, span, u);
        out[..=self.degree].copy_from_slice(&n[..=self.degree]);
    }

    /// Non-allocating form of [`KnotVector::ders_basis_funs`] for hot loops: writes the
    /// derivatives of orders `0..=n` into `ders[0..=n][0..=p]` (rows above the degree are
    /// zero). NURBS Book A2.3, O(p² + n p).
    ///
    /// `span` must come from [`KnotVector::find_span`] and `ders.len() > n` (otherwise this
    /// panics: a caller bug, not an input error).
    #[inline]
    pub fn ders_basis_funs_into(
        &self,
        span: usize,
        u: f64,
        n: usize,
        ders: &mut [[f64; MAX_ORDER]],
    ) {
        let du = n.min(self.degree);
        ders_basis_fixed(&self.knots, self.degree, span, u, du, ders);
        for row in ders.iter_mut().take(n + 1).skip(du + 1) {
            row.iter_mut().for_each(|v| *v = 0.0);
        }
    }

    /// Basis functions and their derivatives up to order `n` (NURBS Book A2.3, O(p² + n p)):
    /// `ders[k][j]` is the `k`-th derivative of `N_{span-p+j,p}` at `u`. Orders above the
    /// degree are identically zero and returned as zero rows.
    pub fn ders_basis_funs(&self, span: usize, u: f64, n: usize) -> Vec<Vec<f64>> {
        let p = self.degree;
        let mut fixed = [[0.0; MAX_ORDER]; MAX_ORDER];
        let du = n.min(p);
        ders_basis_fixed(&self.knots, p, span, u, du, &mut fixed);
        (0..=n)
            .map(|k| {
                if k <= du {
                    fixed[k][..=p].to_vec()
                } else {
                    vec![0.0; p + 1]
                }
            })
            .collect()
    }
}

/// Clamps `u` to the domain `[u_p, u_{m-p}]` of a raw knot slice (NaN stays NaN).
#[inline]
pub(crate) fn clamp_param(knots: &[f64], p: usize, u: f64) -> f64 {
    u.clamp(knots[p], knots[knots.len() - 1 - p])
}

/// A2.1 on a raw knot slice (see [`KnotVector::find_span`]).
#[inline]
pub(crate) fn find_span(knots: &[f64], p: usize, u: f64) -> usize {
    let n = knots.len() - p - 2;
    // Largest i in [p, n] with knots[i] <= u, by a branch-free binary search (the
    // conditional move avoids mispredictions on random queries). Below the domain and NaN
    // give p; at or above the domain end, n.
    let mut lo = p;
    let mut len = n + 1 - p;
    while len > 1 {
        let half = len / 2;
        let mid = lo + half;
        lo = if knots[mid] <= u { mid } else { lo };
        len -= half;
    }
    lo
}

/// A2.2 into a fixed stack array (entries `0..=p` are valid).
#[inline]
pub(crate) fn basis_funs_fixed(knots: &[f64], p: usize, span: usize, u: f64) -> [f64; MAX_ORDER] {
    let mut n = [0.0; MAX_ORDER];
    let mut left = [0.0; MAX_ORDER];
    let mut right = [0.0; MAX_ORDER];
    n[0] = 1.0;
    for j in 1..=p {
        left[j] = u - knots[span + 1 - j];
        right[j] = knots[span + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            let temp = n[r] / (right[r + 1] + left[j - r]);
            n[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        n[j] = saved;
    }
    n
}

/// A2.3 with `n <= p` into `ders[0..=n][0..=p]`, no allocation. Dispatches on the degree so
/// the triangular table is sized `(p+1)²` on the stack (not `MAX_ORDER²`).
#[inline]
pub(crate) fn ders_basis_fixed(
    knots: &[f64],
    p: usize,
    span: usize,
    u: f64,
    n: usize,
    ders: &mut [[f64; MAX_ORDER]],
) {
    match p {
        1 => ders_basis_kernel::<2>(knots, p, span, u, n, ders),
        2 => ders_basis_kernel::<3>(knots, p, span, u, n, ders),
        3 => ders_basis_kernel::<4>(knots, p, span, u, n, ders),
        4 => ders_basis_kernel::<5>(knots, p, span, u, n, ders),
        5 => ders_basis_kernel::<6>(knots, p, span, u, n, ders),
        6 => ders_basis_kernel::<7>(knots, p, span, u, n, ders),
        7 => ders_basis_kernel::<8>(knots, p, span, u, n, ders),
        _ => ders_basis_kernel::<MAX_ORDER>(knots, p, span, u, n, ders),
    }
}

#[inline]
fn ders_basis_kernel<const P1: usize>(
    knots: &[f64],
    p: usize,
    span: usize,
    u: f64,
    n: usize,
    ders: &mut [[f64; MAX_ORDER]],
) {
    let mut ndu = [[0.0; P1]; P1];
    let mut left = [0.0; P1];
    let mut right = [0.0; P1];
    ndu[0][0] = 1.0;
    for j in 1..=p {
        left[j] = u - knots[span + 1 - j];
        right[j] = knots[span + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            // lower triangle: knot differences
            ndu[j][r] = right[r + 1] + left[j - r];
            let temp = ndu[r][j - 1] / ndu[j][r];
            // upper triangle: basis functions
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    for j in 0..=p {
        ders[0][j] = ndu[j][p];
    }
    let mut a = [[0.0; P1]; 2];
    for r in 0..=p {
        let (mut s1, mut s2) = (0usize, 1usize);
        a[0][0] = 1.0;
        for k in 1..=n {
            let mut d = 0.0;
            let rk = r as isize - k as isize;
            let pk = p - k;
            if r >= k {
                let rk = rk as usize;
                a[s2][0] = a[s1][0] / ndu[pk + 1][rk];
                d = a[s2][0] * ndu[rk][pk];
            }
            let j1 = if rk >= -1 { 1 } else { (-rk) as usize };
            let j2 = if (r as isize - 1) <= pk as isize {
                k - 1
            } else {
                p - r
            };
            for j in j1..=j2 {
                let idx = (rk + j as isize) as usize;
                a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][idx];
                d += a[s2][j] * ndu[idx][pk];
            }
            if r <= pk {
                a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
                d += a[s2][k] * ndu[r][pk];
            }
            ders[k][r] = d;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    let mut fac = p as f64;
    for (k, row) in ders.iter_mut().enumerate().take(n + 1).skip(1) {
        for v in row.iter_mut().take(p + 1) {
            *v *= fac;
        }
        fac *= (p - k) as f64;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn find_span_clamps() {
        let kv = KnotVector::new(2, vec![0., 0., 0., 1., 2., 3., 4., 4., 5., 5., 5.]).unwrap();
        assert_eq!(kv.find_span(-1.0), 2);
        assert_eq!(kv.find_span(0.0), 2);
        assert_eq!(kv.find_span(2.5), 4);
        assert_eq!(kv.find_span(4.0), 7);
        assert_eq!(kv.find_span(5.0), 7);
        assert_eq!(kv.find_span(7.0), 7);
        assert_eq!(kv.find_span(f64::NAN), 2);
    }
}
