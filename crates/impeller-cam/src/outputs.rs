//! The run's own files in its output folder: a run owns them, so it removes what an earlier
//! run left there before writing (a Sinumerik run into a folder used before used to leave
//! the old 9 MB `program.ngc` beside the new `program.mpf`), and removes what it wrote when
//! it fails (no partial set of outputs is left behind). Other files in the folder are never
//! touched.

use crate::error::CliError;
use std::path::{Path, PathBuf};

/// Files of a run other than the program: CL data, verification maps, reports.
const RUN_FILES: [&str; 5] = [
    "toolpath.cls",
    "verification_maps.json",
    "report.json",
    "report.html",
    "setup.html",
];

/// Every file a run may write into `out`: `program.<ext>` for every built-in dialect's
/// extension, then [`RUN_FILES`].
pub fn run_outputs(out: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = gcode_emit::DIALECT_NAMES
        .iter()
        .filter_map(|n| gcode_emit::dialect_by_name(n).ok())
        .map(|d| out.join(format!("program.{}", d.extension())))
        .collect();
    files.dedup();
    files.extend(RUN_FILES.iter().map(|f| out.join(f)));
    files
}

/// Removes the run outputs present in `out` (see [`run_outputs`]); returns those removed.
pub fn clear_run_outputs(out: &Path) -> Result<Vec<PathBuf>, CliError> {
    let mut removed = Vec::new();
    for f in run_outputs(out) {
        if f.is_file() {
            std::fs::remove_file(&f).map_err(|source| CliError::Io {
                path: f.display().to_string(),
                source,
            })?;
            removed.push(f);
        }
    }
    Ok(removed)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The program of another dialect and the old reports go; a file of the user's stays.
    #[test]
    fn earlier_run_outputs_are_removed_and_other_files_kept() {
        let d = std::env::temp_dir().join(format!("impeller-cam-outputs-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        for f in ["program.ngc", "program.h", "report.json", "notes.txt"] {
            std::fs::write(d.join(f), "x").unwrap();
        }
        let mut removed = clear_run_outputs(&d).unwrap();
        removed.sort();
        assert_eq!(
            removed,
            [
                d.join("program.h"),
                d.join("program.ngc"),
                d.join("report.json")
            ]
        );
        assert!(d.join("notes.txt").is_file());
        let extensions: Vec<String> = run_outputs(&d)
            .iter()
            .filter_map(|p| p.file_name()?.to_str().map(String::from))
            .filter(|n| n.starts_with("program."))
            .collect();
        assert!(
            extensions.contains(&"program.mpf".to_string()) && extensions.len() >= 4,
            "{extensions:?}"
        );
        std::fs::remove_dir_all(&d).unwrap();
    }
}
