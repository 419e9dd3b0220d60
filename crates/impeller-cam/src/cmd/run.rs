//! `impeller-cam run [JOB.toml] --out DIR`: the whole pipeline.

use crate::error::CliError;
use std::path::PathBuf;

/// Arguments of `impeller-cam run`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Job file (TOML). Without it the embedded default job runs.
    pub job: Option<PathBuf>,
    /// Output directory (created if missing).
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
}

/// Runs the pipeline stages that exist so far and says what it did.
pub fn run(args: Args) -> Result<(), CliError> {
    std::fs::create_dir_all(&args.out).map_err(|source| CliError::Io {
        path: args.out.display().to_string(),
        source,
    })?;
    eprintln!(
        "impeller-cam run: pipeline stages are not wired yet; created {}",
        args.out.display()
    );
    Ok(())
}
