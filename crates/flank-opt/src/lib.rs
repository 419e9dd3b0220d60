//! Flank (SWARF) milling of impeller blades: the cutter's flank cuts a whole ruled blade side
//! in one pass, the ball end finishing the hub fillet at the same time.
//!
//! Two operation kinds (DESIGN §4):
//!
//! - [`FLANK_FINISHING`] ([`finishing`]): paper 002. Initial cutter locations by two-point
//!   tangency with the ball lowered onto the hub; then the cutter shape (ball radius, half
//!   taper angle) and the path (the control points of the two guide curves of the tool-axis
//!   trajectory surface) optimised together for the Rayleigh–Ritz stiffness under accuracy,
//!   hub-tangency and clearance constraints by SLP ([`slp`], LPs by [`lp`]); the catalogue
//!   cutter just below the optimum ([`catalogue`]); the path of the job's tool optimised as a
//!   minimax problem; the written pass measured densely against the design side and refined
//!   until it holds the tolerance ([`measure`], issue 13); the best cylindrical ball end for
//!   comparison.
//! - [`FLANK_SEMI_FINISHING`] ([`semi`]): paper 001 §4. Each free-form blade side split into
//!   sub-ruled strips within the semi-finish tolerance, one flank pass per strip from the
//!   shroud down; compared with isoparametric point milling at the same scallop height.
//!
//! - [`BLADE_POINT_FINISHING`] ([`point_finishing`]): any blade side, ruled or free-form.
//!   [`regions`] chooses per region: a flank pass over a sub-ruled strip where it is within
//!   the tolerance and its whole tool is clear ([`cam_plan::PassCheck`]), five-axis point
//!   milling ([`point`]) elsewhere.
//!
//! Every operation plans both rows of blades ([`rows`]: the reference blade of each row,
//! copied to every blade of the row) and checks its passes for the whole tool against the
//! whole design.
//!
//! The LPs: a primal–dual interior point specialised to the SLP subproblem ([`lp`]: the
//! elastic slacks eliminated, a dense normal system of the few hundred path variables),
//! several times faster there than clarabel, the workspace's general conic solver (DESIGN §2),
//! which remains the fallback should the specialised solve not converge.
//!
//! Dependency direction: `nurbs`, `cam-core`, `impeller-model`, `cutter-stiffness`,
//! `cam-plan` only.

pub mod axis_smoothing;
pub mod catalogue;
pub mod finishing;
pub mod geometry;
pub mod lp;
pub mod measure;
pub mod point;
pub mod point_finishing;
pub mod problem;
pub mod regions;
pub mod rows;
pub mod semi;
pub mod slp;

pub use catalogue::Catalogue;
pub use finishing::{build_flank_finishing, FinishingParams};
pub use geometry::{FlankSide, InitialPath};
pub use point_finishing::{build_blade_point_finishing, BLADE_POINT_FINISHING};
pub use semi::{build_flank_semi_finishing, SemiParams};

/// Kind name of flank finishing in job files.
pub const FLANK_FINISHING: &str = "flank_finishing";
/// Kind name of sub-ruled flank semi-finishing in job files.
pub const FLANK_SEMI_FINISHING: &str = "flank_semi_finishing";

/// Errors of the flank planners (wrapped into [`cam_plan::PlanError`] with the operation's
/// name at the operation boundary).
#[derive(Debug, thiserror::Error)]
pub enum FlankError {
    /// A parameter is out of range.
    #[error("{0}")]
    Param(String),
    /// The geometry defeats the method.
    #[error("{0}")]
    Geometry(String),
    /// The LP solver failed.
    #[error("LP solver: {0}")]
    Solver(String),
    /// The optimised path misses a tolerance the operation was asked to meet (no path is
    /// emitted: a finishing pass outside its tolerance is not machined).
    #[error("{0}")]
    NotAccurate(String),
    /// An envelope or cutter error.
    #[error(transparent)]
    Cam(#[from] cam_core::CamError),
    /// An impeller model error.
    #[error(transparent)]
    Model(#[from] impeller_model::ModelError),
}

impl FlankError {
    /// As a planning error of operation `op`.
    pub fn plan(self, op: &str) -> cam_plan::PlanError {
        match self {
            FlankError::Param(m) => cam_plan::PlanError::param(op, "parameters", m),
            FlankError::Geometry(m) => cam_plan::PlanError::geometry(op, "blade side", m),
            FlankError::Solver(m) => cam_plan::PlanError::geometry(op, "optimiser", m),
            FlankError::NotAccurate(m) => cam_plan::PlanError::geometry(op, "accuracy", m),
            FlankError::Cam(e) => cam_plan::PlanError::cam(op, e),
            FlankError::Model(e) => cam_plan::PlanError::model(op, e),
        }
    }
}

// The README's code blocks are compiled and run as doc tests (`cargo test --doc`).
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
