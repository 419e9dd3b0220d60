//! `impeller-cam post CLFILE --machine MACHINE.toml --dialect NAME --out FILE`: post-process an
//! APT CLDATA file from any CAM system into a program for one machine and controller.

use crate::error::CliError;
use gcode_emit::{
    assemble_program, dialect_by_name, read_cl_file, write_program_file, AssembleOptions,
    ClReadOptions, LineNumbers, OutputMode, ProgramOptions,
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
    /// Controller dialect: linuxcnc, fanuc, sinumerik or heidenhain.
    #[arg(long)]
    pub dialect: String,
    /// Program file to write (written to a temporary file, renamed when complete).
    #[arg(long)]
    pub out: PathBuf,
    /// Output mode (default: joint for linuxcnc and fanuc, tcp for sinumerik and heidenhain).
    #[arg(long, value_enum)]
    pub mode: Option<Mode>,
    /// Tool length, gauge line to tip (mm); enters the kinematics of head machines only.
    #[arg(long, default_value_t = 0.0)]
    pub tool_length: f64,
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
    let machine = Machine::from_file(&args.machine).map_err(|e| msg(&e))?;
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
    let options = AssembleOptions {
        mode,
        retract_mm: args.retract,
        post: PostOptions {
            tool_length: args.tool_length,
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
    let program_options = ProgramOptions {
        line_numbers: (!args.no_line_numbers).then_some(LineNumbers {
            start: 10,
            step: 10,
        }),
        linear_decimals: args.decimals,
        angular_decimals: args.decimals,
        safe_z_machine: args.safe_z.or(machine.safe_z()).unwrap_or(0.0),
        program_number: args.program_number,
        ..ProgramOptions::default()
    };
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
