//! Plans the three plunge-roughing sections of `fixtures/impeller-plunge-400` (Ø30, Ø16 and
//! Ø8 plunge cutters of `fixtures/tools/plunge-cutters.toml`) from the blank turned to the
//! shroud contour and prints their metrics.
//!
//! `cargo run -p plunge-opt --example plan_plunge400`

use cam_core::{Cutter, CutterShape, HolderSegment, Tolerances};
use cam_plan::{
    ClearanceOptions, DesignClearance, Linker, OperationSpec, PlanContext, Process, SafetySurface,
    Tool,
};
use std::error::Error;
use std::path::PathBuf;

/// One cutter: (number, name, diameter, edge length, flute length, shank diameter,
/// stick-out, tool length, teeth, holder diameter, holder length).
type CutterRow = (
    u32,
    &'static str,
    f64,
    f64,
    f64,
    f64,
    f64,
    f64,
    u32,
    f64,
    f64,
);

/// The cutters of `fixtures/tools/plunge-cutters.toml`.
const CUTTERS: [CutterRow; 3] = [
    (
        31,
        "plunge-d30",
        30.0,
        8.0,
        45.0,
        28.0,
        140.0,
        210.0,
        3,
        50.0,
        45.0,
    ),
    (
        32,
        "plunge-d16",
        16.0,
        5.0,
        30.0,
        15.0,
        140.0,
        200.0,
        2,
        32.0,
        40.0,
    ),
    (
        33,
        "plunge-d8",
        8.0,
        3.0,
        20.0,
        7.5,
        140.0,
        190.0,
        2,
        25.0,
        35.0,
    ),
];

fn tool(i: usize) -> Result<Tool, Box<dyn Error>> {
    let (number, name, d, edge, flute, shank, stick, length, teeth, hd, hl) = CUTTERS[i];
    let mut cutter = Cutter::new(
        name,
        CutterShape::FlatEnd { radius: 0.5 * d },
        flute,
        0.5 * shank,
        stick,
    )?;
    cutter.holder = vec![HolderSegment {
        bottom_radius: 0.5 * hd,
        top_radius: 0.5 * hd,
        length: hl,
    }];
    Ok(Tool {
        number,
        cutter,
        teeth,
        tool_length_mm: length,
        plunge_edge_length_mm: Some(edge),
    })
}

fn main() -> Result<(), Box<dyn Error>> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/impeller-plunge-400");
    let impeller = impeller_model::load(root.join("impeller.toml"))?;
    // The blank turned to the shroud contour (as `job-plunge.toml` starts): from the uncut
    // cylinder the Ø16 and Ø8 strokes near the inlet are longer than the stick-out and their
    // holders would enter the blank (the planner refuses such plunges).
    let stock = impeller.turned_stock(0.0)?;
    let tolerances = Tolerances::default();
    let linker = Linker::new(SafetySurface::around_stock(&stock, 10.0)?);
    let mut start = 1.0;
    for i in 0..3 {
        let tool = tool(i)?;
        let process = Process {
            spindle_rpm: [3000.0, 5000.0, 8000.0][i],
            feed_per_tooth_mm: 0.1,
            plunge_feed_per_tooth_mm: Some(0.06),
            depth_of_cut_mm: None,
            width_of_cut_mm: None,
            blade_allowance_mm: 1.0,
            hub_allowance_mm: 0.5,
            rapid_mm_per_min: 10_000.0,
        };
        let mut params = toml::Table::new();
        params.insert("start_fraction".into(), toml::Value::Float(start));
        let spec = OperationSpec {
            name: format!("plunge-{}", tool.name()),
            kind: plunge_opt::KIND.into(),
            tool: tool.name().into(),
            process,
            params,
        };
        let op = plunge_opt::build(&spec)?;
        let clearance = DesignClearance::new(&impeller, &tool, ClearanceOptions::default())?;
        let ctx = PlanContext {
            impeller: &impeller,
            stock: &stock,
            tool: &tool,
            tolerances: &tolerances,
            process: &process,
            clearance: &clearance,
            linker: &linker,
            links: &cam_plan::LinkStats::default(),
        };
        let t0 = std::time::Instant::now();
        let planned = op.plan(&ctx)?;
        println!(
            "== {} ({}), planned in {:.2} s, {} paths",
            op.name(),
            tool.name(),
            t0.elapsed().as_secs_f64(),
            planned.paths.len()
        );
        for (k, v) in &planned.metrics.0 {
            println!("  {k} = {}", serde_json::to_string(v)?);
        }
        for n in &planned.notes {
            println!("  note: {n}");
        }
        if let Some(e) = planned
            .metrics
            .get("section_end_fraction")
            .and_then(|v| v.as_f64())
        {
            start = e;
        }
    }
    Ok(())
}
