//! Typed errors of the fitting algorithms.

use crate::NurbsError;

/// Why a fit could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FitError {
    /// Too few data points (or sections) for the requested degree / control point count.
    #[error("{what}: need at least {needed}, got {got}")]
    TooFewPoints {
        /// What was counted (`points`, `sections`, `grid rows`, ...).
        what: &'static str,
        /// Minimum required.
        needed: usize,
        /// Number given.
        got: usize,
    },
    /// The degree must be at least 1.
    #[error("degree {degree} is invalid: must be >= 1")]
    InvalidDegree {
        /// The degree given.
        degree: usize,
    },
    /// A data point (or derivative) has a non-finite coordinate.
    #[error("data point {index} has a non-finite coordinate")]
    NonFinitePoint {
        /// Index of the offending point.
        index: usize,
    },
    /// Two consecutive data points coincide, so chord-length / centripetal parameters are
    /// not strictly increasing.
    #[error("data points {index} and {next} coincide (zero chord)", next = index + 1)]
    CoincidentPoints {
        /// Index of the first of the two coincident points.
        index: usize,
    },
    /// The requested number of control points is outside `[min, max]`.
    #[error("control point count {n_ctrl} out of range [{min}, {max}]")]
    InvalidControlCount {
        /// Requested count.
        n_ctrl: usize,
        /// Smallest allowed (degree + 1, at least 2).
        min: usize,
        /// Largest allowed (number of data points).
        max: usize,
    },
    /// A tolerance or weight must be finite and positive (weights may be zero).
    #[error("`{field}` = {value} is invalid: {reason}")]
    InvalidValue {
        /// Name of the argument.
        field: &'static str,
        /// The value given.
        value: f64,
        /// What was expected.
        reason: &'static str,
    },
    /// The grid of points is not rectangular.
    #[error("grid row {row} has {got} points, expected {expected}")]
    RaggedGrid {
        /// Index of the offending row.
        row: usize,
        /// Length of row 0.
        expected: usize,
        /// Length of this row.
        got: usize,
    },
    /// The linear system is rank deficient (e.g. parameters violate the Schoenberg–Whitney
    /// condition for the knot vector).
    #[error("the fitting system is singular (rank {rank} < {cols})")]
    SingularSystem {
        /// Numerical rank found.
        rank: usize,
        /// Number of unknowns.
        cols: usize,
    },
    /// The least-squares curve swings away from its data between two data points: the
    /// system is regular but so ill-conditioned (a knot span its section's data barely
    /// reach) that its control points run far from the data. Treated like a singular system
    /// by the adaptive fit (the refinement that caused it is undone).
    #[error(
        "the fitted curve swings {deviation} away from its data between points {point} and {}",
        point + 1
    )]
    Swing {
        /// Index of the data point before the swing.
        point: usize,
        /// Distance of the curve's midpoint between the two points from their chord (data
        /// length unit).
        deviation: f64,
    },
    /// A core operation (curve construction, knot refinement, ...) rejected its input.
    #[error(transparent)]
    Nurbs(#[from] NurbsError),
}
