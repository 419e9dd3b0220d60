//! Plans blade-root finishing of the fixture impeller through the `cam_plan::Operation` API
//! and prints the operation's metrics.
//!
//! `cargo run -p channel-paths --example blade_root`
//!
//! A ball end of radius 1 mm (the impeller's fillet radius) runs along the intersection of the
//! hub's and each blade side's offset surfaces, so its centre stays one ball radius from both;
//! the tool axis leans away from the blade until the shank and holder clear the design. Three
//! stations per blade side keep the example quick in the debug profile (the job default is
//! finer); the reference blade's two sides are planned and copied to all 16 blades.

use cam_core::{Cutter, CutterShape, HolderSegment, Tolerances};
use cam_plan::{
    ClearanceOptions, DesignClearance, Linker, MetricValue, OperationSpec, PlanContext, Process,
    SafetySurface, Tool,
};

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
    let process = Process {
        spindle_rpm: 6000.0,
        feed_per_tooth_mm: 0.1,
        plunge_feed_per_tooth_mm: None,
        depth_of_cut_mm: Some(0.2),
        width_of_cut_mm: Some(0.5),
        blade_allowance_mm: 0.0,
        hub_allowance_mm: 0.0,
        rapid_mm_per_min: 10000.0,
    };
    let tolerances = Tolerances::default();
    let clearance = DesignClearance::new(
        &imp,
        &tool,
        ClearanceOptions {
            sample_tol_mm: 0.05,
            ..ClearanceOptions::default()
        },
    )?;
    let linker = Linker::new(SafetySurface::around_stock(imp.stock(), 10.0)?);
    let ctx = PlanContext {
        impeller: &imp,
        stock: imp.stock(),
        tool: &tool,
        tolerances: &tolerances,
        process: &process,
        clearance: &clearance,
        linker: &linker,
        links: &cam_plan::LinkStats::default(),
        reach: None,
        remaining: None,
        progress: None,
    };
    let op = channel_paths::build_blade_root_finishing(&OperationSpec {
        name: "root".into(),
        kind: channel_paths::BLADE_ROOT_FINISHING.into(),
        tool: "ball-r1".into(),
        process,
        params: toml::from_str("stations = 3")?,
    })?;
    let planned = op.plan(&ctx)?;
    let moves: usize = planned.paths.iter().map(|p| p.moves.len()).sum();
    println!(
        "{} tool paths (one per blade side), {moves} moves",
        planned.paths.len()
    );
    for (name, value) in &planned.metrics.0 {
        let text = match value {
            MetricValue::Bool(b) => b.to_string(),
            MetricValue::Count(n) => n.to_string(),
            MetricValue::Number(x) => format!("{x:.4}"),
            MetricValue::Text(t) => t.clone(),
        };
        println!("  {name:<32} {text}");
    }
    for note in &planned.notes {
        println!("note: {note}");
    }
    Ok(())
}
