//! The job pipeline as a short sequence of stages:
//!
//! 1. [`model`]: the impeller (design geometry and blank);
//! 2. [`plan`]: every `[[operations]]` entry planned through its kind's
//!    [`cam_plan::Operation`] (independent operations in parallel with rayon; then, in job
//!    order, the operations that plan from the stock the earlier ones leave, with that stock
//!    simulated on their CL paths), its paths linked over the safety surface into one CL
//!    operation, then the job's CL files;
//! 3. [`post`]: `toolpath.cls` (APT CLDATA) and the program for the machine and dialect, with
//!    reverse-motion removal checked against the design ([`GougeCheck`]);
//! 4. [`verify`]: independent stock simulation of the operations as posted;
//! 5. the reports (`report.json`, `report.html`).
//!
//! Each stage is timed (`timings_ms` in the report) and announced on stderr. Stages that have
//! nothing to do say so in the report's `notes` instead of inventing output.

use crate::error::CliError;
use crate::job::{Job, StockStartKind};
use crate::progress::Progress;
use crate::registry::{self, Registry};
use crate::report::{OperationReport, PostOperationReport, PostReport, Report, VerificationReport};
use cam_core::{Cutter, CutterLocation, MoveKind, Rates, ToolPath};
use cam_plan::clearance::DesignMesh;
use cam_plan::{
    ClearanceOptions, DesignClearance, LinkStats, Linker, Metrics, PlanContext, PlanError, Plot,
    SafetySurface, Tool,
};
use gcode_emit::assemble::{assemble_program_with_access, AssembledProgram, OperationAccess};
use gcode_emit::{
    read_cl, write_cl_file, write_program_file, AssembleOptions, ClOperation, ClProgram,
    ClReadOptions, ClWriteOptions, LineNumbers, OutputMode, ProgramFrame, ProgramOptions, Spindle,
};
use impeller_model::Impeller;
use machining_sim::{
    ImpellerDesign, ImpellerSampling, ProgressSink, SimOptions, SimProgress, TriDexel,
};
use postproc_kinematics::{AccessibilityChecker, Machine, PostOptions, ReverseMotionOptions};
use rayon::prelude::*;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

/// The machine used when a job names none: LinuxCNC `xyzac-trt` table-table trunnion.
const DEFAULT_MACHINE: &str = include_str!("../embedded/machines/xyzac-trt.toml");

/// Distance above the first point of a linked path where the approach rapid stops and the
/// plunge feed begins (mm): enough to absorb the positioning overshoot of a rapid, short
/// enough not to waste time at plunge feed.
pub const LINK_APPROACH_MM: f64 = 2.0;

fn msg(e: impl std::fmt::Display) -> CliError {
    CliError::Message(e.to_string())
}

fn stage(progress: &Progress, name: &str) -> Instant {
    progress.stage(name);
    Instant::now()
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// One operation of the job after planning: the CL operation the post and the verifier read,
/// with its report figures, the kind's metrics and plots, and the tool it runs with.
#[derive(Debug, Clone)]
pub struct JobOperation {
    /// The CL operation (one linked path, tool number, cutter, spindle, feeds).
    pub cl: ClOperation,
    /// Kind name (`cl_import` for CL data read from a file).
    pub kind: String,
    /// The tool (the job's for planned operations; built from the `CUTTER` record for CL
    /// data, `None` without one).
    pub tool: Option<Tool>,
    /// Rates for the cutting-time estimate.
    pub rates: Rates,
    /// Planning (or reading) time (ms).
    pub plan_ms: f64,
    /// The kind's own metrics.
    pub metrics: Metrics,
    /// The kind's own plots.
    pub plots: Vec<Plot>,
}

impl JobOperation {
    /// The report row: name, kind, tool, moves, length, time, plan time and metrics.
    pub fn report(&self) -> OperationReport {
        let p = &self.cl.path;
        OperationReport {
            name: p.name.clone(),
            kind: self.kind.clone(),
            tool: p.tool.clone(),
            moves: p.moves.len(),
            path_length_mm: p.path_length_mm(),
            cutting_time_s: p.cutting_time_s(&self.rates),
            plan_ms: self.plan_ms,
            metrics: self.metrics.clone(),
        }
    }
}

/// Runs `job` with the registered operation kinds, writing every output file into `out`.
pub fn run_job(job: &Job, out: &Path) -> Result<Report, CliError> {
    run_job_with(job, out, registry::OPERATIONS)
}

/// Runs `job` with the operation kinds of `registry`, writing every output file into `out`:
/// `toolpath.cls`, `program.<ext>` (when there is something to machine),
/// `verification_maps.json` (when verified), `report.json` and `report.html`.
///
/// The run owns these files: an earlier run's (every dialect's program included) are removed
/// first, and the ones written are removed again when the run fails
/// ([`crate::outputs::clear_run_outputs`]).
pub fn run_job_with(job: &Job, out: &Path, registry: &Registry) -> Result<Report, CliError> {
    std::fs::create_dir_all(out).map_err(|source| CliError::Io {
        path: out.display().to_string(),
        source,
    })?;
    crate::outputs::clear_run_outputs(out)?;
    let run = run_stages(job, out, registry);
    if run.is_err() {
        let _ = crate::outputs::clear_run_outputs(out);
    }
    run
}

fn run_stages(job: &Job, out: &Path, registry: &Registry) -> Result<Report, CliError> {
    let total = Instant::now();
    let mut report = Report::new(&job.name);
    let progress = Progress::new(job.quiet);

    let t = stage(&progress, "building the impeller model");
    let impeller = model(job)?;
    report.impeller = serde_json::to_value(impeller.summary()).map_err(msg)?;
    report.set_geometry_plots(&impeller);
    report.view.set_part(&impeller);
    report.timings_ms.insert("model_ms".into(), ms(t));

    let t = stage(&progress, "planning operations");
    let mut operations = plan(job, &impeller, registry, &mut report.notes)?;
    let travel = link_for_machine(job, &impeller, &mut operations, &mut report.notes)?;
    if operations.is_empty() {
        report
            .notes
            .push("no operation to machine: the job names no operation and no CL file".into());
    }
    for op in &operations {
        report.operations.push(op.report());
        report.add_operation_plots(&impeller, op);
        report.view.add_operation(op);
    }
    if job.export_paths {
        let doc = crate::gltf::toolpaths(&operations).to_string();
        gcode_emit::write_atomic(&out.join("toolpaths.gltf"), doc.as_bytes()).map_err(msg)?;
    }
    report.timings_ms.insert("plan_ms".into(), ms(t));

    let t = stage(
        &progress,
        if travel.is_empty() {
            "post-processing"
        } else {
            "writing the tool paths (no program: they leave the machine's travel)"
        },
    );
    let assembled = post(job, &impeller, &operations, &travel, out, &mut report)?;
    report.timings_ms.insert("post_ms".into(), ms(t));

    if travel.is_empty() {
        let t = stage(
            &progress,
            if job.verification.enabled {
                "verifying by stock simulation"
            } else {
                "verification disabled by the job ([verification] enabled = false)"
            },
        );
        verify(
            job,
            &impeller,
            &operations,
            assembled.as_ref(),
            out,
            &mut report,
        )?;
        report.timings_ms.insert("verify_ms".into(), ms(t));
    } else {
        report
            .notes
            .push(crate::travel::travel_error(&report.post.machine, &travel));
        report.notes.push(
            "no program was posted and nothing was verified: the machine cannot run the \
             planned tool paths (toolpath.cls holds them)"
                .into(),
        );
    }
    withhold_defective_program(job, out, &mut report)?;
    report.verdict = Some(crate::verdict::Verdict::of(
        &report,
        job.tolerances.machining_tol,
    ));
    report.setup = crate::setup::section(
        &impeller,
        &load_machine(job)?,
        &job.tools,
        &operations,
        &report,
    );
    gcode_emit::write_atomic(
        &out.join("setup.html"),
        crate::setup::document(&report.job, &report.setup).as_bytes(),
    )
    .map_err(msg)?;
    report
        .timings_ms
        .insert("total_ms".into(), total.elapsed().as_secs_f64() * 1e3);

    report.write(out)?;
    Ok(report)
}

/// The verification gate: a program whose verification found defects is removed (the report
/// still shows where), unless the job allows defects (`run --allow-defects`), which keeps it
/// and says so in the notes. The command line exits with [`crate::EXIT_DEFECTS`] either way.
fn withhold_defective_program(job: &Job, out: &Path, report: &mut Report) -> Result<(), CliError> {
    let Some(defects) = report.verification.as_ref().map(|v| v.defects.clone()) else {
        return Ok(());
    };
    if defects.is_empty() || !report.post.written {
        return Ok(());
    }
    if job.verification.allow_defects {
        report.notes.push(format!(
            "program {} written although verification found defects (--allow-defects): {}",
            report.post.program,
            defects.join("; ")
        ));
        return Ok(());
    }
    let program = Path::new(&report.post.program);
    if program.exists() {
        std::fs::remove_file(program).map_err(|source| CliError::Io {
            path: report.post.program.clone(),
            source,
        })?;
    }
    report.post.written = false;
    report.notes.push(format!(
        "program {} withheld: verification found defects ({}); see the verification section, \
         or run with --allow-defects to keep it",
        report.post.program,
        defects.join("; ")
    ));
    let _ = out;
    Ok(())
}

/// The job's machine (the embedded xyzac-trt when it names none).
fn load_machine(job: &Job) -> Result<Machine, CliError> {
    let (text, file) = machine_text(job)?;
    Machine::from_toml_str(&text, &file).map_err(msg)
}

/// The text of the job's machine file and its name for errors.
fn machine_text(job: &Job) -> Result<(String, String), CliError> {
    match &job.machine {
        Some(p) => Ok((job.read_text(p)?, p.display().to_string())),
        None => Ok((DEFAULT_MACHINE.into(), "embedded xyzac-trt.toml".into())),
    }
}

/// The program frame of the job's machine file (`[program]`: kinematics switch, header,
/// footer, block numbers, coolant codes; see [`gcode_emit::frame`]).
fn load_frame(job: &Job) -> Result<ProgramFrame, CliError> {
    let (text, file) = machine_text(job)?;
    ProgramFrame::from_machine_toml(&text, &file).map_err(msg)
}

/// Largest deviation (mm) of the read-back chords from the controller's motion.
const READBACK_PATH_TOL_MM: f64 = 0.001;

/// The emitted program read back (`gcode_emit::read_back`) into the tool paths the machine
/// really moves: LinuxCNC joint output, every block (rapids, approach, retract, tool-change
/// moves, linearisation blocks) through the forward kinematics with joint interpolation,
/// cut into chords within 1 µm of that motion. Operation `k` is the program from its `k`-th
/// tool change (`M6`) to the next, or — when operations share a tool — from its header
/// comment to the next. `None` (the posted cutter locations are verified instead) for other
/// dialects and output modes, whose syntax the reader does not cover, or when neither marks
/// every operation.
fn read_back_program(
    job: &Job,
    program: &Path,
    operations: &[JobOperation],
) -> Result<Option<Vec<Option<ToolPath>>>, CliError> {
    if job.dialect != "linuxcnc" {
        return Ok(None);
    }
    let text = std::fs::read_to_string(program).map_err(|source| CliError::Io {
        path: program.display().to_string(),
        source,
    })?;
    let file = program.display().to_string();
    let starts: Vec<usize> = text
        .lines()
        .enumerate()
        .filter(|(_, l)| {
            l.split(['(', ';'])
                .next()
                .is_some_and(|code| code.split_whitespace().any(|w| w == "M6" || w == "M06"))
        })
        .map(|(i, _)| i + 1)
        .collect();
    // Consecutive operations with the same tool share one tool change: then each
    // operation's header comment `(<name> - T<n> …)` marks where it starts.
    let starts = if starts.len() == operations.len() {
        starts
    } else {
        let mut found = Vec::with_capacity(operations.len());
        let mut from = 0;
        for op in operations {
            let head = format!(
                "({} - T{}",
                op.cl.path.name,
                op.cl.tool_number.unwrap_or_default()
            );
            let Some(i) = text
                .lines()
                .enumerate()
                .skip(from)
                .find(|(_, l)| l.trim_start().starts_with(&head))
                .map(|(i, _)| i)
            else {
                return Ok(None);
            };
            found.push(i + 1);
            from = i + 1;
        }
        found
    };
    let machine = load_machine(job)?;
    let blocks = gcode_emit::read_gcode(&text, &file).map_err(msg)?;
    let mut paths = Vec::with_capacity(operations.len());
    for (k, op) in operations.iter().enumerate() {
        let Some(cutter) = &op.cl.cutter else {
            paths.push(None);
            continue;
        };
        let (from, to) = (starts[k], starts.get(k + 1).copied().unwrap_or(usize::MAX));
        let slice: Vec<_> = blocks
            .iter()
            .filter(|b| b.line >= from && b.line < to)
            .copied()
            .collect();
        let options = gcode_emit::ReadbackOptions {
            mode: gcode_emit::ReadbackMode::Joint,
            tool_length_mm: op.cl.tool_length_mm.unwrap_or(0.0),
            path_tol_mm: READBACK_PATH_TOL_MM,
            reach_mm: cutter.overall_length,
        };
        let rb = gcode_emit::read_back(
            &slice,
            &machine,
            &options,
            &file,
            &op.cl.path.name,
            &op.cl.path.tool,
        )
        .map_err(msg)?;
        paths.push(Some(rb.path));
    }
    Ok(Some(paths))
}

/// Stage 1: the job's impeller (the embedded default when it names none), on the stock the
/// job starts from (`[stock]`: the impeller file's blank, or that blank turned to the shroud
/// contour).
pub fn model(job: &Job) -> Result<Impeller, CliError> {
    let impeller = match &job.impeller {
        Some(p) if job.is_embedded(p) => {
            impeller_model::from_toml_str(&job.read_text(p)?, p).map_err(msg)
        }
        Some(p) => impeller_model::load(p).map_err(msg),
        None => impeller_model::fixtures::default_impeller().map_err(msg),
    }?;
    match job.stock.start {
        StockStartKind::Blank => Ok(impeller),
        StockStartKind::Turned => {
            let stock = impeller
                .turned_stock(job.stock.turning_allowance_mm)
                .map_err(|e| CliError::Message(format!("[stock] start = \"turned\": {e}")))?;
            Ok(impeller.with_stock(stock))
        }
    }
}

/// Stage 2: plans the job's operations with `registry` (in parallel; each is independent:
/// it plans against the design, not against the stock another one leaves), then reads its CL
/// files. Reader warnings go to `notes`. Errors name the operation, and for parameter errors
/// the job file, line and key.
pub fn plan(
    job: &Job,
    impeller: &Impeller,
    registry: &Registry,
    notes: &mut Vec<String>,
) -> Result<Vec<JobOperation>, CliError> {
    let surface =
        SafetySurface::around_stock(impeller.stock(), job.safety.clearance_mm).map_err(msg)?;
    let linker = Linker::with_blank(surface, impeller.stock());
    let mesh = if job.operations.is_empty() {
        None
    } else {
        Some(design_mesh(job, impeller)?)
    };
    // The machine's rotary travel, for the operations that search for a tool axis.
    let reach = crate::travel::MachineReach(load_machine(job)?);
    let progress = Progress::new(job.quiet);
    let built: Vec<Box<dyn cam_plan::Operation>> = job
        .operations
        .iter()
        .enumerate()
        .map(|(i, spec)| registry::build(registry, spec).map_err(|e| job.operation_error(i, &e)))
        .collect::<Result<_, _>>()?;
    let shared = Shared {
        job,
        impeller,
        linker: &linker,
        mesh: mesh.as_ref(),
        reach: &reach,
        progress: &progress,
    };
    // Operations that plan from the design alone, in parallel; then, in job order, those that
    // plan from the stock the operations before them leave (simulated here).
    let mut planned: Vec<Option<Vec<JobOperation>>> = job
        .operations
        .par_iter()
        .enumerate()
        .map(|(i, spec)| {
            if built[i].needs_remaining() {
                Ok(None)
            } else {
                shared.plan_one(i, spec, built[i].as_ref(), None).map(Some)
            }
        })
        .collect::<Result<_, CliError>>()?;
    for (i, spec) in job.operations.iter().enumerate() {
        if !built[i].needs_remaining() {
            continue;
        }
        let earlier: Vec<&JobOperation> = planned[..i].iter().flatten().flatten().collect();
        let t = Instant::now();
        let task = progress.task(format!("simulating the stock {} plans from", spec.name));
        let remaining = remaining_after(job, impeller, &earlier)?;
        task.done(format!(
            "simulated the stock {} plans from in {:.1} s",
            spec.name,
            t.elapsed().as_secs_f64()
        ));
        let mut ops = shared.plan_one(i, spec, built[i].as_ref(), Some(&remaining))?;
        // The simulation is part of this operation's planning (its steps, if any, are
        // timed with it and keep 0).
        for op in ops.iter_mut().filter(|op| op.plan_ms > 0.0) {
            op.plan_ms = ms(t);
        }
        planned[i] = Some(ops);
    }
    let mut operations: Vec<JobOperation> = planned.into_iter().flatten().flatten().collect();
    for op in &operations {
        for n in &op.cl.comments {
            notes.push(format!("{}: {n}", op.cl.path.name));
        }
    }
    // An operation that found nothing to cut (a rest operation after a complete job) is not
    // posted; its notes say why.
    operations.retain(|op| {
        let keep = !op.cl.path.moves.is_empty();
        if !keep {
            notes.push(format!("{}: planned no moves, not posted", op.cl.path.name));
        }
        keep
    });

    // CL data given by the job (from any CAM system).
    let rates = Rates::default();
    for path in &job.cl_files {
        let t = Instant::now();
        let text = job.read_text(path)?;
        let cl = read_cl(
            &text,
            &path.display().to_string(),
            &ClReadOptions::default(),
        )
        .map_err(msg)?;
        for w in &cl.warnings {
            eprintln!("warning: {}:{}: {}", path.display(), w.line, w.message);
            notes.push(format!("{}:{}: {}", path.display(), w.line, w.message));
        }
        let read_ms = ms(t);
        for op in cl.operations {
            let tool = op.cutter.clone().map(|c| tool_of_cutter(c, op.tool_number));
            operations.push(JobOperation {
                cl: op,
                kind: "cl_import".into(),
                tool,
                rates,
                plan_ms: read_ms,
                metrics: Metrics::new(),
                plots: Vec::new(),
            });
        }
    }
    Ok(operations)
}

/// What every operation of a job plans with (the design mesh, the linker, the machine's
/// reach), shared by [`plan`]'s parallel and ordered passes.
struct Shared<'a> {
    job: &'a Job,
    impeller: &'a Impeller,
    linker: &'a Linker,
    mesh: Option<&'a Arc<DesignMesh>>,
    reach: &'a crate::travel::MachineReach,
    progress: &'a Progress,
}

impl Shared<'_> {
    /// Plans operation `i` of the job (`spec`, built as `op`) and its steps, each linked into
    /// one CL operation, in machining order; `remaining` is the stock the operations before
    /// it leave, for the operations that ask for it.
    fn plan_one(
        &self,
        i: usize,
        spec: &cam_plan::OperationSpec,
        op: &dyn cam_plan::Operation,
        remaining: Option<&cam_plan::RemainingMaterial>,
    ) -> Result<Vec<JobOperation>, CliError> {
        let (job, impeller, linker, progress) =
            (self.job, self.impeller, self.linker, self.progress);
        let fail = |e: PlanError| job.operation_error(i, &e);
        let tool = job.tool(&spec.tool).ok_or_else(|| {
            fail(PlanError::tool(
                &spec.name,
                &spec.tool,
                "not a tool of the job",
            ))
        })?;
        // Further tools the operation plans steps with (a pilot drill).
        let step_tools: Vec<&Tool> = op
            .step_tools()
            .iter()
            .map(|st| {
                job.tool(&st.tool).ok_or_else(|| {
                    fail(PlanError::param(
                        &spec.name,
                        &st.key,
                        format!("\"{}\" is not a tool of the job", st.tool),
                    ))
                })
            })
            .collect::<Result<_, _>>()?;
        let t = Instant::now();
        let label = format!("planning {} ({})", spec.name, spec.kind);
        let task = progress.task(label.clone());
        let listener = task.listener(label);
        let mesh = self
            .mesh
            .cloned()
            .ok_or_else(|| fail(PlanError::geometry(&spec.name, "design mesh", "not built")))?;
        let clearance =
            DesignClearance::with_mesh(impeller, mesh.clone(), tool, clearance_options(job))
                .map_err(|e| fail(rename(e, &spec.name)))?;
        let links = LinkStats::default();
        let ctx = PlanContext {
            impeller,
            stock: impeller.stock(),
            tool,
            tolerances: &job.tolerances,
            process: &spec.process,
            clearance: &clearance,
            linker,
            links: &links,
            reach: Some(self.reach),
            remaining,
            progress: Some(&listener),
        };
        let (planned, steps) = op.plan_with_steps(&ctx, &step_tools).map_err(fail)?;
        let mut main =
            job_operation(&ctx, spec.name.as_str(), &spec.kind, planned).map_err(fail)?;
        let plan_ms = ms(t);
        main.plan_ms = plan_ms;
        task.done(format!(
            "planned {} ({}): {} moves in {:.1} s",
            spec.name,
            spec.kind,
            main.cl.path.moves.len(),
            plan_ms / 1e3
        ));
        // Each step is its own operation with its own tool: linked, checked and fed
        // with that tool, machined before or after the operation.
        let (mut before, mut after) = (Vec::new(), Vec::new());
        for step in steps {
            let step_tool = job.tool(&step.tool).ok_or_else(|| {
                fail(PlanError::tool(
                    &step.name,
                    &step.tool,
                    "a step's tool must be one of the job's tools",
                ))
            })?;
            let clearance = DesignClearance::with_mesh(
                impeller,
                mesh.clone(),
                step_tool,
                clearance_options(job),
            )
            .map_err(|e| fail(rename(e, &step.name)))?;
            let links = LinkStats::default();
            let step_ctx = PlanContext {
                tool: step_tool,
                process: &step.process,
                clearance: &clearance,
                links: &links,
                ..ctx
            };
            // Planned with the operation: its planning time is the operation's.
            let op =
                job_operation(&step_ctx, &step.name, &step.kind, step.planned).map_err(fail)?;
            if step.before {
                before.push(op);
            } else {
                after.push(op);
            }
        }
        before.push(main);
        before.extend(after);
        for op in &mut before {
            op.cl.coolant = job.coolant.get(i).copied().unwrap_or_default();
        }
        Ok(before)
    }
}

/// The verifier's design (blade projectors, side mesh) and the job's blank sampled at the
/// verification resolution: independent, built side by side.
fn design_and_blank(
    job: &Job,
    impeller: &Impeller,
) -> Result<(ImpellerDesign, TriDexel), CliError> {
    let (design, stock) = rayon::join(
        || ImpellerDesign::new(impeller, ImpellerSampling::default()),
        || {
            machining_sim::blank_of(impeller)
                .and_then(|b| TriDexel::from_shape(&b, job.verification.resolution_mm))
        },
    );
    Ok((design.map_err(msg)?, stock.map_err(msg)?))
}

/// The stock the planned operations `earlier` leave on the job's blank, simulated at the
/// job's verification resolution on their CL paths (machining-sim's tri-dexel stock) and
/// measured above the design at the verifier's samples: what a rest operation plans from.
/// Cost: one stock simulation of `earlier` without the overcut reading and the collision
/// checks ([`machining_sim::simulate_residual`]: the same stock and residual as
/// [`verify`]'s simulation of the same paths, in about half its time).
fn remaining_after(
    job: &Job,
    impeller: &Impeller,
    earlier: &[&JobOperation],
) -> Result<cam_plan::RemainingMaterial, CliError> {
    let paths: Vec<(Cutter, ToolPath)> = earlier
        .iter()
        .filter_map(|op| op.cl.cutter.clone().map(|c| (c, op.cl.path.clone())))
        .collect();
    let (design, mut stock) = design_and_blank(job, impeller)?;
    let maps =
        machining_sim::simulate_residual(&mut stock, &design, &paths, &SimOptions::default())
            .map_err(msg)?;
    Ok(cam_plan::RemainingMaterial {
        after: earlier.iter().map(|op| op.cl.path.name.clone()).collect(),
        resolution_mm: job.verification.resolution_mm,
        grids: maps
            .into_iter()
            .map(|m| cam_plan::RestGrid {
                surface: m.name,
                nu: m.nu,
                nv: m.nv,
                points: m.points,
                residual_mm: m.residual_mm,
            })
            .collect(),
    })
}

/// The CL operation of `planned` (an operation or one of its steps) in `ctx`: its paths
/// linked over the safety surface with the checked retracts and approaches of `ctx`'s tool,
/// the link counts as metrics, the process row's feeds, tool and spindle (`plan_ms` 0, for
/// the caller to set).
fn job_operation(
    ctx: &PlanContext<'_>,
    name: &str,
    kind: &str,
    mut planned: cam_plan::PlannedOperation,
) -> Result<JobOperation, PlanError> {
    let tool = ctx.tool;
    let mut path = ctx
        .linker
        .join_checked(
            name,
            tool.name(),
            &planned.paths,
            LINK_APPROACH_MM,
            &ctx.link_check(),
        )
        .map_err(|e| rename(e, name))?;
    let (uncertified, turned) = (ctx.links.uncertified(), ctx.links.turned());
    planned
        .metrics
        .number("uncertified_links", uncertified as f64)
        .number("links_off_axis", turned as f64);
    if uncertified > 0 {
        planned.notes.push(format!(
            "{uncertified} retract(s)/approach(es) could not be certified clear of the \
             design in any direction tried; they follow the tool axis (see the \
             verification)"
        ));
    }
    let rates = ctx.rates();
    set_feeds(&mut path, &rates);
    let mut cl = ClOperation::new(path);
    cl.tool_number = Some(tool.number);
    cl.cutter = Some(tool.cutter.clone());
    cl.tool_length_mm = Some(tool.tool_length_mm);
    cl.spindle = Some(Spindle {
        rpm: ctx.process.spindle_rpm,
        clockwise: true,
    });
    cl.comments = planned.notes.clone();
    Ok(JobOperation {
        cl,
        kind: kind.to_string(),
        tool: Some(tool.clone()),
        rates,
        plan_ms: 0.0,
        metrics: planned.metrics,
        plots: planned.plots,
    })
}

/// A planning error of the framework (clearance, linking) named after `operation`.
fn rename(e: PlanError, operation: &str) -> PlanError {
    match e {
        PlanError::Param { key, reason, .. } => PlanError::Param {
            operation: operation.into(),
            key,
            reason,
        },
        PlanError::Geometry { place, reason, .. } => PlanError::Geometry {
            operation: operation.into(),
            place,
            reason,
        },
        PlanError::Tool { tool, reason, .. } => PlanError::Tool {
            operation: operation.into(),
            tool,
            reason,
        },
        other => other,
    }
}

/// The design mesh of the clearance queries at the job's `chord_tol` (built once, shared by
/// every operation's query and every gouge check).
pub fn design_mesh(job: &Job, impeller: &Impeller) -> Result<Arc<DesignMesh>, CliError> {
    DesignMesh::new(impeller, job.tolerances.chord_tol)
        .map(Arc::new)
        .map_err(|e| CliError::Message(format!("design mesh: {e}")))
}

/// The clearance options of the job: the design mesh and tool frusta at the job's
/// `chord_tol`.
pub fn clearance_options(job: &Job) -> ClearanceOptions {
    ClearanceOptions {
        sample_tol_mm: job.tolerances.chord_tol,
        ..ClearanceOptions::default()
    }
}

/// A tool for a cutter known only from a CL file: its number (0 when absent), one tooth,
/// gauge length = stick-out (the CL file gives neither).
fn tool_of_cutter(cutter: Cutter, number: Option<u32>) -> Tool {
    Tool {
        number: number.unwrap_or(0),
        tool_length_mm: cutter.overall_length,
        cutter,
        teeth: 1,
        plunge_edge_length_mm: None,
    }
}

/// Programs the process row's rates on every non-rapid move that has no feed of its own:
/// cutting moves, links at feed and retracts at the cutting feed, plunges at the plunge feed.
fn set_feeds(path: &mut ToolPath, rates: &Rates) {
    for m in &mut path.moves {
        if m.feed_mm_per_min.is_none() {
            m.feed_mm_per_min = match m.kind {
                MoveKind::Rapid => None,
                MoveKind::Plunge => Some(rates.plunge_mm_per_min),
                MoveKind::Feed | MoveKind::Link | MoveKind::Retract => Some(rates.feed_mm_per_min),
            };
        }
    }
}

/// The post options of the job's program (shared by the post and by
/// [`link_for_machine`], whose posture choice must be the post's).
fn post_options(job: &Job) -> PostOptions {
    PostOptions {
        linearisation_tol: Some(job.tolerances.linearisation_tol),
        // Rapids too: near the part (between plunges the tool travels a few mm above the
        // blank) a joint-interpolated G0 with a rotary change leaves its straight line by
        // more than the clearance; rapids that change branch are routed over the safety
        // surface by `link_for_machine` (the post cannot linearise them).
        linearise_rapids: true,
        // Continuous rotary axes are never unwound: an unwinding is a full turn of the head
        // or table under joint interpolation, which the post cannot linearise; between two
        // plunges of impeller-plunge-400 on the head-head machine one took the cutter 30 mm
        // deep through the blank. The angle then accumulates the operation's real rotation.
        unwind_on_rapid: false,
        reverse_motion: Some(ReverseMotionOptions::default()),
        ..PostOptions::default()
    }
}

/// Machine-aware linking of the planned operations (imported CL data is posted as given):
/// every rapid on which the job's machine would change the solution branch or swing a
/// rotary axis, inside the safety surface, becomes a retract to the safety surface, a travel
/// over it and an approach ([`machine_links::reroute_swinging_rapids`]). Operations are
/// chained as the program runs them (each starts from the posture the previous one ends
/// in). Each planned operation reports `machine_links` (rapids rerouted) and
/// `swinging_rapids_left`; a note names operations with swinging rapids left.
///
/// Returns the operations whose posted blocks leave the machine's travel (with the count,
/// the move range and the range each axis would need, [`crate::travel`]); the run then
/// posts nothing, reports them and fails (exit 3).
pub fn link_for_machine(
    job: &Job,
    impeller: &Impeller,
    operations: &mut [JobOperation],
    notes: &mut Vec<String>,
) -> Result<Vec<crate::travel::TravelViolations>, CliError> {
    if operations.is_empty() {
        return Ok(Vec::new());
    }
    let machine = load_machine(job)?;
    // On a head machine the gauge length moves the tip: planned operations carry their
    // tool's `tool_length_mm`; CL data must give it (`LOADTL/n,LENGTH,l`), never a silent 0.
    if machine.tool_length_matters() {
        if let Some(op) = operations.iter().find(|o| o.cl.tool_length_mm.is_none()) {
            return Err(CliError::Message(format!(
                "operation \"{}\" (T{}) has no tool length: machine {} ({}) turns the tool \
                 about its head, so the gauge length moves the tip; give it in the CL file \
                 with LOADTL/n,LENGTH,l",
                op.cl.path.name,
                op.cl.tool_number.unwrap_or_default(),
                machine.name(),
                machine.kinematics().kind_name()
            )));
        }
    }
    let surface =
        SafetySurface::around_stock(impeller.stock(), job.safety.clearance_mm).map_err(msg)?;
    let linker = Linker::with_blank(surface, impeller.stock());
    let retract_mm = AssembleOptions::default().retract_mm;
    let mut initial: Option<postproc_kinematics::Joints> = None;
    let mut travel = Vec::new();
    for op in operations.iter_mut() {
        let mut options = post_options(job);
        options.initial = initial;
        if let Some(tl) = op.cl.tool_length_mm {
            options.tool_length = tl;
        }
        if op.kind == "cl_import" {
            // Posted as given; only the chaining posture is needed.
            let links = machine_links::reroute_swinging_rapids(
                &mut op.cl.path.clone(),
                &machine,
                &options,
                retract_mm,
                &linker,
                LINK_APPROACH_MM,
            )
            .map_err(msg)?;
            initial = links.last.or(initial);
            travel.extend(links.travel);
            continue;
        }
        let links = machine_links::reroute_swinging_rapids(
            &mut op.cl.path,
            &machine,
            &options,
            retract_mm,
            &linker,
            LINK_APPROACH_MM,
        )
        .map_err(msg)?;
        set_feeds(&mut op.cl.path, &op.rates);
        initial = links.last.or(initial);
        travel.extend(links.travel.clone());
        op.metrics
            .count("machine_links", links.rerouted)
            .count("swinging_rapids_left", links.remaining)
            .count("swinging_rapids_on_surface", links.on_surface);
        if links.remaining > 0 {
            notes.push(format!(
                "{}: {} rapid(s) inside the safety surface change the solution branch or swing \
                 a rotary axis on {} and could not be routed over the safety surface (see the \
                 verification)",
                op.cl.path.name,
                links.remaining,
                machine.name()
            ));
        }
        if links.on_surface > 0 {
            notes.push(format!(
                "{}: {} rapid(s) on the safety surface change the solution branch or swing a \
                 rotary axis on {}; each is written as one block (a detour would start and end \
                 where it does): a tilting axis can swing the part into the tool there. The \
                 verification reads a LinuxCNC program back and judges the joint motion; for \
                 the other dialects it simulates the posted cutter locations (the tip on its \
                 line, as tool-centre-point control moves it)",
                op.cl.path.name,
                links.on_surface,
                machine.name()
            ));
        }
    }
    Ok(travel)
}

/// Stage 3: writes `toolpath.cls` and, when there is something to machine, the program;
/// fills `report.post` (and its notes and displacement plots). Returns the assembled program.
/// When operations leave the machine's travel (`travel`, from [`link_for_machine`]) the
/// program is not posted: `report.post` names it, unwritten, with the violations.
pub fn post(
    job: &Job,
    impeller: &Impeller,
    operations: &[JobOperation],
    travel: &[crate::travel::TravelViolations],
    out: &Path,
    report: &mut Report,
) -> Result<Option<AssembledProgram>, CliError> {
    let cl_ops: Vec<ClOperation> = operations.iter().map(|o| o.cl.clone()).collect();
    let cl_program = ClProgram {
        operations: cl_ops.clone(),
        ..ClProgram::default()
    };
    write_cl_file(
        &out.join("toolpath.cls"),
        &cl_program,
        &ClWriteOptions::default(),
    )
    .map_err(msg)?;

    let machine = load_machine(job)?;
    let frame = load_frame(job)?;
    let dialect = frame.dialect(&job.dialect).map_err(msg)?;
    let mode = match dialect.name() {
        "linuxcnc" | "fanuc" => OutputMode::Joint,
        _ => OutputMode::TcpAngles,
    };
    let options = AssembleOptions {
        mode,
        post: post_options(job),
        ..AssembleOptions::default()
    };
    let program_path = out.join(format!("program.{}", dialect.extension()));
    let mut post = PostReport {
        machine: machine.name().to_string(),
        dialect: dialect.name().to_string(),
        program: String::new(),
        ..PostReport::default()
    };
    if operations.is_empty() {
        report.post = post;
        return Ok(None);
    }
    if !travel.is_empty() {
        // Withheld before posting: the machine cannot run these tool paths.
        post.program = program_path.display().to_string();
        post.travel = travel.to_vec();
        report.post = post;
        return Ok(None);
    }
    // One gouge check per operation with a known tool: the same design clearance query the
    // planners use.
    let mesh = if operations.iter().any(|o| o.tool.is_some()) {
        Some(design_mesh(job, impeller)?)
    } else {
        None
    };
    let checkers: Vec<Option<GougeCheck<'_>>> = operations
        .iter()
        .map(|op| match (&op.tool, &mesh) {
            (Some(t), Some(m)) => GougeCheck::with_mesh(impeller, m.clone(), t, job).map(Some),
            _ => Ok(None),
        })
        .collect::<Result<_, _>>()?;
    // Per operation, how reverse-motion smoothing may change postures without moving the
    // cut by more than the bound (see `reverse_motion_options`); imported CL data only when
    // the job opts in.
    let smoothing: Vec<Option<ReverseMotionOptions>> = operations
        .iter()
        .map(|op| reverse_motion_options(job, op))
        .collect();
    let access: Vec<OperationAccess<'_>> = checkers
        .iter()
        .zip(&smoothing)
        .map(|(c, o)| match (c, o) {
            (Some(c), Some(o)) => OperationAccess::CheckedWith(c, o),
            _ => OperationAccess::CountOnly,
        })
        .collect();
    let unchecked: Vec<&str> = operations
        .iter()
        .filter(|op| op.tool.is_none())
        .map(|op| op.cl.path.name.as_str())
        .collect();
    if !unchecked.is_empty() {
        report.notes.push(format!(
            "reverse motions were counted but not removed in {}: without a CUTTER record \
             a changed tool posture cannot be checked for gouging",
            unchecked.join(", ")
        ));
    }
    let not_opted: Vec<&str> = operations
        .iter()
        .filter(|op| op.kind == "cl_import" && op.tool.is_some() && !job.post.smooth_imported_cl)
        .map(|op| op.cl.path.name.as_str())
        .collect();
    if !not_opted.is_empty() {
        report.notes.push(format!(
            "reverse motions were counted but not removed in the imported CL data {} \
             (opt in with [post] smooth_imported_cl = true)",
            not_opted.join(", ")
        ));
    }
    let assembled = assemble_program_with_access(
        &job.name,
        &cl_ops,
        &machine,
        dialect.as_ref(),
        &options,
        &access,
    )
    .map_err(msg)?;
    let mut program_options = ProgramOptions {
        line_numbers: Some(LineNumbers::new(10, 10)),
        safe_z_machine: machine.safe_z().unwrap_or(0.0),
        ..ProgramOptions::default()
    };
    frame.apply(&mut program_options);
    write_program_file(
        &program_path,
        dialect.as_ref(),
        &assembled.program,
        &program_options,
    )
    .map_err(msg)?;
    for (name, m) in &assembled.metrics {
        if m.max_linearisation_error_mm > job.tolerances.linearisation_tol {
            report.notes.push(format!(
                "post: {name}: the largest linearisation error {:.4} mm exceeds linearisation_tol {} mm (subdivision exhausted, typically where the tool axis passes near the rotary axis' singular direction); the verification of the written program measures what the machine's motion does to the part",
                m.max_linearisation_error_mm, job.tolerances.linearisation_tol
            ));
        }
        if m.max_rapid_linearisation_error_mm > job.tolerances.linearisation_tol {
            report.notes.push(format!(
                "post: {name}: rapid moves leave their intended motion by up to {:.4} mm (joint interpolation near the rotary axis' singular direction); they cut nothing, and the verification of the written program checks what they sweep",
                m.max_rapid_linearisation_error_mm
            ));
        }
        post.max_rapid_linearisation_error_mm = post
            .max_rapid_linearisation_error_mm
            .max(m.max_rapid_linearisation_error_mm);
        post.reverse_motions_before += m.reverse_motions_before;
        post.reverse_motions_after += m.reverse_motions_after;
        post.reverse_motions_cutting_before += m.reverse_motions_cutting_before;
        post.reverse_motions_cutting_after += m.reverse_motions_cutting_after;
        post.reverse_motions_cutting_near_pole += m.reversals.rotate.cutting_near_pole;
        post.reverse_motions_links_before += m.reverse_motions_links_before;
        post.reverse_motions_links_after += m.reverse_motions_links_after;
        post.max_linearisation_error_mm = post
            .max_linearisation_error_mm
            .max(m.max_linearisation_error_mm);
        if m.reconfigurations > 0 {
            report.notes.push(format!(
                "post: {name}: {} cutting move(s) change the rotary solution branch (no posture \
                 choice keeps this machine on one branch through the cut within its limits): \
                 the tool swings away from the planned orientations there",
                m.reconfigurations
            ));
        }
        post.limit_violations += m.limit_violations;
        post.reconfigurations += m.reconfigurations;
        post.blocks += m.blocks;
    }
    for p in &assembled.operations {
        let mut r = PostOperationReport::of(p);
        let planned = report.operations.iter().find(|o| o.name == p.name);
        r.account_with(planned.map(|o| &o.metrics));
        post.reverse_motions_cutting_unaccounted += r.reverse_motions_cutting_unaccounted;
        post.operations.push(r);
        report.add_displacement_plots(p);
    }
    post.program = program_path.display().to_string();
    post.written = true;
    report.post = post;
    match gcode_emit::program_time(
        &machine,
        &assembled,
        &cl_ops,
        &options,
        program_options.safe_z_machine,
    ) {
        Ok(time) => crate::cycle::add_cycle_time(report, time),
        Err(e) => report.notes.push(format!(
            "no cycle time: the machine file {} cannot time the program: {e}",
            machine.name()
        )),
    }
    Ok(Some(assembled))
}

/// The reverse-motion smoothing an operation allows, or `None` (only counted): turning
/// about the ball centre for ball ends in point contact, about the middle of the flutes with
/// the contact line `(0, flute length)` for flank operations, about the tip with the contact
/// on the bottom rim for cutters in bottom contact
/// ([`ReverseMotionOptions::keeping_contact`]); the contact may move at most the job's
/// `machining_tol` (and the post's default bound); imported CL data only with
/// `[post] smooth_imported_cl`.
fn reverse_motion_options(job: &Job, op: &JobOperation) -> Option<ReverseMotionOptions> {
    let tool = op.tool.as_ref()?;
    if op.kind == "cl_import" && !job.post.smooth_imported_cl {
        return None;
    }
    let cutter = &tool.cutter;
    let flank = matches!(op.kind.as_str(), "flank_finishing" | "flank_semi_finishing");
    let mut o =
        ReverseMotionOptions::keeping_contact(cutter, flank.then_some((0.0, cutter.flute_length)));
    o.max_contact_shift_mm = o.max_contact_shift_mm.min(job.tolerances.machining_tol);
    Some(o)
}

/// Stage 4: simulates the operations as posted (smoothed tool axes) on the blank and fills
/// `report.verification` (when enabled and some operation has a known cutter).
pub fn verify(
    job: &Job,
    impeller: &Impeller,
    operations: &[JobOperation],
    assembled: Option<&AssembledProgram>,
    out: &Path,
    report: &mut Report,
) -> Result<(), CliError> {
    // What the machine really does: the written program read back; otherwise the posted
    // cutter locations (or the CL path itself when nothing was posted).
    let read_back = match (job.verification.enabled, assembled, report.post.written) {
        (true, Some(_), true) => {
            read_back_program(job, Path::new(&report.post.program), operations)?
        }
        _ => None,
    };
    let source = if read_back.is_some() {
        "program"
    } else {
        "cutter_locations"
    };
    let verifiable: Vec<(Cutter, ToolPath)> = operations
        .iter()
        .enumerate()
        .filter_map(|(i, op)| {
            let path = match &read_back {
                Some(paths) => paths.get(i).cloned().flatten()?,
                None => assembled
                    .and_then(|a| a.operations.iter().find(|p| p.index == i))
                    .map(|p| posted_path(&op.cl.path, &p.blocks))
                    .unwrap_or_else(|| op.cl.path.clone()),
            };
            op.cl.cutter.clone().map(|c| (c, path))
        })
        .collect();
    if verifiable.len() < operations.len() {
        report.notes.push(format!(
            "{} operation(s) without a CUTTER record were not verified",
            operations.len() - verifiable.len()
        ));
    }
    if !job.verification.enabled || verifiable.is_empty() {
        return Ok(());
    }
    let (design, mut stock) = design_and_blank(job, impeller)?;
    let progress = Progress::new(job.quiet);
    let total: usize = verifiable.iter().map(|(_, p)| p.moves.len()).sum();
    let bar = progress.bar(total as u64, "verifying");
    let sink_bar = bar.clone();
    let options = SimOptions {
        progress: !job.quiet && bar.is_hidden(),
        on_progress: (!bar.is_hidden()).then(|| {
            ProgressSink(std::sync::Arc::new(move |p: SimProgress<'_>| match p {
                SimProgress::Cutting {
                    operation,
                    done_moves,
                    ..
                } => {
                    sink_bar.set_message(format!("verifying {operation}"));
                    sink_bar.set_position(done_moves as u64);
                }
                SimProgress::Measuring => {
                    sink_bar.set_message("measuring overcut and residual".to_string());
                }
            }))
        }),
        ..SimOptions::default()
    };
    let rep = machining_sim::simulate(&mut stock, &design, &verifiable, &options).map_err(msg);
    bar.finish_and_clear();
    let rep = rep?;
    let crosscheck = overcut_crosscheck(&rep, &design, &verifiable, job.verification.crosscheck)?;
    let maps = serde_json::to_string(&rep.maps).map_err(msg)?;
    gcode_emit::write_atomic(&out.join("verification_maps.json"), maps.as_bytes()).map_err(msg)?;
    let limit = job.tolerances.machining_tol
        + machining_sim::overcut_error_bound(
            job.verification.resolution_mm,
            rep.stats.sweep_tol_mm,
            verifiable.iter().map(|(c, _)| c),
        );
    let mut defects = Vec::new();
    if rep.metrics.max_overcut_mm > limit {
        let at = rep
            .max_overcut
            .as_ref()
            .map(|e| {
                format!(
                    " on {} at ({:.3}, {:.3}, {:.3})",
                    e.surface, e.point[0], e.point[1], e.point[2]
                )
            })
            .unwrap_or_default();
        defects.push(format!(
            "overcut {:.4} mm{at} exceeds {:.4} mm (machining_tol {} + simulation error bound)",
            rep.metrics.max_overcut_mm, limit, job.tolerances.machining_tol
        ));
    }
    if rep.metrics.collisions > 0 {
        let first = rep
            .collisions
            .first()
            .map(|c| format!("; first: {}", crate::verdict::collision_text(c)))
            .unwrap_or_default();
        defects.push(format!("{} collision(s){first}", rep.metrics.collisions));
    }
    report.verification = Some(VerificationReport {
        max_overcut_mm: rep.metrics.max_overcut_mm,
        max_residual_mm: rep.metrics.max_residual_mm,
        collisions: rep.metrics.collisions,
        resolution_mm: job.verification.resolution_mm,
        overcut_limit_mm: limit,
        defects,
        surface_groups: crate::surface_groups::surface_groups(&rep.maps),
        source: source.into(),
        details: serde_json::json!({
            "max_overcut": rep.max_overcut,
            "max_residual": rep.max_residual,
            "collision_list": rep.collisions,
            "stats": rep.stats,
            "overcut_crosscheck": crosscheck,
        }),
    });
    report.notes.push(removal_note(
        &verifiable,
        &rep.stats.removed_volume_by_operation_mm3,
    ));
    report.add_map_plots(&rep.maps);
    if job.export_stock {
        // The lattice of `impeller-cam verify`'s stock.stl.
        let stride = (0.3 / job.verification.resolution_mm).round().max(1.0) as usize;
        let mesh = machining_sim::extract_surface(&stock, stride);
        machining_sim::write_stl(&mesh, &out.join("stock.stl"), "impeller-cam run stock")
            .map_err(msg)?;
    }
    crate::view3d::add_verification(&mut report.view, &stock, &rep, job, limit);
    Ok(())
}

/// The note on the material each verified operation removed (the simulation's
/// `removed_volume_by_operation_mm3`) and its mean cut cross-section: that volume over the
/// length of the operation's moves in the material (feed, link and plunge moves, tip path).
/// A finishing operation whose cross-section is far above its allowance times its cutter's
/// width is cutting what an earlier operation left (a finishing ball slotting an unroughed
/// channel touches no shank or holder: no collision, but a broken tool).
fn removal_note(verifiable: &[(Cutter, ToolPath)], by_op: &[f64]) -> String {
    let parts: Vec<String> = verifiable
        .iter()
        .zip(by_op)
        .map(|((_, path), v)| {
            let length =
                path.length_of_mm(|kind| kind.at_cutting_feed() || kind == MoveKind::Plunge);
            let section = if length > 0.0 {
                format!("{:.3} mm² on average over {:.0} mm", v / length, length)
            } else {
                "no cutting moves".into()
            };
            format!("{} {:.0} mm³ ({section})", path.name, v)
        })
        .collect();
    format!(
        "verification: material removed per operation, with the mean cut cross-section (volume \
         over the length of moves in the material): {}",
        parts.join(", ")
    )
}

/// The verifier's overcut re-measured on the exact swept envelopes of the verified paths:
/// the location of the largest reading (`deepest`, [`machining_sim::crosscheck_location`]:
/// projected onto the design surface, its depth inside the envelopes) and the deepest
/// `count` map samples ([`machining_sim::crosscheck_overcut`]); `max_envelope_overcut_mm` is
/// the largest of them, or `null` when `count` is 0 or nothing reads an overcut. The dexel
/// reading is a detector with the simulation's error bound (a thin edge between two cells
/// reads up to that bound); the envelope depth is the depth inside the swept cutters, exact
/// for ball ends, without that error. A map sample carries the depth of the nearest cut end
/// point, which may lie up to a sample spacing away, so the samples alone can miss the cut.
fn overcut_crosscheck(
    rep: &machining_sim::Report,
    design: &dyn machining_sim::DesignModel,
    verifiable: &[(Cutter, ToolPath)],
    count: usize,
) -> Result<serde_json::Value, CliError> {
    if count == 0 || rep.metrics.max_overcut_mm <= 0.0 {
        return Ok(serde_json::Value::Null);
    }
    let deepest = match &rep.max_overcut {
        Some(e) => {
            Some(machining_sim::crosscheck_location(design, verifiable, e.point).map_err(msg)?)
        }
        None => None,
    };
    let points = machining_sim::crosscheck_overcut(rep, verifiable, count).map_err(msg)?;
    let max = points
        .iter()
        .map(|p| p.envelope_overcut_mm)
        .chain(deepest.iter().map(|d| d.envelope_overcut_mm))
        .fold(0.0f64, f64::max);
    Ok(serde_json::json!({
        "samples": points.len(),
        "max_dexel_overcut_mm": rep.metrics.max_overcut_mm,
        "max_envelope_overcut_mm": max,
        "deepest": deepest,
        "points": points,
    }))
}

/// The tool path a posted operation actually machines: the source moves (kinds and feeds
/// kept) with the cutter locations of their posted blocks, i.e. the tool axes after
/// reverse-motion smoothing. `blocks` start with the approach (source index 0), so move `j`
/// is the block with source index `j + 1`; linearisation blocks are left out (they lie on
/// the joint interpolation between two source blocks). O(n).
pub fn posted_path(source: &ToolPath, blocks: &[postproc_kinematics::PostedBlock]) -> ToolPath {
    let mut path = source.clone();
    for b in blocks.iter().filter(|b| !b.inserted) {
        if let Some(m) = b
            .source_index
            .checked_sub(1)
            .and_then(|j| path.moves.get_mut(j))
        {
            m.cl = b.cl;
        }
    }
    path
}

/// The gouge check of reverse-motion smoothing: a changed posture is accepted when the
/// design clearance query of the planners ([`cam_plan::DesignClearance`]: cutter, shank and
/// holder against hub and blades) finds no penetration deeper than `machining_tol / 2`.
///
/// Half the machining tolerance, because the other half is the sampling and chord allowance
/// of the query itself (its stated error), so an accepted posture gouges the design by at most
/// `machining_tol`.
#[derive(Debug)]
pub struct GougeCheck<'a> {
    clearance: DesignClearance<'a>,
    min_clearance_mm: f64,
}

impl<'a> GougeCheck<'a> {
    /// The check of `tool` against `impeller` with the tolerances of `job`.
    pub fn new(impeller: &'a Impeller, tool: &Tool, job: &Job) -> Result<Self, CliError> {
        let clearance = DesignClearance::new(impeller, tool, clearance_options(job))
            .map_err(|e| CliError::Message(format!("tool \"{}\": {e}", tool.name())))?;
        Ok(Self::with(clearance, job.tolerances.machining_tol))
    }

    /// [`GougeCheck::new`] over a shared design mesh.
    pub fn with_mesh(
        impeller: &'a Impeller,
        mesh: Arc<DesignMesh>,
        tool: &Tool,
        job: &Job,
    ) -> Result<Self, CliError> {
        let clearance = DesignClearance::with_mesh(impeller, mesh, tool, clearance_options(job))
            .map_err(|e| CliError::Message(format!("tool \"{}\": {e}", tool.name())))?;
        Ok(Self::with(clearance, job.tolerances.machining_tol))
    }

    /// The check over `clearance` accepting penetration up to `machining_tol / 2`.
    pub fn with(clearance: DesignClearance<'a>, machining_tol: f64) -> Self {
        Self {
            clearance,
            min_clearance_mm: -0.5 * machining_tol.max(0.0),
        }
    }
}

impl AccessibilityChecker for GougeCheck<'_> {
    fn is_accessible(&self, cl: &CutterLocation) -> bool {
        self.clearance.is_clear(cl, self.min_clearance_mm)
    }
}

pub mod machine_links;

#[cfg(test)]
mod tests;
