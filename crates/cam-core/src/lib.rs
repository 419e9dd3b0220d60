//! Shared CAM vocabulary of the impeller toolkit: cutters (with APT conversion and
//! collision-ready frusta), cutter locations, moves, tool paths, named tolerances — and the
//! distance-function core of flank milling: a cutter as an exact family of spheres
//! ([`sphere_family`]) and the signed distance from a point to the envelope it sweeps along a
//! two-guide tool-axis trajectory, with closed-form derivatives ([`envelope`]); cutter-to-surface
//! contact: the cutter location touching a surface point for every cutter shape and the
//! scallop height between neighbouring passes ([`contact`]).
//!
//! Conventions (see the workspace `DESIGN.md` §3): lengths in millimetres, angles in radians,
//! `f64` throughout. A cutter location is the tool *tip* (lowest point of the cutter on its
//! axis) plus the unit tool axis pointing from the tip toward the spindle (APT convention).

pub mod apt;
pub mod assembly;
pub mod contact;
pub mod cutter;
pub mod envelope;
mod envelope_query;
pub mod error;
pub mod guide;
pub mod location;
pub mod path;
pub mod sphere_family;
pub mod tolerance;

pub use apt::{AptCutter, APT_CONSISTENCY_TOL};
pub use assembly::Frustum;
pub use contact::{
    ball_scallop, ball_step_over, bull_nose_effective_radius, bull_nose_scallop,
    bull_nose_step_over, contact_location, contact_location_at_height, scallop_approx,
    step_over_approx, Contact, ContactError, ContactPart,
};
pub use cutter::{Cutter, CutterShape, HolderSegment, RadiusProfile};
pub use envelope::{
    ControlPointGradient, EnvelopeDistance, EnvelopeGradient, EnvelopeOptions, EnvelopeParam,
    SweptEnvelope,
};
pub use error::CamError;
pub use guide::{GuideCurve, GuideEval, MAX_GUIDE_DEGREE};
pub use location::CutterLocation;
pub use path::{Move, MoveKind, Rates, ToolPath};
pub use sphere_family::{SphereFamily, SpherePiece, SweptSphere};
pub use tolerance::Tolerances;

/// Point in the workpiece frame (mm).
pub type Point3 = nalgebra::Point3<f64>;
/// Vector in the workpiece frame (mm).
pub type Vector3 = nalgebra::Vector3<f64>;
/// Unit vector (tool axes, normals).
pub type UnitVector3 = nalgebra::Unit<nalgebra::Vector3<f64>>;

// The README's code blocks are compiled and run as doc tests (`cargo test --doc`).
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
