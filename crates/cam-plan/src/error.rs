//! Planning errors: each names the operation and, where it applies, the blade, channel or
//! position, and says what was wrong.

use thiserror::Error;

/// Why an operation could not be planned.
#[derive(Debug, Error)]
pub enum PlanError {
    /// A job key of the operation (or tool) is missing, unknown or out of range.
    #[error("operation \"{operation}\": {key}: {reason}")]
    Param {
        /// Operation name.
        operation: String,
        /// The offending key (dotted path inside the operation table).
        key: String,
        /// What is wrong with it.
        reason: String,
    },
    /// The operation kind is not registered.
    #[error("operation \"{operation}\": unknown kind \"{kind}\" (known: {known})")]
    UnknownKind {
        /// Operation name.
        operation: String,
        /// The kind given.
        kind: String,
        /// Comma-separated list of registered kinds.
        known: String,
    },
    /// The tool is not suited to the operation (wrong shape, too large for the channel, …).
    #[error("operation \"{operation}\": tool \"{tool}\": {reason}")]
    Tool {
        /// Operation name.
        operation: String,
        /// Tool name.
        tool: String,
        /// Why the tool cannot be used.
        reason: String,
    },
    /// The geometry defeats the method at a named place (no accessible axis, no fit, …).
    #[error("operation \"{operation}\": {place}: {reason}")]
    Geometry {
        /// Operation name.
        operation: String,
        /// Where: blade, channel, section, row or position.
        place: String,
        /// What failed.
        reason: String,
    },
    /// An error of the impeller model.
    #[error("operation \"{operation}\": model: {source}")]
    Model {
        /// Operation name.
        operation: String,
        /// The model error.
        #[source]
        source: impeller_model::ModelError,
    },
    /// An error of the CAM vocabulary (invalid cutter, location, rates).
    #[error("operation \"{operation}\": {source}")]
    Cam {
        /// Operation name.
        operation: String,
        /// The cam-core error.
        #[source]
        source: cam_core::CamError,
    },
    /// An error of the NURBS kernel.
    #[error("operation \"{operation}\": NURBS: {source}")]
    Nurbs {
        /// Operation name.
        operation: String,
        /// The kernel error.
        #[source]
        source: nurbs::NurbsError,
    },
}

impl PlanError {
    /// A parameter error of `operation` at `key`.
    pub fn param(operation: &str, key: impl Into<String>, reason: impl Into<String>) -> Self {
        Self::Param {
            operation: operation.to_string(),
            key: key.into(),
            reason: reason.into(),
        }
    }

    /// A geometry error of `operation` at `place`.
    pub fn geometry(operation: &str, place: impl Into<String>, reason: impl Into<String>) -> Self {
        Self::Geometry {
            operation: operation.to_string(),
            place: place.into(),
            reason: reason.into(),
        }
    }

    /// A tool error of `operation`.
    pub fn tool(operation: &str, tool: &str, reason: impl Into<String>) -> Self {
        Self::Tool {
            operation: operation.to_string(),
            tool: tool.to_string(),
            reason: reason.into(),
        }
    }

    /// Wraps a model error for `operation`.
    pub fn model(operation: &str, source: impeller_model::ModelError) -> Self {
        Self::Model {
            operation: operation.to_string(),
            source,
        }
    }

    /// Wraps a cam-core error for `operation`.
    pub fn cam(operation: &str, source: cam_core::CamError) -> Self {
        Self::Cam {
            operation: operation.to_string(),
            source,
        }
    }

    /// Wraps a NURBS error for `operation`.
    pub fn nurbs(operation: &str, source: nurbs::NurbsError) -> Self {
        Self::Nurbs {
            operation: operation.to_string(),
            source,
        }
    }
}
