//! `impeller-cam`: the command line of the impeller five-axis CAM toolkit, a thin layer over
//! the `impeller_cam` library.
//!
//! Every subcommand exits 0 on success and 1 on a user error with one clear line on stderr
//! (see `../shared/DESIGN.md` §4); `run` exits [`impeller_cam::EXIT_DEFECTS`] (3) when
//! verification finds an overcut beyond tolerance or a collision (the report is written, the
//! program withheld; `--allow-defects` keeps the program and exits 0), and when the machine
//! cannot hold the planned tool paths within its travel (nothing posted, the report lists
//! every violation). Subcommands live in the library's `cmd` module, one module each.

use clap::{Parser, Subcommand};
use impeller_cam::cmd;
use std::process::ExitCode;

/// Turn impeller design geometry into verified five-axis NC programs.
#[derive(Debug, Parser)]
#[command(name = "impeller-cam", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run the whole pipeline on a job file (or the embedded default job).
    Run(cmd::run::Args),
    /// Rayleigh–Ritz stiffness indicator of a conical cutter.
    Stiffness(cmd::stiffness::Args),
    /// Build an impeller and print its measured summary (blade counts, diameters, widths).
    Model(cmd::model::Args),
    /// Post-process an APT CLDATA file into a program for a machine and controller.
    Post(cmd::post::Args),
    /// Verify a CL program against the impeller design (overcut, residual, collisions).
    Verify(cmd::verify::Args),
}

fn main() -> ExitCode {
    // A defect must still reach the user as one line, never as a Rust panic dump.
    std::panic::set_hook(Box::new(|info| {
        let what = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown cause".into());
        let at = info
            .location()
            .map(|l| format!(" at {}:{}", l.file(), l.line()))
            .unwrap_or_default();
        eprintln!("error: internal error ({what}{at}); please report it with the input files");
    }));
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            // clap prints help/version on stdout and usage errors on stderr.
            let code = if e.use_stderr() { 1 } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    let result = match cli.command {
        Command::Run(args) => match cmd::run::run(args) {
            Ok(cmd::run::Outcome::Clean) => Ok(()),
            Ok(cmd::run::Outcome::Defects) => {
                return ExitCode::from(impeller_cam::EXIT_DEFECTS);
            }
            Err(e) => Err(e),
        },
        Command::Stiffness(args) => cmd::stiffness::run(args),
        Command::Model(args) => cmd::model::run(args),
        Command::Post(args) => cmd::post::run(args),
        Command::Verify(args) => cmd::verify::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(1)
        }
    }
}
