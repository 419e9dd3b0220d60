//! `impeller-cam stiffness`: Rayleigh–Ritz stiffness indicator of a conical cutter.

use crate::error::CliError;
use cutter_stiffness::{ConicalCutter, RitzOptions};

/// Arguments of `impeller-cam stiffness`.
#[derive(Debug, clap::Args)]
#[command(allow_negative_numbers = true)]
pub struct Args {
    /// Radius at the ball-centre plane (mm).
    #[arg(long = "tip-radius", value_name = "MM")]
    pub tip_radius: f64,
    /// Half taper angle (degrees).
    #[arg(long = "half-angle", value_name = "DEG", default_value_t = 0.0)]
    pub half_angle: f64,
    /// Length from the chuck face to the ball-centre plane (mm).
    #[arg(long, value_name = "MM")]
    pub length: f64,
    /// Young's modulus (GPa); 600 GPa is typical of cemented carbide.
    #[arg(long, value_name = "GPA", default_value_t = 600.0)]
    pub youngs: f64,
    /// Ritz terms (default: grow until converged to 1e-10 relative, at most 80).
    #[arg(long)]
    pub terms: Option<usize>,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Computes and prints the indicator, its exact value and gradient.
pub fn run(args: Args) -> Result<(), CliError> {
    let cutter = ConicalCutter::new(
        args.tip_radius,
        args.half_angle.to_radians(),
        args.length,
        args.youngs * 1000.0,
    )
    .map_err(|e| CliError::Message(e.to_string()))?;
    let options = RitzOptions {
        terms: args.terms,
        ..RitzOptions::default()
    };
    let report = cutter
        .report(&options)
        .map_err(|e| CliError::Message(e.to_string()))?;
    if args.json {
        let text =
            serde_json::to_string_pretty(&report).map_err(|e| CliError::Message(e.to_string()))?;
        println!("{text}");
    } else {
        println!(
            "stiffness (Rayleigh-Ritz, {} terms): {:.6} N/mm",
            report.terms, report.stiffness_n_per_mm
        );
        println!(
            "exact (same beam model):       {:.6} N/mm",
            report.exact_n_per_mm
        );
        println!(
            "dk/dr:                          {:.6} N/mm per mm",
            report.d_stiffness_d_radius
        );
        println!(
            "dk/dθ:                          {:.6} N/mm per degree",
            report.d_stiffness_d_half_angle_deg
        );
    }
    Ok(())
}
