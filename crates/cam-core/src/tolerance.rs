//! Named tolerances: every tolerance in the toolkit is explicit and carries its meaning.

use crate::CamError;
use serde::{Deserialize, Serialize};

/// The tolerances an operation or a verification works to (mm unless stated).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Tolerances {
    /// Largest chordal deviation between a curve/surface and its polyline/mesh (mm).
    pub chord_tol: f64,
    /// Largest allowed deviation of the machined surface from the design (mm).
    pub machining_tol: f64,
    /// Largest allowed tool-tip deviation from the straight line between two NC blocks
    /// caused by rotary-axis interpolation (mm).
    pub linearisation_tol: f64,
    /// Stock left on finished surfaces by roughing operations (mm).
    pub stock_allowance: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Self {
            chord_tol: 0.01,
            machining_tol: 0.01,
            linearisation_tol: 0.005,
            stock_allowance: 0.5,
        }
    }
}

impl Tolerances {
    /// Checks that every tolerance is finite and > 0 (allowance may be 0).
    pub fn validate(&self) -> Result<(), CamError> {
        for (field, value) in [
            ("chord_tol", self.chord_tol),
            ("machining_tol", self.machining_tol),
            ("linearisation_tol", self.linearisation_tol),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(CamError::NonPositive { field, value });
            }
        }
        if !(self.stock_allowance.is_finite() && self.stock_allowance >= 0.0) {
            return Err(CamError::NonPositive {
                field: "stock_allowance",
                value: self.stock_allowance,
            });
        }
        Ok(())
    }
}
