//! `impeller-cam model [IMPELLER] [--json] [--fit-tol MM] [--stl FILE] [--curves DIR]`: build an impeller,
//! print its measured summary, and optionally export it as a binary STL (hub, blades and
//! their blade-root fillets, within `--chord-tol`) and as TurboGrid curve files
//! (`impeller.inf`, hub, shroud and profile curves, which `model` reads back).

use crate::error::CliError;
use impeller_model::export::{write_curves, write_stl, CurveSampling, Part};
use std::path::PathBuf;

/// Arguments of `impeller-cam model`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Impeller file (parametric `.toml`, or any format `impeller_model::load` reads).
    /// Without it the embedded default impeller (fixture `impeller-8+8`) is used.
    pub impeller: Option<PathBuf>,
    /// Print the summary as JSON on stdout (otherwise as aligned text).
    #[arg(long)]
    pub json: bool,
    /// Write the hub and all blades as a binary STL file.
    #[arg(long, value_name = "FILE")]
    pub stl: Option<PathBuf>,
    /// Largest distance between the STL triangles and the exact surfaces (mm).
    #[arg(long, value_name = "MM", default_value_t = 0.01)]
    pub chord_tol: f64,
    /// Fit tolerance of an imported export (mm): the largest deviation of the fitted hub,
    /// shroud and blade sides from the file's points. Overrides an import file's
    /// `fit_tol_mm`; default 0.01 mm. Not accepted for a parametric impeller (not fitted).
    #[arg(long, value_name = "MM")]
    pub fit_tol: Option<f64>,
    /// Write TurboGrid curve files (impeller.inf, hub.curve, shroud.curve, profiles) into DIR.
    #[arg(long, value_name = "DIR")]
    pub curves: Option<PathBuf>,
}

/// Loads the impeller, measures it and prints the summary.
pub fn run(args: Args) -> Result<(), CliError> {
    let imp = match &args.impeller {
        Some(path) => impeller_model::load_with_fit_tol(path, args.fit_tol),
        None if args.fit_tol.is_some() => {
            return Err(CliError::Message(
                "--fit-tol applies to an imported export; the embedded default impeller is \
                 parametric"
                    .into(),
            ))
        }
        None => impeller_model::fixtures::default_impeller(),
    }
    .map_err(|e| CliError::Message(e.to_string()))?;
    let summary = imp.summary();
    if args.json {
        let text = serde_json::to_string_pretty(&summary)
            .map_err(|e| CliError::Message(format!("cannot format summary: {e}")))?;
        println!("{text}");
    } else {
        let value = serde_json::to_value(&summary)
            .map_err(|e| CliError::Message(format!("cannot format summary: {e}")))?;
        if let serde_json::Value::Object(map) = value {
            for (k, v) in map {
                println!("{k:<30} {v}");
            }
        }
    }
    if let Some(path) = &args.stl {
        let stats = write_stl(&imp, &[Part::Impeller], args.chord_tol, path)
            .map_err(|e| CliError::Message(e.to_string()))?;
        eprintln!(
            "wrote {} ({} triangles, chord tolerance {} mm)",
            path.display(),
            stats.triangles,
            stats.chord_tol_mm
        );
    }
    if let Some(dir) = &args.curves {
        let files = write_curves(&imp, dir, "impeller", &CurveSampling::default())
            .map_err(|e| CliError::Message(e.to_string()))?;
        eprintln!(
            "wrote {} and {} curve files in {}",
            files.inf.display(),
            files.curves.len(),
            dir.display()
        );
    }
    Ok(())
}
