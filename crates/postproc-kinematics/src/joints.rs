//! Joint (axis) values of a five-axis machine: three linear axes and two rotary axes.

use serde::{Deserialize, Serialize};

/// Which of the five axes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AxisId {
    /// Linear X.
    X,
    /// Linear Y.
    Y,
    /// Linear Z.
    Z,
    /// The tilting rotary axis (A about X or B about Y; letter from the machine).
    Tilt,
    /// The rotary axis about Z (always C).
    Rotate,
}

impl AxisId {
    /// All five axes in G-code word order (X Y Z, tilt, C).
    pub const ALL: [AxisId; 5] = [
        AxisId::X,
        AxisId::Y,
        AxisId::Z,
        AxisId::Tilt,
        AxisId::Rotate,
    ];

    /// `true` for the two rotary axes.
    pub fn is_rotary(self) -> bool {
        matches!(self, AxisId::Tilt | AxisId::Rotate)
    }
}

/// Axis values of one block. Linear axes in mm, rotary axes in **radians** (convert with
/// [`crate::Machine::axis_words`] for G-code, which gives degrees).
///
/// Meaning of X Y Z: for table-table machines the tool-tip position in the machine frame with
/// tool length compensation active; for head-table and head-head machines the tool-tip
/// position the machine would have at zero head angles (pivot point minus pivot length plus
/// tool length along the zero-angle spindle direction) — i.e. again the point a controller
/// with tool length compensation along the zero-angle spindle direction commands.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Joints {
    /// X (mm).
    pub x: f64,
    /// Y (mm).
    pub y: f64,
    /// Z (mm).
    pub z: f64,
    /// Tilting axis A or B (rad).
    pub tilt: f64,
    /// Rotary axis C about Z (rad).
    pub rotate: f64,
}

impl Joints {
    /// Value of one axis (mm or rad).
    pub fn get(&self, axis: AxisId) -> f64 {
        match axis {
            AxisId::X => self.x,
            AxisId::Y => self.y,
            AxisId::Z => self.z,
            AxisId::Tilt => self.tilt,
            AxisId::Rotate => self.rotate,
        }
    }

    /// Sets one axis (mm or rad).
    pub fn set(&mut self, axis: AxisId, value: f64) {
        match axis {
            AxisId::X => self.x = value,
            AxisId::Y => self.y = value,
            AxisId::Z => self.z = value,
            AxisId::Tilt => self.tilt = value,
            AxisId::Rotate => self.rotate = value,
        }
    }

    /// The five values in word order X Y Z tilt C.
    pub fn to_array(&self) -> [f64; 5] {
        [self.x, self.y, self.z, self.tilt, self.rotate]
    }

    /// From values in word order X Y Z tilt C.
    pub fn from_array(v: [f64; 5]) -> Self {
        Self {
            x: v[0],
            y: v[1],
            z: v[2],
            tilt: v[3],
            rotate: v[4],
        }
    }

    /// Linear interpolation of every joint: `self + s·(other − self)` — what a controller
    /// without tool-centre-point control does between two blocks.
    pub fn lerp(&self, other: &Joints, s: f64) -> Joints {
        let a = self.to_array();
        let b = other.to_array();
        Joints::from_array(std::array::from_fn(|i| a[i] + s * (b[i] - a[i])))
    }

    /// Rotary travel `|ΔT| + |ΔR|` (rad) to `other`: the measure the posture choice and
    /// linearisation compare solutions by.
    pub fn rotary_travel(&self, other: &Joints) -> f64 {
        (other.tilt - self.tilt).abs() + (other.rotate - self.rotate).abs()
    }

    /// `true` when all five values are finite.
    pub fn is_finite(&self) -> bool {
        self.to_array().iter().all(|v| v.is_finite())
    }
}
