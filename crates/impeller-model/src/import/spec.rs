//! Impeller files that point at a blade-design export instead of describing parameters.
//!
//! ```toml
//! name = "impeller-autoblade-12+12"          # optional, default: the export's file stem
//! [import]
//! file = "../shared/data/pynumeca-centrifugal/cc_autoblade.geomTurbo"
//! fit_tol_mm = 0.01        # largest deviation of fitted curves/surfaces from the data
//! trim_margin = 0.1        # contours cut to the bladed part ± this fraction of it
//! keep_contours = false    # true: keep hub and shroud contours whole (no trimming)
//! span_extension = 0.05    # blade sides extended beyond hub and shroud (fraction of span)
//! fillet_radius_mm = 0.0   # blade-root fillet (not in any export format)
//! stock_margin_mm = 2.0    # cylindrical blank allowance
//! rtzt_unit = "mm"         # length unit of .rtzt files (MM, CM, M, IN, FT, UM)
//! ```
//!
//! A folder of section tables ([`super::tables`]) is imported when `file` names a folder; the
//! tables state neither unit nor blade counts, so the file gives them:
//!
//! ```toml
//! [import]
//! file = "../shared/data/nasa-hecc"
//! table_unit = "IN"        # required for a folder
//! blade_count = 15         # required for a folder: main blades
//! splitter_count = 15      # default: blade_count, when splitter sections are present
//! hub_file = "…"           # optional: the hub `x r` table (default: the folder's *hub* file)
//! shroud_file = "…"        # optional, likewise (resolved like `file`)
//! theta_sense = "counter_clockwise_looking_aft"   # or "clockwise_looking_aft"
//! ```
//!
//! `file` is resolved against this file's folder and then against each folder above it, so a
//! path written relative to the repository root (`../shared/data/...`) also works from a
//! fixture folder, in the main checkout and in nested worktrees alike. The reader is chosen
//! by the export's extension (`.inf`, `.geomTurbo`, `.rtzt`).

use super::build::{import_file, ImportOptions, Imported};
use super::error::ImportError;
use super::raw::LengthUnit;
use super::tables::{TableOptions, ThetaSense};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The `[import]` table.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImportSection {
    /// The export file (see the module docs for how it is found).
    pub file: PathBuf,
    /// Fit tolerance, mm.
    #[serde(default)]
    pub fit_tol_mm: Option<f64>,
    /// Trim margin (fraction of the bladed meridional length).
    #[serde(default)]
    pub trim_margin: Option<f64>,
    /// Keep the contours whole.
    #[serde(default)]
    pub keep_contours: bool,
    /// Blade extension beyond hub and shroud (fraction of the span).
    #[serde(default)]
    pub span_extension: Option<f64>,
    /// Blade-root fillet radius, mm.
    #[serde(default)]
    pub fillet_radius_mm: Option<f64>,
    /// Stock allowance, mm.
    #[serde(default)]
    pub stock_margin_mm: Option<f64>,
    /// Length unit of `.rtzt` files.
    #[serde(default)]
    pub rtzt_unit: Option<String>,
    /// Length unit of a folder of section tables.
    #[serde(default)]
    pub table_unit: Option<String>,
    /// Main blade count of a folder of section tables.
    #[serde(default)]
    pub blade_count: Option<usize>,
    /// Splitter count of a folder of section tables.
    #[serde(default)]
    pub splitter_count: Option<usize>,
    /// Hub contour table of a folder of section tables.
    #[serde(default)]
    pub hub_file: Option<PathBuf>,
    /// Shroud contour table of a folder of section tables.
    #[serde(default)]
    pub shroud_file: Option<PathBuf>,
    /// Sense of θ of a folder of section tables.
    #[serde(default)]
    pub theta_sense: Option<String>,
}

/// A whole import file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImportSpec {
    /// Impeller name.
    #[serde(default)]
    pub name: Option<String>,
    /// What to import and how.
    pub import: ImportSection,
}

/// Whether TOML `text` is an import file (it has an `[import]` table).
pub fn is_import_toml(text: &str) -> bool {
    text.parse::<toml::Table>()
        .is_ok_and(|t| t.contains_key("import"))
}

fn line_of(text: &str, at: usize) -> usize {
    text.as_bytes()[..at.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// Finds `rel` relative to `base` or to any folder above it.
pub fn resolve(base: &Path, rel: &Path) -> Option<PathBuf> {
    if rel.is_absolute() {
        return rel.exists().then(|| rel.to_path_buf());
    }
    // Relative bases are made absolute first so the search can climb above them.
    let base = std::fs::canonicalize(base).unwrap_or_else(|_| base.to_path_buf());
    base.ancestors().map(|a| a.join(rel)).find(|p| p.exists())
}

impl ImportSpec {
    /// Parses an import file; errors name the file and line.
    pub fn parse(text: &str, path: &Path) -> Result<Self, ImportError> {
        toml::from_str(text).map_err(|e: toml::de::Error| ImportError::Syntax {
            file: path.to_path_buf(),
            line: e.span().map_or(0, |s| line_of(text, s.start)),
            expected: e.message().trim().to_string(),
            found: e
                .span()
                .and_then(|s| text.get(s))
                .map(super::text::excerpt)
                .unwrap_or_default(),
        })
    }

    /// The options this file asks for.
    pub fn options(&self, text: &str, path: &Path) -> Result<ImportOptions, ImportError> {
        let d = ImportOptions::default();
        let s = &self.import;
        let bad = |key: &str, reason: String| ImportError::Invalid {
            file: path.to_path_buf(),
            line: super::super::params::field_line(text, &format!("import.{key}")),
            field: format!("import.{key}"),
            reason,
        };
        let unit = |key: &str, u: &str| {
            LengthUnit::from_name(u)
                .ok_or_else(|| bad(key, format!("{u:?} is not one of MM, CM, M, IN, FT, UM")))
        };
        let rtzt_unit = match &s.rtzt_unit {
            None => d.rtzt_unit,
            Some(u) => unit("rtzt_unit", u)?,
        };
        let base = path.parent().unwrap_or(Path::new("."));
        let table_file = |key: &str, f: &Option<PathBuf>| -> Result<Option<PathBuf>, ImportError> {
            match f {
                None => Ok(None),
                Some(f) => resolve(base, f).map(Some).ok_or_else(|| {
                    bad(
                        key,
                        format!(
                            "{} not found relative to {} or any folder above it",
                            f.display(),
                            base.display()
                        ),
                    )
                }),
            }
        };
        let theta_sense = match s.theta_sense.as_deref() {
            None | Some("counter_clockwise_looking_aft") => ThetaSense::CounterClockwiseLookingAft,
            Some("clockwise_looking_aft") => ThetaSense::ClockwiseLookingAft,
            Some(other) => {
                return Err(bad(
                    "theta_sense",
                    format!(
                        "{other:?} is not \"counter_clockwise_looking_aft\" or \
                         \"clockwise_looking_aft\""
                    ),
                ))
            }
        };
        let tables = TableOptions {
            unit: s
                .table_unit
                .as_deref()
                .map(|u| unit("table_unit", u))
                .transpose()?,
            blade_count: s.blade_count,
            splitter_count: s.splitter_count,
            hub_file: table_file("hub_file", &s.hub_file)?,
            shroud_file: table_file("shroud_file", &s.shroud_file)?,
            theta_sense,
        };
        Ok(ImportOptions {
            fit_tol_mm: s.fit_tol_mm.unwrap_or(d.fit_tol_mm),
            trim_margin: if s.keep_contours {
                None
            } else {
                Some(s.trim_margin.unwrap_or(0.1))
            },
            span_extension: s.span_extension.unwrap_or(d.span_extension),
            fillet_radius_mm: s.fillet_radius_mm.unwrap_or(d.fillet_radius_mm),
            stock_margin_mm: s.stock_margin_mm.unwrap_or(d.stock_margin_mm),
            name: self.name.clone(),
            rtzt_unit,
            tables,
        })
    }
}

/// Reads the export an import file points at and builds the impeller. Option values out of
/// range are reported by the stages that use them (prepare, fit, assemble).
pub fn from_import_toml(text: &str, path: &Path) -> Result<Imported, ImportError> {
    from_import_toml_with(text, path, None)
}

/// [`from_import_toml`] with the fit tolerance (mm) replaced by `fit_tol_mm` when given (a
/// command-line option overriding the file's `fit_tol_mm`).
pub fn from_import_toml_with(
    text: &str,
    path: &Path,
    fit_tol_mm: Option<f64>,
) -> Result<Imported, ImportError> {
    let spec = ImportSpec::parse(text, path)?;
    let mut opts = spec.options(text, path)?;
    if let Some(t) = fit_tol_mm {
        opts.fit_tol_mm = t;
    }
    let base = path.parent().unwrap_or(Path::new("."));
    let file = resolve(base, &spec.import.file).ok_or_else(|| ImportError::Invalid {
        file: path.to_path_buf(),
        line: super::super::params::field_line(text, "import.file"),
        field: "import.file".into(),
        reason: format!(
            "{} not found relative to {} or any folder above it",
            spec.import.file.display(),
            base.display()
        ),
    })?;
    if !file.is_dir() {
        let s = &spec.import;
        let table_keys = [
            ("table_unit", s.table_unit.is_some()),
            ("blade_count", s.blade_count.is_some()),
            ("splitter_count", s.splitter_count.is_some()),
            ("hub_file", s.hub_file.is_some()),
            ("shroud_file", s.shroud_file.is_some()),
            ("theta_sense", s.theta_sense.is_some()),
        ];
        if let Some((key, _)) = table_keys.iter().find(|(_, set)| *set) {
            return Err(ImportError::Invalid {
                file: path.to_path_buf(),
                line: super::super::params::field_line(text, &format!("import.{key}")),
                field: format!("import.{key}"),
                reason: format!(
                    "only a folder of section tables takes it; {} is a file whose format \
                     states it",
                    file.display()
                ),
            });
        }
    }
    import_file(&file, &opts)
}
