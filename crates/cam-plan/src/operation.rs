//! The [`Operation`] trait, the context an operation plans in, and what it returns.
//!
//! The pipeline knows an operation only through this trait and one registration of its kind:
//! a function [`Builder`] that turns the job's `[[operations]]` table ([`OperationSpec`]) into
//! a boxed operation. Each operation crate exports one builder per kind.

use crate::linking::{widening_profile, LinkCheck, LinkStats, DEFAULT_LINK_QUERIES};
use crate::{DesignClearance, Linker, Metrics, PlanError, Plot, Process, RemainingMaterial, Tool};
use cam_core::{CutterLocation, Move, Rates, Tolerances, ToolPath};
use impeller_model::{Impeller, Stock};

/// Everything an operation plans with. Built by the pipeline once per operation.
#[derive(Debug, Clone, Copy)]
pub struct PlanContext<'a> {
    /// The impeller (design geometry).
    pub impeller: &'a Impeller,
    /// The blank the impeller is cut from.
    pub stock: &'a Stock,
    /// The operation's tool.
    pub tool: &'a Tool,
    /// The job's tolerances (every one accepted is used).
    pub tolerances: &'a Tolerances,
    /// The operation's process row (feeds, speeds, depths, allowances).
    pub process: &'a Process,
    /// Clearance of this tool (cutter, shank, holder) against the design.
    pub clearance: &'a DesignClearance<'a>,
    /// Linking moves over the job's safety surface.
    pub linker: &'a Linker,
    /// Outcomes of the checked retracts and approaches ([`PlanContext::link`],
    /// [`PlanContext::close`]).
    pub links: &'a LinkStats,
    /// The tool axes the job's machine can take (its rotary travel), when known: operations
    /// that search for an axis skip the ones it cannot reach ([`PlanContext::reaches`]).
    pub reach: Option<&'a dyn AxisReach>,
    /// The stock the job's earlier operations leave, measured above the design: given to
    /// the operations that ask for it ([`Operation::needs_remaining`]), `None` otherwise.
    pub remaining: Option<&'a RemainingMaterial>,
    /// Where the caller wants to hear how far a long planning has come
    /// ([`PlanContext::progress`]); `None`: nobody listens.
    pub progress: Option<&'a dyn PlanProgress>,
}

/// A listener for how far an operation's planning has come: a person waits on it (a
/// spinner's message, a line in a log). Operations whose planning can take long report units
/// of their own work (`what`: "samples", "regions", …) through [`PlanContext::progress`], from
/// any thread, as often as they like: the listener throttles what it shows.
pub trait PlanProgress: Sync + std::fmt::Debug {
    /// `done` of `total` units of `what` are planned.
    fn report(&self, what: &str, done: usize, total: usize);
}

/// Which tool axes (unit vectors in the workpiece frame, from the tip toward the spindle) a
/// machine can present to the part within its rotary travel: the machine-side constraint an
/// operation's axis search respects so that its postures can be posted. The linear travel,
/// which depends on where the tip is, is not part of it (the run checks it after planning).
pub trait AxisReach: Sync + std::fmt::Debug {
    /// Whether some posture within the rotary travel gives the tool axis `axis`.
    fn reaches(&self, axis: &nalgebra::Vector3<f64>) -> bool;
}

/// A [`PlanProgress`] that keeps every report in order of arrival (for tests, and for callers
/// that summarise a planning's progress afterwards).
#[derive(Debug, Default)]
pub struct ProgressLog(std::sync::Mutex<Vec<(String, usize, usize)>>);

impl ProgressLog {
    /// The reports so far: `(what, done, total)`.
    pub fn reports(&self) -> Vec<(String, usize, usize)> {
        self.0
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .clone()
    }
}

impl PlanProgress for ProgressLog {
    fn report(&self, what: &str, done: usize, total: usize) {
        self.0
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .push((what.to_string(), done, total));
    }
}

impl PlanContext<'_> {
    /// Tells the caller's listener ([`PlanContext::progress`]) that `done` of `total` units
    /// of `what` are planned; nothing without one. O(1) plus the listener.
    pub fn progress(&self, what: &str, done: usize, total: usize) {
        if let Some(p) = self.progress {
            p.report(what, done, total);
        }
    }

    /// Whether the job's machine can present the tool axis `axis` (unit, workpiece frame;
    /// `true` when no machine constrains the planning). O(1).
    pub fn reaches(&self, axis: &nalgebra::Vector3<f64>) -> bool {
        self.reach.is_none_or(|r| r.reaches(axis))
    }

    /// Feed, plunge and rapid rates of this operation's tool and process row.
    pub fn rates(&self) -> Rates {
        self.process.rates(self.tool)
    }

    /// The design check of this operation's retracts and approaches: its clearance query,
    /// keeping its smallest allowance (never below 0; a move that starts closer may stay as
    /// close), certified within half the machining tolerance.
    pub fn link_check(&self) -> LinkCheck<'_> {
        LinkCheck {
            clearance: self.clearance,
            profile: widening_profile(&self.tool.cutter),
            stats: self.links,
            floor_mm: self
                .process
                .blade_allowance_mm
                .min(self.process.hub_allowance_mm)
                .max(0.0),
            tol_mm: 0.5 * self.tolerances.machining_tol,
            max_queries: DEFAULT_LINK_QUERIES,
            cutter: Some(&self.tool.cutter),
        }
    }

    /// Linking moves from `from` to `to` ([`Linker::link_checked`] with
    /// [`PlanContext::link_check`]).
    pub fn link(
        &self,
        from: &CutterLocation,
        to: &CutterLocation,
        approach_mm: f64,
    ) -> Result<Vec<Move>, PlanError> {
        self.linker
            .link_checked(from, to, approach_mm, &self.link_check())
    }

    /// Approach and retract of `path` ([`Linker::close_checked`] with
    /// [`PlanContext::link_check`]).
    pub fn close(&self, path: &mut ToolPath, approach_mm: f64) -> Result<(), PlanError> {
        self.linker
            .close_checked(path, approach_mm, &self.link_check())
    }
}

/// What an operation returns.
#[derive(Debug, Clone, Default)]
pub struct PlannedOperation {
    /// Tool paths in machining order, one per channel or blade side. Each starts with its
    /// approach from the safety surface and ends with its retract to it (the pipeline links
    /// consecutive paths with [`Linker::link`]).
    pub paths: Vec<ToolPath>,
    /// The kind's own metrics under the fixed names of DESIGN §4 (the pipeline adds `moves`,
    /// `path_length_mm`, `cutting_time_s` and `plan_ms`).
    pub metrics: Metrics,
    /// The kind's own plots.
    pub plots: Vec<Plot>,
    /// Remarks for the report (what was skipped and why, warnings).
    pub notes: Vec<String>,
}

/// A machining operation that plans tool paths on an impeller.
///
/// Object safe: the pipeline holds `Box<dyn Operation>`. `plan` must not panic on any
/// impeller or parameters; it returns a [`PlanError`] naming the operation, the place and the
/// reason instead.
pub trait Operation: std::fmt::Debug + Send + Sync {
    /// The kind name as written in job files (`plunge_roughing`, …).
    fn kind(&self) -> &'static str;
    /// The operation's name in the job.
    fn name(&self) -> &str;
    /// Name of the tool it needs (a key into the job's tools).
    fn tool(&self) -> &str;
    /// Plans the operation.
    fn plan(&self, ctx: &PlanContext<'_>) -> Result<PlannedOperation, PlanError>;

    /// Whether the operation plans from the stock the job's earlier operations leave
    /// ([`PlanContext::remaining`]): the pipeline then plans it after them, with their cuts
    /// simulated. Default: no.
    fn needs_remaining(&self) -> bool {
        false
    }

    /// Further tools of the job the operation plans steps of its own with (a pilot drill
    /// before plunge roughing), with the keys that name them. Default: none.
    fn step_tools(&self) -> Vec<StepTool> {
        Vec::new()
    }

    /// Plans the operation and the steps it machines with the further tools `tools` (the
    /// job's tools named by [`Operation::step_tools`], in that order). The pipeline posts
    /// every step as its own operation (own tool change, feeds, report row), before or after
    /// the operation as [`PlannedStep::before`] says. Default: [`Operation::plan`], no step.
    fn plan_with_steps(
        &self,
        ctx: &PlanContext<'_>,
        tools: &[&Tool],
    ) -> Result<(PlannedOperation, Vec<PlannedStep>), PlanError> {
        let _ = tools;
        Ok((self.plan(ctx)?, Vec::new()))
    }
}

/// A further tool of the job an operation plans a step with ([`Operation::step_tools`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StepTool {
    /// The operation's (dotted) key that names the tool, for error locations.
    pub key: String,
    /// The tool's name in the job.
    pub tool: String,
}

/// A step an operation plans with a further tool of the job ([`Operation::plan_with_steps`]):
/// posted as its own operation.
#[derive(Debug, Clone)]
pub struct PlannedStep {
    /// Its name in the job's report (unique: usually the operation's name with a suffix).
    pub name: String,
    /// Its kind name in the report (e.g. `pilot_drilling`).
    pub kind: String,
    /// The tool it runs with (one of the operation's [`StepTool`]s).
    pub tool: String,
    /// Its process row (spindle speed, feeds; allowances as the operation's).
    pub process: Process,
    /// Machined before the operation (`true`) or after it.
    pub before: bool,
    /// Its paths (each from and back to the safety surface), metrics, plots and notes.
    pub planned: PlannedOperation,
}

/// One `[[operations]]` table of a job: the common keys, the process row and the kind's own
/// keys (everything else in the table), left for the kind's builder to deserialise with
/// [`crate::params::parse`] (which rejects unknown keys).
#[derive(Debug, Clone, PartialEq)]
pub struct OperationSpec {
    /// Operation name (unique in the job).
    pub name: String,
    /// Kind name.
    pub kind: String,
    /// Tool name.
    pub tool: String,
    /// The process row.
    pub process: Process,
    /// The kind's own keys.
    pub params: toml::Table,
}

/// Turns an operation table into an operation of one kind.
pub type Builder = fn(&OperationSpec) -> Result<Box<dyn Operation>, PlanError>;
