//! `impeller-cam stiffness`: Rayleigh–Ritz stiffness indicator of a conical cutter.

use crate::error::CliError;
use cutter_stiffness::{ConicalCutter, RitzOptions};
use serde::Serialize;

/// What `--json` prints: the indicator and its gradient in the command's own parameters
/// (radius at the ball-centre plane, half angle in degrees, chuck-to-ball-centre length).
#[derive(Debug, Serialize)]
struct Output {
    stiffness_n_per_mm: f64,
    exact_n_per_mm: f64,
    terms: usize,
    /// ∂k/∂(radius at the ball-centre plane), half angle and length held (N/mm per mm).
    d_stiffness_d_radius: f64,
    /// ∂k/∂θ, radius at the ball-centre plane and length held (N/mm per degree).
    d_stiffness_d_half_angle_deg: f64,
}

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
    // The command speaks the literature's beam form; the model is parametrised by ball radius
    // r = r_c cos θ and tip-to-chuck length L + r (see cutter_stiffness::ConicalCutter).
    // Checked here in the command's own names (the model's error would name its internal
    // parameters: `--tip-radius -1` said `bottom_radius`, `--half-angle 95` `ball_radius`).
    let bad = |option: &str, value: f64, want: &str| {
        Err(CliError::Message(format!(
            "--{option} {value}: must be {want}"
        )))
    };
    if !(args.tip_radius.is_finite() && args.tip_radius > 0.0) {
        return bad("tip-radius", args.tip_radius, "a radius > 0 mm");
    }
    if !(args.half_angle.is_finite() && (0.0..90.0).contains(&args.half_angle)) {
        return bad("half-angle", args.half_angle, "an angle in [0, 90) degrees");
    }
    if !(args.length.is_finite() && args.length > 0.0) {
        return bad("length", args.length, "a length > 0 mm");
    }
    if !(args.youngs.is_finite() && args.youngs > 0.0) {
        return bad("youngs", args.youngs, "a modulus > 0 GPa");
    }
    let theta = args.half_angle.to_radians();
    let cutter =
        ConicalCutter::from_load_plane(args.tip_radius, theta, args.length, args.youngs * 1000.0)
            .map_err(|e| CliError::Message(e.to_string()))?;
    let options = RitzOptions {
        terms: args.terms,
        ..RitzOptions::default()
    };
    let rep = cutter
        .report(&options)
        .map_err(|e| CliError::Message(e.to_string()))?;
    // Chain rule back to (r_c, θ, L): r = r_c cos θ, length = L + r_c cos θ.
    let (sn, co) = theta.sin_cos();
    let k_r = rep.d_stiffness_d_ball_radius;
    let k_len = rep.d_stiffness_d_length;
    let report = Output {
        stiffness_n_per_mm: rep.stiffness_n_per_mm,
        exact_n_per_mm: rep.exact_n_per_mm,
        terms: rep.terms,
        d_stiffness_d_radius: (k_r + k_len) * co,
        d_stiffness_d_half_angle_deg: (rep.d_stiffness_d_half_angle
            - (k_r + k_len) * args.tip_radius * sn)
            * (std::f64::consts::PI / 180.0),
    };
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
