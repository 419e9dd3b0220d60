//! `impeller-cam run [JOB.toml] --out DIR`: the whole pipeline.

use crate::error::CliError;
use crate::job::Job;
use std::path::PathBuf;

/// Arguments of `impeller-cam run`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Job file (TOML). Without it the embedded default job runs (fixture impeller-8+8 on
    /// the LinuxCNC xyzac-trt machine).
    pub job: Option<PathBuf>,
    /// Output directory (created if missing).
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
}

/// Runs the job and prints where its outputs are.
pub fn run(args: Args) -> Result<(), CliError> {
    let job = match &args.job {
        Some(p) => Job::from_file(p)?,
        None => Job::default_job()?,
    };
    let report = crate::pipeline::run_job(&job, &args.out)?;
    eprintln!(
        "[impeller-cam] {}: {} operation(s), program {}, report {}",
        report.job,
        report.operations.len(),
        if report.post.written {
            report.post.program.as_str()
        } else {
            "(none: nothing to machine)"
        },
        args.out.join("report.html").display()
    );
    for n in &report.notes {
        eprintln!("[impeller-cam] note: {n}");
    }
    Ok(())
}
