//! Normal thickness of a blade along the flow, with blunt or rounded leading/trailing edges.
//!
//! The designer tabulates the normal thickness τ(m) (mm) against the blade's own meridional
//! fraction m ∈ [0, 1] (leading edge 0, trailing edge 1); between table points it is the
//! natural cubic spline of [`Law`]. A **blunt** edge keeps τ up to the edge, which is then
//! closed by a flat face. A **rounded** edge is a nose of length ℓ (in m; ℓ · meridional
//! length = τ) with half thickness `h(d) = τ/2 · sqrt(1 − (1 − d/ℓ)⁴)` at distance d < ℓ from
//! the edge: a parabolic tip of radius ≈ τ/2 (h² ≈ τ² d/ℓ) that joins the nominal thickness
//! with matching first and second derivatives (C², so interpolated sides follow it closely).
//!
//! Because `h` has an infinite slope at the edge, blade surfaces are not parametrised by m but
//! by a parameter u with m = μ(u) quadratic near a rounded edge ([`ThicknessLaw::m_of_u`]), so
//! `h(μ(u))` is smooth in u and the pressure and suction sides meet with a common tangent.

use crate::law::Law;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Shape of a leading or trailing edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EdgeShape {
    /// Thickness kept to the edge; the edge is a flat face between the two sides.
    Blunt,
    /// Rounded nose of tip radius about τ/2 (see the module docs).
    Rounded,
}

/// Normal thickness distribution of one blade with its edge shapes.
#[derive(Debug, Clone, PartialEq)]
pub struct ThicknessLaw {
    law: Law,
    leading: EdgeShape,
    trailing: EdgeShape,
    nose_le: f64,
    nose_te: f64,
}

impl ThicknessLaw {
    /// Thickness law `law` (mm against blade-local m) with the given edges;
    /// `meridional_length_mm` (the blade's mean meridional length) sizes rounded noses.
    pub fn new(
        law: Law,
        leading: EdgeShape,
        trailing: EdgeShape,
        meridional_length_mm: f64,
    ) -> Self {
        let l = meridional_length_mm.max(1e-9);
        let nose_le = (law.eval(0.0) / l).clamp(1e-6, 0.25);
        let nose_te = (law.eval(1.0) / l).clamp(1e-6, 0.25);
        Self {
            law,
            leading,
            trailing,
            nose_le,
            nose_te,
        }
    }

    /// Leading-edge shape.
    pub fn leading(&self) -> EdgeShape {
        self.leading
    }

    /// Trailing-edge shape.
    pub fn trailing(&self) -> EdgeShape {
        self.trailing
    }

    /// The tabulated (nominal) thickness τ(m) in mm, without edge rounding.
    pub fn nominal(&self, m: f64) -> f64 {
        self.law.eval(m)
    }

    /// Extent (in m) of the rounded noses at the leading and trailing edge (0 when blunt).
    pub fn nose_lengths(&self) -> (f64, f64) {
        (
            if self.leading == EdgeShape::Rounded {
                self.nose_le
            } else {
                0.0
            },
            if self.trailing == EdgeShape::Rounded {
                self.nose_te
            } else {
                0.0
            },
        )
    }

    /// Actual normal thickness at m (mm): nominal, reduced inside rounded noses.
    pub fn thickness(&self, m: f64) -> f64 {
        let mut t = self.law.eval(m);
        let (le, te) = self.nose_lengths();
        if le > 0.0 && m < le {
            let d = (m / le).clamp(0.0, 1.0);
            t *= (1.0 - (1.0 - d).powi(4)).max(0.0).sqrt();
        }
        if te > 0.0 && m > 1.0 - te {
            let d = ((1.0 - m) / te).clamp(0.0, 1.0);
            t *= (1.0 - (1.0 - d).powi(4)).max(0.0).sqrt();
        }
        t
    }

    /// The blade parameter map m = μ(u): identity for blunt edges, quadratic at rounded ones
    /// (`(1 − cos πu)/2`, `1 − cos(πu/2)` or `sin(πu/2)`), monotone from 0 to 1.
    pub fn m_of_u(&self, u: f64) -> f64 {
        match (self.leading, self.trailing) {
            (EdgeShape::Blunt, EdgeShape::Blunt) => u,
            (EdgeShape::Rounded, EdgeShape::Rounded) => 0.5 * (1.0 - (PI * u).cos()),
            (EdgeShape::Rounded, EdgeShape::Blunt) => 1.0 - (0.5 * PI * u).cos(),
            (EdgeShape::Blunt, EdgeShape::Rounded) => (0.5 * PI * u).sin(),
        }
    }

    /// Smallest nominal thickness in the table (mm).
    pub fn min_nominal(&self) -> f64 {
        self.law.table_range().0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounded_nose_is_zero_at_edge_and_nominal_beyond() {
        let t = ThicknessLaw::new(
            Law::constant(0.8),
            EdgeShape::Rounded,
            EdgeShape::Blunt,
            40.0,
        );
        assert_eq!(t.thickness(0.0), 0.0);
        assert!((t.thickness(0.5) - 0.8).abs() < 1e-15);
        assert!((t.thickness(1.0) - 0.8).abs() < 1e-15);
        let (le, te) = t.nose_lengths();
        assert!((le * 40.0 - 0.8).abs() < 1e-12 && te == 0.0);
        // Thickness grows linearly with u near a rounded edge: smooth surfaces.
        let r1 = t.thickness(t.m_of_u(1e-4)) / 1e-4;
        let r2 = t.thickness(t.m_of_u(2e-4)) / 2e-4;
        assert!((r1 - r2).abs() / r1 < 1e-3);
    }

    #[test]
    fn parameter_maps_are_monotone_onto_unit_interval() {
        for (a, b) in [
            (EdgeShape::Blunt, EdgeShape::Blunt),
            (EdgeShape::Rounded, EdgeShape::Blunt),
            (EdgeShape::Blunt, EdgeShape::Rounded),
            (EdgeShape::Rounded, EdgeShape::Rounded),
        ] {
            let t = ThicknessLaw::new(Law::constant(1.0), a, b, 50.0);
            assert!(t.m_of_u(0.0).abs() < 1e-15 && (t.m_of_u(1.0) - 1.0).abs() < 1e-15);
            let mut prev = -1.0;
            for i in 0..=100 {
                let m = t.m_of_u(i as f64 / 100.0);
                assert!(m > prev);
                prev = m;
            }
        }
    }
}
