//! `impeller-cam verify --impeller IMPELLER --cl CLFILE [--stock …] [--resolution MM] --out
//! DIR`: independent verification of a CL program (APT CLDATA with `CUTTER/` records, from any
//! CAM system) against the impeller design with the tri-dexel simulation of `machining-sim`.
//!
//! Writes `DIR/summary.json` (the DESIGN verification metrics `max_overcut_mm`,
//! `max_residual_mm`, `collisions`, their locations, every collision per move and the
//! timings), `DIR/maps.json` (overcut/residual grids per design surface), `DIR/stock.stl`
//! (the final stock) and `DIR/crosscheck.json` (dexel overcut against cam-core's swept
//! envelopes at the deepest samples).

use crate::error::CliError;
use gcode_emit::{read_cl_file, ClReadOptions};
use machining_sim::{
    crosscheck_overcut, export::write_json, extract_surface, simulate, write_stl, BoxStock,
    ImpellerDesign, ImpellerSampling, RevolvedStock, SimOptions, StockShape, TriDexel,
};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `impeller-cam verify`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Impeller file (TOML, as for `impeller-cam model`), or `default` for the embedded
    /// fixture.
    #[arg(long)]
    pub impeller: String,
    /// APT CLDATA file with `CUTTER/` records.
    #[arg(long)]
    pub cl: PathBuf,
    /// Blank: `box:XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX`, `cylinder:DIAMETER,HEIGHT` (from z = 0) or
    /// `revolved:Z,R;Z,R;...` (closed meridional outline); default: the impeller's blank.
    #[arg(long)]
    pub stock: Option<String>,
    /// Dexel cell size (mm).
    #[arg(long, default_value_t = 0.1)]
    pub resolution: f64,
    /// Output directory (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Largest thickness the overcut/residual probes measure (mm).
    #[arg(long, default_value_t = 5.0)]
    pub probe_depth: f64,
    /// STL lattice spacing in dexel cells (1 = full resolution; default: about 0.3 mm).
    #[arg(long)]
    pub stl_stride: Option<usize>,
    /// Number of deepest samples cross-checked against the swept envelopes (0 = none).
    #[arg(long, default_value_t = 20)]
    pub crosscheck: usize,
    /// Skip the shank/holder collision checks (rapid moves are always checked).
    #[arg(long)]
    pub no_collisions: bool,
}

fn numbers(text: &str, what: &str) -> Result<Vec<f64>, CliError> {
    text.split(',')
        .map(|s| {
            s.trim()
                .parse::<f64>()
                .map_err(|_| CliError::Message(format!("--stock {what}: `{s}` is not a number")))
        })
        .collect()
}

fn parse_stock(spec: &str) -> Result<Box<dyn StockShape>, CliError> {
    let msg = |e: machining_sim::SimError| CliError::Message(format!("--stock: {e}"));
    let (kind, rest) = spec.split_once(':').ok_or_else(|| {
        CliError::Message(format!(
            "--stock `{spec}`: expected box:..., cylinder:... or revolved:..."
        ))
    })?;
    match kind {
        "box" => {
            let v = numbers(rest, "box")?;
            if v.len() != 6 {
                return Err(CliError::Message(
                    "--stock box: expected 6 numbers XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX".into(),
                ));
            }
            Ok(Box::new(
                BoxStock::new([v[0], v[1], v[2]], [v[3], v[4], v[5]]).map_err(msg)?,
            ))
        }
        "cylinder" => {
            let v = numbers(rest, "cylinder")?;
            if v.len() != 2 {
                return Err(CliError::Message(
                    "--stock cylinder: expected DIAMETER,HEIGHT".into(),
                ));
            }
            Ok(Box::new(
                RevolvedStock::cylinder(0.5 * v[0], 0.0, v[1]).map_err(msg)?,
            ))
        }
        "revolved" => {
            let mut pts = Vec::new();
            for (k, pair) in rest.split(';').enumerate() {
                let v = numbers(pair, "revolved")?;
                if v.len() != 2 {
                    return Err(CliError::Message(format!(
                        "--stock revolved: point {k} must be Z,R"
                    )));
                }
                pts.push((v[0], v[1]));
            }
            Ok(Box::new(RevolvedStock::new(pts).map_err(msg)?))
        }
        other => Err(CliError::Message(format!(
            "--stock: unknown kind `{other}` (box, cylinder, revolved)"
        ))),
    }
}

/// Loads the impeller, the CL program and the blank, simulates and writes the results.
pub fn run(args: Args) -> Result<(), CliError> {
    let start = Instant::now();
    let impeller = if args.impeller == "default" {
        impeller_model::fixtures::default_impeller()
    } else {
        impeller_model::load(&args.impeller)
    }
    .map_err(|e| CliError::Message(format!("{}: {e}", args.impeller)))?;
    let program = read_cl_file(&args.cl, &ClReadOptions::default())
        .map_err(|e| CliError::Message(e.to_string()))?;
    for w in &program.warnings {
        eprintln!(
            "verify: warning: {}:{}: {}",
            args.cl.display(),
            w.line,
            w.message
        );
    }
    let mut ops = Vec::new();
    for op in &program.operations {
        let cutter = op.cutter.clone().ok_or_else(|| {
            CliError::Message(format!(
                "{}: operation `{}` has no usable CUTTER record",
                args.cl.display(),
                op.path.name
            ))
        })?;
        ops.push((cutter, op.path.clone()));
    }
    if ops.is_empty() {
        return Err(CliError::Message(format!(
            "{}: no operations with moves",
            args.cl.display()
        )));
    }
    let sim_err = |e: machining_sim::SimError| CliError::Message(e.to_string());
    let design = ImpellerDesign::new(&impeller, ImpellerSampling::default()).map_err(sim_err)?;
    let blank: Box<dyn StockShape> = match &args.stock {
        Some(spec) => parse_stock(spec)?,
        None => Box::new(design.blank().map_err(sim_err)?),
    };
    let mut stock = TriDexel::from_shape(blank.as_ref(), args.resolution).map_err(sim_err)?;
    eprintln!(
        "verify: {} operations, {} moves; stock {} rays ({:.1} MB) at {} mm",
        ops.len(),
        ops.iter().map(|(_, p)| p.moves.len()).sum::<usize>(),
        stock.ray_count(),
        stock.memory_bytes() as f64 / 1e6,
        args.resolution
    );
    let options = SimOptions {
        check_collisions: !args.no_collisions,
        probe_depth_mm: args.probe_depth,
        progress: true,
        ..SimOptions::default()
    };
    let report = simulate(&mut stock, &design, &ops, &options).map_err(sim_err)?;
    std::fs::create_dir_all(&args.out).map_err(|source| CliError::Io {
        path: args.out.display().to_string(),
        source,
    })?;
    report
        .write_summary_json(&args.out.join("summary.json"))
        .map_err(sim_err)?;
    report
        .write_maps_json(&args.out.join("maps.json"))
        .map_err(sim_err)?;
    eprintln!("verify: extracting the final stock surface");
    let stride = args
        .stl_stride
        .unwrap_or_else(|| (0.3 / args.resolution).round().max(1.0) as usize)
        .max(1);
    let mesh = extract_surface(&stock, stride);
    write_stl(
        &mesh,
        &args.out.join("stock.stl"),
        "impeller-cam verify stock",
    )
    .map_err(sim_err)?;
    if args.crosscheck > 0 {
        let checks = crosscheck_overcut(&report, &ops, args.crosscheck).map_err(sim_err)?;
        write_json(&args.out.join("crosscheck.json"), &checks).map_err(sim_err)?;
    }
    eprintln!(
        "verify: max_overcut_mm {:.4}, max_residual_mm {:.4}, collisions {} ({:.1} s); wrote {}",
        report.metrics.max_overcut_mm,
        report.metrics.max_residual_mm,
        report.metrics.collisions,
        start.elapsed().as_secs_f64(),
        args.out.display()
    );
    Ok(())
}
