//! The conical cutter model of the flank-milling literature and catalogue cutters.

use crate::beam::{Beam, Section};
use crate::error::{check, StiffnessError};
use crate::ritz::{RitzOptions, RitzSolution};
use cam_core::{Cutter, CutterShape};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// A conical cutter as a cantilever: bottom radius `r` at the ball-centre plane, half taper
/// angle `θ`, length `L` from the chuck face to the ball-centre plane, Young's modulus `E`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ConicalCutter {
    /// Radius at the ball-centre plane `r` (mm).
    pub bottom_radius: f64,
    /// Half taper angle `θ` (rad), in `[0, π/2)`.
    pub half_angle: f64,
    /// Length from the chuck face to the ball-centre plane `L` (mm).
    pub length: f64,
    /// Young's modulus `E` (N/mm²).
    pub youngs_modulus: f64,
}

/// The stiffness indicator and its gradient, as printed by `impeller-cam stiffness`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StiffnessReport {
    /// Rayleigh–Ritz indicator (N/mm).
    pub stiffness_n_per_mm: f64,
    /// Exact value of the same beam model (N/mm).
    pub exact_n_per_mm: f64,
    /// Ritz terms used.
    pub terms: usize,
    /// ∂k/∂r of the Ritz indicator (N/mm per mm).
    pub d_stiffness_d_radius: f64,
    /// ∂k/∂θ of the Ritz indicator (N/mm per degree).
    pub d_stiffness_d_half_angle_deg: f64,
}

impl ConicalCutter {
    /// Validates and builds the model.
    pub fn new(
        bottom_radius: f64,
        half_angle: f64,
        length: f64,
        youngs_modulus: f64,
    ) -> Result<Self, StiffnessError> {
        check(
            "bottom_radius",
            bottom_radius,
            bottom_radius > 0.0,
            "must be > 0",
        )?;
        check(
            "half_angle",
            half_angle,
            (0.0..PI / 2.0).contains(&half_angle),
            "must be in [0°, 90°)",
        )?;
        check("length", length, length > 0.0, "must be > 0")?;
        check(
            "youngs_modulus",
            youngs_modulus,
            youngs_modulus > 0.0,
            "must be > 0",
        )?;
        Ok(Self {
            bottom_radius,
            half_angle,
            length,
            youngs_modulus,
        })
    }

    /// Radius `ρ(x) = r + (L − x) tan θ` at distance `x` from the chuck face.
    pub fn radius_at(&self, x: f64) -> f64 {
        self.bottom_radius + (self.length - x) * self.half_angle.tan()
    }

    /// The model as a one-section beam.
    pub fn beam(&self) -> Beam {
        Beam {
            sections: vec![Section {
                length: self.length,
                radius_clamp_side: self.radius_at(0.0),
                radius_load_side: self.bottom_radius,
            }],
            youngs_modulus: self.youngs_modulus,
        }
    }

    /// Exact stiffness `k = 3 π E r R³ / (4 L³)`, `R = r + L tan θ` (N/mm).
    pub fn exact_stiffness(&self) -> f64 {
        let big_r = self.radius_at(0.0);
        3.0 * PI * self.youngs_modulus * self.bottom_radius * big_r.powi(3)
            / (4.0 * self.length.powi(3))
    }

    /// Exact gradient `(∂k/∂r, ∂k/∂θ)` of the closed form (θ in radians).
    pub fn exact_gradient(&self) -> (f64, f64) {
        let big_r = self.radius_at(0.0);
        let c = 3.0 * PI * self.youngs_modulus / (4.0 * self.length.powi(3));
        let sec2 = 1.0 / self.half_angle.cos().powi(2);
        let dr = c * (big_r.powi(3) + 3.0 * self.bottom_radius * big_r.powi(2));
        let dtheta = c * 3.0 * self.bottom_radius * big_r.powi(2) * self.length * sec2;
        (dr, dtheta)
    }

    /// Rayleigh–Ritz indicator, exact value and the indicator's gradient.
    ///
    /// `∂I/∂r = π ρ³` and `∂I/∂θ = π ρ³ (L − x) sec² θ` enter the exact Ritz sensitivity
    /// (see the crate docs). Cost: a few Cholesky solves of size ≤ `max_terms`.
    pub fn report(&self, options: &RitzOptions) -> Result<StiffnessReport, StiffnessError> {
        let beam = self.beam();
        let sol = RitzSolution::solve(&beam, options)?;
        let d_r = sol.derivative(&beam, |x| PI * self.radius_at(x).powi(3));
        let sec2 = 1.0 / self.half_angle.cos().powi(2);
        let d_theta = sol.derivative(&beam, |x| {
            PI * self.radius_at(x).powi(3) * (self.length - x) * sec2
        });
        Ok(StiffnessReport {
            stiffness_n_per_mm: sol.stiffness,
            exact_n_per_mm: beam.exact_stiffness(),
            terms: sol.terms,
            d_stiffness_d_radius: d_r,
            d_stiffness_d_half_angle_deg: d_theta * PI / 180.0,
        })
    }
}

/// The beam of a catalogue cutter: the fluted part from its load plane (ball centre for ball
/// ends, corner-arc centre plane for bull noses, the tip for flat ends) up to the flute
/// length with the cutter's own profile radius, then the shank up to the holder face
/// (stick-out = `overall_length`).
///
/// Above the load plane every supported profile is linear in the height (the cone of a
/// tapered ball end starts at the tangency height `r(1 − sin θ)`, below the ball centre), so
/// the beam model is exact for the cutter's geometry.
pub fn cutter_beam(cutter: &Cutter, youngs_modulus: f64) -> Result<Beam, StiffnessError> {
    cutter.validate()?;
    let h_load = match cutter.shape {
        CutterShape::BallEnd { radius } => radius,
        CutterShape::TaperedBallEnd { ball_radius, .. } => ball_radius,
        CutterShape::BullNose { corner_radius, .. } => corner_radius,
        CutterShape::FlatEnd { .. } | CutterShape::TaperedFlatEnd { .. } => 0.0,
    };
    if h_load >= cutter.flute_length {
        return Err(StiffnessError::UnsupportedCutter(cutter.name.clone()));
    }
    let mut sections = Vec::new();
    if cutter.overall_length > cutter.flute_length {
        sections.push(Section {
            length: cutter.overall_length - cutter.flute_length,
            radius_clamp_side: cutter.shank_radius,
            radius_load_side: cutter.shank_radius,
        });
    }
    sections.push(Section {
        length: cutter.flute_length - h_load,
        radius_clamp_side: cutter.shape.radius_at(cutter.flute_length),
        radius_load_side: cutter.shape.radius_at(h_load),
    });
    Beam::new(sections, youngs_modulus)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_form_gradient_matches_finite_differences() {
        let c = ConicalCutter::new(3.0, 4f64.to_radians(), 50.0, 600e3).unwrap();
        let (dr, dt) = c.exact_gradient();
        let h = 1e-6;
        let k = |r: f64, t: f64| {
            ConicalCutter {
                bottom_radius: r,
                half_angle: t,
                ..c
            }
            .exact_stiffness()
        };
        let fd_r = (k(3.0 + h, c.half_angle) - k(3.0 - h, c.half_angle)) / (2.0 * h);
        let fd_t = (k(3.0, c.half_angle + h) - k(3.0, c.half_angle - h)) / (2.0 * h);
        assert!((dr / fd_r - 1.0).abs() < 1e-7);
        assert!((dt / fd_t - 1.0).abs() < 1e-7);
    }

    #[test]
    fn closed_form_equals_beam_integral() {
        let c = ConicalCutter::new(2.0, 6f64.to_radians(), 70.0, 210e3).unwrap();
        assert!((c.exact_stiffness() / c.beam().exact_stiffness() - 1.0).abs() < 1e-13);
    }
}
