//! The job pipeline: impeller model → operations → CL file → post-processing → program →
//! independent verification → reports.
//!
//! Each stage is timed (`timings_ms` in the report) and announced on stderr. Stages that have
//! nothing to do say so in the report's `notes` instead of inventing output.

use crate::error::CliError;
use crate::job::Job;
use crate::report::{OperationReport, PostReport, Report, VerificationReport};
use cam_core::Rates;
use gcode_emit::{
    assemble_program, dialect_by_name, read_cl_file, write_cl_file, write_program_file,
    AssembleOptions, ClOperation, ClProgram, ClReadOptions, ClWriteOptions, LineNumbers,
    OutputMode, ProgramOptions,
};
use impeller_model::Impeller;
use machining_sim::{ImpellerDesign, ImpellerSampling, SimOptions, TriDexel};
use postproc_kinematics::{Machine, PostOptions};
use std::path::Path;
use std::time::Instant;

/// The machine used when a job names none: LinuxCNC `xyzac-trt` table-table trunnion.
const DEFAULT_MACHINE: &str = include_str!("../../../fixtures/machines/xyzac-trt.toml");

fn msg(e: impl std::fmt::Display) -> CliError {
    CliError::Message(e.to_string())
}

fn stage(name: &str) -> Instant {
    eprintln!("[impeller-cam] {name} …");
    Instant::now()
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// Runs `job`, writing every output file into `out`.
pub fn run_job(job: &Job, out: &Path) -> Result<Report, CliError> {
    let total = Instant::now();
    std::fs::create_dir_all(out).map_err(|source| CliError::Io {
        path: out.display().to_string(),
        source,
    })?;
    let mut report = Report::new(&job.name);

    // 1. The impeller.
    let t = stage("building the impeller model");
    let impeller = match &job.impeller {
        Some(p) => impeller_model::load(p),
        None => impeller_model::fixtures::default_impeller(),
    }
    .map_err(msg)?;
    report.impeller = serde_json::to_value(impeller.summary()).map_err(msg)?;
    report.set_geometry_plots(&impeller);
    report.timings_ms.insert("model_ms".into(), ms(t));

    // 2. Operations: CL data given by the job (from any CAM system).
    let t = stage("planning operations");
    let mut operations: Vec<ClOperation> = Vec::new();
    for path in &job.cl_files {
        let cl = read_cl_file(path, &ClReadOptions::default()).map_err(msg)?;
        for w in &cl.warnings {
            eprintln!("warning: {}:{}: {}", path.display(), w.line, w.message);
            report
                .notes
                .push(format!("{}:{}: {}", path.display(), w.line, w.message));
        }
        operations.extend(cl.operations);
    }
    if operations.is_empty() {
        report.notes.push(
            "no operation to machine: the job names no CL file, and the planning crates \
             (plunge-opt, channel-paths, flank-opt) are not part of this release yet"
                .into(),
        );
    }
    let rates = Rates::default();
    for op in &operations {
        report.operations.push(OperationReport {
            name: op.path.name.clone(),
            kind: "cl_import".into(),
            tool: op.path.tool.clone(),
            moves: op.path.moves.len(),
            path_length_mm: op.path.path_length_mm(),
            cutting_time_s: op.path.cutting_time_s(&rates),
            plan_ms: 0.0,
        });
    }
    report.timings_ms.insert("plan_ms".into(), ms(t));

    // 3. CL file of every operation.
    let cl_program = ClProgram {
        operations: operations.clone(),
        ..ClProgram::default()
    };
    write_cl_file(
        &out.join("toolpath.cls"),
        &cl_program,
        &ClWriteOptions::default(),
    )
    .map_err(msg)?;

    // 4. Post-processing and the program.
    let t = stage("post-processing");
    let machine = match &job.machine {
        Some(p) => Machine::from_file(p),
        None => Machine::from_toml_str(DEFAULT_MACHINE, "embedded xyzac-trt.toml"),
    }
    .map_err(msg)?;
    let dialect = dialect_by_name(&job.dialect).map_err(msg)?;
    let mode = match dialect.name() {
        "linuxcnc" | "fanuc" => OutputMode::Joint,
        _ => OutputMode::TcpAngles,
    };
    let options = AssembleOptions {
        mode,
        post: PostOptions {
            linearisation_tol: Some(job.tolerances.linearisation_tol),
            ..PostOptions::default()
        },
        ..AssembleOptions::default()
    };
    let program_path = out.join(format!("program.{}", dialect.extension()));
    let mut post = PostReport {
        machine: machine.name().to_string(),
        dialect: dialect.name().to_string(),
        program: program_path.display().to_string(),
        ..PostReport::default()
    };
    if !operations.is_empty() {
        let assembled =
            assemble_program(&job.name, &operations, &machine, dialect.as_ref(), &options)
                .map_err(msg)?;
        let program_options = ProgramOptions {
            line_numbers: Some(LineNumbers {
                start: 10,
                step: 10,
            }),
            safe_z_machine: machine.safe_z().unwrap_or(0.0),
            ..ProgramOptions::default()
        };
        write_program_file(
            &program_path,
            dialect.as_ref(),
            &assembled.program,
            &program_options,
        )
        .map_err(msg)?;
        for (_, m) in &assembled.metrics {
            post.reverse_motions_before += m.reverse_motions_before;
            post.reverse_motions_after += m.reverse_motions_after;
            post.max_linearisation_error_mm = post
                .max_linearisation_error_mm
                .max(m.max_linearisation_error_mm);
            post.limit_violations += m.limit_violations;
            post.blocks += m.blocks;
        }
        post.written = true;
    } else {
        post.program = String::new();
    }
    report.post = post;
    report.timings_ms.insert("post_ms".into(), ms(t));

    // 5. Independent verification.
    let t = stage("verifying by stock simulation");
    let verifiable: Vec<(cam_core::Cutter, cam_core::ToolPath)> = operations
        .iter()
        .filter_map(|op| op.cutter.clone().map(|c| (c, op.path.clone())))
        .collect();
    if verifiable.len() < operations.len() {
        report.notes.push(format!(
            "{} operation(s) without a CUTTER record were not verified",
            operations.len() - verifiable.len()
        ));
    }
    if job.verification.enabled && !verifiable.is_empty() {
        let (v, maps) = verify(&impeller, &verifiable, job, out)?;
        report.add_map_plots(&maps);
        report.verification = Some(v);
    }
    report.timings_ms.insert("verify_ms".into(), ms(t));
    report
        .timings_ms
        .insert("total_ms".into(), total.elapsed().as_secs_f64() * 1e3);

    report.write(out)?;
    Ok(report)
}

fn verify(
    impeller: &Impeller,
    ops: &[(cam_core::Cutter, cam_core::ToolPath)],
    job: &Job,
    out: &Path,
) -> Result<(VerificationReport, Vec<machining_sim::SurfaceMap>), CliError> {
    let design = ImpellerDesign::new(impeller, ImpellerSampling::default()).map_err(msg)?;
    let blank = design.blank().map_err(msg)?;
    let mut stock = TriDexel::from_shape(&blank, job.verification.resolution_mm).map_err(msg)?;
    let options = SimOptions {
        progress: true,
        ..SimOptions::default()
    };
    let rep = machining_sim::simulate(&mut stock, &design, ops, &options).map_err(msg)?;
    let maps = serde_json::to_string(&rep.maps).map_err(msg)?;
    gcode_emit::write_atomic(&out.join("verification_maps.json"), maps.as_bytes()).map_err(msg)?;
    let v = VerificationReport {
        max_overcut_mm: rep.metrics.max_overcut_mm,
        max_residual_mm: rep.metrics.max_residual_mm,
        collisions: rep.metrics.collisions,
        resolution_mm: job.verification.resolution_mm,
        details: serde_json::json!({
            "max_overcut": rep.max_overcut,
            "max_residual": rep.max_residual,
            "collision_list": rep.collisions,
            "stats": rep.stats,
        }),
    };
    Ok((v, rep.maps))
}
