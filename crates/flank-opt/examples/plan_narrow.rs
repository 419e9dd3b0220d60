//! Plans flank finishing of a fixture impeller (default `fixtures/impeller-30-narrow`) through
//! the `cam_plan::Operation` API and prints its metrics as JSON.
//!
//! `cargo run -p flank-opt --example plan_narrow -- [IMPELLER.toml] [semi] [key=value ...]`
//! (extra `key=value` pairs become the operation's TOML keys, e.g. `initial_path="mid_normal"`;
//! `--r=MM` and `--deg=DEG` set the job tool's ball radius and half angle, default 3 mm, 3°).

use cam_core::{Cutter, CutterShape, Tolerances};
use cam_plan::{
    ClearanceOptions, DesignClearance, Linker, OperationSpec, PlanContext, Process, SafetySurface,
    Tool,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args
        .iter()
        .find(|a| a.ends_with(".toml"))
        .cloned()
        .unwrap_or_else(|| "fixtures/impeller-30-narrow/impeller.toml".into());
    let semi = args.iter().any(|a| a == "semi");
    let extra: String = args
        .iter()
        .filter(|a| a.contains('=') && !a.starts_with("--"))
        .map(|a| format!("{a}\n"))
        .collect();
    let opt = |key: &str, default: f64| -> Result<f64, std::num::ParseFloatError> {
        args.iter()
            .find_map(|a| a.strip_prefix(&format!("--{key}=")))
            .map_or(Ok(default), str::parse)
    };
    let (r, deg) = (opt("r", 3.0)?, opt("deg", 3.0)?);
    let impeller = impeller_model::load(&path)?;
    let shape = if semi {
        CutterShape::BallEnd { radius: r }
    } else {
        CutterShape::TaperedBallEnd {
            ball_radius: r,
            half_angle: deg.to_radians(),
        }
    };
    let cutter = Cutter::new("tbe", shape, 60.0, 8.0, 70.0)?;
    let tool = Tool {
        number: 1,
        cutter,
        teeth: 4,
        tool_length_mm: 120.0,
        plunge_edge_length_mm: None,
    };
    let process = Process {
        spindle_rpm: 12000.0,
        feed_per_tooth_mm: 0.05,
        plunge_feed_per_tooth_mm: None,
        depth_of_cut_mm: None,
        width_of_cut_mm: None,
        blade_allowance_mm: if semi { 0.3 } else { 0.0 },
        hub_allowance_mm: if semi { 0.3 } else { 0.0 },
        rapid_mm_per_min: 10000.0,
    };
    let tolerances = Tolerances {
        machining_tol: 0.02,
        ..Tolerances::default()
    };
    let clearance = DesignClearance::new(&impeller, &tool, ClearanceOptions::default())?;
    let linker = Linker::new(SafetySurface::around_stock(impeller.stock(), 10.0)?);
    let ctx = PlanContext {
        impeller: &impeller,
        stock: impeller.stock(),
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
    let spec = OperationSpec {
        name: "flank".into(),
        kind: if semi {
            flank_opt::FLANK_SEMI_FINISHING
        } else {
            flank_opt::FLANK_FINISHING
        }
        .into(),
        tool: "tbe".into(),
        process,
        params: toml::from_str(&extra)?,
    };
    let op = if semi {
        flank_opt::build_flank_semi_finishing(&spec)?
    } else {
        flank_opt::build_flank_finishing(&spec)?
    };
    let t0 = std::time::Instant::now();
    let planned = op.plan(&ctx)?;
    eprintln!("planned in {:.2} s", t0.elapsed().as_secs_f64());
    println!("{}", serde_json::to_string_pretty(&planned.metrics)?);
    for n in &planned.notes {
        eprintln!("note: {n}");
    }
    if std::env::var_os("FLANK_SHOW_MAPS").is_some() {
        for plot in &planned.plots {
            if let cam_plan::PlotKind::HeatMap { values, .. } = &plot.kind {
                eprintln!("{}", plot.title);
                for row in values {
                    let cells: Vec<String> = row.iter().map(|v| format!("{v:6.3}")).collect();
                    eprintln!("  {}", cells.join(" "));
                }
            }
        }
    }
    let len: f64 = planned.paths.first().map_or(0.0, |p| p.path_length_mm());
    eprintln!("{} paths, first {len:.1} mm", planned.paths.len());
    Ok(())
}
