//! Tri-dexel stock: three grids of axis-parallel rays (along X, Y and Z) through a common
//! lattice of cell centres, each ray holding the sorted, disjoint material intervals along it.
//!
//! Storage: one [`Segments`] per ray, an enum with zero, one or two intervals inline (f32
//! coordinates, absolute in the workpiece frame: 6·10⁻⁶ mm precision at 100 mm) and a heap
//! vector only for rays crossing more material pieces; 32 bytes per ray plus 8 bytes per
//! spilled interval. For a bounding box of `Lx × Ly × Lz` at cell `h` the rays number
//! `(Lx·Ly + Ly·Lz + Lz·Lx)/h²`: memory and any whole-stock pass are O(h⁻²) per direction.
//!
//! The three grids share the lattice `x_i = x₀ + (i + ½) h` (likewise y, z), so every edge of
//! the lattice of cell centres lies on a ray of one grid: membership at lattice nodes is
//! consistent between grids and surface crossings along lattice edges are exact (used by
//! [`crate::surface_mesh`]).

use crate::error::SimError;
use crate::stock_shape::StockShape;
use rayon::prelude::*;

/// Material intervals along one ray, sorted and disjoint, `[start, end]` with start < end.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum Segments {
    /// No material.
    #[default]
    Empty,
    /// One interval.
    One([f32; 2]),
    /// Two intervals.
    Two([[f32; 2]; 2]),
    /// Three or more intervals (or fewer after removal, without shrinking back).
    Many(Vec<[f32; 2]>),
}

impl Segments {
    /// Builds from sorted disjoint intervals.
    pub fn from_slice(s: &[[f32; 2]]) -> Self {
        match s.len() {
            0 => Segments::Empty,
            1 => Segments::One(s[0]),
            2 => Segments::Two([s[0], s[1]]),
            _ => Segments::Many(s.to_vec()),
        }
    }

    /// The intervals.
    #[inline]
    pub fn as_slice(&self) -> &[[f32; 2]] {
        match self {
            Segments::Empty => &[],
            Segments::One(a) => std::slice::from_ref(a),
            Segments::Two(a) => a,
            Segments::Many(v) => v,
        }
    }

    /// Whether the ray holds no material.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.as_slice().is_empty()
    }

    /// Heap bytes used beyond the inline enum.
    pub fn heap_bytes(&self) -> usize {
        match self {
            Segments::Many(v) => v.capacity() * std::mem::size_of::<[f32; 2]>(),
            _ => 0,
        }
    }

    /// Whether coordinate `t` lies in material.
    #[inline]
    pub fn contains(&self, t: f64) -> bool {
        let t = t as f32;
        self.as_slice().iter().any(|s| s[0] <= t && t <= s[1])
    }

    /// Total material length on the ray.
    pub fn length(&self) -> f64 {
        self.as_slice().iter().map(|s| f64::from(s[1] - s[0])).sum()
    }

    /// Length of material inside `[a, b]`.
    #[inline]
    pub fn overlap(&self, a: f64, b: f64) -> f64 {
        let (a, b) = (a as f32, b as f32);
        let mut sum = 0.0f64;
        for s in self.as_slice() {
            let lo = s[0].max(a);
            let hi = s[1].min(b);
            if hi > lo {
                sum += f64::from(hi - lo);
            }
        }
        sum
    }

    /// Removes `[a, b]` from the material; returns the length removed. Allocation-free
    /// except when an inline two-interval ray is split into three.
    #[inline]
    pub fn subtract(&mut self, a: f64, b: f64) -> f64 {
        let (a, b) = (a as f32, b as f32);
        let s = self.as_slice();
        let n = s.len();
        if n == 0 || b <= s[0][0] || a >= s[n - 1][1] || b <= a {
            return 0.0;
        }
        // Overlapping index range i..j (exclusive).
        let mut i = 0;
        while i < n && s[i][1] <= a {
            i += 1;
        }
        let mut j = i;
        while j < n && s[j][0] < b {
            j += 1;
        }
        if i >= j {
            return 0.0;
        }
        let mut removed = 0.0f64;
        for seg in &s[i..j] {
            removed += f64::from(seg[1].min(b) - seg[0].max(a));
        }
        let left = (s[i][0] < a).then_some([s[i][0], a]);
        let right = (s[j - 1][1] > b).then_some([b, s[j - 1][1]]);
        match self {
            Segments::Many(v) => {
                let mid = left.into_iter().chain(right);
                v.splice(i..j, mid);
            }
            _ => {
                let mut buf = [[0.0f32; 2]; 4];
                let mut k = 0;
                for seg in s[..i]
                    .iter()
                    .copied()
                    .chain(left)
                    .chain(right)
                    .chain(s[j..].iter().copied())
                {
                    buf[k] = seg;
                    k += 1;
                }
                *self = Segments::from_slice(&buf[..k]);
            }
        }
        removed
    }

    /// First material boundary (start or end of an interval) in `(a, b]` for increasing
    /// coordinates when `a < b`, or in `[b, a)` scanning downward when `b < a`.
    pub fn first_boundary(&self, a: f64, b: f64) -> Option<f64> {
        let mut best: Option<f64> = None;
        for s in self.as_slice() {
            for e in [f64::from(s[0]), f64::from(s[1])] {
                let inside = if a < b {
                    e > a && e <= b
                } else {
                    e < a && e >= b
                };
                if inside {
                    best = Some(match best {
                        Some(x) if (x - a).abs() <= (e - a).abs() => x,
                        _ => e,
                    });
                }
            }
        }
        best
    }
}

/// One grid of parallel rays along coordinate `dir`; rays are indexed by the other two
/// coordinates `u = (dir+1)%3`, `v = (dir+2)%3`, row-major in `v`.
#[derive(Debug, Clone)]
pub struct DexelGrid {
    dir: usize,
    nu: usize,
    nv: usize,
    u0: f64,
    v0: f64,
    cell: f64,
    rays: Vec<Segments>,
    /// Material bounds of the ray tiles, kept up to date by the removal
    /// (`crate::cull::TileBounds`; only removal changes rays, and only by removing material).
    tiles: crate::cull::TileBounds,
}

impl DexelGrid {
    /// Ray direction (0 = X, 1 = Y, 2 = Z).
    pub fn dir(&self) -> usize {
        self.dir
    }
    /// Number of rays along u and v.
    pub fn size(&self) -> (usize, usize) {
        (self.nu, self.nv)
    }
    /// Coordinate of ray column `i` (u) and row `j` (v).
    #[inline]
    pub fn ray_uv(&self, i: usize, j: usize) -> (f64, f64) {
        (
            self.u0 + (i as f64 + 0.5) * self.cell,
            self.v0 + (j as f64 + 0.5) * self.cell,
        )
    }
    /// The ray at column `i`, row `j`.
    #[inline]
    pub fn ray(&self, i: usize, j: usize) -> &Segments {
        &self.rays[j * self.nu + i]
    }
    /// Rows of rays (each `nu` long), mutable, in order. The tile bounds are forgotten:
    /// changes made through these rows are not marked.
    pub(crate) fn rows_seq_mut(&mut self) -> std::slice::ChunksMut<'_, Segments> {
        self.tiles.invalidate();
        self.rays.chunks_mut(self.nu.max(1))
    }
    /// The tile bounds brought up to date ([`crate::cull::TileBounds::refresh`]), and the
    /// rows of rays (each `nu` long), mutable, for parallel processing; changes to the rows
    /// must be marked in the bounds.
    pub(crate) fn tiles_and_rows_mut(
        &mut self,
    ) -> (
        &crate::cull::TileBounds,
        rayon::slice::ChunksMut<'_, Segments>,
    ) {
        self.tiles.refresh(&self.rays, self.nu);
        (&self.tiles, self.rays.par_chunks_mut(self.nu.max(1)))
    }
    /// The grid's lattice without its rays.
    #[inline]
    pub fn geometry(&self) -> GridGeometry {
        GridGeometry {
            dir: self.dir,
            nu: self.nu,
            nv: self.nv,
            u0: self.u0,
            v0: self.v0,
            cell: self.cell,
        }
    }
    /// Inclusive index range of rays whose coordinate lies within `[lo, hi]` along u (or v
    /// with `v = true`); `None` when empty.
    #[inline]
    pub fn index_range(&self, lo: f64, hi: f64, v: bool) -> Option<(usize, usize)> {
        self.geometry().index_range(lo, hi, v)
    }
    /// Index of the ray nearest to `(u, v)`, clamped to the grid.
    #[inline]
    pub fn nearest(&self, u: f64, v: f64) -> (usize, usize) {
        let f = |x: f64, o: f64, n: usize| {
            let k = ((x - o) / self.cell - 0.5).round();
            (k.max(0.0) as usize).min(n.saturating_sub(1))
        };
        (f(u, self.u0, self.nu), f(v, self.v0, self.nv))
    }
    /// Memory used by the rays (bytes).
    pub fn memory_bytes(&self) -> usize {
        self.rays.capacity() * std::mem::size_of::<Segments>()
            + self.rays.iter().map(Segments::heap_bytes).sum::<usize>()
    }
    /// Total material length over all rays times the cell area: this grid's volume estimate.
    pub fn volume(&self) -> f64 {
        self.rays.par_iter().map(Segments::length).sum::<f64>() * self.cell * self.cell
    }
}

/// The lattice of a [`DexelGrid`] without its rays: a copy used for index computations while
/// the rays are borrowed mutably.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridGeometry {
    dir: usize,
    nu: usize,
    nv: usize,
    u0: f64,
    v0: f64,
    cell: f64,
}

impl GridGeometry {
    /// Ray direction (0 = X, 1 = Y, 2 = Z).
    #[inline]
    pub fn dir(&self) -> usize {
        self.dir
    }
    /// Number of rays along u and v.
    #[inline]
    pub fn size(&self) -> (usize, usize) {
        (self.nu, self.nv)
    }
    /// Inclusive index range of rays whose coordinate lies within `[lo, hi]` along u (or v
    /// with `v = true`); `None` when empty. O(1).
    #[inline]
    pub fn index_range(&self, lo: f64, hi: f64, v: bool) -> Option<(usize, usize)> {
        let (o, n) = if v {
            (self.v0, self.nv)
        } else {
            (self.u0, self.nu)
        };
        let a = ((lo - o) / self.cell - 0.5).ceil().max(0.0);
        let b = ((hi - o) / self.cell - 0.5).floor();
        if n == 0 || !(a.is_finite() && b.is_finite()) || b < a || a >= n as f64 || b < 0.0 {
            return None;
        }
        Some((a as usize, (b as usize).min(n - 1)))
    }
}

/// The tri-dexel stock.
#[derive(Debug, Clone)]
pub struct TriDexel {
    min: [f64; 3],
    max: [f64; 3],
    cell: f64,
    n: [usize; 3],
    grids: [DexelGrid; 3],
}

/// Largest number of rays per grid accepted (guards against a resolution typo; 2·10⁷ rays
/// are 480 MB per grid).
pub const MAX_RAYS_PER_GRID: usize = 20_000_000;

impl TriDexel {
    /// Samples `shape` on ray grids of spacing `cell` (mm) over the shape's bounding box
    /// (padded by one cell). Each ray's intervals come from [`StockShape::ray_intervals`].
    /// O(rays) work, parallel over rows.
    pub fn from_shape(shape: &dyn StockShape, cell: f64) -> Result<Self, SimError> {
        if !(cell.is_finite() && cell > 0.0) {
            return Err(SimError::InvalidOption {
                name: "resolution",
                value: cell,
                reason: "must be finite and > 0",
            });
        }
        let (lo, hi) = shape.bounding_box();
        let mut min = [0.0; 3];
        let mut max = [0.0; 3];
        let mut n = [0usize; 3];
        for k in 0..3 {
            if !(lo[k].is_finite() && hi[k].is_finite() && hi[k] >= lo[k]) {
                return Err(SimError::InvalidStock(
                    "bounding box is empty or not finite".into(),
                ));
            }
            min[k] = lo[k] - cell;
            let cells = ((hi[k] + cell - min[k]) / cell).ceil();
            n[k] = cells as usize;
            max[k] = min[k] + n[k] as f64 * cell;
        }
        for d in 0..3 {
            let rays = n[(d + 1) % 3].saturating_mul(n[(d + 2) % 3]);
            if rays > MAX_RAYS_PER_GRID {
                return Err(SimError::InvalidOption {
                    name: "resolution",
                    value: cell,
                    reason: "too fine for the stock size (more than 2·10⁷ rays per grid)",
                });
            }
        }
        let make = |d: usize| {
            let (ua, va) = ((d + 1) % 3, (d + 2) % 3);
            let mut g = DexelGrid {
                dir: d,
                nu: n[ua],
                nv: n[va],
                u0: min[ua],
                v0: min[va],
                cell,
                rays: vec![Segments::Empty; n[ua] * n[va]],
                tiles: crate::cull::TileBounds::default(),
            };
            let nu = g.nu;
            let (u0, v0) = (g.u0, g.v0);
            g.rays
                .par_chunks_mut(nu.max(1))
                .enumerate()
                .for_each(|(j, row)| {
                    let v = v0 + (j as f64 + 0.5) * cell;
                    let mut buf = Vec::new();
                    let mut segs: Vec<[f32; 2]> = Vec::new();
                    for (i, ray) in row.iter_mut().enumerate() {
                        let u = u0 + (i as f64 + 0.5) * cell;
                        buf.clear();
                        shape.ray_intervals(d, u, v, &mut buf);
                        segs.clear();
                        normalise(&mut buf);
                        segs.extend(buf.iter().map(|&(a, b)| [a as f32, b as f32]));
                        *ray = Segments::from_slice(&segs);
                    }
                });
            g
        };
        let grids = [make(0), make(1), make(2)];
        Ok(Self {
            min,
            max,
            cell,
            n,
            grids,
        })
    }

    /// Cell size (mm).
    pub fn cell(&self) -> f64 {
        self.cell
    }
    /// Lower corner of the lattice box.
    pub fn min(&self) -> [f64; 3] {
        self.min
    }
    /// Upper corner of the lattice box.
    pub fn max(&self) -> [f64; 3] {
        self.max
    }
    /// Number of cells along X, Y, Z.
    pub fn cells(&self) -> [usize; 3] {
        self.n
    }
    /// Grid of rays along coordinate `d`.
    pub fn grid(&self, d: usize) -> &DexelGrid {
        &self.grids[d % 3]
    }
    pub(crate) fn grids_mut(&mut self) -> &mut [DexelGrid; 3] {
        &mut self.grids
    }
    /// Total number of rays.
    pub fn ray_count(&self) -> usize {
        self.grids.iter().map(|g| g.rays.len()).sum()
    }
    /// Memory used by the three grids (bytes).
    pub fn memory_bytes(&self) -> usize {
        self.grids.iter().map(DexelGrid::memory_bytes).sum()
    }
    /// Volume of material (mm³): mean of the three grids' estimates.
    pub fn volume(&self) -> f64 {
        self.grids.iter().map(DexelGrid::volume).sum::<f64>() / 3.0
    }

    /// Whether point `p` is in material according to the ray of grid `d` nearest to it
    /// (exact along `d`, lateral error up to half a cell diagonal).
    #[inline]
    pub fn contains_via(&self, d: usize, p: &[f64; 3]) -> bool {
        self.nearest_ray(d, p)
            .is_some_and(|(i, j)| self.grids[d % 3].ray(i, j).contains(p[d]))
    }

    /// The index of grid `d`'s ray nearest to `p`, `None` more than half a cell outside
    /// the grid.
    #[inline]
    fn nearest_ray(&self, d: usize, p: &[f64; 3]) -> Option<(usize, usize)> {
        let g = &self.grids[d % 3];
        let (u, v) = (p[(d + 1) % 3], p[(d + 2) % 3]);
        let h = self.cell;
        if u < g.u0 - 0.5 * h
            || v < g.v0 - 0.5 * h
            || u > g.u0 + (g.nu as f64 + 0.5) * h
            || v > g.v0 + (g.nv as f64 + 0.5) * h
        {
            return None;
        }
        Some(g.nearest(u, v))
    }

    /// The point of grid `d`'s ray nearest to `p` at `p`'s coordinate `d`: where
    /// [`TriDexel::contains_via`] reads membership exactly. `None` where that reads outside
    /// the grid.
    #[inline]
    pub fn nearest_ray_point(&self, d: usize, p: &[f64; 3]) -> Option<[f64; 3]> {
        let (i, j) = self.nearest_ray(d, p)?;
        let (ru, rv) = self.grids[d % 3].ray_uv(i, j);
        let mut q = *p;
        q[(d + 1) % 3] = ru;
        q[(d + 2) % 3] = rv;
        Some(q)
    }

    /// Membership by majority vote of the three grids' nearest rays.
    pub fn contains(&self, p: &[f64; 3]) -> bool {
        (0..3).filter(|&d| self.contains_via(d, p)).count() >= 2
    }
}

/// Sorts and merges overlapping intervals, dropping empty ones.
pub(crate) fn normalise(v: &mut Vec<(f64, f64)>) {
    v.retain(|&(a, b)| b > a && a.is_finite() && b.is_finite());
    v.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(v.len());
    for &(a, b) in v.iter() {
        match out.last_mut() {
            Some(last) if a <= last.1 => last.1 = last.1.max(b),
            _ => out.push((a, b)),
        }
    }
    *v = out;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segments_are_compact() {
        assert!(std::mem::size_of::<Segments>() <= 32);
    }

    #[test]
    fn subtract_splits_trims_and_removes() {
        let mut s = Segments::One([0.0, 10.0]);
        assert!((s.subtract(2.0, 3.0) - 1.0).abs() < 1e-6);
        assert_eq!(s.as_slice(), &[[0.0, 2.0], [3.0, 10.0]]);
        assert!((s.subtract(5.0, 6.0) - 1.0).abs() < 1e-6);
        assert_eq!(s.as_slice(), &[[0.0, 2.0], [3.0, 5.0], [6.0, 10.0]]);
        assert!((s.subtract(1.0, 7.0) - 4.0).abs() < 1e-6);
        assert_eq!(s.as_slice(), &[[0.0, 1.0], [7.0, 10.0]]);
        assert_eq!(s.subtract(20.0, 30.0), 0.0);
        assert!((s.subtract(-1.0, 20.0) - 4.0).abs() < 1e-6, "{s:?}");
        assert!(s.is_empty());
    }

    #[test]
    fn bad_resolutions_are_typed_errors() {
        let b = crate::stock_shape::BoxStock::new([0.0; 3], [100.0; 3]).unwrap();
        for h in [0.0, -1.0, f64::NAN, 1e-4] {
            assert!(
                matches!(
                    TriDexel::from_shape(&b, h),
                    Err(SimError::InvalidOption {
                        name: "resolution",
                        ..
                    })
                ),
                "{h}"
            );
        }
    }

    #[test]
    fn first_boundary_scans_both_ways() {
        let s = Segments::Two([[0.0, 1.0], [2.0, 3.0]]);
        assert_eq!(s.first_boundary(0.5, 5.0), Some(1.0));
        assert_eq!(s.first_boundary(2.5, -1.0), Some(2.0));
        assert_eq!(s.first_boundary(3.5, 5.0), None);
    }
}
