//! `impeller-cam post CLFILE --machine MACHINE.toml --dialect NAME --out FILE`: post-process an
//! APT CLDATA file from any CAM system into a program for one machine and controller.

use crate::error::CliError;
use gcode_emit::{
    assemble_program, dialect_by_name, read_cl_file, write_program_file, AssembleOptions,
    ClReadOptions, LineNumbers, OutputMode, ProgramFrame, ProgramOptions,
};
use postproc_kinematics::{Machine, PostOptions};
use std::path::PathBuf;

/// Output mode on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Mode {
    /// Machine joint values, inverse-time feed (LinuxCNC, Fanuc and Sinumerik).
    Joint,
    /// Tool-centre-point control with rotary axis angles (all dialects).
    Tcp,
    /// Tool-centre-point control with tool vectors (Fanuc G43.5, Sinumerik A3/B3/C3).
    Vector,
}

/// Arguments of `impeller-cam post`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// APT CLDATA file (GOTO/x,y,z,i,j,k with MULTAX, FEDRAT, LOADTL, CUTTER, ...).
    pub cl_file: PathBuf,
    /// Machine description (TOML, see fixtures/machines/).
    #[arg(long)]
    pub machine: PathBuf,
    /// Controller dialect: linuxcnc, fanuc, sinumerik, heidenhain (ISO) or heidenhain_conversational (Klartext).
    #[arg(long)]
    pub dialect: String,
    /// Program file to write (written to a temporary file, renamed when complete).
    #[arg(long)]
    pub out: PathBuf,
    /// Output mode (default: joint for linuxcnc and fanuc, tcp for sinumerik and heidenhain).
    #[arg(long, value_enum)]
    pub mode: Option<Mode>,
    /// Tool length, gauge line to tip (mm), for the operations whose `LOADTL` gives none
    /// (`LOADTL/n,LENGTH,l` wins). It enters the kinematics of head-table and head-head
    /// machines only, which refuse a program without it.
    #[arg(long)]
    pub tool_length: Option<f64>,
    /// Approach / retract distance along the tool axis at each operation's ends (mm).
    #[arg(long, default_value_t = 10.0)]
    pub retract: f64,
    /// Machine Z to retract to between operations (mm; default: the machine file's safe_z).
    #[arg(long)]
    pub safe_z: Option<f64>,
    /// Decimals of linear and angular words.
    #[arg(long, default_value_t = 4)]
    pub decimals: usize,
    /// Write no block numbers (Heidenhain always numbers blocks).
    #[arg(long)]
    pub no_line_numbers: bool,
    /// Program number (Fanuc O-number).
    #[arg(long, default_value_t = 1000)]
    pub program_number: u32,
}

/// Reads the CL file and the machine, posts every operation and writes the program.
pub fn run(args: Args) -> Result<(), CliError> {
    let msg = |e: &dyn std::fmt::Display| CliError::Message(e.to_string());
    let dialect = dialect_by_name(&args.dialect).map_err(|e| msg(&e))?;
    let mode = match args.mode {
        Some(Mode::Joint) => OutputMode::Joint,
        Some(Mode::Tcp) => OutputMode::TcpAngles,
        Some(Mode::Vector) => OutputMode::TcpVector,
        None => match dialect.name() {
            "linuxcnc" | "fanuc" => OutputMode::Joint,
            _ => OutputMode::TcpAngles,
        },
    };
    if !dialect.supports(mode) {
        return Err(CliError::Message(format!(
            "dialect {} cannot write {mode:?} output; choose another --mode",
            dialect.name()
        )));
    }
    let machine_text = std::fs::read_to_string(&args.machine).map_err(|source| CliError::Io {
        path: args.machine.display().to_string(),
        source,
    })?;
    let machine_file = args.machine.display().to_string();
    let machine = Machine::from_toml_str(&machine_text, &machine_file).map_err(|e| msg(&e))?;
    let frame =
        ProgramFrame::from_machine_toml(&machine_text, &machine_file).map_err(|e| msg(&e))?;
    let dialect = frame.dialect(dialect.name()).map_err(|e| msg(&e))?;
    if let Some(l) = args.tool_length {
        if !(l.is_finite() && l > 0.0) {
            return Err(CliError::Message(format!(
                "--tool-length must be a length > 0 mm, got {l}"
            )));
        }
    }
    let cl = read_cl_file(&args.cl_file, &ClReadOptions::default()).map_err(|e| msg(&e))?;
    for w in &cl.warnings {
        eprintln!(
            "warning: {}:{}: {}",
            args.cl_file.display(),
            w.line,
            w.message
        );
    }
    if cl.operations.is_empty() {
        return Err(CliError::Message(format!(
            "{}: no moves found (no GOTO records)",
            args.cl_file.display()
        )));
    }
    // On a head machine the gauge length moves the tip: never a silent 0 (the program of
    // top-ring.cls on headhead-ac used to be 20 mm off without --tool-length 115).
    if machine.tool_length_matters() && args.tool_length.is_none() {
        if let Some(op) = cl.operations.iter().find(|op| op.tool_length_mm.is_none()) {
            return Err(CliError::Message(format!(
                "{}: operation \"{}\" (T{}) has no tool length: machine {} ({}) turns the \
                 tool about its head, so the gauge length moves the tip; give it with \
                 LOADTL/n,LENGTH,l in the CL file or --tool-length",
                args.cl_file.display(),
                op.path.name,
                op.tool_number.unwrap_or_default(),
                machine.name(),
                machine.kinematics().kind_name()
            )));
        }
    }
    let options = AssembleOptions {
        mode,
        retract_mm: args.retract,
        post: PostOptions {
            tool_length: args.tool_length.unwrap_or(0.0),
            ..PostOptions::default()
        },
        ..AssembleOptions::default()
    };
    let name = cl
        .part_name
        .clone()
        .filter(|n| !n.trim().is_empty())
        .or_else(|| {
            args.cl_file
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
        })
        .unwrap_or_else(|| "PROGRAM".into());
    let assembled = assemble_program(&name, &cl.operations, &machine, dialect.as_ref(), &options)
        .map_err(|e| CliError::Message(format!("{}: {e}", args.cl_file.display())))?;
    let mut program_options = ProgramOptions {
        line_numbers: Some(LineNumbers::new(10, 10)),
        linear_decimals: args.decimals,
        angular_decimals: args.decimals,
        safe_z_machine: match args.safe_z {
            Some(z) => z,
            None => machine
                .require_safe_z()
                .map_err(|e| CliError::Message(format!("{}: {e}", args.machine.display())))?,
        },
        program_number: args.program_number,
        ..ProgramOptions::default()
    };
    frame.apply(&mut program_options);
    if args.no_line_numbers {
        program_options.line_numbers = None;
    }
    write_program_file(
        &args.out,
        dialect.as_ref(),
        &assembled.program,
        &program_options,
    )
    .map_err(|e| msg(&e))?;
    for (op, m) in &assembled.metrics {
        eprintln!(
            "{op}: {} blocks, reverse motions {} -> {}, max linearisation error {:.4} mm, limit violations {}",
            m.blocks, m.reverse_motions_before, m.reverse_motions_after, m.max_linearisation_error_mm, m.limit_violations
        );
    }
    eprintln!(
        "wrote {} ({} operations, {}, {:?})",
        args.out.display(),
        assembled.program.operations.len(),
        dialect.name(),
        mode
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(dir: &std::path::Path, dialect: &str, mode: Option<Mode>) -> Args {
        let cl = dir.join("in.cls");
        std::fs::write(
            &cl,
            "PARTNO IMP\nMULTAX/ON\nLOADTL/2\nCUTTER/6,3,0,3,0,0,30\nSPINDL/RPM,9000,CLW\n\
             COOLNT/FLOOD\nFEDRAT/MMPM,600\nGOTO/25,10,5,0.1,0.05,0.99373\n\
             GOTO/20,15,4,0.2,0.1,0.97468\nGOTO/15,20,3,0.3,0.15,0.94207\nFINI\n",
        )
        .unwrap();
        Args {
            cl_file: cl,
            machine: PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                .join("embedded/machines/xyzac-trt.toml"),
            dialect: dialect.into(),
            out: dir.join(format!("out.{dialect}")),
            mode,
            tool_length: None,
            retract: 10.0,
            safe_z: None,
            decimals: 4,
            no_line_numbers: false,
            program_number: 1000,
        }
    }

    fn scratch(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("impeller-post-{}-{tag}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn posts_a_cl_file_for_every_dialect() {
        let dir = scratch("ok");
        for (d, needle) in [
            ("linuxcnc", "G93 G1"),
            ("fanuc", "G43 H2"),
            ("sinumerik", "TRAORI"),
            ("heidenhain", "M128"),
        ] {
            let a = args(&dir, d, None);
            let out = a.out.clone();
            run(a).unwrap();
            let text = std::fs::read_to_string(&out).unwrap();
            assert!(text.contains(needle), "{d}:\n{text}");
            // xyzac-trt is set up for a trivkins controller: no kinematics switch (M429
            // used to be line 2, which a stock trivkins LinuxCNC rejects).
            assert!(
                !text.contains("M429") && !text.contains("M428"),
                "{d}:\n{text}"
            );
            // The machine file's safe_z (100 mm) is the retract height.
            assert!(
                text.contains("Z100") || text.contains("Z+100"),
                "{d}:\n{text}"
            );
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A head-head machine never gets a silent tool length of 0: without `LOADTL/n,LENGTH,l`
    /// or `--tool-length` the post refuses (and writes nothing); the CL file's length and
    /// the option give the same program, and a different one from another length (the tip
    /// moves with the gauge length).
    #[test]
    fn head_machines_take_the_tool_length_from_loadtl_or_refuse() {
        let dir = scratch("headhead");
        let head = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../../fixtures/machines/headhead-ac.toml");
        let mut a = args(&dir, "fanuc", None);
        a.machine = head.clone();
        let out = a.out.clone();
        let e = run(a).unwrap_err().to_string();
        assert!(
            e.contains("in.cls: operation")
                && e.contains("has no tool length")
                && e.contains("head-head"),
            "{e}"
        );
        assert!(!out.exists(), "no program written");
        let program = |tool_length: Option<f64>, loadtl: &str, file: &str| {
            let mut a = args(&dir, "fanuc", None);
            let cl = std::fs::read_to_string(&a.cl_file).unwrap();
            std::fs::write(&a.cl_file, cl.replace("LOADTL/2", loadtl)).unwrap();
            a.machine = head.clone();
            a.tool_length = tool_length;
            a.out = dir.join(file);
            let out = a.out.clone();
            run(a).unwrap();
            std::fs::read_to_string(out).unwrap()
        };
        let by_option = program(Some(115.0), "LOADTL/2", "a.nc");
        let by_loadtl = program(None, "LOADTL/2,LENGTH,115", "b.nc");
        let shorter = program(Some(95.0), "LOADTL/2", "c.nc");
        assert_eq!(by_option, by_loadtl);
        assert_ne!(by_option, shorter);
        // A table-table machine needs none.
        run(args(&dir, "fanuc", None)).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn user_errors_are_one_line_messages() {
        let dir = scratch("err");
        let e = run(args(&dir, "haas", None)).unwrap_err().to_string();
        assert_eq!(
            e,
            "unknown dialect `haas`; valid dialects: linuxcnc, fanuc, sinumerik, heidenhain, heidenhain_conversational"
        );
        let e = run(args(&dir, "heidenhain", Some(Mode::Joint)))
            .unwrap_err()
            .to_string();
        assert!(e.contains("cannot write Joint"), "{e}");
        let mut a = args(&dir, "fanuc", None);
        std::fs::write(&a.cl_file, "GOTO/1,2\n").unwrap();
        let e = run(a).unwrap_err().to_string();
        assert!(e.contains("in.cls:1: GOTO field 0"), "{e}");
        a = args(&dir, "fanuc", None);
        a.out = dir.join("missing-dir/out.nc");
        assert!(run(a).is_err());
        assert!(!e.contains('\n'));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A machine without `safe_z` is refused (the post used to retract to machine Z0).
    #[test]
    fn a_machine_without_safe_z_is_an_error_naming_the_key() {
        let dir = scratch("nosafe");
        let text = std::fs::read_to_string(
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("embedded/machines/xyzac-trt.toml"),
        )
        .unwrap();
        let stripped: String = text
            .lines()
            .filter(|l| !l.trim_start().starts_with("safe_z"))
            .map(|l| format!("{l}\n"))
            .collect();
        assert!(text.contains("safe_z") && !stripped.contains("safe_z"));
        let machine = dir.join("nosafe.toml");
        std::fs::write(&machine, stripped).unwrap();
        let mut a = args(&dir, "linuxcnc", None);
        a.machine = machine;
        let out = a.out.clone();
        let e = run(a).unwrap_err().to_string();
        assert!(e.contains("`safe_z`") && e.contains("nosafe.toml"), "{e}");
        assert!(!out.exists(), "no program written");
        // An explicit --safe-z still works.
        let mut a = args(&dir, "linuxcnc", None);
        a.machine = dir.join("nosafe.toml");
        a.safe_z = Some(150.0);
        run(a).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
