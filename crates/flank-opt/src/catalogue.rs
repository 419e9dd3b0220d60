//! A cutter catalogue: the tapered ball ends one can buy, as a grid of ball radii and half
//! angles (the usual steps are 0.25 mm and 0.5°). The optimiser's continuous optimum is
//! rounded *down* to the catalogue ("the catalogue cutter just below the optimum", paper 002):
//! a smaller radius and angle only add clearance, so the constraints stay satisfiable.

use crate::FlankError;
use serde::{Deserialize, Serialize};

/// An arithmetic range of catalogue values.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Steps {
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// Step between values.
    pub step: f64,
}

impl Steps {
    /// The largest catalogue value `<= x` (`None` below `min`).
    pub fn floor(&self, x: f64) -> Option<f64> {
        if x < self.min - 1e-12 {
            return None;
        }
        let k = ((x.min(self.max) - self.min) / self.step + 1e-9).floor();
        Some(self.min + k * self.step)
    }
    /// All values, largest first.
    pub fn descending(&self) -> Vec<f64> {
        let n = ((self.max - self.min) / self.step + 1e-9).floor() as usize;
        (0..=n)
            .rev()
            .map(|k| self.min + k as f64 * self.step)
            .collect()
    }
    fn validate(&self, key: &str) -> Result<(), FlankError> {
        if !(self.min.is_finite() && self.max >= self.min && self.step > 0.0) {
            return Err(FlankError::Param(format!(
                "catalogue.{key}: needs finite min <= max and step > 0"
            )));
        }
        if (self.max - self.min) / self.step > 10_000.0 {
            return Err(FlankError::Param(format!(
                "catalogue.{key}: more than 10000 values"
            )));
        }
        Ok(())
    }
}

/// The catalogue (a table of the operation, or a file such as
/// `fixtures/tools/tapered-ball-catalogue.toml`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Catalogue {
    /// Ball radii (mm).
    pub ball_radius_mm: Steps,
    /// Half taper angles (degrees); `min = 0` includes the cylindrical ball ends.
    pub half_angle_deg: Steps,
}

impl Default for Catalogue {
    /// Ball radius 1–6 mm in 0.25 mm steps, half angle 0–8° in 0.5° steps.
    fn default() -> Self {
        Self {
            ball_radius_mm: Steps {
                min: 1.0,
                max: 6.0,
                step: 0.25,
            },
            half_angle_deg: Steps {
                min: 0.0,
                max: 8.0,
                step: 0.5,
            },
        }
    }
}

impl Catalogue {
    /// Parses a catalogue file's text (unknown keys are errors).
    pub fn from_toml_str(text: &str) -> Result<Self, FlankError> {
        let c: Self =
            toml::from_str(text).map_err(|e| FlankError::Param(format!("catalogue: {e}")))?;
        c.validate()?;
        Ok(c)
    }

    /// Checks both ranges.
    pub fn validate(&self) -> Result<(), FlankError> {
        self.ball_radius_mm.validate("ball_radius_mm")?;
        self.half_angle_deg.validate("half_angle_deg")
    }

    /// The catalogue cutter just below the optimum `(r, θ in radians)`: `(r, θ)` rounded down
    /// in each parameter. `None` when the optimum is below the smallest cutter.
    pub fn below(&self, r: f64, theta: f64) -> Option<(f64, f64)> {
        let rc = self.ball_radius_mm.floor(r)?;
        let tc = self.half_angle_deg.floor(theta.to_degrees())?;
        Some((rc, tc.to_radians()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounds_down_to_the_grid() {
        let c = Catalogue::default();
        let (r, t) = c.below(3.37, 2.74f64.to_radians()).unwrap();
        assert!((r - 3.25).abs() < 1e-12);
        assert!((t.to_degrees() - 2.5).abs() < 1e-9);
        assert!(c.below(0.5, 0.0).is_none());
        assert_eq!(c.ball_radius_mm.descending()[0], 6.0);
        let text = "ball_radius_mm = { min = 1.0, max = 4.0, step = 0.5 }\n\
                    half_angle_deg = { min = 0.0, max = 5.0, step = 0.5 }\n";
        let f = Catalogue::from_toml_str(text).unwrap();
        assert_eq!(f.ball_radius_mm.max, 4.0);
        assert!(Catalogue::from_toml_str("x = 1").is_err());
    }
}
