//! Stepped / tapered cantilever beams of solid circular section and their exact tip
//! compliance.

use crate::error::{check, StiffnessError};
use crate::quadrature::gauss_legendre;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// A beam section of linearly varying radius, listed from the clamp toward the load.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Section {
    /// Length along the beam (mm).
    pub length: f64,
    /// Radius at the end nearer the clamp (mm).
    pub radius_clamp_side: f64,
    /// Radius at the end nearer the load (mm).
    pub radius_load_side: f64,
}

/// A cantilever clamped at `x = 0` and loaded transversely at its free end `x = L`, made of
/// sections listed from the clamp to the load.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Beam {
    /// Sections from the clamp (x = 0) to the loaded end (x = L).
    pub sections: Vec<Section>,
    /// Young's modulus (N/mm² = MPa).
    pub youngs_modulus: f64,
}

impl Beam {
    /// Builds and validates a beam.
    ///
    /// Errors: no section, a non-positive length or radius, a non-positive modulus.
    pub fn new(sections: Vec<Section>, youngs_modulus: f64) -> Result<Self, StiffnessError> {
        if sections.is_empty() {
            return Err(StiffnessError::EmptyBeam);
        }
        check(
            "youngs_modulus",
            youngs_modulus,
            youngs_modulus > 0.0,
            "must be > 0",
        )?;
        for s in &sections {
            check("section.length", s.length, s.length > 0.0, "must be > 0")?;
            check(
                "section.radius_clamp_side",
                s.radius_clamp_side,
                s.radius_clamp_side > 0.0,
                "must be > 0",
            )?;
            check(
                "section.radius_load_side",
                s.radius_load_side,
                s.radius_load_side > 0.0,
                "must be > 0",
            )?;
        }
        Ok(Self {
            sections,
            youngs_modulus,
        })
    }

    /// Total length `L` (mm).
    pub fn length(&self) -> f64 {
        self.sections.iter().map(|s| s.length).sum()
    }

    /// `(x0, x1, section)` for each section.
    pub(crate) fn spans(&self) -> impl Iterator<Item = (f64, f64, &Section)> + '_ {
        let mut x = 0.0;
        self.sections.iter().map(move |s| {
            let x0 = x;
            x += s.length;
            (x0, x, s)
        })
    }

    /// Exact tip compliance `w(L)/F = ∫₀ᴸ (L − x)² / (E I(x)) dx` (mm/N) by the unit-load
    /// method.
    ///
    /// With `s = L − x` and `ρ = α + β s` on a section, `∫₀^S s²/(α+βs)⁴ ds = S³/(3α(α+βS)³)`
    /// (closed form, valid for `β = 0`). If the linear radius law extrapolates to `α ≤ 0`
    /// at the load point, a composite 16-point Gauss–Legendre rule over 16 panels is used on
    /// that section instead (the integrand is smooth there; relative error < 1e-14 for the
    /// radius ratios of real tools). O(sections).
    pub fn exact_compliance(&self) -> f64 {
        let l = self.length();
        let mut total = 0.0;
        for (x0, x1, sec) in self.spans() {
            let (s1, s2) = (l - x1, l - x0);
            let (rho1, rho2) = (sec.radius_load_side, sec.radius_clamp_side);
            let beta = (rho2 - rho1) / (s2 - s1);
            let alpha = rho1 - beta * s1;
            let part = if alpha > 1e-6 * rho1.min(rho2) {
                let g = |s: f64| s.powi(3) / (3.0 * alpha * (alpha + beta * s).powi(3));
                g(s2) - g(s1)
            } else {
                composite_gauss(s1, s2, |s| {
                    let rho = rho1 + beta * (s - s1);
                    s * s / rho.powi(4)
                })
            };
            total += part;
        }
        4.0 / (PI * self.youngs_modulus) * total
    }

    /// Exact stiffness `1 / exact_compliance()` (N/mm).
    pub fn exact_stiffness(&self) -> f64 {
        1.0 / self.exact_compliance()
    }
}

fn composite_gauss(a: f64, b: f64, f: impl Fn(f64) -> f64) -> f64 {
    let (xs, ws) = gauss_legendre(16);
    let panels = 16;
    let h = (b - a) / panels as f64;
    let mut sum = 0.0;
    for p in 0..panels {
        let c = a + (p as f64 + 0.5) * h;
        for (x, w) in xs.iter().zip(&ws) {
            sum += w * f(c + 0.5 * h * x);
        }
    }
    0.5 * h * sum
}

/// Second moment of area of a solid circle of radius `rho`.
pub(crate) fn inertia(rho: f64) -> f64 {
    PI * rho.powi(4) / 4.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cylinder_is_three_ei_over_l_cubed() {
        let (r, l, e) = (3.0, 40.0, 600e3);
        let beam = Beam::new(
            vec![Section {
                length: l,
                radius_clamp_side: r,
                radius_load_side: r,
            }],
            e,
        )
        .unwrap();
        let k = 3.0 * e * inertia(r) / l.powi(3);
        assert!((beam.exact_stiffness() / k - 1.0).abs() < 1e-14);
    }

    #[test]
    fn closed_form_matches_quadrature_on_a_taper_and_a_step() {
        let beam = Beam::new(
            vec![
                Section {
                    length: 15.0,
                    radius_clamp_side: 4.0,
                    radius_load_side: 4.0,
                },
                Section {
                    length: 25.0,
                    radius_clamp_side: 4.5,
                    radius_load_side: 2.0,
                },
            ],
            210e3,
        )
        .unwrap();
        let l = beam.length();
        let mut total = 0.0;
        for (x0, x1, s) in beam.spans() {
            total += composite_gauss(x0, x1, |x| {
                let t = (x - x0) / (x1 - x0);
                let rho = s.radius_clamp_side + t * (s.radius_load_side - s.radius_clamp_side);
                (l - x).powi(2) / (beam.youngs_modulus * inertia(rho))
            });
        }
        assert!((beam.exact_compliance() / total - 1.0).abs() < 1e-13);
    }

    #[test]
    fn invalid_beams_are_rejected() {
        assert_eq!(Beam::new(vec![], 1.0), Err(StiffnessError::EmptyBeam));
        let s = Section {
            length: 1.0,
            radius_clamp_side: 1.0,
            radius_load_side: 1.0,
        };
        assert!(Beam::new(vec![s], -1.0).is_err());
        for bad in [
            Section { length: 0.0, ..s },
            Section {
                radius_clamp_side: f64::NAN,
                ..s
            },
            Section {
                radius_load_side: -2.0,
                ..s
            },
        ] {
            assert!(matches!(
                Beam::new(vec![bad], 1.0),
                Err(StiffnessError::InvalidParameter { .. })
            ));
        }
    }
}
