//! Flank finishing of one blade side: the tool path of a tapered ball end optimised by SLP
//! (sequential linear programming with clarabel), first as a minimax problem for a fixed
//! cutter, then with the cutter shape free to maximise stiffness under the accuracy, hub and
//! clearance constraints.
//!
//! `cargo run -p flank-opt --example side_slp`
//!
//! The impeller is a 30-blade ruled design like the `impeller-30-narrow` fixture (built here
//! from parameters). The pressure side is sampled 10 × 4; the path starts from two-point
//! tangency with the ball lowered onto the hub (10 cutter locations) and runs at most four
//! SLP iterations, which keeps the example quick in the debug profile (the operation
//! `flank_finishing` uses more locations and iterations; see `examples/plan_narrow.rs`).

use cam_core::CutterShape;
use flank_opt::finishing::{optimise, RunSettings};
use flank_opt::problem::{Mode, ProblemSettings};
use flank_opt::{FlankSide, InitialPath};
use impeller_model::Side;

const IMPELLER: &str = r#"
name = "test"
fillet_radius_mm = 3.0
[hub]
type = "quarter_ellipse"
inlet_zr_mm = [70.0, 47.0]
outlet_zr_mm = [10.0, 160.0]
[shroud]
type = "quarter_ellipse"
inlet_zr_mm = [70.0, 100.0]
outlet_zr_mm = [24.0, 160.0]
[main]
count = 30
kind = "ruled"
thickness_mm = [[0.0, 2.0], [0.5, 2.4], [1.0, 2.0]]
leading_edge = "blunt"
trailing_edge = "blunt"
span_extension = 0.05
[[main.wrap]]
span = 0.0
theta_deg = [[0.0, 0.0], [0.5, 9.0], [1.0, 20.0]]
[[main.wrap]]
span = 1.0
theta_deg = [[0.0, 0.0], [0.5, 13.0], [1.0, 20.0]]
[stock]
diameter_mm = 324.0
height_mm = 74.0
"#;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let imp = impeller_model::from_toml_str(IMPELLER, "narrow-30.toml")?;
    let side = FlankSide::new(&imp, Side::Pressure, 10, 4)?;
    let run = RunSettings {
        problem: ProblemSettings {
            overcut_tol: 0.02,
            undercut_tol: 0.02,
            hub_tol: 0.01,
            min_clearance: 0.1,
            flute_length: 60.0,
            stick_out: 70.0,
            youngs: 600e3,
            min_sample_height: 3.0,
        },
        locations: 10,
        max_iterations: 4,
        trust_radius: 0.5,
        output_locations: 10,
    };
    let shape = CutterShape::TaperedBallEnd {
        ball_radius: 2.5,
        half_angle: 2f64.to_radians(),
    };
    for (label, mode) in [
        ("minimax path, cutter fixed", Mode::Minimax),
        ("shape and path for stiffness", Mode::Shape),
    ] {
        let t0 = std::time::Instant::now();
        let res = optimise(&side, shape, InitialPath::TwoPoint, mode, &run)?;
        println!("== {label} ({:.1} s)", t0.elapsed().as_secs_f64());
        println!(
            "  largest |deviation|: initial {:.4} mm",
            res.initial_max_deviation_mm
        );
        println!(
            "  final: overcut {:.4} mm, undercut {:.4} mm, hub gap {:.4} mm, \
             clearance to the next blade {:.3} mm",
            res.max_overcut_mm, res.max_undercut_mm, res.hub_error_mm, res.min_clearance_mm
        );
        println!(
            "  cutter stiffness {:.1} N/mm; {} SLP iterations, stopped: {}",
            res.stiffness_n_per_mm,
            res.iterations,
            res.termination.as_str()
        );
        let merits: Vec<String> = res
            .merit_history
            .iter()
            .map(|m| format!("{m:.4}"))
            .collect();
        println!("  merit per iteration: {}", merits.join(" → "));
        if let (Some(first), Some(last)) = (res.locations.first(), res.locations.last()) {
            println!(
                "  {} cutter locations, tip from ({:.2}, {:.2}, {:.2}) to ({:.2}, {:.2}, {:.2})",
                res.locations.len(),
                first.tip.x,
                first.tip.y,
                first.tip.z,
                last.tip.x,
                last.tip.y,
                last.tip.z
            );
        }
    }
    Ok(())
}
