//! The job pipeline: impeller model → operations → CL file → post-processing → program →
//! independent verification → reports.
//!
//! Each stage is timed (`timings_ms` in the report) and announced on stderr. Stages that have
//! nothing to do say so in the report's `notes` instead of inventing output.
//!
//! Post-processing removes reverse motions of the rotary axes (paper 004) in every operation
//! whose cutter is known, re-checking each changed posture against the design with
//! [`DesignClearance`]; verification then simulates the tool paths as posted (smoothed tool
//! axes), not the CL data as given.

use crate::error::CliError;
use crate::job::Job;
use crate::report::{OperationReport, PostOperationReport, PostReport, Report, VerificationReport};
use cam_core::{Cutter, CutterLocation, CutterShape, Rates, ToolPath};
use gcode_emit::assemble::{assemble_program_with_access, AssembledProgram, OperationAccess};
use gcode_emit::{
    dialect_by_name, read_cl_file, write_cl_file, write_program_file, AssembleOptions, ClOperation,
    ClProgram, ClReadOptions, ClWriteOptions, LineNumbers, OutputMode, ProgramOptions,
};
use machining_sim::{DesignModel, ImpellerDesign, ImpellerSampling, SimOptions, TriDexel};
use postproc_kinematics::{AccessibilityChecker, Machine, PostOptions, ReverseMotionOptions};
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
            reverse_motion: Some(ReverseMotionOptions::default()),
            ..PostOptions::default()
        },
        ..AssembleOptions::default()
    };
    // The design, built once: accessibility checks here, stock simulation below.
    let design = if operations.is_empty() {
        None
    } else {
        Some(ImpellerDesign::new(&impeller, ImpellerSampling::default()).map_err(msg)?)
    };
    let program_path = out.join(format!("program.{}", dialect.extension()));
    let mut post = PostReport {
        machine: machine.name().to_string(),
        dialect: dialect.name().to_string(),
        program: program_path.display().to_string(),
        ..PostReport::default()
    };
    let mut assembled: Option<AssembledProgram> = None;
    if let Some(design) = &design {
        let checkers: Vec<Option<DesignClearance<'_, ImpellerDesign>>> = operations
            .iter()
            .map(|op| {
                op.cutter
                    .as_ref()
                    .map(|c| DesignClearance::new(design, c, job.tolerances.machining_tol))
            })
            .collect();
        let access: Vec<OperationAccess<'_>> = checkers
            .iter()
            .map(|c| match c {
                Some(c) => OperationAccess::Checked(c),
                None => OperationAccess::CountOnly,
            })
            .collect();
        let unchecked: Vec<&str> = operations
            .iter()
            .filter(|op| op.cutter.is_none())
            .map(|op| op.path.name.as_str())
            .collect();
        if !unchecked.is_empty() {
            report.notes.push(format!(
                "reverse motions were counted but not removed in {}: without a CUTTER record \
                 a changed tool posture cannot be checked for gouging",
                unchecked.join(", ")
            ));
        }
        let assembled_program = assemble_program_with_access(
            &job.name,
            &operations,
            &machine,
            dialect.as_ref(),
            &options,
            &access,
        )
        .map_err(msg)?;
        let assembled = assembled.insert(assembled_program);
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
        for p in &assembled.operations {
            post.operations.push(PostOperationReport::of(p));
            report.add_displacement_plots(p);
        }
        post.written = true;
    } else {
        post.program = String::new();
    }
    report.post = post;
    report.timings_ms.insert("post_ms".into(), ms(t));

    // 5. Independent verification.
    let t = stage("verifying by stock simulation");
    // Simultaneous operations are verified as posted (smoothed tool axes).
    let verifiable: Vec<(Cutter, ToolPath)> = operations
        .iter()
        .enumerate()
        .filter_map(|(i, op)| {
            let path = assembled
                .as_ref()
                .and_then(|a| a.operations.iter().find(|p| p.index == i))
                .map(|p| posted_path(&op.path, &p.blocks))
                .unwrap_or_else(|| op.path.clone());
            op.cutter.clone().map(|c| (c, path))
        })
        .collect();
    if verifiable.len() < operations.len() {
        report.notes.push(format!(
            "{} operation(s) without a CUTTER record were not verified",
            operations.len() - verifiable.len()
        ));
    }
    if let (true, false, Some(design)) = (
        job.verification.enabled,
        verifiable.is_empty(),
        design.as_ref(),
    ) {
        let (v, maps) = verify(design, &verifiable, job, out)?;
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
    design: &ImpellerDesign,
    ops: &[(Cutter, ToolPath)],
    job: &Job,
    out: &Path,
) -> Result<(VerificationReport, Vec<machining_sim::SurfaceMap>), CliError> {
    let blank = design.blank().map_err(msg)?;
    let mut stock = TriDexel::from_shape(&blank, job.verification.resolution_mm).map_err(msg)?;
    let options = SimOptions {
        progress: true,
        ..SimOptions::default()
    };
    let rep = machining_sim::simulate(&mut stock, design, ops, &options).map_err(msg)?;
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

/// The tool path a posted operation actually machines: the source moves (kinds and feeds
/// kept) with the cutter locations of their posted blocks, i.e. the tool axes after
/// reverse-motion smoothing. `blocks` start with the approach (source index 0), so move `j`
/// is the block with source index `j + 1`; linearisation blocks are left out (they lie on
/// the joint interpolation between two source blocks). O(n).
fn posted_path(source: &ToolPath, blocks: &[postproc_kinematics::PostedBlock]) -> ToolPath {
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

/// Gouge test of a cutter location against a design's signed distance, used to re-check the
/// postures changed by reverse-motion smoothing.
///
/// The cutter's fluted part is the solid of revolution of radius `ρ(h)`
/// ([`CutterShape::radius_at`]) about the axis for heights `0 ≤ h ≤ L` (flute length). Its
/// cross-section at height `h` is a disc of radius `ρ(h)` centred on the axis point
/// `c(h) = tip + h·axis`, and that disc lies inside the ball of radius `ρ(h)` about `c(h)`.
/// So `d(c(h)) ≥ ρ(h)`, with `d` the design's signed distance (negative inside; a lower
/// bound of the true distance outside), proves the disc clear of the design: a conservative
/// no-gouge test per height. A posture is accepted when
/// `d(c(h)) ≥ ρ(h) − machining_tol / 2` at every sample height:
/// - the ball centre (ball end and tapered ball: `h = r`, where the ball of radius `r`
///   contains the whole ball part of the cutter exactly, so a ball end tangent to any
///   surface passes; bull nose: the corner centres' height `h = r_c`);
/// - a uniform grid from the top of the ball part (`r` for a ball end, the cone tangency
///   height `r(1 − sin θ)` for a tapered ball, 0 otherwise) up to `L`, with step
///   `s ≤ min(r/2, √(2·r·machining_tol))`, `r` the nominal radius (ball, flat or outer
///   radius; tip radius of a tapered flat end).
///
/// Between two grid heights the two balls cover the cutter except a rim band of radial depth
/// `ρ − √(ρ² − s²/4) ≤ s²/(4ρ) ≤ machining_tol / 2` (for `ρ ≥ r`), so an accepted posture
/// penetrates the design by at most `machining_tol`, up to the accuracy of `d` near the
/// surface; below the ball part of a bull nose (`ρ < r`) the band is wider (`s²/(4ρ)`).
/// The test is conservative: a flat bottom (flat end, bull nose, tapered flat end) touching a
/// surface fails it, because the ball about the tip reaches below the tip; such postures keep
/// their original orientation. Shank and holder are not tested here; the verification's
/// collision check covers them.
///
/// Cost: O(L / s) signed-distance queries per posture, stopping at the first failure.
#[derive(Debug)]
pub struct DesignClearance<'a, D: DesignModel> {
    design: &'a D,
    /// (height h, required signed distance of `tip + h·axis`).
    samples: Vec<(f64, f64)>,
}

impl<'a, D: DesignModel> DesignClearance<'a, D> {
    /// The checker of `cutter` against `design` with tolerance `machining_tol` (mm, ≥ 0).
    pub fn new(design: &'a D, cutter: &Cutter, machining_tol: f64) -> Self {
        let tol = machining_tol.max(0.0);
        // (nominal radius, ball centre height, top of the part the centre's ball contains).
        let (nominal, centre, top) = match cutter.shape {
            CutterShape::FlatEnd { radius } => (radius, None, 0.0),
            CutterShape::BallEnd { radius } => (radius, Some(radius), radius),
            CutterShape::BullNose {
                radius,
                corner_radius,
            } => (radius, Some(corner_radius), 0.0),
            CutterShape::TaperedBallEnd {
                ball_radius,
                half_angle,
            } => (
                ball_radius,
                Some(ball_radius),
                ball_radius * (1.0 - half_angle.sin()),
            ),
            CutterShape::TaperedFlatEnd { tip_radius, .. } => (tip_radius, None, 0.0),
        };
        let length = cutter.flute_length.max(0.0);
        let mut samples = Vec::new();
        if let Some(h) = centre.filter(|h| *h <= length) {
            samples.push((h, cutter.shape.radius_at(h) - tol / 2.0));
        }
        let grid_start = top.min(length);
        let step_max = (nominal / 2.0).min((2.0 * nominal * tol).sqrt());
        let span = length - grid_start;
        let n = if step_max > 0.0 {
            (span / step_max).ceil().max(1.0) as usize
        } else {
            1
        };
        let step = span / n as f64;
        for k in 0..=n {
            let h = grid_start + step * k as f64;
            samples.push((h, cutter.shape.radius_at(h) - tol / 2.0));
        }
        Self { design, samples }
    }
}

impl<D: DesignModel> AccessibilityChecker for DesignClearance<'_, D> {
    fn is_accessible(&self, cl: &CutterLocation) -> bool {
        let axis = cl.axis.into_inner();
        self.samples
            .iter()
            .all(|&(h, need)| self.design.signed_distance(&(cl.tip + axis * h)) >= need)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cam_core::{Point3, Vector3};
    use impeller_model::Side;

    fn ball(r: f64) -> Cutter {
        Cutter::new("ball", CutterShape::BallEnd { radius: r }, 20.0, r, 40.0).unwrap()
    }

    #[test]
    fn sampling_covers_the_flutes_with_the_stated_step() {
        let design = machining_sim::BoxDesign {
            min: [-1.0, -1.0, -1.0],
            max: [1.0, 1.0, 0.0],
            sample_spacing: 0.5,
        };
        let tol = 0.01;
        let c = DesignClearance::new(&design, &ball(3.0), tol);
        // The ball centre first (exact ball test), then the grid from the ball's top to L.
        assert_eq!(c.samples[0].0, 3.0);
        assert!((c.samples[0].1 - (3.0 - tol / 2.0)).abs() < 1e-12);
        let grid: Vec<f64> = c.samples[1..].iter().map(|s| s.0).collect();
        assert_eq!(grid.first().copied(), Some(3.0));
        assert!((grid.last().copied().unwrap() - 20.0).abs() < 1e-9);
        let bound = (2.0 * 3.0 * tol).sqrt().min(1.5);
        assert!(grid.windows(2).all(|w| w[1] - w[0] <= bound + 1e-12));
        // A ball end resting on the box's top face is accessible; 0.02 mm lower it is not
        // (beyond the tolerance), and so is any flat end touching it (conservative test).
        let up = Vector3::z();
        let on = CutterLocation::new(Point3::new(0.0, 0.0, 0.0), up).unwrap();
        let below = CutterLocation::new(Point3::new(0.0, 0.0, -0.02), up).unwrap();
        assert!(c.is_accessible(&on));
        assert!(!c.is_accessible(&below));
        let flat = Cutter::new(
            "flat",
            CutterShape::FlatEnd { radius: 3.0 },
            20.0,
            3.0,
            40.0,
        )
        .unwrap();
        let f = DesignClearance::new(&design, &flat, tol);
        assert!(!f.is_accessible(&on));
        let lifted = CutterLocation::new(Point3::new(0.0, 0.0, 3.0), up).unwrap();
        assert!(f.is_accessible(&lifted));
    }

    #[test]
    fn checker_rejects_a_plunge_into_a_blade_and_accepts_a_posture_above_the_shroud() {
        let imp = impeller_model::fixtures::default_impeller().unwrap();
        let design = ImpellerDesign::new(&imp, ImpellerSampling::default()).unwrap();
        let checker = DesignClearance::new(&design, &ball(3.0), 0.01);
        // Mid-thickness of the main blade at mid-chord, mid-span.
        let blade = imp.main().blade();
        let (ps, ss) = (blade.side(Side::Pressure), blade.side(Side::Suction));
        let ((u0, u1), (v0, v1)) = ps.domain();
        let (u, v) = (0.5 * (u0 + u1), 0.5 * (v0 + v1));
        let mid = Point3::from(0.5 * (ps.point(u, v) + ss.point(u, v)));
        assert!(design.signed_distance(&mid) < -0.1, "inside the blade");
        let radial = Vector3::new(mid.x, mid.y, 0.0);
        for axis in [Vector3::z(), radial, Vector3::new(mid.x, mid.y, 30.0)] {
            let cl = CutterLocation::new(mid, axis).unwrap();
            assert!(!checker.is_accessible(&cl), "{axis:?}");
        }
        // 2 mm above the blank (top of the shroud contour), tilted 10° outward.
        let top = imp.summary().axial_height_mm;
        let t = 10f64.to_radians();
        let cl = CutterLocation::new(
            Point3::new(30.0, 0.0, top + 2.0),
            Vector3::new(t.sin(), 0.0, t.cos()),
        )
        .unwrap();
        assert!(checker.is_accessible(&cl));
    }
}
