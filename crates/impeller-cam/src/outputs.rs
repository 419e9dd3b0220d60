//! The run's own files in its output folder: a run owns them, so it removes what an earlier
//! run left there before writing (a Sinumerik run into a folder used before used to leave
//! the old 9 MB `program.ngc` beside the new `program.mpf`), and removes what it wrote when
//! it fails (no partial set of outputs is left behind). Other files in the folder are never
//! touched.

use crate::error::CliError;
use std::path::{Path, PathBuf};

/// Files of a run other than the program: CL data, verification maps, exports, reports.
const RUN_FILES: [&str; 7] = [
    "toolpath.cls",
    "verification_maps.json",
    "stock.stl",
    "toolpaths.gltf",
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

/// Refuses an output folder that holds entries a run does not write (see [`run_outputs`]),
/// unless `force`: a run into a folder of other work (`--out .` in a project folder, a
/// mistyped path) would otherwise mix its outputs with files it does not own. Nothing is
/// read or changed; a missing folder is fine. The error names the folder, up to three of
/// the entries and how many there are, and the two ways on.
pub fn check_owned(out: &Path, force: bool) -> Result<(), CliError> {
    if force {
        return Ok(());
    }
    let entries = match std::fs::read_dir(out) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(source) => {
            return Err(CliError::Io {
                path: out.display().to_string(),
                source,
            })
        }
    };
    let owned = run_outputs(out);
    let mut foreign: Vec<String> = entries
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| !owned.contains(p))
        .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    if foreign.is_empty() {
        return Ok(());
    }
    foreign.sort();
    let n = foreign.len();
    let shown = foreign
        .iter()
        .take(3)
        .map(|f| format!("`{f}`"))
        .collect::<Vec<_>>()
        .join(", ");
    let more = if n > 3 {
        format!(" and {} more", n - 3)
    } else {
        String::new()
    };
    Err(CliError::Message(format!(
        "--out {}: the folder holds {n} entr{} a run does not write ({shown}{more}); give an \
         empty or new folder, or --force to write the run's files beside them (they are left \
         untouched)",
        out.display(),
        if n == 1 { "y" } else { "ies" }
    )))
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

    /// A folder of other work is refused before a run (issue 35: a run owns its folder, and
    /// refuses one holding other files unless --force); a folder of run outputs only, an empty
    /// or a missing one is fine.
    #[test]
    fn a_folder_of_other_files_is_refused_unless_forced() {
        let d = std::env::temp_dir().join(format!("impeller-cam-owned-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        assert!(check_owned(&d, false).is_ok(), "missing folder");
        std::fs::create_dir_all(&d).unwrap();
        assert!(check_owned(&d, false).is_ok(), "empty folder");
        for f in ["program.mpf", "report.html", "toolpath.cls"] {
            std::fs::write(d.join(f), "x").unwrap();
        }
        assert!(check_owned(&d, false).is_ok(), "run outputs only");
        for f in ["Cargo.toml", "a.txt", "b.txt", "c.txt"] {
            std::fs::write(d.join(f), "x").unwrap();
        }
        std::fs::create_dir_all(d.join("src")).unwrap();
        let e = check_owned(&d, false).unwrap_err().to_string();
        assert!(
            e.contains(
                "holds 5 entries a run does not write (`Cargo.toml`, `a.txt`, `b.txt` and 2 more)"
            ) && e.contains("--force"),
            "{e}"
        );
        assert!(check_owned(&d, true).is_ok());
        std::fs::remove_dir_all(&d).unwrap();
    }
}
