//! `impeller-cam model [IMPELLER] [--json]`: build an impeller and print its measured summary.

use crate::error::CliError;
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
}

/// Loads the impeller, measures it and prints the summary.
pub fn run(args: Args) -> Result<(), CliError> {
    let imp = match &args.impeller {
        Some(path) => impeller_model::load(path),
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
    Ok(())
}
