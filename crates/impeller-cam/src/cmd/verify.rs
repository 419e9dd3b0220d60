//! `impeller-cam verify --impeller IMPELLER --cl CLFILE [--stock …] [--resolution MM] --out
//! DIR`: independent verification of a CL program (APT CLDATA with `CUTTER/` records, from any
//! CAM system) against the impeller design with the tri-dexel simulation of `machining-sim`.
//!
//! Writes `DIR/summary.json` (the DESIGN verification metrics `max_overcut_mm`,
//! `max_residual_mm`, `collisions`, their locations, every collision per move and the
//! timings), `DIR/maps.json` (overcut/residual grids per design surface), `DIR/stock.stl`
//! (the final stock) and `DIR/crosscheck.json` (dexel overcut against cam-core's swept
//! envelopes at the deepest samples).
//!
//! A LinuxCNC G-code program can be verified instead of a CL file: `--gcode PROG --machine
//! MACHINE.toml --cutter SPEC`. The program is read back with `gcode_emit::read_back`: every
//! block, rapids included, goes through the machine's forward kinematics with the
//! controller's interpolation (`--interpolation joint`, the default: the joints move
//! linearly, what a controller without TCP does; `tcp`: tool tip and angles linear), cut into
//! chords that follow that motion within 1 µm, so the swept volume is the real, curved tool
//! motion. An axis moved before it was ever programmed is an error, and so is a `G53` move in
//! a tool-tip program (its workpiece position is unknown); in joint output `G53` values are
//! the joints (the work offset is the machine zero). The set-up rapids before the first fully
//! known position (wherever the machine stood when the program started) are listed, not
//! simulated.

use crate::error::CliError;
use cam_core::{Cutter, CutterShape, ToolPath};
use gcode_emit::{read_back, read_gcode_file, ReadbackMode, ReadbackOptions};
use gcode_emit::{read_cl_file, ClReadOptions};
use machining_sim::Interpolation;
use machining_sim::{
    crosscheck_overcut, export::write_json, extract_surface, simulate, write_stl, BoxStock,
    ImpellerDesign, ImpellerSampling, RevolvedStock, SimOptions, StockShape, TriDexel,
};
use postproc_kinematics::Machine;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Arguments of `impeller-cam verify`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Impeller file (TOML, as for `impeller-cam model`), or `default` for the embedded
    /// fixture.
    #[arg(long)]
    pub impeller: String,
    /// APT CLDATA file with `CUTTER/` records.
    #[arg(long, required_unless_present = "gcode", conflicts_with = "gcode")]
    pub cl: Option<PathBuf>,
    /// LinuxCNC G-code program to verify through forward kinematics (with --machine, --cutter).
    #[arg(long, requires_all = ["machine", "cutter"])]
    pub gcode: Option<PathBuf>,
    /// Machine description (TOML) for --gcode.
    #[arg(long)]
    pub machine: Option<PathBuf>,
    /// Cutter for --gcode: `flat:R`, `ball:R`, `bull:R,RC`, `tapered-ball:R,HALF_DEG` or
    /// `tapered-flat:R,HALF_DEG` (mm, degrees), with --flute-length, --shank-radius,
    /// --stick-out.
    #[arg(long)]
    pub cutter: Option<String>,
    /// Flute length of --cutter (mm).
    #[arg(long, default_value_t = 20.0)]
    pub flute_length: f64,
    /// Shank radius of --cutter (mm; default: the cutter's radius at the flute length).
    #[arg(long)]
    pub shank_radius: Option<f64>,
    /// Stick-out (tip to holder face) of --cutter (mm).
    #[arg(long, default_value_t = 50.0)]
    pub stick_out: f64,
    /// How the controller interpolates --gcode blocks: `joint` (joints linear) or `tcp`
    /// (tool tip and rotary angles linear).
    #[arg(long, default_value = "joint", value_parser = ["joint", "tcp"])]
    pub interpolation: String,
    /// Tool length, gauge line to tip (mm), for the kinematics of head machines.
    #[arg(long, default_value_t = 0.0)]
    pub tool_length: f64,
    /// Blank: `box:XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX`, `cylinder:DIAMETER,HEIGHT` (from z = 0) or
    /// `revolved:Z,R;Z,R;...` (closed meridional outline); default: the impeller's blank.
    #[arg(long)]
    pub stock: Option<String>,
    /// Dexel cell size (mm).
    #[arg(long, default_value_t = 0.1)]
    pub resolution: f64,
    /// Output directory (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Largest thickness the overcut/residual probes measure (mm).
    #[arg(long, default_value_t = 3.0)]
    pub probe_depth: f64,
    /// STL lattice spacing in dexel cells (1 = full resolution; default: about 0.3 mm).
    #[arg(long)]
    pub stl_stride: Option<usize>,
    /// Number of deepest samples cross-checked against the swept envelopes (0 = none).
    #[arg(long, default_value_t = 20)]
    pub crosscheck: usize,
    /// Skip the shank/holder collision checks (rapid moves are always checked).
    #[arg(long)]
    pub no_collisions: bool,
}

fn numbers(text: &str, what: &str) -> Result<Vec<f64>, CliError> {
    text.split(',')
        .map(|s| {
            s.trim()
                .parse::<f64>()
                .map_err(|_| CliError::Message(format!("--stock {what}: `{s}` is not a number")))
        })
        .collect()
}

fn parse_stock(spec: &str) -> Result<Box<dyn StockShape>, CliError> {
    let msg = |e: machining_sim::SimError| CliError::Message(format!("--stock: {e}"));
    let (kind, rest) = spec.split_once(':').ok_or_else(|| {
        CliError::Message(format!(
            "--stock `{spec}`: expected box:..., cylinder:... or revolved:..."
        ))
    })?;
    match kind {
        "box" => {
            let v = numbers(rest, "box")?;
            if v.len() != 6 {
                return Err(CliError::Message(
                    "--stock box: expected 6 numbers XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX".into(),
                ));
            }
            Ok(Box::new(
                BoxStock::new([v[0], v[1], v[2]], [v[3], v[4], v[5]]).map_err(msg)?,
            ))
        }
        "cylinder" => {
            let v = numbers(rest, "cylinder")?;
            if v.len() != 2 {
                return Err(CliError::Message(
                    "--stock cylinder: expected DIAMETER,HEIGHT".into(),
                ));
            }
            Ok(Box::new(
                RevolvedStock::cylinder(0.5 * v[0], 0.0, v[1]).map_err(msg)?,
            ))
        }
        "revolved" => {
            let mut pts = Vec::new();
            for (k, pair) in rest.split(';').enumerate() {
                let v = numbers(pair, "revolved")?;
                if v.len() != 2 {
                    return Err(CliError::Message(format!(
                        "--stock revolved: point {k} must be Z,R"
                    )));
                }
                pts.push((v[0], v[1]));
            }
            Ok(Box::new(RevolvedStock::new(pts).map_err(msg)?))
        }
        other => Err(CliError::Message(format!(
            "--stock: unknown kind `{other}` (box, cylinder, revolved)"
        ))),
    }
}

/// Loads the impeller, the CL program and the blank, simulates and writes the results.
pub fn run(args: Args) -> Result<(), CliError> {
    let start = Instant::now();
    let impeller = if args.impeller == "default" {
        impeller_model::fixtures::default_impeller()
    } else {
        impeller_model::load(&args.impeller)
    }
    .map_err(|e| CliError::Message(format!("{}: {e}", args.impeller)))?;
    let (ops, interpolation) = match (&args.cl, &args.gcode) {
        (Some(cl), _) => (read_cl_ops(cl)?, Interpolation::Tcp),
        (None, Some(gcode)) => read_gcode_ops(&args, gcode)?,
        (None, None) => {
            return Err(CliError::Message(
                "give --cl CLFILE or --gcode PROGRAM".into(),
            ))
        }
    };
    let sim_err = |e: machining_sim::SimError| CliError::Message(e.to_string());
    let design = ImpellerDesign::new(&impeller, ImpellerSampling::default()).map_err(sim_err)?;
    let blank: Box<dyn StockShape> = match &args.stock {
        Some(spec) => parse_stock(spec)?,
        None => Box::new(design.blank().map_err(sim_err)?),
    };
    let mut stock = TriDexel::from_shape(blank.as_ref(), args.resolution).map_err(sim_err)?;
    eprintln!(
        "verify: {} operations, {} moves; stock {} rays ({:.1} MB) at {} mm",
        ops.len(),
        ops.iter().map(|(_, p)| p.moves.len()).sum::<usize>(),
        stock.ray_count(),
        stock.memory_bytes() as f64 / 1e6,
        args.resolution
    );
    let options = SimOptions {
        interpolation,
        check_collisions: !args.no_collisions,
        probe_depth_mm: args.probe_depth,
        progress: true,
        ..SimOptions::default()
    };
    let report = simulate(&mut stock, &design, &ops, &options).map_err(sim_err)?;
    std::fs::create_dir_all(&args.out).map_err(|source| CliError::Io {
        path: args.out.display().to_string(),
        source,
    })?;
    report
        .write_summary_json(&args.out.join("summary.json"))
        .map_err(sim_err)?;
    report
        .write_maps_json(&args.out.join("maps.json"))
        .map_err(sim_err)?;
    eprintln!("verify: extracting the final stock surface");
    let stride = args
        .stl_stride
        .unwrap_or_else(|| (0.3 / args.resolution).round().max(1.0) as usize)
        .max(1);
    let mesh = extract_surface(&stock, stride);
    write_stl(
        &mesh,
        &args.out.join("stock.stl"),
        "impeller-cam verify stock",
    )
    .map_err(sim_err)?;
    if args.crosscheck > 0 {
        let checks = crosscheck_overcut(&report, &ops, args.crosscheck).map_err(sim_err)?;
        write_json(&args.out.join("crosscheck.json"), &checks).map_err(sim_err)?;
    }
    eprintln!(
        "verify: max_overcut_mm {:.4}, max_residual_mm {:.4}, collisions {} ({:.1} s); wrote {}",
        report.metrics.max_overcut_mm,
        report.metrics.max_residual_mm,
        report.metrics.collisions,
        start.elapsed().as_secs_f64(),
        args.out.display()
    );
    Ok(())
}

/// Operations (cutter + tool path) of a CL file.
fn read_cl_ops(cl: &Path) -> Result<Vec<(Cutter, ToolPath)>, CliError> {
    let program = read_cl_file(cl, &ClReadOptions::default())
        .map_err(|e| CliError::Message(e.to_string()))?;
    for w in &program.warnings {
        eprintln!(
            "verify: warning: {}:{}: {}",
            cl.display(),
            w.line,
            w.message
        );
    }
    let mut ops = Vec::new();
    for op in &program.operations {
        let cutter = op.cutter.clone().ok_or_else(|| {
            CliError::Message(format!(
                "{}: operation `{}` has no usable CUTTER record",
                cl.display(),
                op.path.name
            ))
        })?;
        if !op.path.moves.is_empty() {
            ops.push((cutter, op.path.clone()));
        }
    }
    if ops.is_empty() {
        return Err(CliError::Message(format!(
            "{}: no operations with moves",
            cl.display()
        )));
    }
    Ok(ops)
}

/// The cutter given by `--cutter` and its dimensions.
fn parse_cutter(args: &Args, spec: &str) -> Result<Cutter, CliError> {
    let (kind, rest) = spec.split_once(':').ok_or_else(|| {
        CliError::Message(format!(
            "--cutter `{spec}`: expected KIND:VALUES, e.g. ball:3"
        ))
    })?;
    let v = numbers(rest, "cutter")?;
    let need = |n: usize| {
        if v.len() == n {
            Ok(())
        } else {
            Err(CliError::Message(format!(
                "--cutter {kind}: expected {n} number(s), got {}",
                v.len()
            )))
        }
    };
    let shape = match kind {
        "flat" => {
            need(1)?;
            CutterShape::FlatEnd { radius: v[0] }
        }
        "ball" => {
            need(1)?;
            CutterShape::BallEnd { radius: v[0] }
        }
        "bull" => {
            need(2)?;
            CutterShape::BullNose {
                radius: v[0],
                corner_radius: v[1],
            }
        }
        "tapered-ball" => {
            need(2)?;
            CutterShape::TaperedBallEnd {
                ball_radius: v[0],
                half_angle: v[1].to_radians(),
            }
        }
        "tapered-flat" => {
            need(2)?;
            CutterShape::TaperedFlatEnd {
                tip_radius: v[0],
                half_angle: v[1].to_radians(),
            }
        }
        other => {
            return Err(CliError::Message(format!(
                "--cutter: unknown kind `{other}` (flat, ball, bull, tapered-ball, tapered-flat)"
            )))
        }
    };
    let shank = args
        .shank_radius
        .unwrap_or_else(|| shape.radius_at(args.flute_length));
    Cutter::new(spec, shape, args.flute_length, shank, args.stick_out)
        .map_err(|e| CliError::Message(format!("--cutter {spec}: {e}")))
}

/// Largest deviation (mm) of the read-back chords from the controller's tip path (and,
/// over the flute length, of the tool axis): far below any dexel cell.
const READBACK_PATH_TOL_MM: f64 = 0.001;

/// The operation of a G-code program read back through forward kinematics (one tool path
/// with every move, subdivided to follow the controller's interpolation).
fn read_gcode_ops(
    args: &Args,
    gcode: &Path,
) -> Result<(Vec<(Cutter, ToolPath)>, Interpolation), CliError> {
    let (Some(machine_file), Some(cutter_spec)) = (&args.machine, &args.cutter) else {
        return Err(CliError::Message(
            "--gcode needs --machine and --cutter".into(),
        ));
    };
    let machine = Machine::from_file(machine_file).map_err(|e| CliError::Message(e.to_string()))?;
    let cutter = parse_cutter(args, cutter_spec)?;
    let blocks = read_gcode_file(gcode).map_err(|e| CliError::Message(e.to_string()))?;
    let options = ReadbackOptions {
        mode: if args.interpolation == "tcp" {
            ReadbackMode::TcpAngles
        } else {
            ReadbackMode::Joint
        },
        tool_length_mm: args.tool_length,
        path_tol_mm: READBACK_PATH_TOL_MM,
        reach_mm: cutter.flute_length,
    };
    let file = gcode.display().to_string();
    let rb = read_back(&blocks, &machine, &options, &file, "gcode", &cutter.name)
        .map_err(|e| CliError::Message(e.to_string()))?;
    if !rb.unplaced_start_lines.is_empty() {
        eprintln!(
            "verify: {file}: lines {:?}: set-up rapids before the first fully programmed \
             position (machine position unknown) are not simulated",
            rb.unplaced_start_lines
        );
    }
    if rb.path.moves.is_empty() {
        return Err(CliError::Message(format!("{file}: no motion blocks")));
    }
    Ok((vec![(cutter, rb.path)], Interpolation::Tcp))
}

#[cfg(test)]
mod tests {
    use super::*;
    use cam_core::MoveKind;
    use clap::Parser;
    use postproc_kinematics::Joints;

    #[derive(Debug, Parser)]
    struct Cli {
        #[command(flatten)]
        args: Args,
    }

    fn args(extra: &[&str]) -> Args {
        let mut v = vec!["verify", "--impeller", "default", "--out", "/tmp/none"];
        v.extend_from_slice(extra);
        Cli::parse_from(v).args
    }

    #[test]
    fn stock_and_cutter_specs_parse_or_say_what_is_wrong() {
        assert!(parse_stock("box:0,0,0,1,1,1").is_ok());
        assert!(parse_stock("cylinder:79,44").is_ok());
        assert!(parse_stock("revolved:0,0;0,10;5,10;5,0").is_ok());
        let e = parse_stock("box:1,2")
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("6 numbers"), "{e}");
        let e = parse_stock("sphere:3")
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("unknown kind"), "{e}");
        let a = args(&["--cl", "x.cls"]);
        assert!(parse_cutter(&a, "ball:3").is_ok());
        assert!(parse_cutter(&a, "tapered-ball:1.5,3").is_ok());
        let e = parse_cutter(&a, "bull:3")
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("expected 2"), "{e}");
    }

    #[test]
    fn gcode_blocks_become_forward_kinematics_locations_with_joint_interpolation() {
        let dir = std::env::temp_dir().join(format!("verify_gcode_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let prog = dir.join("p.ngc");
        std::fs::write(
            &prog,
            "%\nG21 G90 G94\nG53 G0 Z100\nG0 X10 Y0 Z60 A0 C0\nG1 X12 Y1 Z40 A30 C45 F500\nG1 X14 Y2 Z38 A30 C90\n%\n",
        )
        .unwrap();
        let machine = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/embedded/machines/xyzac-trt.toml"
        );
        let a = args(&[
            "--gcode",
            prog.to_str().unwrap(),
            "--machine",
            machine,
            "--cutter",
            "ball:2",
        ]);
        let (ops, interp) = read_gcode_ops(&a, &prog).unwrap();
        assert!(matches!(interp, Interpolation::Tcp));
        assert_eq!(ops.len(), 1);
        let path = &ops[0].1;
        // The G53 retract comes before X/Y are known: a set-up move, not placed.
        assert_eq!(path.moves[0].kind, MoveKind::Rapid);
        let m = Machine::from_file(machine).unwrap();
        let j0 = Joints {
            x: 10.0,
            y: 0.0,
            z: 60.0,
            tilt: 0.0,
            rotate: 0.0,
        };
        let j1 = Joints {
            x: 12.0,
            y: 1.0,
            z: 40.0,
            tilt: 30f64.to_radians(),
            rotate: 45f64.to_radians(),
        };
        let j2 = Joints {
            x: 14.0,
            y: 2.0,
            z: 38.0,
            tilt: 30f64.to_radians(),
            rotate: 90f64.to_radians(),
        };
        assert!((path.moves[0].cl.tip - m.forward(&j0, 0.0).tip).norm() < 1e-9);
        let last = path.moves.last().unwrap().cl;
        assert!((last.tip - m.forward(&j2, 0.0).tip).norm() < 1e-9);
        // Every point of the joint-interpolated last block lies within the read-back
        // tolerance of the chords the simulator sweeps.
        let tips: Vec<_> = path.moves.iter().map(|mv| mv.cl.tip.coords).collect();
        for k in 0..=200 {
            let t = m.forward(&j1.lerp(&j2, k as f64 / 200.0), 0.0).tip.coords;
            let d = tips
                .windows(2)
                .map(|w| {
                    let ab = w[1] - w[0];
                    let s = ((t - w[0]).dot(&ab) / ab.norm_squared().max(1e-300)).clamp(0.0, 1.0);
                    (t - (w[0] + ab * s)).norm()
                })
                .fold(f64::INFINITY, f64::min);
            assert!(d <= READBACK_PATH_TOL_MM + 1e-9, "{d}");
        }
        // A feed move with C never programmed is an error naming the line and the axis.
        std::fs::write(&prog, "G0 X1 Y2 Z60 A0\nG1 X3 F500\n").unwrap();
        let e = read_gcode_ops(&a, &prog)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains(":2:") && e.contains("axis C"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
