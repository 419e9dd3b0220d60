//! Plans the three plunge-roughing sections of `fixtures/impeller-plunge-400` (Ø30, Ø16 and
//! Ø8 plunge cutters of `fixtures/tools/plunge-cutters.toml`) from the blank turned to the
//! shroud contour and prints their metrics.
//!
//! `cargo run --release -p plunge-opt --example plan_plunge400 [-- --fine]`; with `--fine`
//! each section's plan is also re-measured with the centre disk sampled 0.05 mm apart.

use cam_core::{Cutter, CutterShape, HolderSegment, Tolerances};
use cam_plan::{
    ClearanceOptions, DesignClearance, Linker, OperationSpec, PlanContext, Process, SafetySurface,
    Tool,
};
use plunge_opt::interference::{travel_sampled, Material, Stroke, INTERFERENCE_TRAVEL_TOL_MM};
use rayon::prelude::*;
use std::error::Error;
use std::path::PathBuf;

/// One flat-end tool: (number, name, diameter, plunge edge length (`None`: cuts to the
/// centre), flute length, shank diameter, stick-out, tool length, teeth, holder diameter,
/// holder length).
type ToolRow = (
    u32,
    &'static str,
    f64,
    Option<f64>,
    f64,
    f64,
    f64,
    f64,
    u32,
    f64,
    f64,
);

/// The plunge cutters of `fixtures/tools/plunge-cutters.toml`.
const CUTTERS: [ToolRow; 3] = [
    (
        31,
        "plunge-d30",
        30.0,
        Some(8.0),
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
        Some(5.0),
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
        Some(3.0),
        20.0,
        7.5,
        140.0,
        190.0,
        2,
        25.0,
        35.0,
    ),
];

/// The flat-bottom pilot drills of the same file.
const DRILLS: [ToolRow; 2] = [
    (
        34,
        "drill-d16",
        16.0,
        None,
        90.0,
        16.0,
        140.0,
        200.0,
        2,
        32.0,
        40.0,
    ),
    (
        35, "drill-d8", 8.0, None, 100.0, 8.0, 140.0, 190.0, 2, 25.0, 35.0,
    ),
];

fn flat_tool(row: ToolRow) -> Result<Tool, Box<dyn Error>> {
    let (number, name, d, edge, flute, shank, stick, length, teeth, hd, hl) = row;
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
        plunge_edge_length_mm: edge,
    })
}

fn main() -> Result<(), Box<dyn Error>> {
    let fine = std::env::args().any(|a| a == "--fine");
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/impeller-plunge-400");
    let impeller = impeller_model::load(root.join("impeller.toml"))?;
    // The blank turned to the shroud contour (as `job.toml` starts): from the uncut
    // cylinder the Ø16 and Ø8 strokes near the inlet are longer than the stick-out and their
    // holders would enter the blank (the planner refuses such plunges).
    let stock = impeller.turned_stock(0.0)?;
    let tolerances = Tolerances::default();
    let linker = Linker::new(SafetySurface::around_stock(&stock, 10.0)?);
    let mut start = 1.0;
    for i in 0..3 {
        let tool = flat_tool(CUTTERS[i])?;
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
        let drill = flat_tool(DRILLS[if i == 0 { 0 } else { 1 }])?;
        let params: toml::Table = toml::from_str(&format!(
            "start_fraction = {start:?}\n[pilot]\ntool = \"{}\"\nspindle_rpm = 4000.0\n\
             feed_per_tooth_mm = 0.05",
            drill.name()
        ))?;
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
            reach: None,
            remaining: None,
            progress: None,
        };
        let t0 = std::time::Instant::now();
        let (planned, steps) = op.plan_with_steps(&ctx, &[&drill])?;
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
        for step in &steps {
            println!(
                "  step {} ({}, {}): {} paths",
                step.name,
                step.kind,
                step.tool,
                step.planned.paths.len()
            );
            for (k, v) in &step.planned.metrics.0 {
                println!("    {k} = {}", serde_json::to_string(v)?);
            }
        }
        if fine {
            // The plan re-measured with the centre disk sampled 0.05 mm apart (5× finer than
            // the planner's 0.25 mm): how much the sampling hides between samples.
            let section = plunge_opt::PlungeRoughing::from_spec(&spec)?;
            let plan = section.plan_section(&ctx, Some(&drill))?;
            let r = 0.5 * CUTTERS[i].2;
            let core = r - CUTTERS[i].3.unwrap_or(r);
            let pilot_r = drill.cutter.shape.radius_at(0.0);
            let drilled: Vec<Stroke> = plan
                .feed
                .pilots
                .iter()
                .map(|p| plunge_opt::entries::pilot_stroke(p, pilot_r))
                .collect();
            let material = Material {
                drilled: &drilled,
                ..Material::stock(&stock)
            };
            let strokes: Vec<Stroke> = plan
                .final_segments()
                .iter()
                .flatten()
                .map(|p| plunge_opt::feed_plan::stroke(p, r, core))
                .collect();
            let fine: Vec<f64> = (0..strokes.len())
                .into_par_iter()
                .map(|k| travel_sampled(&strokes[k], &strokes[..k], &material, 0.05))
                .collect();
            println!(
                "  fine check (0.05 mm disk sampling): {} plunges above {} mm, largest travel {:.4} mm \
                 (planner's 0.25 mm sampling: {:.4} mm)",
                fine.iter().filter(|t| **t > INTERFERENCE_TRAVEL_TOL_MM).count(),
                INTERFERENCE_TRAVEL_TOL_MM,
                fine.iter().copied().fold(0.0, f64::max),
                plan.feed.travel.iter().copied().fold(0.0, f64::max)
            );
        }
        // The next section starts a little toward the outlet from where this one ended
        // (as job.toml does).
        start = [0.33, 0.07, 0.0][i];
    }
    Ok(())
}
