//! Typed errors of machine files, kinematics and path post-processing.

use serde::Serialize;
use thiserror::Error;

/// Errors reading or validating a machine description.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum MachineError {
    /// The file could not be read.
    #[error("{file}: cannot read machine file: {message}")]
    Io {
        /// File name as given.
        file: String,
        /// Operating-system message.
        message: String,
    },
    /// TOML syntax or a field of the wrong type / missing field.
    #[error("{file}:{line}:{column}: {message}")]
    Syntax {
        /// File name as given.
        file: String,
        /// 1-based line of the offending text (0 when the parser gave no position).
        line: usize,
        /// 1-based column.
        column: usize,
        /// Parser message (names the key).
        message: String,
    },
    /// A field has a value that parses but is not acceptable.
    #[error("{file}{}: field `{field}`: {message}", line_suffix(*line))]
    Invalid {
        /// File name as given.
        file: String,
        /// 1-based line of the field (0 when the field is absent from the file; the message
        /// then shows no line).
        line: usize,
        /// Dotted field path, e.g. `axes.A.min`.
        field: String,
        /// What is wrong.
        message: String,
    },
}

/// Errors of single-pose kinematics.
#[derive(Debug, Error, Clone, PartialEq, Serialize)]
pub enum KinematicsError {
    /// A joint value lies outside the axis travel (value and limits in mm or degrees).
    #[error("axis {axis} = {value:.6} outside its limits [{min:.6}, {max:.6}]")]
    OutOfLimits {
        /// Axis letter.
        axis: char,
        /// Required value (mm for X/Y/Z, degrees for rotary axes).
        value: f64,
        /// Lower limit (same unit).
        min: f64,
        /// Upper limit (same unit).
        max: f64,
    },
    /// The tool orientation cannot be produced by the rotary axes at all.
    #[error("tool axis ({0:.6}, {1:.6}, {2:.6}) cannot be reached by the rotary axes")]
    UnreachableOrientation(f64, f64, f64),
    /// Non-finite input (NaN or infinite coordinates or tool length).
    #[error("non-finite input: {0}")]
    NonFinite(&'static str),
}

/// Errors of path-level post-processing.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum PostError {
    /// A block could not be transformed (names the source block index and the cause, e.g. the
    /// axis whose limits are violated).
    #[error("block {index}: {source}")]
    Block {
        /// Index of the source move / cutter location (0-based).
        index: usize,
        /// Cause.
        source: KinematicsError,
    },
    /// Invalid post-processing option.
    #[error("invalid option `{field}`: {message}")]
    InvalidOption {
        /// Option name.
        field: &'static str,
        /// What is wrong.
        message: String,
    },
    /// Reverse-motion smoothing failed (e.g. the B-spline least-squares system was singular).
    #[error("reverse-motion smoothing: {0}")]
    Smoothing(String),
}

fn line_suffix(line: usize) -> String {
    if line == 0 {
        String::new()
    } else {
        format!(":{line}")
    }
}
