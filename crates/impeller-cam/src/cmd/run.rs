//! `impeller-cam run [JOB.toml] --out DIR`: the whole pipeline.

use crate::error::CliError;
use crate::job::Job;
use crate::verdict::Verdict;
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
    /// Keep the program (and exit 0) when verification finds an overcut beyond tolerance or a
    /// collision; the defects are still printed and reported.
    #[arg(long)]
    pub allow_defects: bool,
    /// No progress on stderr (stage lines and bars); the summary, notes and defects are
    /// still printed. Bars are drawn only when stderr is a terminal.
    #[arg(long, short)]
    pub quiet: bool,
    /// Write into an output folder that also holds files a run does not write (they are
    /// left untouched); without it such a folder is refused before anything runs.
    #[arg(long)]
    pub force: bool,
    /// Also write the machined stock from verification as `stock.stl` (binary STL, surface
    /// nets on the verifier's dexels at a 0.3 mm lattice or the verification resolution if
    /// coarser), to open in other viewers.
    #[arg(long)]
    pub export_stock: bool,
    /// Also write the tool paths as `toolpaths.gltf` (glTF 2.0 line primitives per
    /// operation: cutting moves in the operation's colour, links and rapids grey).
    #[arg(long)]
    pub export_paths: bool,
}

/// What `impeller-cam run` ended with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// The program passed verification (or was not verified).
    Clean,
    /// Verification found defects (see the report) and the program was withheld (no
    /// `--allow-defects`).
    Defects,
}

/// Runs the job and prints where its outputs are.
pub fn run(args: Args) -> Result<Outcome, CliError> {
    let mut job = match &args.job {
        Some(p) => Job::from_file(p)?,
        None => Job::default_job()?,
    };
    crate::outputs::check_owned(&args.out, args.force)?;
    job.verification.allow_defects = args.allow_defects;
    job.quiet = args.quiet;
    job.export_stock = args.export_stock;
    job.export_paths = args.export_paths;
    let report = crate::pipeline::run_job(&job, &args.out)?;
    for n in &report.notes {
        eprintln!("[impeller-cam] note: {n}");
    }
    let verdict = report
        .verdict
        .clone()
        .unwrap_or_else(|| Verdict::of(&report, job.tolerances.machining_tol));
    for d in &verdict.defects {
        eprintln!("[impeller-cam] DEFECT: {d}");
    }
    // A program outside the travel is never posted, --allow-defects or not.
    let kept = args.allow_defects && !verdict.outside_travel;
    if !verdict.defects.is_empty() && kept {
        eprintln!("[impeller-cam] the program was written anyway (--allow-defects)");
    }
    // The last line: what was made, whether it passed, under which limits.
    let cycle = report
        .post
        .cycle_time
        .as_ref()
        .map(|t| format!(", cycle time {}", crate::cycle::hms(t.total_s)))
        .unwrap_or_default();
    eprintln!(
        "[impeller-cam] {}: {} operation(s){cycle}, {}, report {}",
        report.job,
        report.operations.len(),
        verdict.summary(&report.post.program),
        args.out.join("report.html").display()
    );
    if verdict.defects.is_empty() || kept {
        Ok(Outcome::Clean)
    } else {
        Ok(Outcome::Defects)
    }
}
