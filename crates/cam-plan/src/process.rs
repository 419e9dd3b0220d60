//! The process row of an operation, as on a shop sheet: spindle speed, feed per tooth, depth
//! and width of cut, allowances. Feed rates and cutting time follow from it.

use crate::{PlanError, Tool};
use cam_core::Rates;
use serde::{Deserialize, Serialize};

/// Rapid traverse rate used for time estimates when the job gives none (mm/min).
pub const DEFAULT_RAPID_MM_PER_MIN: f64 = 10_000.0;

/// Cutting data of one operation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Process {
    /// Spindle speed (rev/min).
    pub spindle_rpm: f64,
    /// Feed per tooth while cutting (mm).
    pub feed_per_tooth_mm: f64,
    /// Feed per tooth while plunging along the axis (mm); default: half the cutting value.
    #[serde(default)]
    pub plunge_feed_per_tooth_mm: Option<f64>,
    /// Axial depth of cut (mm): level step of roughing, plunge step of plunge milling.
    #[serde(default)]
    pub depth_of_cut_mm: Option<f64>,
    /// Radial width of cut / step-over (mm).
    #[serde(default)]
    pub width_of_cut_mm: Option<f64>,
    /// Material left on the blade sides (mm).
    #[serde(default)]
    pub blade_allowance_mm: f64,
    /// Material left on the hub (mm).
    #[serde(default)]
    pub hub_allowance_mm: f64,
    /// Rapid traverse rate for time estimates (mm/min).
    #[serde(default = "default_rapid")]
    pub rapid_mm_per_min: f64,
}

fn default_rapid() -> f64 {
    DEFAULT_RAPID_MM_PER_MIN
}

impl Process {
    /// Cutting feed `n · f_z · z` (mm/min) with `z` teeth.
    pub fn feed_mm_per_min(&self, teeth: u32) -> f64 {
        self.spindle_rpm * self.feed_per_tooth_mm * f64::from(teeth)
    }

    /// Plunge feed (mm/min) with `z` teeth.
    pub fn plunge_mm_per_min(&self, teeth: u32) -> f64 {
        self.spindle_rpm
            * self
                .plunge_feed_per_tooth_mm
                .unwrap_or(0.5 * self.feed_per_tooth_mm)
            * f64::from(teeth)
    }

    /// The rates of `tool` for time estimates and programmed feeds.
    pub fn rates(&self, tool: &Tool) -> Rates {
        Rates {
            feed_mm_per_min: self.feed_mm_per_min(tool.teeth),
            plunge_mm_per_min: self.plunge_mm_per_min(tool.teeth),
            rapid_mm_per_min: self.rapid_mm_per_min,
        }
    }

    /// Checks every number; errors name the operation and the key.
    pub fn validate(&self, operation: &str) -> Result<(), PlanError> {
        let pos = |key: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(PlanError::param(
                    operation,
                    format!("process.{key}"),
                    format!("{v} must be finite and > 0"),
                ))
            }
        };
        pos("spindle_rpm", self.spindle_rpm)?;
        pos("feed_per_tooth_mm", self.feed_per_tooth_mm)?;
        pos("rapid_mm_per_min", self.rapid_mm_per_min)?;
        if let Some(v) = self.plunge_feed_per_tooth_mm {
            pos("plunge_feed_per_tooth_mm", v)?;
        }
        if let Some(v) = self.depth_of_cut_mm {
            pos("depth_of_cut_mm", v)?;
        }
        if let Some(v) = self.width_of_cut_mm {
            pos("width_of_cut_mm", v)?;
        }
        for (key, v) in [
            ("blade_allowance_mm", self.blade_allowance_mm),
            ("hub_allowance_mm", self.hub_allowance_mm),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(PlanError::param(
                    operation,
                    format!("process.{key}"),
                    format!("{v} must be finite and >= 0"),
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn feed_is_speed_times_feed_per_tooth_times_teeth() {
        let p = Process {
            spindle_rpm: 12_000.0,
            feed_per_tooth_mm: 0.05,
            plunge_feed_per_tooth_mm: None,
            depth_of_cut_mm: None,
            width_of_cut_mm: None,
            blade_allowance_mm: 0.0,
            hub_allowance_mm: 0.0,
            rapid_mm_per_min: DEFAULT_RAPID_MM_PER_MIN,
        };
        assert!((p.feed_mm_per_min(2) - 1200.0).abs() < 1e-9);
        assert!((p.plunge_mm_per_min(2) - 600.0).abs() < 1e-9);
        assert!(p.validate("op").is_ok());
        let bad = Process {
            spindle_rpm: 0.0,
            ..p
        };
        assert!(bad
            .validate("op")
            .unwrap_err()
            .to_string()
            .contains("spindle_rpm"));
    }
}
