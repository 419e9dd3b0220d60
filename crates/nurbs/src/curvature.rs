//! Principal curvatures and directions of a surface from its first and second fundamental
//! forms.

use nalgebra::Vector3;

use crate::surface::{NurbsSurface, SurfaceDerivs2};

/// Principal curvatures at a surface point.
///
/// Sign convention: a curvature is positive where the surface bends toward the normal
/// `n = su × sv / |su × sv|` (a sphere with outward normals has `k1 = k2 = −1/R`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrincipalCurvatures {
    /// Larger principal curvature (1/mm for mm geometry).
    pub k1: f64,
    /// Smaller principal curvature.
    pub k2: f64,
    /// Unit tangent direction of `k1`.
    pub dir1: Vector3<f64>,
    /// Unit tangent direction of `k2` (`dir1 × dir2 = normal`).
    pub dir2: Vector3<f64>,
    /// Unit normal used for the signs.
    pub normal: Vector3<f64>,
}

impl PrincipalCurvatures {
    /// Gaussian curvature `K = k1 k2`.
    pub fn gaussian(&self) -> f64 {
        self.k1 * self.k2
    }
    /// Mean curvature `H = (k1 + k2) / 2`.
    pub fn mean(&self) -> f64 {
        0.5 * (self.k1 + self.k2)
    }
}

impl SurfaceDerivs2 {
    /// Principal curvatures from the fundamental forms `I = [E F; F G]`,
    /// `II = [L M; M N]` (`L = suu·n`, `M = suv·n`, `N = svv·n`): the eigen-pairs of the
    /// shape operator `I⁻¹ II`, computed as a symmetric 2×2 eigenproblem in the orthonormal
    /// tangent frame `e1 = su/|su|`, `e2 = n × e1` (closed form, O(1)). `None` where the
    /// normal is undefined (see [`SurfaceDerivs2::normal`]).
    pub fn principal_curvatures(&self) -> Option<PrincipalCurvatures> {
        let n = self.normal()?;
        let a11 = self.su.norm();
        let e1 = self.su / a11;
        let e2 = n.cross(&e1);
        let a12 = self.sv.dot(&e1);
        let a22 = self.sv.dot(&e2);
        let (l, m, nn) = (self.suu.dot(&n), self.suv.dot(&n), self.svv.dot(&n));
        // J maps (du, dv) to frame coordinates: J = [a11 a12; 0 a22]; W = J⁻ᵀ II J⁻¹.
        let (i11, i12, i22) = (1.0 / a11, -a12 / (a11 * a22), 1.0 / a22);
        // B J⁻¹ with J⁻¹ = [i11 i12; 0 i22]
        let b11 = l * i11;
        let b12 = l * i12 + m * i22;
        let b21 = m * i11;
        let b22 = m * i12 + nn * i22;
        // J⁻ᵀ (B J⁻¹), J⁻ᵀ = [i11 0; i12 i22]
        let w11 = i11 * b11;
        let w12 = i11 * b12;
        let w21 = i12 * b11 + i22 * b21;
        let w22 = i12 * b12 + i22 * b22;
        let w12 = 0.5 * (w12 + w21);
        let mean = 0.5 * (w11 + w22);
        let d = (0.25 * (w11 - w22) * (w11 - w22) + w12 * w12).sqrt();
        let theta = 0.5 * (2.0 * w12).atan2(w11 - w22);
        let dir1 = e1 * theta.cos() + e2 * theta.sin();
        let dir2 = n.cross(&dir1);
        Some(PrincipalCurvatures {
            k1: mean + d,
            k2: mean - d,
            dir1,
            dir2,
            normal: n,
        })
    }
}

impl NurbsSurface {
    /// Principal curvatures at `(u, v)` (see [`SurfaceDerivs2::principal_curvatures`]).
    pub fn principal_curvatures(&self, u: f64, v: f64) -> Option<PrincipalCurvatures> {
        self.derivs2(u, v).principal_curvatures()
    }
}
