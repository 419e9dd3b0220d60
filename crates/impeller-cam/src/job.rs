//! The job file: what `impeller-cam run` machines, on which machine, in which dialect.
//!
//! ```toml
//! name = "impeller-8+8"
//! impeller = "impeller.toml"                 # relative to this file; any importable format
//! machine = "../machines/xyzac-trt.toml"     # optional: embedded xyzac-trt
//! dialect = "linuxcnc"                       # linuxcnc | fanuc | sinumerik | heidenhain
//!
//! [tolerances]                               # optional, mm
//! chord_tol = 0.01
//! linearisation_tol = 0.005
//!
//! [verification]                             # optional
//! enabled = true
//! resolution_mm = 0.1                      # dexel spacing (mm)
//!
//! [[cl_files]]                               # CL data from any CAM system: posted + verified
//! path = "rough.cls"
//! ```
//!
//! Paths are relative to the job file. Unknown keys are errors (a misspelt key must not be
//! silently ignored on a real machine).

use crate::error::CliError;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The embedded default job (the `impeller-8+8` fixture on the embedded xyzac-trt machine).
pub const DEFAULT_JOB_NAME: &str = "impeller-8+8 (embedded default)";

/// A parsed job with every path resolved against the job file's folder.
#[derive(Debug, Clone)]
pub struct Job {
    /// Job name (report title, program name).
    pub name: String,
    /// Impeller file; `None` = embedded default impeller.
    pub impeller: Option<PathBuf>,
    /// Machine file; `None` = embedded xyzac-trt machine.
    pub machine: Option<PathBuf>,
    /// Dialect name.
    pub dialect: String,
    /// Tolerances.
    pub tolerances: cam_core::Tolerances,
    /// Verification settings.
    pub verification: VerificationSpec,
    /// CL files to post-process and verify.
    pub cl_files: Vec<PathBuf>,
}

/// Verification settings of a job.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct VerificationSpec {
    /// Run the stock simulation.
    pub enabled: bool,
    /// Dexel spacing (mm).
    pub resolution_mm: f64,
}

impl Default for VerificationSpec {
    fn default() -> Self {
        Self {
            enabled: true,
            resolution_mm: 0.1,
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawJob {
    name: Option<String>,
    impeller: Option<PathBuf>,
    machine: Option<PathBuf>,
    #[serde(default = "default_dialect")]
    dialect: String,
    #[serde(default)]
    tolerances: Option<RawTolerances>,
    #[serde(default)]
    verification: VerificationSpec,
    #[serde(default)]
    cl_files: Vec<RawClFile>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTolerances {
    chord_tol: Option<f64>,
    machining_tol: Option<f64>,
    linearisation_tol: Option<f64>,
    stock_allowance: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawClFile {
    path: PathBuf,
}

fn default_dialect() -> String {
    "linuxcnc".into()
}

impl Job {
    /// The embedded default job.
    pub fn default_job() -> Self {
        Self {
            name: DEFAULT_JOB_NAME.into(),
            impeller: None,
            machine: None,
            dialect: default_dialect(),
            tolerances: cam_core::Tolerances::default(),
            verification: VerificationSpec::default(),
            cl_files: Vec::new(),
        }
    }

    /// Reads and validates a job file. Errors name the file, the line and the field.
    pub fn from_file(path: &Path) -> Result<Self, CliError> {
        let text = std::fs::read_to_string(path).map_err(|source| CliError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_toml_str(&text, path)
    }

    /// Parses job text; `path` locates relative paths and names the file in errors.
    pub fn from_toml_str(text: &str, path: &Path) -> Result<Self, CliError> {
        let raw: RawJob = toml::from_str(text).map_err(|e| {
            let line = e
                .span()
                .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1)
                .unwrap_or(0);
            CliError::Message(format!("{}:{line}: {}", path.display(), e.message().trim()))
        })?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let resolve = |p: PathBuf| if p.is_absolute() { p } else { dir.join(p) };
        let mut tolerances = cam_core::Tolerances::default();
        if let Some(t) = raw.tolerances {
            tolerances.chord_tol = t.chord_tol.unwrap_or(tolerances.chord_tol);
            tolerances.machining_tol = t.machining_tol.unwrap_or(tolerances.machining_tol);
            tolerances.linearisation_tol =
                t.linearisation_tol.unwrap_or(tolerances.linearisation_tol);
            tolerances.stock_allowance = t.stock_allowance.unwrap_or(tolerances.stock_allowance);
        }
        tolerances
            .validate()
            .map_err(|e| CliError::Message(format!("{}: [tolerances] {e}", path.display())))?;
        let v = raw.verification;
        if !(v.resolution_mm.is_finite() && v.resolution_mm > 0.0) {
            return Err(CliError::Message(format!(
                "{}: [verification] resolution_mm = {} must be finite and > 0",
                path.display(),
                v.resolution_mm
            )));
        }
        let name = raw.name.unwrap_or_else(|| {
            path.parent()
                .and_then(|p| p.file_name())
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| "job".into())
        });
        Ok(Self {
            name,
            impeller: raw.impeller.map(resolve),
            machine: raw.machine.map(resolve),
            dialect: raw.dialect,
            tolerances,
            verification: v,
            cl_files: raw.cl_files.into_iter().map(|c| resolve(c.path)).collect(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_resolve_against_the_job_folder() {
        let job = Job::from_toml_str(
            "name = \"j\"\nimpeller = \"imp.toml\"\nmachine = \"../m.toml\"\n[[cl_files]]\npath = \"a.cls\"\n",
            Path::new("/x/y/job.toml"),
        )
        .unwrap();
        assert_eq!(job.impeller.unwrap(), Path::new("/x/y/imp.toml"));
        assert_eq!(job.machine.unwrap(), Path::new("/x/y/../m.toml"));
        assert_eq!(job.cl_files, vec![PathBuf::from("/x/y/a.cls")]);
        assert_eq!(job.dialect, "linuxcnc");
    }

    #[test]
    fn errors_name_file_line_and_field() {
        let err = Job::from_toml_str("name = \"j\"\nimpeler = \"x\"\n", Path::new("job.toml"))
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("job.toml:2:"), "{err}");
        assert!(err.contains("impeler"), "{err}");
        let err = Job::from_toml_str("[tolerances]\nchord_tol = -1.0\n", Path::new("job.toml"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("chord_tol"), "{err}");
        let err = Job::from_toml_str(
            "[verification]\nresolution_mm = 0.0\n",
            Path::new("job.toml"),
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("resolution_mm"), "{err}");
    }
}
