//! NURBS curves in `D` dimensions: construction with validation, evaluation (A4.1 via
//! A2.2), derivatives of any order (A3.2 for the non-rational part, A4.2 for the rational
//! quotient rule).

use nalgebra::SVector;

use crate::error::NurbsError;
use crate::homogeneous::HSpline;
use crate::knots::{basis_funs_fixed, clamp_param, ders_basis_fixed, KnotVector};
use crate::util::binomial;
use crate::MAX_ORDER;

/// A (possibly rational) B-spline curve in `D` dimensions,
/// `C(u) = Σ N_{i,p}(u) w_i P_i / Σ N_{i,p}(u) w_i` on the domain `[u_p, u_{m-p}]`.
///
/// Non-rational curves store no weights (all weights are 1). Control points are stored in
/// Euclidean (not homogeneous) form.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "NurbsCurveData<D>", into = "NurbsCurveData<D>")]
pub struct NurbsCurve<const D: usize> {
    knots: KnotVector,
    ctrl: Vec<SVector<f64, D>>,
    weights: Option<Vec<f64>>,
}

/// Planar NURBS curve.
pub type Curve2 = NurbsCurve<2>;
/// Spatial NURBS curve.
pub type Curve3 = NurbsCurve<3>;

/// Serialised form of a [`NurbsCurve`]; validated by [`NurbsCurve::new`] on the way back.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct NurbsCurveData<const D: usize> {
    /// Degree `p`.
    pub degree: usize,
    /// Knots `u_0..=u_m`.
    pub knots: Vec<f64>,
    /// Control points `P_0..=P_n` (Euclidean).
    pub control_points: Vec<SVector<f64, D>>,
    /// Weights `w_0..=w_n`; absent for a non-rational curve.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weights: Option<Vec<f64>>,
}

impl<const D: usize> TryFrom<NurbsCurveData<D>> for NurbsCurve<D> {
    type Error = NurbsError;
    fn try_from(d: NurbsCurveData<D>) -> Result<Self, NurbsError> {
        NurbsCurve::new(d.degree, d.knots, d.control_points, d.weights)
    }
}

impl<const D: usize> From<NurbsCurve<D>> for NurbsCurveData<D> {
    fn from(c: NurbsCurve<D>) -> Self {
        NurbsCurveData {
            degree: c.knots.degree(),
            knots: c.knots.knots().to_vec(),
            control_points: c.ctrl,
            weights: c.weights,
        }
    }
}

impl<const D: usize> NurbsCurve<D> {
    /// Builds and validates a curve: knot vector (see [`KnotVector::new`]), knot count
    /// `n_ctrl + degree + 1`, finite control points, and (if given) one positive finite
    /// weight per control point. `weights: None` means a non-rational curve.
    pub fn new(
        degree: usize,
        knots: Vec<f64>,
        ctrl: Vec<SVector<f64, D>>,
        weights: Option<Vec<f64>>,
    ) -> Result<Self, NurbsError> {
        let kv = KnotVector::new(degree, knots)?;
        Self::from_knot_vector(kv, ctrl, weights)
    }

    /// As [`NurbsCurve::new`] with an already validated knot vector.
    pub fn from_knot_vector(
        knots: KnotVector,
        ctrl: Vec<SVector<f64, D>>,
        weights: Option<Vec<f64>>,
    ) -> Result<Self, NurbsError> {
        let degree = knots.degree();
        let expected = ctrl.len() + degree + 1;
        if knots.knots().len() != expected {
            return Err(NurbsError::KnotCountMismatch {
                n_knots: knots.knots().len(),
                n_ctrl: ctrl.len(),
                degree,
                expected,
            });
        }
        for (index, p) in ctrl.iter().enumerate() {
            if !p.iter().all(|c| c.is_finite()) {
                return Err(NurbsError::NonFiniteControlPoint { index });
            }
        }
        if let Some(w) = &weights {
            if w.len() != ctrl.len() {
                return Err(NurbsError::LengthMismatch {
                    what: "curve weights".into(),
                    expected: ctrl.len(),
                    got: w.len(),
                });
            }
            for (index, &value) in w.iter().enumerate() {
                if !(value.is_finite() && value > 0.0) {
                    return Err(NurbsError::InvalidWeight { index, value });
                }
            }
        }
        Ok(NurbsCurve {
            knots,
            ctrl,
            weights,
        })
    }

    /// Builds a curve from homogeneous data `(w_i P_i, w_i)` stored with stride `D + 1`
    /// (or Euclidean with stride `D` when `rational` is false). Used by the knot
    /// algorithms, which work in homogeneous space.
    pub(crate) fn from_homogeneous(
        knots: KnotVector,
        data: &[f64],
        rational: bool,
    ) -> Result<Self, NurbsError> {
        let (ctrl, weights) = crate::util::split_homogeneous::<D>(data, rational);
        Self::from_knot_vector(knots, ctrl, weights)
    }

    /// Homogeneous control data, stride `D + 1` if rational else `D`.
    pub(crate) fn homogeneous(&self) -> Vec<f64> {
        crate::util::to_homogeneous(&self.ctrl, self.weights.as_deref())
    }

    /// The control polygon in homogeneous form for the chapter-5 algorithms.
    pub(crate) fn to_hspline(&self) -> HSpline {
        HSpline {
            p: self.degree(),
            knots: self.knots.knots().to_vec(),
            pts: self.homogeneous(),
            dim: if self.is_rational() { D + 1 } else { D },
        }
    }

    /// Rebuilds a curve (validating it) from a homogeneous control polygon.
    pub(crate) fn from_hspline(h: &HSpline, rational: bool) -> Result<Self, NurbsError> {
        let kv = KnotVector::new(h.p, h.knots.clone())?;
        Self::from_homogeneous(kv, &h.pts, rational)
    }

    /// Same knots and weights, control points mapped by `f` (callers guarantee `f`
    /// keeps finite points finite, e.g. a rigid motion).
    pub(crate) fn map_control_points(
        &self,
        f: impl Fn(SVector<f64, D>) -> SVector<f64, D>,
    ) -> Self {
        NurbsCurve {
            knots: self.knots.clone(),
            ctrl: self.ctrl.iter().map(|p| f(*p)).collect(),
            weights: self.weights.clone(),
        }
    }

    /// Parameter domain `[u_p, u_{m-p}]`.
    #[inline]
    pub fn domain(&self) -> (f64, f64) {
        self.knots.domain()
    }

    /// Degree `p`.
    #[inline]
    pub fn degree(&self) -> usize {
        self.knots.degree()
    }

    /// The knot vector.
    #[inline]
    pub fn knots(&self) -> &KnotVector {
        &self.knots
    }

    /// Control points `P_0..=P_n` (Euclidean).
    #[inline]
    pub fn control_points(&self) -> &[SVector<f64, D>] {
        &self.ctrl
    }

    /// Weights, or `None` for a non-rational curve.
    #[inline]
    pub fn weights(&self) -> Option<&[f64]> {
        self.weights.as_deref()
    }

    /// True when the curve carries weights.
    #[inline]
    pub fn is_rational(&self) -> bool {
        self.weights.is_some()
    }

    /// Point `C(u)` (NURBS Book A4.1 on top of A2.2; O(p² + p D), no allocation).
    /// Parameters outside the domain are clamped to it.
    #[inline]
    pub fn point(&self, u: f64) -> SVector<f64, D> {
        let p = self.knots.degree();
        let kn = self.knots.knots();
        let u = clamp_param(kn, p, u);
        let w = self.weights.as_deref();
        match p {
            1 => return crate::kernels::curve_point::<D, 2>(&self.knots, &self.ctrl, w, u),
            2 => return crate::kernels::curve_point::<D, 3>(&self.knots, &self.ctrl, w, u),
            3 => return crate::kernels::curve_point::<D, 4>(&self.knots, &self.ctrl, w, u),
            _ => {}
        }
        let span = crate::knots::find_span(kn, p, u);
        let n = basis_funs_fixed(kn, p, span, u);
        let first = span - p;
        match &self.weights {
            None => {
                let mut c = SVector::<f64, D>::zeros();
                for j in 0..=p {
                    c += self.ctrl[first + j] * n[j];
                }
                c
            }
            Some(w) => {
                let mut c = SVector::<f64, D>::zeros();
                let mut ws = 0.0;
                for j in 0..=p {
                    let nw = n[j] * w[first + j];
                    c += self.ctrl[first + j] * nw;
                    ws += nw;
                }
                c / ws
            }
        }
    }

    /// Point, first and second derivative `[C, C', C'']` without allocation (A3.2/A4.2
    /// specialised to order 2; O(p² + p D)). Parameters outside the domain are clamped.
    pub fn derivs2(&self, u: f64) -> [SVector<f64, D>; 3] {
        let p = self.knots.degree();
        let u = clamp_param(self.knots.knots(), p, u);
        let w = self.weights.as_deref();
        match p {
            1 => return crate::kernels::curve_derivs2::<D, 2>(&self.knots, &self.ctrl, w, u),
            2 => return crate::kernels::curve_derivs2::<D, 3>(&self.knots, &self.ctrl, w, u),
            3 => return crate::kernels::curve_derivs2::<D, 4>(&self.knots, &self.ctrl, w, u),
            _ => {}
        }
        let mut out = [SVector::<f64, D>::zeros(); 3];
        self.derivs_into(u, &mut out);
        out
    }

    /// Derivatives `[C(u), C'(u), ..., C⁽ⁿ⁾(u)]` of any order, rational curves included.
    ///
    /// Non-rational part: NURBS Book A3.2 (derivatives of the homogeneous curve `A(u)` and
    /// weight `w(u)` from A2.3 basis derivatives); rational curves then apply A4.2,
    /// `C⁽ᵏ⁾ = (A⁽ᵏ⁾ − Σ_{i=1..k} C(k,i) w⁽ⁱ⁾ C⁽ᵏ⁻ⁱ⁾) / w`. Orders above the degree of a
    /// non-rational curve are zero. Cost O(p² + n p D + n² D). Parameters outside the
    /// domain are clamped (one-sided derivatives at the ends and at knots: the span with
    /// `u_i <= u < u_{i+1}` is used, i.e. right-sided, except at the domain end).
    pub fn derivs(&self, u: f64, n: usize) -> Vec<SVector<f64, D>> {
        let mut out = vec![SVector::<f64, D>::zeros(); n + 1];
        self.derivs_into(u, &mut out);
        out
    }

    /// As [`NurbsCurve::derivs`] writing `out.len() - 1` orders into `out` (no
    /// allocation for orders below [`crate::MAX_ORDER`]).
    pub fn derivs_into(&self, u: f64, out: &mut [SVector<f64, D>]) {
        if out.is_empty() {
            return;
        }
        let n = out.len() - 1;
        let p = self.knots.degree();
        let kn = self.knots.knots();
        let u = clamp_param(kn, p, u);
        let span = crate::knots::find_span(kn, p, u);
        let du = n.min(p);
        let mut nd = [[0.0; MAX_ORDER]; MAX_ORDER];
        ders_basis_fixed(kn, p, span, u, du, &mut nd);
        let first = span - p;
        for o in out.iter_mut() {
            *o = SVector::zeros();
        }
        match &self.weights {
            None => {
                for k in 0..=du {
                    let mut c = SVector::<f64, D>::zeros();
                    for j in 0..=p {
                        c += self.ctrl[first + j] * nd[k][j];
                    }
                    out[k] = c;
                }
            }
            Some(w) => {
                // A(u) derivatives go straight into `out`, w(u) derivatives into `wd`.
                let mut wd = [0.0; MAX_ORDER];
                for k in 0..=du {
                    let mut a = SVector::<f64, D>::zeros();
                    let mut ws = 0.0;
                    for j in 0..=p {
                        let nw = nd[k][j] * w[first + j];
                        a += self.ctrl[first + j] * nw;
                        ws += nw;
                    }
                    out[k] = a;
                    wd[k] = ws;
                }
                // A4.2 (w⁽ⁱ⁾ = 0 for i > p)
                for k in 0..=n {
                    let mut v = out[k];
                    for i in 1..=k.min(p) {
                        v -= out[k - i] * (binomial(k, i) * wd[i]);
                    }
                    out[k] = v / wd[0];
                }
            }
        }
    }
}
