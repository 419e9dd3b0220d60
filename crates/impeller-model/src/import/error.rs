//! The importers' error type: every failure names the file, and the line and field where the
//! input stopped making sense.

use std::path::PathBuf;

/// Why a blade-design export could not be imported.
///
/// Parse errors carry the 1-based line number and a phrase saying what was expected there, so
/// the message alone lets a user fix the file (`hub.curve:12: expected 3 numbers (x y z),
/// found "1.0 abc"`).
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    /// The file could not be read.
    #[error("{}: cannot read: {source}", file.display())]
    Io {
        /// The file concerned.
        file: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// A line does not have the expected form.
    #[error("{}:{line}: expected {expected}, found {found:?}", file.display())]
    Syntax {
        /// The file concerned.
        file: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What the line should have held (field names and their form).
        expected: String,
        /// The offending text, shortened to at most 60 characters.
        found: String,
    },
    /// The file ended while more data was expected.
    #[error("{}:{line}: unexpected end of file, expected {expected}", file.display())]
    UnexpectedEof {
        /// The file concerned.
        file: PathBuf,
        /// Number of the last line of the file (0 for an empty file).
        line: usize,
        /// What was still expected.
        expected: String,
    },
    /// A value parsed but is out of range or inconsistent with the rest of the file.
    #[error("{}:{line}: invalid {field}: {reason}", file.display())]
    Invalid {
        /// The file concerned.
        file: PathBuf,
        /// 1-based line number of the value (0 when the problem concerns the whole file).
        line: usize,
        /// The field (keyword, column or entity) that is wrong.
        field: String,
        /// Why it is wrong.
        reason: String,
    },
    /// The data parsed but its geometry cannot form an impeller (too few points, degenerate
    /// sections, a fit that fails its tolerance, ...).
    #[error("{}: {entity}: {reason}", file.display())]
    Geometry {
        /// The file the geometry came from.
        file: PathBuf,
        /// The entity concerned (`hub`, `blade "main blade" section 2`, ...).
        entity: String,
        /// What is wrong with it.
        reason: String,
    },
}

impl ImportError {
    /// The file the error refers to.
    pub fn file(&self) -> &std::path::Path {
        match self {
            ImportError::Io { file, .. }
            | ImportError::Syntax { file, .. }
            | ImportError::UnexpectedEof { file, .. }
            | ImportError::Invalid { file, .. }
            | ImportError::Geometry { file, .. } => file,
        }
    }

    /// The 1-based line the error refers to, when it concerns one line.
    pub fn line(&self) -> Option<usize> {
        match self {
            ImportError::Syntax { line, .. }
            | ImportError::UnexpectedEof { line, .. }
            | ImportError::Invalid { line, .. } => Some(*line),
            ImportError::Io { .. } | ImportError::Geometry { .. } => None,
        }
    }
}
