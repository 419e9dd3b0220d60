//! Stiffness indicator of a tapered ball-end cutter against its taper angle.
//!
//! `cargo run -p cutter-stiffness --example taper_sweep`
//!
//! A carbide cutter (E = 600 GPa) with radius 3.14 mm at the ball-centre plane and a 40 mm beam
//! from the chuck face to that plane (the command line's `stiffness` example): the
//! Rayleigh–Ritz indicator, the exact value of the same beam model, the ratio to the
//! cylindrical cutter and the gradient an optimiser uses, for half angles 0°–5°.
#![allow(clippy::approx_constant)] // 3.14 mm is a published cutter radius, not π.

use cutter_stiffness::{ConicalCutter, RitzOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    const E_CARBIDE: f64 = 600e3; // N/mm²
    let cylinder = ConicalCutter::from_load_plane(3.14, 0.0, 40.0, E_CARBIDE)?
        .report(&RitzOptions::default())?
        .stiffness_n_per_mm;
    println!(
        "{:>6} {:>12} {:>12} {:>9} {:>14} {:>14} {:>14}",
        "θ/deg", "k_ritz N/mm", "k_exact N/mm", "k/k_cyl", "dk/dr", "dk/dθ", "dk/dlength"
    );
    for deg in 0..=5 {
        let theta = f64::from(deg).to_radians();
        let cutter = ConicalCutter::from_load_plane(3.14, theta, 40.0, E_CARBIDE)?;
        let r = cutter.report(&RitzOptions::default())?;
        println!(
            "{deg:>6} {:>12.2} {:>12.2} {:>9.3} {:>14.2} {:>14.2} {:>14.3}",
            r.stiffness_n_per_mm,
            r.exact_n_per_mm,
            r.stiffness_n_per_mm / cylinder,
            r.d_stiffness_d_ball_radius,
            r.d_stiffness_d_half_angle,
            r.d_stiffness_d_length,
        );
    }
    Ok(())
}
