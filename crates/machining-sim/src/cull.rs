//! Conservative bounds of the material along the rays of a dexel grid, at two granularities,
//! used by [`crate::removal::apply_batch`] to skip whole groups of rays that a tool part
//! cannot touch.
//!
//! A bound is the smallest interval along the ray direction containing every material
//! interval of its rays. Material removal only shrinks material, so a bound computed at any
//! earlier time of a batch still contains the rays' material: skipping a group whose bound
//! is disjoint from a part's extent is exact at any later time, without updating the bound.
//!
//! * [`ChunkBound`]: [`CHUNK`] consecutive rays of one row, built lazily while the row is
//!   processed and recomputed after a placement removed material from it (only to keep it
//!   tight).
//! * [`TileBounds`]: [`TILE`] × [`TILE`] rays, built for a whole grid once per batch; a
//!   placement's ray range is shrunk to the tiles its part can touch before the placement is
//!   bucketed into rows.
//!
//! Cost: building a grid's tiles reads every ray's first and last interval once, O(rays),
//! in parallel over tile rows.

use crate::dexel::{DexelGrid, Segments};
use rayon::prelude::*;

/// Rays per chunk of a row.
pub(crate) const CHUNK: usize = 16;

/// Rays per side of a tile.
pub(crate) const TILE: usize = 32;

/// Material extent along the rays of a group of rays (empty when `lo > hi`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct ChunkBound {
    lo: f32,
    hi: f32,
    /// To be recomputed before use.
    pub(crate) stale: bool,
}

impl ChunkBound {
    /// A bound that must be computed before use.
    pub(crate) const STALE: Self = Self {
        lo: 0.0,
        hi: 0.0,
        stale: true,
    };

    const EMPTY: Self = Self {
        lo: f32::INFINITY,
        hi: f32::NEG_INFINITY,
        stale: false,
    };

    /// Bound of the rays `rays`.
    pub(crate) fn of(rays: &[Segments]) -> Self {
        let mut b = Self::EMPTY;
        for r in rays {
            b.add(r);
        }
        b
    }

    #[inline]
    fn add(&mut self, r: &Segments) {
        let s = r.as_slice();
        if let (Some(f), Some(l)) = (s.first(), s.last()) {
            self.lo = self.lo.min(f[0]);
            self.hi = self.hi.max(l[1]);
        }
    }

    /// Whether some material inside the bound can lie in `[lo, hi]` along the rays: false
    /// exactly when every contained interval ends before `lo` or starts after `hi` is
    /// guaranteed by the bound (the same closed comparisons as the per-ray test).
    #[inline]
    pub(crate) fn meets(&self, (lo, hi): (f64, f64)) -> bool {
        f64::from(self.hi) >= lo && f64::from(self.lo) <= hi
    }
}

/// Bounds of the [`TILE`] × [`TILE`] tiles of one grid, tile `(ti, tj)` holding rays
/// `ti·TILE ..` along u and `tj·TILE ..` along v.
#[derive(Debug, Clone, Default)]
pub(crate) struct TileBounds {
    nt_u: usize,
    bounds: Vec<ChunkBound>,
}

impl TileBounds {
    /// Bounds of the grid's tiles as the grid is now.
    pub(crate) fn new(grid: &DexelGrid) -> Self {
        let (nu, _) = grid.size();
        let nt_u = nu.div_ceil(TILE);
        let bounds = grid
            .row_bands_par(TILE)
            .flat_map_iter(|tile_rows| {
                let mut line = vec![ChunkBound::EMPTY; nt_u];
                for row in tile_rows.chunks(nu.max(1)) {
                    for (ti, rays) in row.chunks(TILE).enumerate() {
                        if let Some(b) = line.get_mut(ti) {
                            for r in rays {
                                b.add(r);
                            }
                        }
                    }
                }
                line
            })
            .collect();
        Self { nt_u, bounds }
    }

    /// Bound of tile `(ti, tj)` (empty outside the grid).
    #[inline]
    pub(crate) fn get(&self, ti: usize, tj: usize) -> ChunkBound {
        if ti >= self.nt_u {
            return ChunkBound::EMPTY;
        }
        self.bounds
            .get(tj * self.nt_u + ti)
            .copied()
            .unwrap_or(ChunkBound::EMPTY)
    }
}

/// An open interval along the rays of a chunk that none of its rays holds material in
/// (empty when `lo >= hi`). Removal only shrinks material, so it stays air for the rest of
/// the batch: a cutting extent strictly inside it meets no material of the chunk.
#[derive(Debug, Clone, Copy)]
pub(crate) struct AirSpan {
    lo: f32,
    hi: f32,
}

impl AirSpan {
    /// No known air.
    pub(crate) const NONE: Self = Self { lo: 0.0, hi: 0.0 };

    /// Whether `[lo, hi]` lies strictly inside the air (then no material interval of the
    /// chunk meets it, by the closed comparisons of [`ChunkBound::meets`]).
    #[inline]
    pub(crate) fn contains(&self, (lo, hi): (f64, f64)) -> bool {
        f64::from(self.lo) < lo && hi < f64::from(self.hi)
    }

    /// The whole line, to be narrowed ray by ray around `ext` ([`Self::narrow`]).
    #[inline]
    pub(crate) fn around(_ext: (f64, f64)) -> Self {
        Self {
            lo: f32::NEG_INFINITY,
            hi: f32::INFINITY,
        }
    }

    /// Narrows the air to the gap of `segs` around `ext`; false when some material
    /// interval meets `ext` (the chunk has no common air around it).
    #[inline]
    pub(crate) fn narrow(&mut self, segs: &[[f32; 2]], (lo, hi): (f64, f64)) -> bool {
        for s in segs {
            if f64::from(s[1]) < lo {
                self.lo = self.lo.max(s[1]);
            } else if f64::from(s[0]) > hi {
                self.hi = self.hi.min(s[0]);
            } else {
                return false;
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chunk_bound_spans_first_start_to_last_end() {
        let rays = [
            Segments::Empty,
            Segments::Two([[1.0, 2.0], [5.0, 6.0]]),
            Segments::One([-3.0, -1.0]),
        ];
        let b = ChunkBound::of(&rays);
        assert_eq!((b.lo, b.hi), (-3.0, 6.0));
        assert!(b.meets((6.0, 7.0)), "closed at the top end");
        assert!(b.meets((-4.0, -3.0)), "closed at the bottom end");
        assert!(!b.meets((6.000_001, 7.0)));
        assert!(!ChunkBound::of(&[Segments::Empty]).meets((-1e9, 1e9)));
    }
}
