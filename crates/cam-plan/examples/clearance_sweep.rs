//! The design clearance query: how far a ball-end tool with shank and holder stays from the
//! fixture impeller's hub, shroud contour and blades as it moves across a channel.
//!
//! `cargo run -p cam-plan --example clearance_sweep`
//!
//! The tool (ball end r = 1 mm, 6 mm flutes, Ø3 mm shank, 25 mm stick-out, Ø20 × 30 mm
//! holder) stands on the hub's channel-side normal, its tip 0.5 mm above the hub, at
//! mid-meridian, and is carried through one blade pitch (45°, main blade to main blade with
//! a splitter between). For each angle the query reports the signed clearance, the nearest
//! design part and which part of the tool is nearest.

use cam_core::{Cutter, CutterLocation, CutterShape, HolderSegment, Point3};
use cam_plan::{ClearanceOptions, DesignClearance, Tool};
use std::f64::consts::PI;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let imp = impeller_model::fixtures::default_impeller()?;
    let mut cutter = Cutter::new(
        "ball-r1",
        CutterShape::BallEnd { radius: 1.0 },
        6.0,
        1.5,
        25.0,
    )?;
    cutter.holder = vec![HolderSegment {
        bottom_radius: 10.0,
        top_radius: 10.0,
        length: 30.0,
    }];
    let tool = Tool {
        number: 7,
        cutter,
        teeth: 2,
        tool_length_mm: 80.0,
        plunge_edge_length_mm: None,
    };
    let options = ClearanceOptions {
        sample_tol_mm: 0.05,
        ..ClearanceOptions::default()
    };
    let query = DesignClearance::new(&imp, &tool, options)?;
    let hub = imp.hub();
    let pitch = 2.0 * PI / imp.summary().main_blade_count as f64;
    println!(
        "{:>8} {:>14} {:>10}  nearest design part",
        "φ/deg", "clearance/mm", "tool part"
    );
    for k in 0..=16 {
        let phi = pitch * f64::from(k) / 16.0;
        let n = hub.normal(0.5, phi);
        let tip = hub.point(0.5, phi) + n * 0.5;
        let cl = CutterLocation::new(Point3::from(tip), n)?;
        let c = query.clearance(&cl);
        println!(
            "{:>8.2} {:>14.3} {:>10}  {:?}",
            phi.to_degrees(),
            c.distance_mm,
            format!("{:?}", c.tool_part),
            c.design_part
        );
    }
    Ok(())
}
