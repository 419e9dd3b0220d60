//! The command line's error type: one clear line for the user.

/// An error reported to the user as a single line on stderr (exit code 1).
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file concerned.
        path: String,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// Any other user-facing error, already formatted.
    #[error("{0}")]
    Message(String),
}
