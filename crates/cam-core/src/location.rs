//! Cutter locations: tool tip point plus unit tool axis (APT convention).

use crate::{CamError, Point3, UnitVector3, Vector3};
use serde::{Deserialize, Serialize};

/// A cutter location (CL): the tool tip — the lowest point of the cutter on its axis — and the
/// unit tool axis pointing from the tip toward the spindle. For a ball end the ball centre is
/// `tip + r·axis`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CutterLocation {
    /// Tool tip point (mm, workpiece frame).
    pub tip: Point3,
    /// Unit tool axis, tip → spindle.
    pub axis: UnitVector3,
}

impl CutterLocation {
    /// Builds a CL from a tip point and any non-zero axis vector (normalised here).
    ///
    /// Errors: non-finite coordinates or a zero / non-finite axis.
    pub fn new(tip: Point3, axis: Vector3) -> Result<Self, CamError> {
        if !(tip.x.is_finite() && tip.y.is_finite() && tip.z.is_finite()) {
            return Err(CamError::NonFinitePoint(tip.x, tip.y, tip.z));
        }
        let n = axis.norm();
        if !(n.is_finite() && n > 0.0) {
            return Err(CamError::InvalidAxis(axis.x, axis.y, axis.z));
        }
        Ok(Self {
            tip,
            axis: UnitVector3::new_unchecked(axis / n),
        })
    }

    /// A CL with the tool axis along +Z (three-axis orientation).
    pub fn vertical(tip: Point3) -> Self {
        Self {
            tip,
            axis: Vector3::z_axis(),
        }
    }

    /// The point on the tool axis at height `h` (mm) above the tip.
    pub fn axis_point(&self, h: f64) -> Point3 {
        self.tip + self.axis.into_inner() * h
    }
}
