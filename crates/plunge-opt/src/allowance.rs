//! Hub allowance: the material the plunges leave above the hub on the channel floor.
//!
//! What is measured: on a grid of [`GRID_M`] × [`GRID_S`] hub points `H` over the section's
//! floor (channel coordinates `(m, s)`, [`crate::rows::ChannelFrame`]), a point is *covered*
//! by a plunge when the line through `H` along the plunge's axis passes within the cutter
//! radius of the axis, i.e. `H` lies under the plunge's bottom disk. Above a covered point
//! the floor after roughing is the lowest of the covering plunges' bottom planes; the height
//! of that plane above `H`, measured along the hub normal at `H`, is the allowance left
//! there (the process row's hub allowance plus whatever the flat bottoms leave between
//! their tangency rings and across the cusps between footprints). Points no plunge covers
//! (the strip along the blades outside the side rows' footprints) are not part of the
//! floor the plunges machine and are left out. The maximum and the mean over covered points
//! are reported.
//!
//! Cost: O(grid × plunges), independent per grid point (rayon).

use crate::axial_depth::{Floor, RevolvedFloor};
use crate::interference::Stroke;
use crate::rows::ChannelFrame;
use rayon::prelude::*;

/// Grid points along the meridian over the section.
pub const GRID_M: usize = 81;
/// Grid points across the channel.
pub const GRID_S: usize = 41;

/// Hub allowance statistics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HubAllowance {
    /// Largest height of the roughed floor above the hub (mm).
    pub max_mm: f64,
    /// Mean over covered grid points (mm).
    pub mean_mm: f64,
    /// Grid points covered by at least one plunge.
    pub covered: usize,
}

/// The hub allowance left by `strokes` over the floor `m ∈ [m_lo, m_hi]`, `s ∈ [0, 1]`.
pub fn hub_allowance(
    frame: &ChannelFrame<'_>,
    strokes: &[Stroke],
    m_lo: f64,
    m_hi: f64,
) -> HubAllowance {
    let hub = RevolvedFloor::new(frame.impeller().hub().meridional());
    let pts: Vec<(usize, usize)> = (0..GRID_M)
        .flat_map(|i| (0..GRID_S).map(move |j| (i, j)))
        .collect();
    let heights: Vec<Option<f64>> = pts
        .par_iter()
        .map(|&(i, j)| {
            let m = m_lo + (m_hi - m_lo) * i as f64 / (GRID_M - 1) as f64;
            let s = j as f64 / (GRID_S - 1) as f64;
            let (u, v) = frame.hub_uv(m, s);
            let fp = hub.eval(u, v);
            let mut best: Option<f64> = None;
            for k in strokes {
                let a = k.axis;
                let rel = fp.p - k.end.coords;
                let h = rel.dot(&a);
                if (rel - a * h).norm() > k.radius {
                    continue;
                }
                let na = fp.n.dot(&a);
                if na <= 1e-9 {
                    continue;
                }
                // Bottom plane through the tip with normal a, reached from H along n.
                let height = -h / na;
                best = Some(best.map_or(height, |b: f64| b.min(height)));
            }
            best
        })
        .collect();
    let covered: Vec<f64> = heights.into_iter().flatten().collect();
    let n = covered.len();
    HubAllowance {
        max_mm: covered.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        mean_mm: if n > 0 {
            covered.iter().sum::<f64>() / n as f64
        } else {
            f64::NAN
        },
        covered: n,
    }
}
