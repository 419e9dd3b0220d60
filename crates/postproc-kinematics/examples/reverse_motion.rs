//! Posts a finishing pass whose C axis swings back (as in paper 004, fig. 12) on the LinuxCNC
//! xyzac-trt machine, removes the reverse motion and writes the axis displacement curves as
//! SVG: `cargo run -p postproc-kinematics --example reverse_motion -- [OUT.svg]`.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use cam_core::{CutterLocation, Move, Point3};
use postproc_kinematics::plot::displacement_svg;
use postproc_kinematics::{post_path, Machine, PostOptions, ReverseMotionOptions};

fn main() {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "reverse_motion.svg".to_string());
    let file = format!(
        "{}/../../fixtures/machines/xyzac-trt.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let m = Machine::from_file(&file).unwrap();
    let n = 200;
    let moves: Vec<Move> = (0..n)
        .map(|i| {
            let s = i as f64 / (n - 1) as f64;
            let g = (s - 0.5) / 0.06;
            let c = 60.0 * s - 20.0 * g * (-g * g).exp();
            let a = -20.0 - 10.0 * s;
            let tip = Point3::new(-30.0 + 60.0 * s, 10.0 * (3.0 * s).sin(), 5.0 + 3.0 * s);
            let mut mv = Move::feed(CutterLocation {
                tip,
                axis: m.tool_axis(a.to_radians(), c.to_radians()),
            });
            mv.feed_mm_per_min = Some(800.0);
            mv
        })
        .collect();
    let opts = PostOptions {
        reverse_motion: Some(ReverseMotionOptions::default()),
        ..Default::default()
    };
    let posted = post_path(&m, &moves, &opts).unwrap();
    let rep = posted.reverse_motion.as_ref().unwrap();
    println!(
        "reverse motions: C {} -> {}, A {} -> {}; largest angle change {:.2} deg; {} blocks ({} inserted), max linearisation error {:.4} mm",
        rep.rotate_before,
        rep.rotate_after,
        rep.tilt_before,
        rep.tilt_after,
        rep.max_angle_change_deg,
        posted.metrics.blocks,
        posted.metrics.inserted_blocks,
        posted.metrics.max_linearisation_error_mm
    );
    let svg = displacement_svg(&rep.after, Some(&rep.before), true, 800, 400);
    let tmp = format!("{out}.tmp");
    std::fs::write(&tmp, svg).unwrap();
    std::fs::rename(&tmp, &out).unwrap();
    println!("wrote {out}");
}
