//! Typed errors of `cam-core`.

/// Errors raised when CAM entities are built from invalid data.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CamError {
    /// A cutter dimension is out of its valid range.
    #[error("invalid cutter dimension `{field}` = {value}: {reason}")]
    InvalidCutter {
        /// Name of the offending field (e.g. `corner_radius`).
        field: &'static str,
        /// The value given.
        value: f64,
        /// What was expected.
        reason: &'static str,
    },
    /// A tool axis had zero or non-finite length.
    #[error("tool axis ({0}, {1}, {2}) is not a finite non-zero vector")]
    InvalidAxis(f64, f64, f64),
    /// A point coordinate was not finite.
    #[error("point ({0}, {1}, {2}) has a non-finite coordinate")]
    NonFinitePoint(f64, f64, f64),
    /// A tolerance or rate must be finite and strictly positive.
    #[error("`{field}` = {value} must be finite and > 0")]
    NonPositive {
        /// Name of the offending field.
        field: &'static str,
        /// The value given.
        value: f64,
    },
}
