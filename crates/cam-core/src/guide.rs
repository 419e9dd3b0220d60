//! Guiding curves of a tool-axis trajectory surface, evaluated without allocation.
//!
//! A five-axis flank-milling tool path is a one-parameter motion of the tool axis, given by two
//! guiding curves `P0(s)` (a point on the axis near the tip) and `P1(s)` (a point higher up).
//! The envelope distance evaluates both curves and their first two derivatives millions of
//! times, so this module keeps a private, validated copy of each curve (degree, knots, control
//! points, optional weights) and evaluates it with fixed-size stack arrays:
//!
//! - knot span and basis functions with derivatives up to order 2: the `nurbs` crate's
//!   stack-array kernels (The NURBS Book A2.1–A2.3), O(log n + p²);
//! - rational curves: homogeneous evaluation then the quotient rule (NURBS Book eq. 4.8),
//!   `P = A/W`, `P' = (A' − W'P)/W`, `P'' = (A'' − 2W'P' − W''P)/W`.
//!
//! The control-point sensitivity of a point is the rational basis `R_i(s) = w_i N_i(s) / W(s)`
//! (weights held fixed), which is what the envelope derivative scatters onto control points.

use crate::{CamError, Vector3};

/// Largest supported guide-curve degree (stack arrays are sized `MAX_GUIDE_DEGREE + 1`).
pub const MAX_GUIDE_DEGREE: usize = 7;
const NB: usize = MAX_GUIDE_DEGREE + 1;

/// A validated B-spline or NURBS space curve used as a guiding curve.
#[derive(Debug, Clone, PartialEq)]
pub struct GuideCurve {
    degree: usize,
    kv: nurbs::KnotVector,
    ctrl: Vec<Vector3>,
    weights: Option<Vec<f64>>,
}

/// Value and first two derivatives of a guide at one parameter, plus the (rational) basis
/// functions that map control points to the point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GuideEval {
    /// `[C(s), C'(s), C''(s)]`.
    pub d: [Vector3; 3],
    /// Index of the first control point with a non-zero basis function (`span − degree`).
    pub first: usize,
    /// Number of non-zero basis functions (`degree + 1`).
    pub count: usize,
    /// `R_{first+i}(s)` for `i < count`: ∂C(s)/∂Q_{first+i} = R_{first+i}(s)·I.
    pub basis: [f64; NB],
}

impl GuideCurve {
    /// Builds a guide from degree, full knot vector (`n + p + 1` non-decreasing values),
    /// control points and optional positive weights (`None` = non-rational).
    ///
    /// Errors: [`CamError::InvalidGuide`] naming what is wrong.
    pub fn new(
        degree: usize,
        knots: Vec<f64>,
        ctrl: Vec<Vector3>,
        weights: Option<Vec<f64>>,
    ) -> Result<Self, CamError> {
        let bad = |reason: &'static str| Err(CamError::InvalidGuide { reason });
        if degree == 0 || degree > MAX_GUIDE_DEGREE {
            return bad("degree must be in 1..=7");
        }
        if ctrl.len() < degree + 1 {
            return bad("needs at least degree + 1 control points");
        }
        if knots.len() != ctrl.len() + degree + 1 {
            return bad("knot count must be control points + degree + 1");
        }
        if knots.iter().any(|k| !k.is_finite()) || knots.windows(2).any(|w| w[1] < w[0]) {
            return bad("knots must be finite and non-decreasing");
        }
        if knots[ctrl.len()] <= knots[degree] {
            return bad("parameter domain is empty");
        }
        if ctrl
            .iter()
            .any(|q| !(q.x.is_finite() && q.y.is_finite() && q.z.is_finite()))
        {
            return bad("control points must be finite");
        }
        if let Some(w) = &weights {
            if w.len() != ctrl.len() {
                return bad("weight count must equal control point count");
            }
            if w.iter().any(|x| !(x.is_finite() && *x > 0.0)) {
                return bad("weights must be finite and > 0");
            }
        }
        let kv = nurbs::KnotVector::new(degree, knots).map_err(|_| CamError::InvalidGuide {
            reason: "knot vector rejected by the nurbs crate (multiplicity too high)",
        })?;
        Ok(Self {
            degree,
            kv,
            ctrl,
            weights,
        })
    }

    /// Copies a `nurbs` space curve (rational or not) into a guide.
    pub fn from_curve(curve: &nurbs::Curve3) -> Result<Self, CamError> {
        let ctrl = curve
            .control_points()
            .iter()
            .map(|q| Vector3::new(q[0], q[1], q[2]))
            .collect();
        Self::new(
            curve.degree(),
            curve.knots().knots().to_vec(),
            ctrl,
            curve.weights().map(<[f64]>::to_vec),
        )
    }

    /// The guide as a `nurbs` curve (e.g. after an optimiser moved its control points).
    pub fn to_curve(&self) -> Result<nurbs::Curve3, CamError> {
        nurbs::Curve3::new(
            self.degree,
            self.kv.knots().to_vec(),
            self.ctrl.clone(),
            self.weights.clone(),
        )
        .map_err(|_| CamError::InvalidGuide {
            reason: "rejected by nurbs::NurbsCurve::new",
        })
    }

    /// Degree.
    pub fn degree(&self) -> usize {
        self.degree
    }
    /// Full knot vector.
    pub fn knots(&self) -> &[f64] {
        self.kv.knots()
    }
    /// Control points.
    pub fn control_points(&self) -> &[Vector3] {
        &self.ctrl
    }
    /// Weights (`None` for a non-rational curve).
    pub fn weights(&self) -> Option<&[f64]> {
        self.weights.as_deref()
    }
    /// Mutable control points (e.g. for an optimiser updating the path in place).
    pub fn control_points_mut(&mut self) -> &mut [Vector3] {
        &mut self.ctrl
    }

    /// Parameter domain `[u_p, u_n]`.
    pub fn domain(&self) -> (f64, f64) {
        self.kv.domain()
    }

    /// Knot span index of `u` (clamped to the domain), NURBS Book A2.1 (the `nurbs` kernel).
    pub fn find_span(&self, u: f64) -> usize {
        self.kv.find_span(u)
    }

    /// Basis functions and their first two derivatives at `u` in span `span`
    /// (NURBS Book A2.3 with n = 2, the `nurbs` crate's stack-array kernel). `ders[k][j]` =
    /// k-th derivative of `N_{span−p+j}`.
    fn ders_basis(&self, span: usize, u: f64, ders: &mut [[f64; NB]; 3]) {
        let mut full = [[0.0; nurbs::MAX_ORDER]; 3];
        self.kv.ders_basis_funs_into(span, u, 2, &mut full);
        for (row, src) in ders.iter_mut().zip(&full) {
            row.copy_from_slice(&src[..NB]);
        }
    }

    /// Point and first two derivatives at `u` (clamped to the domain), with the rational basis.
    /// No allocation; O(p²).
    pub fn eval2(&self, u: f64) -> GuideEval {
        let (span, n) = self.basis2(u);
        self.combine2(span, &n)
    }

    /// True when `other` has the same degree and knots, so one basis evaluation serves both
    /// (the envelope then evaluates the basis once per frame; weights may differ).
    pub fn shares_basis_with(&self, other: &GuideCurve) -> bool {
        self.degree == other.degree && self.kv.knots() == other.kv.knots()
    }

    /// Knot span and non-rational basis functions with two derivatives at `u` (clamped).
    pub(crate) fn basis2(&self, u: f64) -> (usize, [[f64; NB]; 3]) {
        let span = self.find_span(u);
        let (lo, hi) = self.domain();
        let mut n = [[0.0; NB]; 3];
        self.ders_basis(span, u.clamp(lo, hi), &mut n);
        (span, n)
    }

    /// Point and derivatives from a span and basis computed by `basis2` of this curve or of
    /// one that [shares its basis](Self::shares_basis_with).
    pub(crate) fn combine2(&self, span: usize, n: &[[f64; NB]; 3]) -> GuideEval {
        let p = self.degree;
        let first = span - p;
        let mut d = [Vector3::zeros(); 3];
        let mut basis = [0.0; NB];
        match &self.weights {
            None => {
                for (j, q) in self.ctrl[first..=first + p].iter().enumerate() {
                    d[0] += q * n[0][j];
                    d[1] += q * n[1][j];
                    d[2] += q * n[2][j];
                }
                basis[..=p].copy_from_slice(&n[0][..=p]);
            }
            Some(w) => {
                let mut aw = [Vector3::zeros(); 3];
                let mut ww = [0.0; 3];
                for j in 0..=p {
                    let wj = w[first + j];
                    let q = &self.ctrl[first + j];
                    for k in 0..3 {
                        aw[k] += q * (wj * n[k][j]);
                        ww[k] += wj * n[k][j];
                    }
                }
                let c0 = aw[0] / ww[0];
                let c1 = (aw[1] - c0 * ww[1]) / ww[0];
                let c2 = (aw[2] - c1 * (2.0 * ww[1]) - c0 * ww[2]) / ww[0];
                d = [c0, c1, c2];
                for j in 0..=p {
                    basis[j] = w[first + j] * n[0][j] / ww[0];
                }
            }
        }
        GuideEval {
            d,
            first,
            count: p + 1,
            basis,
        }
    }

    /// Point only at `u` (clamped), NURBS Book A2.2 + A4.1. No allocation; O(p²).
    pub fn point(&self, u: f64) -> Vector3 {
        let p = self.degree;
        let span = self.find_span(u);
        let (lo, hi) = self.domain();
        let u = u.clamp(lo, hi);
        let mut nb = [0.0; NB];
        self.kv.basis_funs(span, u, &mut nb);
        let first = span - p;
        match &self.weights {
            None => (0..=p).fold(Vector3::zeros(), |acc, j| {
                acc + self.ctrl[first + j] * nb[j]
            }),
            Some(w) => {
                let mut a = Vector3::zeros();
                let mut ws = 0.0;
                for j in 0..=p {
                    let wj = w[first + j] * nb[j];
                    a += self.ctrl[first + j] * wj;
                    ws += wj;
                }
                a / ws
            }
        }
    }

    /// An upper bound of `|C'(u)|` over knot span `span` (as returned by [`Self::find_span`]),
    /// or of `|C'(u) − B'(u)|` when `minus` is a curve sharing this one's basis: the largest
    /// norm of the hodograph control points `p·(Q_{i+1} − Q_i)/(u_{i+p+1} − u_{i+1})`,
    /// `i = span − p … span − 1`, whose convex combination `C'` is on that span (NURBS Book
    /// eq. 3.4). `None` for rational curves (their derivative is not such a combination).
    /// O(p), no allocation.
    pub fn derivative_bound(&self, span: usize, minus: Option<&GuideCurve>) -> Option<f64> {
        if self.weights.is_some() || minus.is_some_and(|m| m.weights.is_some()) {
            return None;
        }
        let p = self.degree;
        let u = self.kv.knots();
        let q = |i: usize| match minus {
            Some(m) => self.ctrl[i] - m.ctrl[i],
            None => self.ctrl[i],
        };
        let mut best: f64 = 0.0;
        for i in span.saturating_sub(p)..span {
            let du = u[i + p + 1] - u[i + 1];
            if du > 0.0 {
                best = best.max((q(i + 1) - q(i)).norm() * p as f64 / du);
            }
        }
        Some(best)
    }

    /// An upper bound of `|C''(u)|` over knot span `span`, or of `|C''(u) − B''(u)|` when
    /// `minus` is a curve sharing this one's basis: the largest norm of the second hodograph's
    /// control points `(p − 1)·(Q'_{i+1} − Q'_i)/(u_{i+p+1} − u_{i+2})`, `i = span − p …
    /// span − 2`, with `Q'_i` the first hodograph's (see [`Self::derivative_bound`]); their
    /// convex combination is `C''` on that span. `Some(0)` for degree 1 (linear on each
    /// span); `None` for rational curves or a zero-length knot difference among those used.
    /// O(p), no allocation.
    pub fn second_derivative_bound(&self, span: usize, minus: Option<&GuideCurve>) -> Option<f64> {
        if self.weights.is_some() || minus.is_some_and(|m| m.weights.is_some()) {
            return None;
        }
        let p = self.degree;
        if p < 2 {
            return Some(0.0);
        }
        let u = self.kv.knots();
        let q = |i: usize| match minus {
            Some(m) => self.ctrl[i] - m.ctrl[i],
            None => self.ctrl[i],
        };
        let first = |i: usize| -> Option<Vector3> {
            let du = u[i + p + 1] - u[i + 1];
            (du > 0.0).then(|| (q(i + 1) - q(i)) * (p as f64 / du))
        };
        let lo = span.checked_sub(p)?;
        let mut best: f64 = 0.0;
        for i in lo..span.saturating_sub(1) {
            let du = u[i + p + 1] - u[i + 2];
            if du <= 0.0 {
                return None;
            }
            let d2 = (first(i + 1)? - first(i)?) * ((p - 1) as f64 / du);
            best = best.max(d2.norm());
        }
        Some(best)
    }

    /// Distinct knot values inside the domain (span boundaries), in increasing order.
    pub fn breakpoints(&self) -> Vec<f64> {
        let (lo, hi) = self.domain();
        let mut out: Vec<f64> = Vec::new();
        for &k in &self.kv.knots()[self.degree..=self.ctrl.len()] {
            if (lo..=hi).contains(&k) && out.last().is_none_or(|&l| k > l) {
                out.push(k);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cubic() -> GuideCurve {
        GuideCurve::new(
            3,
            vec![0.0, 0.0, 0.0, 0.0, 0.3, 0.7, 1.0, 1.0, 1.0, 1.0],
            vec![
                Vector3::new(0.0, 0.0, 0.0),
                Vector3::new(1.0, 2.0, 0.5),
                Vector3::new(3.0, 2.5, 1.0),
                Vector3::new(4.0, 0.0, 2.0),
                Vector3::new(6.0, -1.0, 1.5),
                Vector3::new(7.0, 1.0, 0.0),
            ],
            Some(vec![1.0, 0.8, 1.5, 1.0, 0.7, 1.2]),
        )
        .unwrap()
    }

    #[test]
    fn derivatives_match_central_differences() {
        let c = cubic();
        for &u in &[0.05, 0.33, 0.5, 0.69, 0.95] {
            let e = c.eval2(u);
            let h = 1e-5;
            let (m, p) = (c.eval2(u - h), c.eval2(u + h));
            assert!((e.d[0] - c.point(u)).norm() < 1e-12);
            assert!((e.d[1] - (p.d[0] - m.d[0]) / (2.0 * h)).norm() < 1e-6 * e.d[1].norm());
            let fd2 = (p.d[1] - m.d[1]) / (2.0 * h);
            assert!(
                (e.d[2] - fd2).norm() < 1e-5 * e.d[2].norm(),
                "{u}: {} vs {}",
                e.d[2],
                fd2
            );
            let s: f64 = e.basis[..e.count].iter().sum();
            assert!((s - 1.0).abs() < 1e-12, "rational basis sums to one");
            let q: Vector3 = (0..e.count)
                .map(|i| c.control_points()[e.first + i] * e.basis[i])
                .sum();
            assert!((q - e.d[0]).norm() < 1e-12);
        }
    }

    #[test]
    #[allow(clippy::needless_range_loop)]
    fn agrees_with_the_nurbs_crate() {
        let c = cubic();
        let n = c.to_curve().unwrap();
        let back = GuideCurve::from_curve(&n).unwrap();
        assert_eq!(back, c);
        for &u in &[0.0, 0.2, 0.5, 0.8, 1.0] {
            let d = n.derivs(u, 2);
            let e = c.eval2(u);
            for k in 0..3 {
                let dk = Vector3::new(d[k][0], d[k][1], d[k][2]);
                assert!((dk - e.d[k]).norm() < 1e-9 * (1.0 + dk.norm()), "{u} {k}");
            }
        }
    }

    #[test]
    fn invalid_guides_are_rejected() {
        let q = vec![Vector3::zeros(); 4];
        assert!(GuideCurve::new(0, vec![0.0; 5], q.clone(), None).is_err());
        assert!(GuideCurve::new(3, vec![0.0; 7], q.clone(), None).is_err());
        assert!(GuideCurve::new(3, vec![0.0; 8], q.clone(), None).is_err());
        let k = vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
        assert!(GuideCurve::new(3, k.clone(), q.clone(), Some(vec![1.0, -1.0, 1.0, 1.0])).is_err());
        assert!(GuideCurve::new(3, k, q, None).is_ok());
    }
}
