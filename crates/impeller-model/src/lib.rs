//! Centrifugal impeller geometry as exact NURBS: hub, shroud, main and splitter blades,
//! channels; parametric builder, ruled and sub-ruled approximations of blades.
//!
//! Frame and units: millimetres and radians; the impeller axis is +Z pointing from the hub's
//! back face toward the inlet, origin on the axis at the back face. Hub and shroud are exact
//! NURBS surfaces of revolution of their meridional (z, r) contours; every blade side is a
//! NURBS surface parametrised u along the flow (leading → trailing edge) and v from hub to
//! shroud, extended a little beyond both.
//!
//! Entry points: [`load`] (any supported file), [`from_toml_str`] (parametric TOML),
//! [`Impeller::from_parts`] and [`Blade::from_sides`] (for importers),
//! [`fixtures::default_impeller`].
//!
//! Modules by idea: [`params`] (the TOML schema and its validation), [`builder`] (parameters →
//! NURBS), [`law`] and [`thickness`] (design laws), [`meridional`] and [`revolved`] (hub and
//! shroud), [`blade`] (sides, camber, rows), [`impeller`], [`stock`], [`channel`] (edges on
//! hub/shroud, channels, widths), [`query`] (closest points, signed distances), [`summary`],
//! [`ruled`] (ruled and sub-ruled approximation), [`fit`] (interpolation of sampled design),
//! [`root`] (bracketed scalar roots, Illinois regula falsi),
//! [`fillet`] (the rolling-ball blade-root fillet as geometry: sections, spine, distance),
//! [`levels`] (depth levels between hub and shroud, boundaries of offset surfaces on a level).
//!
//! Conventions: the hub's channel-side normal points into the channel, the shroud's out of
//! it; each blade side has an outward normal ([`Blade::outward_normal`]); blade k+1 of a row
//! is blade k turned by +2π/N about +Z, and channel k lies between main blades k and k+1. In
//! parametric impellers the suction side faces +θ, the pressure side −θ (the impeller turns
//! toward −θ; positive wrap angles sweep blades backward).
//!
//! Dependencies: `nurbs` (the project's kernel), `nalgebra` (small vectors, dense LU for
//! interpolation), `serde` + `toml` (the parametric file), `thiserror`, `rayon` (blades are
//! independent).

pub mod blade;
pub mod builder;
pub mod channel;
pub mod error;
pub mod export;
pub mod fillet;
pub mod fit;
pub mod fixtures;
pub mod impeller;
pub mod import;
pub mod law;
pub mod levels;
pub mod meridional;
pub mod params;
pub mod query;
pub mod revolved;
pub mod root;
pub mod ruled;
pub mod stock;
pub mod summary;
pub mod thickness;

pub use blade::{Blade, BladeDesign, BladeEdge, BladeKind, BladeSet, Side};
pub use error::ModelError;
pub use impeller::Impeller;
pub use meridional::MeridionalCurve;
pub use params::ImpellerSpec;
pub use revolved::RevolvedSurface;
pub use stock::Stock;
pub use thickness::{EdgeShape, ThicknessLaw};

use std::path::Path;

/// Loads an impeller from a file, choosing the reader by extension: `.toml` parametric, or an
/// import file when it has an `[import]` table ([`import::spec`]); `.inf` (TurboGrid curve
/// set), `.geomTurbo` (AutoGrid) and `.rtzt` (BladeGen, mm) exports are imported with
/// [`import::ImportOptions::default`].
pub fn load(path: impl AsRef<Path>) -> Result<Impeller, ModelError> {
    load_with_fit_tol(path, None)
}

/// [`load`] with the import fit tolerance (mm) set to `fit_tol_mm` when given: it replaces
/// the default of export files and the `fit_tol_mm` of import `.toml` files. A parametric
/// impeller file is not fitted, so a tolerance given for one is an error (never ignored).
pub fn load_with_fit_tol(
    path: impl AsRef<Path>,
    fit_tol_mm: Option<f64>,
) -> Result<Impeller, ModelError> {
    let path = path.as_ref();
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    match ext.as_deref() {
        Some("toml") => {
            let text = std::fs::read_to_string(path).map_err(|source| ModelError::Io {
                path: path.to_path_buf(),
                source,
            })?;
            if import::is_import_toml(&text) {
                return Ok(import::from_import_toml_with(&text, path, fit_tol_mm)?.impeller);
            }
            if let Some(t) = fit_tol_mm {
                return Err(import::ImportError::Invalid {
                    file: path.to_path_buf(),
                    line: 0,
                    field: "fit tolerance".into(),
                    reason: format!(
                        "{t} mm given, but a parametric impeller file is built exactly, not \
                         fitted to data"
                    ),
                }
                .into());
            }
            from_toml_str(&text, path)
        }
        Some("inf" | "geomturbo" | "rtzt") => {
            let mut opts = import::ImportOptions::default();
            if let Some(t) = fit_tol_mm {
                opts.fit_tol_mm = t;
            }
            Ok(import::import_file(path, &opts)?.impeller)
        }
        _ => Err(ModelError::UnsupportedFormat {
            path: path.to_path_buf(),
        }),
    }
}

/// 1-based line of byte offset `at` in `text`.
fn line_of(text: &str, at: usize) -> usize {
    text.as_bytes()[..at.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// Parses, validates and builds a parametric impeller from TOML text; `path` names the source
/// in errors (file and line of the offending field).
pub fn from_toml_str(text: &str, path: impl AsRef<Path>) -> Result<Impeller, ModelError> {
    let path = path.as_ref();
    let spec = ImpellerSpec::from_toml_str(text).map_err(|e| ModelError::Parse {
        path: path.to_path_buf(),
        line: e.span().map_or(0, |s| line_of(text, s.start)),
        message: e.message().trim().to_string(),
    })?;
    builder::build(&spec).map_err(|e| match e {
        ModelError::Invalid { ref field, .. } => ModelError::InFile {
            path: path.to_path_buf(),
            line: params::field_line(text, field),
            source: Box::new(e),
        },
        other => other,
    })
}
