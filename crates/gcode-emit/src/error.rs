//! Typed errors of `gcode-emit`.

/// Everything that can go wrong while reading CL files, building programs or writing them.
#[derive(Debug, thiserror::Error)]
pub enum GcodeError {
    /// A CL (APT CLDATA) record could not be read. `field` is 1-based over the record's
    /// parameters after the `/` (0 = the record word itself).
    #[error("{file}:{line}: {record} field {field}: {reason}")]
    ClParse {
        /// File name (or `<memory>`).
        file: String,
        /// 1-based line of the record's first physical line.
        line: usize,
        /// The record word (`GOTO`, `CUTTER`, ...).
        record: String,
        /// 1-based parameter index (0 = the record word).
        field: usize,
        /// What was wrong.
        reason: String,
    },
    /// A G-code program could not be read. `word` is the offending word (e.g. `X1.2.3`).
    #[error("{file}:{line}: word `{word}`: {reason}")]
    GcodeParse {
        /// File name (or `<memory>`).
        file: String,
        /// 1-based line.
        line: usize,
        /// The offending word.
        word: String,
        /// What was wrong.
        reason: String,
    },
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file concerned.
        path: String,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// The `[program]` table of a machine file is not acceptable.
    #[error("{file}:{line}: field `{field}`: {message}")]
    Frame {
        /// Machine file.
        file: String,
        /// 1-based line (0 when unknown).
        line: usize,
        /// Dotted key, e.g. `program.kinematics`.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A dialect name was not recognised.
    #[error("unknown dialect `{name}`; valid dialects: {valid}")]
    UnknownDialect {
        /// The name given.
        name: String,
        /// Comma-separated list of valid names.
        valid: String,
    },
    /// A dialect cannot express the requested output.
    #[error("dialect {dialect} cannot write {what}")]
    Unsupported {
        /// Dialect name.
        dialect: &'static str,
        /// What was asked for.
        what: String,
    },
    /// A tool-vector operation has a block without a tool vector.
    #[error("operation `{operation}` block {block}: tool-vector output needs a tool vector")]
    MissingToolVector {
        /// Operation name.
        operation: String,
        /// 0-based block index.
        block: usize,
    },
    /// A value to be written is NaN or infinite.
    #[error("operation `{operation}` block {block}: word {word} has non-finite value {value}")]
    NonFinite {
        /// Operation name.
        operation: String,
        /// 0-based block index inside the operation.
        block: usize,
        /// Address letter or word.
        word: String,
        /// The value.
        value: f64,
    },
    /// A program option is out of range.
    #[error("program option `{field}`: {reason}")]
    InvalidOption {
        /// Name of the option.
        field: &'static str,
        /// What was wrong.
        reason: String,
    },
    /// A cutting block reached the output without a feed (it would be written `F0`).
    #[error(
        "operation `{operation}` block {block}: no {what} feed for a cutting move \
         (give the CL data a FEDRAT or the post a default feed)"
    )]
    MissingFeed {
        /// Operation name.
        operation: String,
        /// 0-based block index inside the posted operation.
        block: usize,
        /// `inverse-time` or `mm/min`.
        what: &'static str,
    },
    /// Post-processing (kinematics) failed on a block.
    #[error("operation `{operation}` move {index}: {reason}")]
    Kinematics {
        /// Operation name.
        operation: String,
        /// 0-based move index in the tool path.
        index: usize,
        /// The kinematics error, formatted.
        reason: String,
    },
}
