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
    /// An APT 7-parameter cutter describes a shape this crate has no exact model for.
    #[error("APT cutter not supported: {reason}")]
    AptUnsupported {
        /// Why the combination does not map (e.g. a non-zero bottom angle α).
        reason: &'static str,
    },
    /// An APT 7-parameter cutter's fields contradict each other for the shape they select.
    #[error(
        "APT cutter field `{field}` = {value} inconsistent with the shape (expected {expected})"
    )]
    AptInconsistent {
        /// The offending APT field (`d`, `r`, `e`, `f`, `alpha`, `beta`, `h`).
        field: &'static str,
        /// The value given.
        value: f64,
        /// The value the selected shape requires.
        expected: f64,
    },
    /// A guiding curve of a tool-axis trajectory is unusable.
    #[error("invalid guiding curve: {reason}")]
    InvalidGuide {
        /// What is wrong.
        reason: &'static str,
    },
    /// The two guiding curves meet (or nearly) at parameter `s`, so the tool axis is undefined.
    #[error("guiding curves coincide at s = {s}: tool axis undefined")]
    DegenerateAxis {
        /// Trajectory parameter where |P1 − P0| vanishes.
        s: f64,
    },
}
