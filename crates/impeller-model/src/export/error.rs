//! The exporters' error type.

use std::path::PathBuf;

/// Why an export could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// Writing or renaming a file failed (no partial file is left behind).
    #[error("{}: cannot write: {source}", file.display())]
    Io {
        /// The file concerned.
        file: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// A tolerance or count argument is out of range.
    #[error("invalid {field}: {reason}")]
    Invalid {
        /// The argument.
        field: &'static str,
        /// Why it is invalid.
        reason: String,
    },
    /// A surface could not be triangulated within the chord tolerance.
    #[error("{part}: {reason}")]
    Tessellation {
        /// The part or surface concerned.
        part: String,
        /// What went wrong.
        reason: String,
    },
}
