//! `impeller-cam`: the job pipeline of the impeller five-axis CAM toolkit as a library, and
//! the command line over it.
//!
//! [`run_job`] runs a [`Job`] (parsed from a job file with [`Job::from_file`], or the embedded
//! default [`Job::default_job`]) end to end and writes the program, the CL file and the
//! reports into a folder: impeller model → planned operations → post-processing → independent
//! verification → reports (see [`pipeline`]). Operation kinds are found in a registry
//! ([`registry::OPERATIONS`]); [`run_job_with`] takes another one (a library user's own
//! operations, or test operations).
//!
//! The command line (`src/main.rs`) is a thin layer over [`cmd`]: every subcommand exits 0 on
//! success and 1 on a user error with one clear line on stderr (`../shared/DESIGN.md` §4).

pub mod cmd;
pub mod cycle;
pub mod error;
pub mod gltf;
pub mod job;
pub mod outputs;
pub mod pipeline;
pub mod plot;
pub mod progress;
pub mod registry;
pub mod report;
pub mod setup;
pub mod surface_groups;
pub mod travel;
pub mod verdict;
pub mod view3d;

pub use error::CliError;
pub use job::Job;
pub use pipeline::{run_job, run_job_with};
pub use report::Report;

/// Exit code of `impeller-cam run` when verification finds an overcut beyond the tolerance
/// (`machining_tol` plus the simulation's error bound) or a collision: the report is written
/// and shows where, the program is withheld (`--allow-defects` keeps it and exits 0); also
/// when the machine cannot hold the planned tool paths within its travel (no program is
/// posted; the report lists the violations).
pub const EXIT_DEFECTS: u8 = 3;

// The README's code blocks are compiled and run as doc tests (`cargo test --doc`).
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
