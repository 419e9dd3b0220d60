//! JSON exports of a verification report: the per-surface overcut/residual maps for plots and
//! the summary with the DESIGN metric names. Files are written to a temporary file and
//! renamed into place.

use crate::error::SimError;
use crate::measure::{Extremum, SurfaceMap};
use crate::simulate::{Collision, Report, SimStats};
use serde::Serialize;
use std::path::Path;

/// Summary document: the DESIGN metrics at top level, then locations, collisions, stats.
#[derive(Debug, Clone, Serialize)]
pub struct Summary<'a> {
    /// Largest overcut (mm).
    pub max_overcut_mm: f64,
    /// Largest residual (mm).
    pub max_residual_mm: f64,
    /// Moves with a collision.
    pub collisions: usize,
    /// How much `max_overcut_mm` may under-read the true overcut (mm).
    pub overcut_error_bound_mm: f64,
    /// Where the largest overcut is.
    pub max_overcut: Option<&'a Extremum>,
    /// Where the largest residual is.
    pub max_residual: Option<&'a Extremum>,
    /// Every collision, per move and part.
    pub collision_list: &'a [Collision],
    /// Counters and timings.
    pub stats: &'a SimStats,
}

/// Maps document.
#[derive(Debug, Clone, Serialize)]
pub struct MapsDoc<'a> {
    /// Dexel cell size (mm).
    pub resolution_mm: f64,
    /// One grid per design surface (row-major in v; null = not sampled).
    pub surfaces: &'a [SurfaceMap],
}

impl Report {
    /// The summary view.
    pub fn summary(&self) -> Summary<'_> {
        Summary {
            max_overcut_mm: self.metrics.max_overcut_mm,
            max_residual_mm: self.metrics.max_residual_mm,
            collisions: self.metrics.collisions,
            overcut_error_bound_mm: self.metrics.overcut_error_bound_mm,
            max_overcut: self.max_overcut.as_ref(),
            max_residual: self.max_residual.as_ref(),
            collision_list: &self.collisions,
            stats: &self.stats,
        }
    }

    /// Writes the summary JSON.
    pub fn write_summary_json(&self, path: &Path) -> Result<(), SimError> {
        write_json(path, &self.summary())
    }

    /// Writes the per-surface maps JSON.
    pub fn write_maps_json(&self, path: &Path) -> Result<(), SimError> {
        write_json(
            path,
            &MapsDoc {
                resolution_mm: self.stats.resolution_mm,
                surfaces: &self.maps,
            },
        )
    }
}

/// Serialises `value` as pretty JSON into `path` atomically.
pub fn write_json<T: Serialize>(path: &Path, value: &T) -> Result<(), SimError> {
    let text = serde_json::to_string_pretty(value).map_err(|source| SimError::Json {
        path: path.display().to_string(),
        source,
    })?;
    let io = |source| SimError::Io {
        path: path.display().to_string(),
        source,
    };
    let tmp = path.with_extension("json.tmp");
    std::fs::write(&tmp, text).map_err(io)?;
    std::fs::rename(&tmp, path).map_err(io)
}
