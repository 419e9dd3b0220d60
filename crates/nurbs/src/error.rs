//! Typed errors of the crate: every validation failure says which entity (knot, control
//! point, weight, parameter direction) is wrong and where.

use std::fmt;

/// Parametric direction of a surface, used to say which knot vector or control-net
/// direction an error (or an operation) refers to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Direction {
    /// The first surface parameter `u` (control-net index `i`).
    U,
    /// The second surface parameter `v` (control-net index `j`).
    V,
}

impl fmt::Display for Direction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Direction::U => f.write_str("u"),
            Direction::V => f.write_str("v"),
        }
    }
}

/// Everything that can go wrong when building or transforming NURBS entities.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NurbsError {
    /// The degree is 0 or larger than [`crate::MAX_DEGREE`].
    #[error("degree {degree} is outside the supported range 1..={max}")]
    DegreeOutOfRange {
        /// Requested degree.
        degree: usize,
        /// Largest supported degree ([`crate::MAX_DEGREE`]).
        max: usize,
    },
    /// Fewer knots than a degree-`p` spline with `p + 1` control points needs.
    #[error("knot vector has {len} knots; degree {degree} needs at least {min}")]
    TooFewKnots {
        /// Number of knots given.
        len: usize,
        /// Degree.
        degree: usize,
        /// Minimum number of knots, `2 (degree + 1)`.
        min: usize,
    },
    /// A knot is NaN or infinite.
    #[error("knot {index} is not finite ({value})")]
    NonFiniteKnot {
        /// Index of the offending knot.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// A knot is smaller than its predecessor.
    #[error("knot {index} ({value}) is smaller than the knot before it ({previous})")]
    DecreasingKnot {
        /// Index of the offending knot.
        index: usize,
        /// Its value.
        value: f64,
        /// Value of knot `index - 1`.
        previous: f64,
    },
    /// A knot value is repeated more often than allowed (`degree + 1` at the ends,
    /// `degree` in the interior).
    #[error(
        "knot value {value} starting at index {index} has multiplicity {multiplicity}, more than the allowed {max}"
    )]
    KnotMultiplicity {
        /// Index of the first occurrence of the value.
        index: usize,
        /// The repeated knot value.
        value: f64,
        /// Its multiplicity.
        multiplicity: usize,
        /// Largest allowed multiplicity at this position.
        max: usize,
    },
    /// The parameter domain `[knots[p], knots[m - p]]` has zero length.
    #[error("parameter domain [{start}, {end}] is empty")]
    EmptyDomain {
        /// Domain start.
        start: f64,
        /// Domain end.
        end: f64,
    },
    /// The number of knots is not `n_ctrl + degree + 1`.
    #[error(
        "{n_knots} knots do not fit {n_ctrl} control points of degree {degree} (need n_ctrl + degree + 1 = {expected})"
    )]
    KnotCountMismatch {
        /// Number of knots given.
        n_knots: usize,
        /// Number of control points given.
        n_ctrl: usize,
        /// Degree.
        degree: usize,
        /// Required number of knots.
        expected: usize,
    },
    /// A list has the wrong number of entries (weights vs. control points, a ragged
    /// control-net row, ...).
    #[error("{what}: expected {expected} entries, got {got}")]
    LengthMismatch {
        /// What was being checked (e.g. `"weights"`, `"control net row 3"`).
        what: String,
        /// Expected number of entries.
        expected: usize,
        /// Number of entries found.
        got: usize,
    },
    /// A curve control point has a NaN or infinite coordinate.
    #[error("control point {index} has a non-finite coordinate")]
    NonFiniteControlPoint {
        /// Index of the control point.
        index: usize,
    },
    /// A curve weight is not positive and finite.
    #[error("weight {index} is {value}; weights must be positive and finite")]
    InvalidWeight {
        /// Index of the weight.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// A surface control point has a NaN or infinite coordinate.
    #[error("surface control point ({i}, {j}) has a non-finite coordinate")]
    NonFiniteSurfaceControlPoint {
        /// Index along `u`.
        i: usize,
        /// Index along `v`.
        j: usize,
    },
    /// A surface weight is not positive and finite.
    #[error("surface weight ({i}, {j}) is {value}; weights must be positive and finite")]
    InvalidSurfaceWeight {
        /// Index along `u`.
        i: usize,
        /// Index along `v`.
        j: usize,
        /// Its value.
        value: f64,
    },
    /// A surface knot vector is invalid; `source` says how.
    #[error("knot vector in {direction}: {source}")]
    SurfaceKnots {
        /// Which knot vector.
        direction: Direction,
        /// The knot-vector error.
        #[source]
        source: Box<NurbsError>,
    },
    /// A parameter lies outside the domain where the operation needs it (splitting needs
    /// an interior parameter, knot insertion a parameter inside the domain).
    #[error("parameter {value} is outside the allowed range [{start}, {end}]")]
    ParameterOutOfDomain {
        /// The parameter.
        value: f64,
        /// Start of the allowed range.
        start: f64,
        /// End of the allowed range.
        end: f64,
    },
    /// Inserting a knot that many times would push its multiplicity above the degree.
    #[error(
        "cannot insert knot {value} {times} times: it already has multiplicity {multiplicity} and the degree is {degree}"
    )]
    InsertionExceedsMultiplicity {
        /// Knot value.
        value: f64,
        /// Requested number of insertions.
        times: usize,
        /// Existing multiplicity.
        multiplicity: usize,
        /// Degree (largest interior multiplicity).
        degree: usize,
    },
    /// Geometric input that defines no valid entity (zero radius, zero sweep, zero
    /// axis, non-orthogonal frame, non-finite angle, ...).
    #[error("invalid geometry: {0}")]
    InvalidGeometry(String),
}

impl NurbsError {
    pub(crate) fn in_direction(self, direction: Direction) -> Self {
        NurbsError::SurfaceKnots {
            direction,
            source: Box::new(self),
        }
    }
}
