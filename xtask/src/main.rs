//! Project automation, invoked as `cargo xtask <command>` (alias in `.cargo/config.toml`).
//!
//! - `cargo xtask regress`: runs every fixture job end to end with `impeller-cam run`,
//!   compares the metrics of its `report.json` with the bounds stored beside the fixture
//!   (`fixtures/<name>/bounds.toml`), prints a table, writes `target/regress/summary.json`
//!   and exits non-zero on any breach.
//! - `cargo xtask ci`: what CI runs — installs the test consumers (`rs274`, `chromium`) when
//!   missing, then fmt, clippy, the whole test suite, the regressions and a closing
//!   `tests: N passed, N failed` line (see [`ci`]).
//! - `cargo xtask bench`: runs the criterion benchmarks in release and writes the benchmarks
//!   that ran in this invocation to `target/bench/bmf.json` (Bencher Metric Format: `latency`
//!   in ns per iteration with its confidence bounds, throughput as a separate measure where a
//!   benchmark declared one; see [`bench`]), and the closest-point query set to
//!   `target/bench/closest_point_queries.csv`.

#![allow(clippy::print_stdout)]

mod bench;
mod ci;
mod regress;

use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Debug, Parser)]
#[command(name = "cargo xtask", about = "Project automation")]
struct Cli {
    #[command(subcommand)]
    command: Cmd,
}

#[derive(Debug, Subcommand)]
enum Cmd {
    /// Run every fixture job end to end and check its metrics against the stored bounds.
    Regress(regress::Args),
    /// What CI runs: install test consumers, fmt, clippy, tests, regressions, totals.
    Ci(ci::Args),
    /// Run the criterion benchmarks and export them in Bencher Metric Format.
    Bench(bench::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Cmd::Regress(a) => regress::run(a),
        Cmd::Bench(a) => bench::run(a),
        Cmd::Ci(a) => ci::run(a),
    };
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(e) => {
            eprintln!("xtask: error: {e}");
            ExitCode::from(2)
        }
    }
}

/// The workspace root (parent of this crate's manifest directory).
pub(crate) fn workspace_root() -> PathBuf {
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    here.parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| here.to_path_buf())
}

/// The cargo target directory (honours `CARGO_TARGET_DIR`).
pub(crate) fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| workspace_root().join("target"))
}

/// Runs a command inheriting stdio; error if it fails.
pub(crate) fn run_cmd(cmd: &mut std::process::Command) -> Result<(), String> {
    let status = cmd
        .status()
        .map_err(|e| format!("cannot start {cmd:?}: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("{cmd:?} failed with {status}"))
    }
}

/// Writes `contents` to `path` through a temporary file and a rename.
pub(crate) fn write_atomic(path: &Path, contents: &[u8]) -> Result<(), String> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    let tmp = path.with_extension("tmp");
    std::fs::write(&tmp, contents).map_err(|e| format!("{}: {e}", tmp.display()))?;
    std::fs::rename(&tmp, path).map_err(|e| format!("{}: {e}", path.display()))
}
