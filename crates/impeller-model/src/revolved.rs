//! Hub and shroud: exact NURBS surfaces of revolution of their meridional contours about Z.
//!
//! The surface is the tensor product of the (z, r) contour (parameter u, inlet → outlet) with
//! the rational quadratic full circle of nine control points and weights 1, √2/2, 1, ...
//! (NURBS Book A8.1, §7.5): S(u, v) = (r(u) cos φ(v), r(u) sin φ(v), z(u)), v ∈ [0, 1] going
//! once around +Z. φ(v) is piecewise rational; [`RevolvedSurface::v_of_angle`] inverts it
//! per quarter by bisection.
//! Its natural normal S_u × S_v is the meridional channel-side normal (see
//! [`crate::meridional`]): into the channel for the hub, out of it for the shroud.

use crate::error::ModelError;
use crate::meridional::MeridionalCurve;
use nalgebra::{Vector2, Vector3};
use nurbs::NurbsSurface;
use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_2, TAU};

/// A surface of revolution about Z with its meridional contour.
#[derive(Debug, Clone)]
pub struct RevolvedSurface {
    meridional: MeridionalCurve,
    surface: NurbsSurface,
}

impl RevolvedSurface {
    /// Revolves `meridional` once about +Z.
    pub fn new(meridional: MeridionalCurve) -> Result<Self, ModelError> {
        let c = meridional.curve();
        let circle: [(f64, f64, f64); 9] = [
            (1.0, 0.0, 1.0),
            (1.0, 1.0, FRAC_1_SQRT_2),
            (0.0, 1.0, 1.0),
            (-1.0, 1.0, FRAC_1_SQRT_2),
            (-1.0, 0.0, 1.0),
            (-1.0, -1.0, FRAC_1_SQRT_2),
            (0.0, -1.0, 1.0),
            (1.0, -1.0, FRAC_1_SQRT_2),
            (1.0, 0.0, 1.0),
        ];
        let cw: Vec<f64> = match c.weights() {
            Some(w) => w.to_vec(),
            None => vec![1.0; c.control_points().len()],
        };
        let mut ctrl = Vec::new();
        let mut weights = Vec::new();
        for (p, &w) in c.control_points().iter().zip(&cw) {
            let (z, r) = (p[0], p[1]);
            ctrl.push(
                circle
                    .iter()
                    .map(|&(x, y, _)| Vector3::new(r * x, r * y, z))
                    .collect::<Vec<_>>(),
            );
            weights.push(circle.iter().map(|&(_, _, wc)| w * wc).collect::<Vec<_>>());
        }
        let knots_v = vec![
            0.0, 0.0, 0.0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1.0, 1.0, 1.0,
        ];
        let surface = NurbsSurface::new(
            c.degree(),
            2,
            c.knots().knots().to_vec(),
            knots_v,
            ctrl,
            Some(weights),
        )?;
        Ok(Self {
            meridional,
            surface,
        })
    }

    /// The meridional contour.
    pub fn meridional(&self) -> &MeridionalCurve {
        &self.meridional
    }

    /// The exact NURBS surface (u along the contour, v ∈ [0, 1] around Z).
    pub fn surface(&self) -> &NurbsSurface {
        &self.surface
    }

    /// Surface parameter v of the polar angle φ (any real; reduced to [0, 2π)): per quarter,
    /// the root of the monotone angle of the rational quadratic arc, found by bisection to
    /// 1e-15.
    pub fn v_of_angle(phi: f64) -> f64 {
        let a = phi.rem_euclid(TAU);
        let q = (a / FRAC_PI_2).floor().min(3.0);
        let local = a - q * FRAC_PI_2;
        let w = FRAC_1_SQRT_2;
        let angle = |s: f64| {
            let x = (1.0 - s) * (1.0 - s) + 2.0 * w * s * (1.0 - s);
            let y = 2.0 * w * s * (1.0 - s) + s * s;
            y.atan2(x)
        };
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..55 {
            let mid = 0.5 * (lo + hi);
            if angle(mid) < local {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        (q + 0.5 * (lo + hi)) * 0.25
    }

    /// The meridian at polar angle φ: the isocurve v(φ) of the surface, an exact NURBS copy of
    /// the contour turned into the plane of φ.
    pub fn meridian(&self, phi: f64) -> Result<nurbs::NurbsCurve<3>, ModelError> {
        Ok(self.surface.iso_curve_at_v(Self::v_of_angle(phi))?)
    }

    /// The parallel circle at contour parameter t: the isocurve u = t (exact rational circle).
    pub fn parallel(&self, t: f64) -> Result<nurbs::NurbsCurve<3>, ModelError> {
        Ok(self.surface.iso_curve_at_u(t)?)
    }

    /// Point at contour parameter t and polar angle φ (closed form).
    pub fn point(&self, t: f64, phi: f64) -> Vector3<f64> {
        let zr = self.meridional.point(t);
        Vector3::new(zr[1] * phi.cos(), zr[1] * phi.sin(), zr[0])
    }

    /// Unit channel-side normal at contour parameter t and angle φ.
    pub fn normal(&self, t: f64, phi: f64) -> Vector3<f64> {
        let n = self.meridional.normal(t);
        Vector3::new(n[1] * phi.cos(), n[1] * phi.sin(), n[0])
    }

    /// Closest point to `p`: (contour parameter, angle, signed distance along the
    /// channel-side normal). Exact reduction to the meridional half plane: the closest point
    /// of a surface of revolution lies in the meridian plane of `p`.
    pub fn closest(&self, p: &Vector3<f64>) -> (f64, f64, f64) {
        let phi = p.y.atan2(p.x);
        let zr = Vector2::new(p.z, (p.x * p.x + p.y * p.y).sqrt());
        let (t, d) = self.meridional.closest(zr);
        (t, phi, d)
    }

    /// Signed distance of `p` to the surface (positive on the channel side of the hub /
    /// outside the shroud).
    pub fn signed_distance(&self, p: &Vector3<f64>) -> f64 {
        self.meridional.closest(MeridionalCurve::zr_of(p)).1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nurbs_surface_matches_closed_form() {
        let m = MeridionalCurve::quarter_ellipse([40.0, 8.0], [4.0, 38.5]).unwrap();
        let s = RevolvedSurface::new(m).unwrap();
        for i in 0..=10 {
            let t = i as f64 / 10.0;
            for k in 0..24 {
                let phi = k as f64 * 0.3 - 1.0;
                let v = RevolvedSurface::v_of_angle(phi);
                let p = s.surface().point(t, v);
                let q = s.point(t, phi);
                assert!((p - q).norm() < 1e-9, "{t} {phi}: {p} vs {q}");
                let n = s.surface().normal(t, v).unwrap();
                assert!((n - s.normal(t, phi)).norm() < 1e-9);
            }
        }
    }
}
