//! What every impeller machining operation shares.
//!
//! An operation (plunge roughing, channel roughing, hub and blade-root finishing, flank
//! semi-finishing and finishing) is a type implementing [`Operation`]: given a
//! [`PlanContext`] (the impeller, its blank, the tool, the tolerances, the process row and the
//! shared services) it returns a [`PlannedOperation`] — its tool paths in machining order, its
//! own metrics under the fixed names of DESIGN §4, and the data of its plots — or a typed
//! [`PlanError`] naming the operation, the blade or channel and the reason.
//!
//! The services every planner needs live here once:
//! - [`clearance`]: signed clearance of the cutter, shank and holder against the design (hub,
//!   shroud contour, every blade), with the part that is nearest: a triangulated
//!   [`DesignMesh`] (shared by every tool's query) as prefilter, exact NURBS distances near
//!   the surface for the cutter, shank and holder frusta as convex shapes against the mesh;
//! - [`pass_check`]: the whole tool (cutter, shank, holder) of a cutting pass, every posture
//!   and every motion between two, against the whole design with a floor per part;
//! - [`fillet_margin`]: the blade-root fillets in the clearance of a ball near the corner
//!   between hub and blade (a lower bound, motions certified);
//! - [`axis_smoothing`]: the tool axes of a ball-end cutting run made monotone and smooth
//!   about the ball centres, re-checked with the whole-tool query, kept reversals reported
//!   with their reasons;
//! - [`linking`]: retract along the tool axis to a safety surface, travel on it, approach
//!   along the tool axis;
//! - [`pattern`]: rotational copy of one channel's or blade's paths to every channel/blade
//!   (paper 003's "object transformation");
//! - [`order`]: channel and blade ordering that keeps rapids short;
//! - [`remaining`]: the stock the job's earlier operations leave above the design, for the
//!   operations that machine what is left.
//!
//! Job-file vocabulary shared by the pipeline and the operation crates: [`Tool`] (a cutter with
//! its number, teeth, holder and gauge length), [`Process`] (the shop-sheet row: spindle speed,
//! feed per tooth, depth and width of cut, allowances → feed rates), [`params`] (deserialising
//! a kind's own keys with errors that name the key).
//!
//! Dependency direction (DESIGN §2): `nurbs`, `cam-core`, `impeller-model` only; the verifier
//! (`machining-sim`) never depends on this crate. Third-party: parry3d-f64 (the workspace's
//! choice for BVH and convex-shape distance queries) in [`clearance`].

pub mod axis_smoothing;
pub mod clearance;
pub mod error;
pub mod fillet_margin;
pub mod linking;
mod mesh_distance;
pub mod metrics;
pub mod operation;
pub mod order;
pub mod params;
pub mod pass_check;
pub mod pattern;
pub mod process;
pub mod remaining;
pub mod tool;

pub use axis_smoothing::{AxisSmoothing, KeptReason, PostureCheck, RunSmoothing, SmoothingSummary};
pub use clearance::{
    Clearance, ClearanceOptions, DesignClearance, DesignMesh, DesignPart, PartSet, Row, ToolPart,
};
pub use error::PlanError;
pub use fillet_margin::FilletMargin;
pub use linking::{LinkCheck, LinkStats, Linker, SafetySurface, ToolEnvelope, RAPID_TRACE_STOP_MM};
pub use metrics::{MetricValue, Metrics, Plot, PlotKind, PlotSeries};
pub use operation::{
    AxisReach, Builder, Operation, OperationSpec, PlanContext, PlanProgress, PlannedOperation,
    PlannedStep, ProgressLog, StepTool,
};
pub use pass_check::{PassCheck, PassFloors, PassViolation, PostureClearance};
pub use process::Process;
pub use remaining::{RemainingMaterial, RestGrid};
pub use tool::Tool;

/// Point in the workpiece frame (mm).
pub type Point3 = cam_core::Point3;
/// Vector in the workpiece frame (mm).
pub type Vector3 = cam_core::Vector3;

// The README's code blocks are compiled and run as doc tests (`cargo test --doc`).
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
