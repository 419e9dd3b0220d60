//! Shared CAM vocabulary of the impeller toolkit: cutters, cutter locations, moves, tool
//! paths and named tolerances.
//!
//! Conventions (see the workspace `DESIGN.md` §3): lengths in millimetres, angles in radians,
//! `f64` throughout. A cutter location is the tool *tip* (lowest point of the cutter on its
//! axis) plus the unit tool axis pointing from the tip toward the spindle (APT convention).

pub mod cutter;
pub mod error;
pub mod location;
pub mod path;
pub mod tolerance;

pub use cutter::{Cutter, CutterShape, HolderSegment};
pub use error::CamError;
pub use location::CutterLocation;
pub use path::{Move, MoveKind, Rates, ToolPath};
pub use tolerance::Tolerances;

/// Point in the workpiece frame (mm).
pub type Point3 = nalgebra::Point3<f64>;
/// Vector in the workpiece frame (mm).
pub type Vector3 = nalgebra::Vector3<f64>;
/// Unit vector (tool axes, normals).
pub type UnitVector3 = nalgebra::Unit<nalgebra::Vector3<f64>>;
