//! Reads the embedded default job (the one `impeller-cam run` runs without a job file) and
//! prints its plan: machine, dialect, tolerances, verification settings, tools, operations in
//! order with their process rows and the CL files it posts — without running it.
//!
//! `cargo run -p impeller-cam --example default_job`
//!
//! Running the whole pipeline (`impeller_cam::run_job`) plans every operation, post-processes
//! and verifies by stock simulation; use the command line in release for that:
//! `cargo run --release -p impeller-cam -- run --out out/`.

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let job = impeller_cam::Job::default_job()?;
    println!("job `{}`", job.name);
    if let Some(p) = &job.impeller {
        println!("  impeller  {}", p.display());
    }
    if let Some(p) = &job.machine {
        println!("  machine   {}", p.display());
    }
    println!("  dialect   {}", job.dialect);
    println!("  tolerances {:?}", job.tolerances);
    println!(
        "  verification: {} at {} mm",
        if job.verification.enabled {
            "on"
        } else {
            "off"
        },
        job.verification.resolution_mm
    );
    println!("tools:");
    for t in &job.tools {
        println!(
            "  T{:<3} {:<24} {:?}",
            t.number, t.cutter.name, t.cutter.shape
        );
    }
    println!("operations:");
    if job.operations.is_empty() {
        println!("  (none)");
    }
    for (i, op) in job.operations.iter().enumerate() {
        let p = &op.process;
        println!(
            "  {:>2}. {:<28} {:<24} tool {:<22} {:>6.0} rpm, {:.3} mm/tooth",
            i + 1,
            op.name,
            op.kind,
            op.tool,
            p.spindle_rpm,
            p.feed_per_tooth_mm
        );
    }
    println!("CL files (posted and verified like planned operations):");
    for f in &job.cl_files {
        println!("  {}", f.display());
    }
    Ok(())
}
