//! A tool as the job file names it: a `cam-core` cutter (shape, flutes, shank, stick-out,
//! holder frusta) with its number in the magazine, its number of teeth, its gauge length and,
//! for flat-end plunge cutters, the length of the bottom cutting edge.

use crate::PlanError;
use cam_core::{Cutter, CutterShape};
use serde::{Deserialize, Serialize};

/// A tool of the job.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Tool {
    /// Tool number (the `T` word).
    pub number: u32,
    /// The cutter: shape, flute length, shank radius, stick-out (`overall_length`: tip to
    /// holder face) and holder segments stacked from the holder face up.
    pub cutter: Cutter,
    /// Number of teeth (flutes or inserts), for feed per tooth → feed rate.
    pub teeth: u32,
    /// Gauge length: spindle gauge line to tool tip (mm). Head kinematics need it.
    pub tool_length_mm: f64,
    /// Flat-end plunge cutters: radial length of the bottom cutting edge, measured inward
    /// from the rim (mm). The disk of radius `radius − edge` about the axis does not cut
    /// (paper 000 §2). `None` for tools that cut across the whole bottom.
    pub plunge_edge_length_mm: Option<f64>,
}

impl Tool {
    /// The tool's name (the cutter's).
    pub fn name(&self) -> &str {
        &self.cutter.name
    }

    /// Nominal radius of the cutting end at its widest point near the tip: the flat, ball or
    /// outer radius; the tip radius of a tapered flat end; the ball radius of a tapered ball.
    pub fn nominal_radius(&self) -> f64 {
        match self.cutter.shape {
            CutterShape::FlatEnd { radius }
            | CutterShape::BallEnd { radius }
            | CutterShape::BullNose { radius, .. } => radius,
            CutterShape::TaperedBallEnd { ball_radius, .. } => ball_radius,
            CutterShape::TaperedFlatEnd { tip_radius, .. } => tip_radius,
        }
    }

    /// Radius of the non-cutting centre disk of a flat-end plunge cutter
    /// (`radius − plunge_edge_length`), `None` when the tool has no such disk.
    pub fn core_radius(&self) -> Option<f64> {
        let edge = self.plunge_edge_length_mm?;
        match self.cutter.shape {
            CutterShape::FlatEnd { radius } | CutterShape::BullNose { radius, .. } => {
                Some((radius - edge).max(0.0))
            }
            _ => None,
        }
    }

    /// Checks the cutter and the tool's own numbers; errors name the tool and the key.
    pub fn validate(&self) -> Result<(), PlanError> {
        let err = |key: &str, reason: String| PlanError::Tool {
            operation: "-".into(),
            tool: self.cutter.name.clone(),
            reason: format!("{key}: {reason}"),
        };
        self.cutter
            .validate()
            .map_err(|e| err("shape", e.to_string()))?;
        if self.teeth == 0 {
            return Err(err("teeth", "must be at least 1".into()));
        }
        if !(self.tool_length_mm.is_finite() && self.tool_length_mm >= self.cutter.overall_length) {
            return Err(err(
                "tool_length_mm",
                format!(
                    "{} must be finite and at least the stick-out {}",
                    self.tool_length_mm, self.cutter.overall_length
                ),
            ));
        }
        if let Some(e) = self.plunge_edge_length_mm {
            let r = self.nominal_radius();
            if !(e.is_finite() && e > 0.0 && e <= r) {
                return Err(err(
                    "plunge_edge_length_mm",
                    format!("{e} must be in (0, radius = {r}]"),
                ));
            }
        }
        Ok(())
    }
}
