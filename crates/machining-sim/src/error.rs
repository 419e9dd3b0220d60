//! Typed errors of `machining-sim`.

/// Errors of the simulation and its exports.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// An option is out of range.
    #[error("invalid option `{name}` = {value}: {reason}")]
    InvalidOption {
        /// Option name.
        name: &'static str,
        /// Value given.
        value: f64,
        /// What was expected.
        reason: &'static str,
    },
    /// The stock description is unusable.
    #[error("invalid stock: {0}")]
    InvalidStock(String),
    /// A cutter is invalid.
    #[error("operation {operation}: {source}")]
    InvalidCutter {
        /// Operation (tool path) name.
        operation: String,
        /// The cutter validation error.
        source: cam_core::CamError,
    },
    /// A cutter location is not finite.
    #[error("operation {operation}, move {index}: cutter location is not finite")]
    NonFiniteMove {
        /// Operation (tool path) name.
        operation: String,
        /// Move index within the path.
        index: usize,
    },
    /// The swept envelope of the cross-check could not be built or queried.
    #[error("swept envelope: {0}")]
    Envelope(cam_core::CamError),
    /// The design model could not be meshed or sampled.
    #[error("design model: {0}")]
    Design(String),
    /// A file could not be written.
    #[error("{path}: {source}")]
    Io {
        /// File concerned.
        path: String,
        /// Underlying error.
        source: std::io::Error,
    },
    /// JSON serialisation failed.
    #[error("{path}: {source}")]
    Json {
        /// File concerned.
        path: String,
        /// Underlying error.
        source: serde_json::Error,
    },
}
