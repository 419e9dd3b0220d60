//! The `ParametricCurve` and `ParametricSurface` traits: the geometry interface other
//! crates program against, so users can plug in their own curves and surfaces.

use nalgebra::{SVector, Vector3};

use crate::curve::NurbsCurve;
use crate::surface::{NurbsSurface, SurfaceDerivs2};

/// A regular parametric curve `C: [a, b] → ℝᴰ`.
pub trait ParametricCurve<const D: usize> {
    /// Parameter domain `(a, b)`.
    fn domain(&self) -> (f64, f64);
    /// Point `C(u)`; implementations clamp `u` to the domain.
    fn point(&self, u: f64) -> SVector<f64, D>;
    /// `[C(u), C'(u), ..., C⁽ⁿ⁾(u)]`.
    fn derivs(&self, u: f64, n: usize) -> Vec<SVector<f64, D>>;
}

/// A parametric surface `S: [u0, u1] × [v0, v1] → ℝ³`.
pub trait ParametricSurface {
    /// Parameter domain `((u0, u1), (v0, v1))`.
    fn domain(&self) -> ((f64, f64), (f64, f64));
    /// Point `S(u, v)`; implementations clamp the parameters to the domain.
    fn point(&self, u: f64, v: f64) -> Vector3<f64>;
    /// Point and partial derivatives up to second order.
    fn derivs2(&self, u: f64, v: f64) -> SurfaceDerivs2;
    /// Unit normal `su × sv / |su × sv|`, `None` where singular.
    fn normal(&self, u: f64, v: f64) -> Option<Vector3<f64>> {
        self.derivs2(u, v).normal()
    }
}

impl<const D: usize> ParametricCurve<D> for NurbsCurve<D> {
    fn domain(&self) -> (f64, f64) {
        NurbsCurve::domain(self)
    }
    fn point(&self, u: f64) -> SVector<f64, D> {
        NurbsCurve::point(self, u)
    }
    fn derivs(&self, u: f64, n: usize) -> Vec<SVector<f64, D>> {
        NurbsCurve::derivs(self, u, n)
    }
}

impl ParametricSurface for NurbsSurface {
    fn domain(&self) -> ((f64, f64), (f64, f64)) {
        NurbsSurface::domain(self)
    }
    fn point(&self, u: f64, v: f64) -> Vector3<f64> {
        NurbsSurface::point(self, u, v)
    }
    fn derivs2(&self, u: f64, v: f64) -> SurfaceDerivs2 {
        NurbsSurface::derivs2(self, u, v)
    }
}
