//! Typed errors of the impeller model: every message names the file, line or field at fault.

use std::path::PathBuf;

/// Everything that can go wrong while reading, validating or building an impeller.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// The file's extension names no supported format.
    #[error("{path}: unsupported impeller format (expected .toml, .inf, .geomTurbo or .rtzt)")]
    UnsupportedFormat {
        /// The file concerned.
        path: PathBuf,
    },
    /// The TOML text is malformed or a field has the wrong type.
    #[error("{path}:{line}: {message}")]
    Parse {
        /// The file concerned.
        path: PathBuf,
        /// 1-based line of the error (0 when unknown).
        line: usize,
        /// What the parser expected.
        message: String,
    },
    /// A parameter is out of its valid range; `field` is its dotted path (`main.count`).
    #[error("{field} {reason}")]
    Invalid {
        /// Dotted path of the parameter (`main.thickness_mm[2]`).
        field: String,
        /// What is wrong, phrased to follow the field name (`must be > 0`).
        reason: String,
    },
    /// A validation error located in a file.
    #[error("{path}:{line}: {source}")]
    InFile {
        /// The file concerned.
        path: PathBuf,
        /// 1-based line of the offending field (0 when unknown).
        line: usize,
        /// The validation error.
        source: Box<ModelError>,
    },
    /// The assembled geometry is inconsistent (e.g. blades intersect, sides swapped).
    #[error("invalid geometry: {0}")]
    Geometry(String),
    /// A blade-design export (or an import file pointing at one) could not be imported.
    #[error(transparent)]
    Import(#[from] crate::import::ImportError),
    /// An error from the NURBS kernel while building a curve or surface.
    #[error("nurbs: {0}")]
    Nurbs(#[from] nurbs::NurbsError),
}

impl ModelError {
    /// Shorthand for [`ModelError::Invalid`].
    pub fn invalid(field: impl Into<String>, reason: impl Into<String>) -> Self {
        Self::Invalid {
            field: field.into(),
            reason: reason.into(),
        }
    }

    /// The dotted field path when this is (or wraps) a validation error.
    pub fn field(&self) -> Option<&str> {
        match self {
            Self::Invalid { field, .. } => Some(field),
            Self::InFile { source, .. } => source.field(),
            _ => None,
        }
    }
}
