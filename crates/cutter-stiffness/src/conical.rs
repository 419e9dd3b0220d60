//! The conical cutter model of the flank-milling literature and catalogue cutters.

use crate::beam::{Beam, Section};
use crate::error::{check, StiffnessError};
use crate::ritz::{RitzOptions, RitzSolution};
use cam_core::{Cutter, CutterShape};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// A tapered ball-end cutter as a cantilever, in the one parameter set shared with the
/// envelope ([`cam_core::CutterShape::TaperedBallEnd`] and `cam_core::SphereFamily`):
/// ball radius `r`, half taper angle `θ` (radians), `length` from the tool tip to the chuck
/// (holder) face — heights measured from the tip like every cutter height in `cam-core` — and
/// Young's modulus `E`. The cone is tangent to the ball and runs up to the chuck face.
///
/// The beam of the crate docs follows from it: clamped at the chuck face, loaded at the
/// ball-centre plane (height `r` above the tip), so the beam length is `L = length − r` and the
/// radius at the load plane is the cone's radius at height `r`, `r_c = r / cos θ`
/// (the cone `R(h) = r cos θ + (h − r(1 − sin θ)) tan θ` at `h = r`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ConicalCutter {
    /// Ball radius `r` (mm).
    pub ball_radius: f64,
    /// Half taper angle `θ` (rad), in `[0, π/2)`.
    pub half_angle: f64,
    /// Tool tip to chuck face (mm), `> r`.
    pub length: f64,
    /// Young's modulus `E` (N/mm²).
    pub youngs_modulus: f64,
}

/// The stiffness indicator and its gradient in the cutter's parameters
/// ([`ConicalCutter`]: ball radius, half angle in radians, length from the tip).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StiffnessReport {
    /// Rayleigh–Ritz indicator (N/mm).
    pub stiffness_n_per_mm: f64,
    /// Exact value of the same beam model (N/mm).
    pub exact_n_per_mm: f64,
    /// Ritz terms used.
    pub terms: usize,
    /// ∂k/∂r of the Ritz indicator (N/mm per mm of ball radius).
    pub d_stiffness_d_ball_radius: f64,
    /// ∂k/∂θ of the Ritz indicator (N/mm per radian).
    pub d_stiffness_d_half_angle: f64,
    /// ∂k/∂length of the Ritz indicator (N/mm per mm of tip-to-chuck length).
    pub d_stiffness_d_length: f64,
}

impl ConicalCutter {
    /// Validates and builds the model.
    pub fn new(
        ball_radius: f64,
        half_angle: f64,
        length: f64,
        youngs_modulus: f64,
    ) -> Result<Self, StiffnessError> {
        check("ball_radius", ball_radius, ball_radius > 0.0, "must be > 0")?;
        check(
            "half_angle",
            half_angle,
            (0.0..PI / 2.0).contains(&half_angle),
            "must be in [0°, 90°)",
        )?;
        check(
            "length",
            length,
            length > ball_radius,
            "must exceed the ball radius (tip to chuck face)",
        )?;
        check(
            "youngs_modulus",
            youngs_modulus,
            youngs_modulus > 0.0,
            "must be > 0",
        )?;
        Ok(Self {
            ball_radius,
            half_angle,
            length,
            youngs_modulus,
        })
    }

    /// The same cutter from the literature's beam parameters: radius `r_c` at the ball-centre
    /// plane, half angle `θ` (rad) and beam length `L` from the chuck face to the ball-centre
    /// plane (paper 002's form; `r = r_c cos θ`, `length = L + r`).
    pub fn from_load_plane(
        radius_at_load_plane: f64,
        half_angle: f64,
        beam_length: f64,
        youngs_modulus: f64,
    ) -> Result<Self, StiffnessError> {
        check(
            "bottom_radius",
            radius_at_load_plane,
            radius_at_load_plane > 0.0,
            "must be > 0 (radius at the ball-centre plane)",
        )?;
        check(
            "beam_length",
            beam_length,
            beam_length > 0.0,
            "must be > 0 (chuck face to ball-centre plane)",
        )?;
        let r = radius_at_load_plane * half_angle.cos();
        Self::new(r, half_angle, beam_length + r, youngs_modulus)
    }

    /// Radius at the ball-centre plane `r_c = r / cos θ` (mm).
    pub fn load_plane_radius(&self) -> f64 {
        self.ball_radius / self.half_angle.cos()
    }

    /// Beam length from the chuck face to the ball-centre plane, `length − r` (mm).
    pub fn beam_length(&self) -> f64 {
        self.length - self.ball_radius
    }

    /// Radius `ρ(x) = r_c + (L − x) tan θ` at distance `x` from the chuck face.
    pub fn radius_at(&self, x: f64) -> f64 {
        self.load_plane_radius() + (self.beam_length() - x) * self.half_angle.tan()
    }

    /// The model as a one-section beam.
    pub fn beam(&self) -> Beam {
        Beam {
            sections: vec![Section {
                length: self.beam_length(),
                radius_clamp_side: self.radius_at(0.0),
                radius_load_side: self.load_plane_radius(),
            }],
            youngs_modulus: self.youngs_modulus,
        }
    }

    /// Exact stiffness `k = 3 π E r_c R³ / (4 L³)`, `R = r_c + L tan θ` (N/mm).
    pub fn exact_stiffness(&self) -> f64 {
        let big_r = self.radius_at(0.0);
        3.0 * PI * self.youngs_modulus * self.load_plane_radius() * big_r.powi(3)
            / (4.0 * self.beam_length().powi(3))
    }

    /// Maps a gradient in the beam parameters `(r_c, θ, L)` to the cutter parameters
    /// `(r, θ, length)`: `r_c = r / cos θ`, `L = length − r`, so
    /// `∂/∂r = ∂/∂r_c / cos θ − ∂/∂L`, `∂/∂θ = ∂/∂θ|_beam + ∂/∂r_c · r sin θ / cos² θ`,
    /// `∂/∂length = ∂/∂L`.
    fn into_cutter_params(self, d_rc: f64, d_theta: f64, d_l: f64) -> [f64; 3] {
        let (sn, co) = self.half_angle.sin_cos();
        [
            d_rc / co - d_l,
            d_theta + d_rc * self.ball_radius * sn / (co * co),
            d_l,
        ]
    }

    /// Exact gradient `(∂k/∂r, ∂k/∂θ, ∂k/∂length)` of the closed form (θ in radians).
    pub fn exact_gradient(&self) -> [f64; 3] {
        let (rc, l) = (self.load_plane_radius(), self.beam_length());
        let t = self.half_angle.tan();
        let big_r = rc + l * t;
        let c = 3.0 * PI * self.youngs_modulus / 4.0;
        let sec2 = 1.0 + t * t;
        let d_rc = c * (big_r.powi(3) + 3.0 * rc * big_r.powi(2)) / l.powi(3);
        let d_theta = c * 3.0 * rc * big_r.powi(2) * l * sec2 / l.powi(3);
        let d_l = c * rc * (3.0 * big_r.powi(2) * t / l.powi(3) - 3.0 * big_r.powi(3) / l.powi(4));
        self.into_cutter_params(d_rc, d_theta, d_l)
    }

    /// Rayleigh–Ritz indicator, exact value and the indicator's gradient in `(r, θ, length)`.
    ///
    /// Beam-parameter sensitivities first: `∂I/∂r_c = π ρ³` and `∂I/∂θ = π ρ³ (L − x) sec² θ`
    /// enter the exact Ritz sensitivity (crate docs); for the beam length, mapping the beam to
    /// `ξ = x/L` gives `k = 1/(L³ f̂ᵀK̂⁻¹f̂)`, so `∂k/∂L = −3k/L` plus the Ritz sensitivity to
    /// `∂I/∂L|_ξ = π ρ³ (L − x) tan θ / L`. Then [`Self::into_cutter_params`]. Cost: a few
    /// Cholesky solves of size ≤ `max_terms`.
    pub fn report(&self, options: &RitzOptions) -> Result<StiffnessReport, StiffnessError> {
        let beam = self.beam();
        let sol = RitzSolution::solve(&beam, options)?;
        let l = self.beam_length();
        let t = self.half_angle.tan();
        let d_rc = sol.derivative(&beam, |x| PI * self.radius_at(x).powi(3));
        let sec2 = 1.0 + t * t;
        let d_theta = sol.derivative(&beam, |x| PI * self.radius_at(x).powi(3) * (l - x) * sec2);
        let d_l = -3.0 * sol.stiffness / l
            + sol.derivative(&beam, |x| PI * self.radius_at(x).powi(3) * (l - x) * t / l);
        let [dr, dt, dlen] = self.into_cutter_params(d_rc, d_theta, d_l);
        Ok(StiffnessReport {
            stiffness_n_per_mm: sol.stiffness,
            exact_n_per_mm: beam.exact_stiffness(),
            terms: sol.terms,
            d_stiffness_d_ball_radius: dr,
            d_stiffness_d_half_angle: dt,
            d_stiffness_d_length: dlen,
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
        let g = c.exact_gradient();
        let h = 1e-6;
        let k = |d: [f64; 3]| {
            ConicalCutter {
                ball_radius: c.ball_radius + d[0],
                half_angle: c.half_angle + d[1],
                length: c.length + d[2],
                ..c
            }
            .exact_stiffness()
        };
        for (i, gi) in g.iter().enumerate() {
            let mut e = [0.0; 3];
            e[i] = h;
            let fd = (k(e) - k(e.map(|x| -x))) / (2.0 * h);
            assert!((gi / fd - 1.0).abs() < 1e-6, "{i}: {gi} vs {fd}");
        }
    }

    #[test]
    fn closed_form_equals_beam_integral() {
        let c = ConicalCutter::new(2.0, 6f64.to_radians(), 70.0, 210e3).unwrap();
        assert!((c.exact_stiffness() / c.beam().exact_stiffness() - 1.0).abs() < 1e-13);
    }

    #[test]
    fn load_plane_form_round_trips() {
        let c = ConicalCutter::from_load_plane(3.2, 3f64.to_radians(), 40.0, 600e3).unwrap();
        assert!((c.load_plane_radius() - 3.2).abs() < 1e-12);
        assert!((c.beam_length() - 40.0).abs() < 1e-12);
        assert!((c.ball_radius - 3.2 * 3f64.to_radians().cos()).abs() < 1e-12);
    }
}
