//! Material removal on the tri-dexel stock and in-process collision detection of the
//! non-cutting parts, for a batch of cutter positions.
//!
//! For each grid, the placements are bucketed by the ray rows their boxes touch and rows are
//! processed in parallel (rayon); inside a row the positions are applied in their machining
//! order, so every ray sees exactly the sequential history and the result does not depend on
//! the batch size or thread count. Per position and row only the rays inside the part's box
//! (clipped to the stock lattice) *and* inside the band around its projected axis are
//! visited, and a ray whose material lies outside the part's extent along the ray is skipped
//! before any geometry; the same extent test runs first on whole tiles of rays (shrinking
//! the placement's ray range before it is bucketed into rows) and on chunks of a row, against
//! the material bounds of the private `cull` module ([`apply_batch`] proves each cull exact; [`apply_batch_reference`] is
//! the plain sequential definition, and `tests/removal_equivalence.rs` checks both agree bit
//! for bit). Per ray the cutter's interval is the closed-form ray–solid-of-revolution
//! intersection of [`crate::tool_solid`], subtracted from the ray's material list.
//!
//! Collisions are detected against the stock *as it is when the position is reached*: the
//! shank and holder pieces (and, for rapid moves, the whole tool) are intersected with each
//! ray and any material overlap longer than the collision tolerance is a hit. Depth reported
//! = longest overlap along a ray (≥ the normal penetration for the ray direction closest to
//! the contact normal).
//!
//! Cost per position: O(A/h²) bound checks per grid, A the area of the part's projected
//! band inside its box, plus one ray–solid intersection per ray whose material overlaps the
//! part's extent; memory: the row buckets (one `u32` per placement and row touched) and the
//! hit list (allocation-free kernel except when a two-interval ray splits into three).

use crate::cull::{AirSpan, ChunkBound, TileBounds, CHUNK, TILE};
use crate::dexel::{GridGeometry, Segments, TriDexel};
use crate::reach::Reach;
use crate::tool_solid::{Piece, RayLocal, RevolvedSolid};
use crate::witness::Witness;
use cam_core::Cutter;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// The three parts of a cutter used by the simulation.
#[derive(Debug, Clone)]
pub struct ToolBody {
    /// Fluted part (removes material).
    pub cutting: RevolvedSolid,
    /// Shank between flutes and holder.
    pub shank: RevolvedSolid,
    /// Holder segments.
    pub holder: RevolvedSolid,
}

impl ToolBody {
    /// Splits a cutter into its cutting part, shank and holder.
    pub fn new(cutter: &Cutter) -> Self {
        let all = RevolvedSolid::non_cutting_parts(cutter);
        let (mut shank, mut holder) = (Vec::new(), Vec::new());
        for p in all.pieces() {
            if p.heights().1 <= cutter.overall_length + 1e-12 {
                shank.push(*p);
            } else {
                holder.push(*p);
            }
        }
        Self {
            cutting: RevolvedSolid::cutting_part(cutter),
            shank: RevolvedSolid::new(shank),
            holder: RevolvedSolid::new(holder),
        }
    }
}

/// What part of the tool hit material.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PartKind {
    /// Shank (above the flutes).
    Shank,
    /// Holder.
    Holder,
    /// Any part of the tool during a rapid move.
    RapidMove,
}

/// One cutter position of a batch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    /// Tool tip.
    pub tip: [f64; 3],
    /// Unit tool axis.
    pub axis: [f64; 3],
    /// Index of the tool body.
    pub tool: usize,
    /// Rapid move: no cutting, any material contact is a collision.
    pub rapid: bool,
}

/// A material contact of a non-cutting part found on one row of rays.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StockHit {
    /// Index of the placement in its batch.
    pub placement: usize,
    /// Part that touched material.
    pub part: PartKind,
    /// Longest material overlap along a ray (mm).
    pub depth: f64,
    /// Middle of that overlap.
    pub point: [f64; 3],
}

#[derive(Debug, Clone, Copy)]
struct Range2 {
    i0: usize,
    i1: usize,
    j0: usize,
    j1: usize,
}

impl Range2 {
    fn has_row(&self, j: usize) -> bool {
        j >= self.j0 && j <= self.j1
    }
    fn has(&self, i: usize) -> bool {
        i >= self.i0 && i <= self.i1
    }

    /// The range shrunk to the `cull::TILE`² tiles whose material bound meets `extent`
    /// (an interval along the rays containing the part's points on every ray of the tile,
    /// given the tile's coordinate ranges `(ua, ub)`, `(va, vb)`); `None` when no tile does.
    /// `(u0, v0)`: coordinates of ray (0, 0). O(tiles of the range).
    fn shrink(
        &self,
        tiles: &TileBounds,
        (u0, v0): (f64, f64),
        cell: f64,
        extent: impl Fn((f64, f64), (f64, f64)) -> Option<(f64, f64)>,
    ) -> Option<Self> {
        let Range2 { i0, i1, j0, j1 } = *self;
        let (mut a0, mut a1, mut b0, mut b1) = (usize::MAX, 0, usize::MAX, 0);
        for tj in j0 / TILE..=j1 / TILE {
            let (ja, jb) = ((tj * TILE).max(j0), (tj * TILE + TILE - 1).min(j1));
            let vs = (v0 + ja as f64 * cell, v0 + jb as f64 * cell);
            for ti in i0 / TILE..=i1 / TILE {
                let (ia, ib) = ((ti * TILE).max(i0), (ti * TILE + TILE - 1).min(i1));
                let us = (u0 + ia as f64 * cell, u0 + ib as f64 * cell);
                if extent(us, vs).is_some_and(|e| tiles.get(ti, tj).meets(e)) {
                    (a0, a1) = (a0.min(ia), a1.max(ib));
                    (b0, b1) = (b0.min(ja), b1.max(jb));
                }
            }
        }
        (a0 <= a1).then_some(Range2 {
            i0: a0,
            i1: a1,
            j0: b0,
            j1: b1,
        })
    }
}

/// Clips a piece of a solid placed at (tip, axis) to the box `[lo, hi]` inflated by the
/// piece's radius; returns the clipped piece as a frustum/sphere/torus slab.
fn clip_piece(
    p: &Piece,
    tip: &[f64; 3],
    axis: &[f64; 3],
    lo: &[f64; 3],
    hi: &[f64; 3],
) -> Option<Piece> {
    let (mut h0, mut h1) = p.heights();
    let r = p.max_radius();
    for k in 0..3 {
        let (a, b) = (lo[k] - r, hi[k] + r);
        if axis[k].abs() < 1e-12 {
            if tip[k] < a || tip[k] > b {
                return None;
            }
        } else {
            let (mut s, mut e) = ((a - tip[k]) / axis[k], (b - tip[k]) / axis[k]);
            if s > e {
                std::mem::swap(&mut s, &mut e);
            }
            h0 = h0.max(s);
            h1 = h1.min(e);
        }
    }
    if h1 <= h0 {
        return None;
    }
    Some(match *p {
        Piece::Frustum { .. } => Piece::Frustum {
            h0,
            h1,
            r0: p.radius_at(h0),
            r1: p.radius_at(h1),
        },
        Piece::Sphere { hc, radius, .. } => Piece::Sphere { h0, h1, hc, radius },
        Piece::Torus {
            hc, major, minor, ..
        } => Piece::Torus {
            h0,
            h1,
            hc,
            major,
            minor,
        },
    })
}

/// 3-D box of a piece (conservative: cylinder of its largest radius).
fn piece_box(p: &Piece, tip: &[f64; 3], axis: &[f64; 3]) -> ([f64; 3], [f64; 3]) {
    let (h0, h1) = p.heights();
    let r = p.max_radius();
    let mut lo = [0.0; 3];
    let mut hi = [0.0; 3];
    for k in 0..3 {
        let ext = r * (1.0 - axis[k] * axis[k]).max(0.0).sqrt();
        let a = tip[k] + h0 * axis[k];
        let b = tip[k] + h1 * axis[k];
        lo[k] = a.min(b) - ext;
        hi[k] = a.max(b) + ext;
    }
    (lo, hi)
}

fn merge_box(acc: &mut Option<([f64; 3], [f64; 3])>, b: ([f64; 3], [f64; 3])) {
    match acc {
        None => *acc = Some(b),
        Some((lo, hi)) => {
            for k in 0..3 {
                lo[k] = lo[k].min(b.0[k]);
                hi[k] = hi[k].max(b.1[k]);
            }
        }
    }
}

struct Prep {
    cut_box: Option<([f64; 3], [f64; 3])>,
    coll_box: Option<([f64; 3], [f64; 3])>,
    /// Largest radius of the clipped collision pieces (mm).
    coll_radius: f64,
    /// Height span of the clipped collision pieces along the axis (mm).
    coll_span: (f64, f64),
    coll: std::ops::Range<usize>,
}

/// Result of applying a batch.
#[derive(Debug, Clone, Default)]
pub struct BatchOutcome {
    /// Material removed (mm³, mean over the three grids).
    pub removed_volume: f64,
    /// Non-cutting contacts (one per placement, part and row at most).
    pub hits: Vec<StockHit>,
}

/// Clipped pieces and boxes of a batch (shared by [`apply_batch`] and
/// [`apply_batch_reference`]).
struct Prepared {
    coll_pieces: Vec<(Piece, PartKind)>,
    preps: Vec<Prep>,
}

fn prepare(
    stock: &TriDexel,
    bodies: &[ToolBody],
    batch: &[Placement],
    check_collisions: bool,
) -> Prepared {
    let lo = stock.min();
    let hi = stock.max();
    let mut coll_pieces: Vec<(Piece, PartKind)> = Vec::new();
    let mut preps = Vec::with_capacity(batch.len());
    for pl in batch {
        let body = &bodies[pl.tool];
        let mut cut_box = None;
        if !pl.rapid {
            for p in body.cutting.pieces() {
                if let Some(c) = clip_piece(p, &pl.tip, &pl.axis, &lo, &hi) {
                    merge_box(&mut cut_box, piece_box(&c, &pl.tip, &pl.axis));
                }
            }
        }
        let start = coll_pieces.len();
        let mut coll_box = None;
        let mut coll_radius: f64 = 0.0;
        let mut coll_span = (f64::INFINITY, f64::NEG_INFINITY);
        if check_collisions || pl.rapid {
            let parts: [(&RevolvedSolid, PartKind); 3] = if pl.rapid {
                [
                    (&body.cutting, PartKind::RapidMove),
                    (&body.shank, PartKind::RapidMove),
                    (&body.holder, PartKind::RapidMove),
                ]
            } else {
                [
                    (&body.shank, PartKind::Shank),
                    (&body.holder, PartKind::Holder),
                    (&body.holder, PartKind::Holder),
                ]
            };
            let n_parts = if pl.rapid { 3 } else { 2 };
            for (solid, kind) in parts.iter().take(n_parts) {
                for p in solid.pieces() {
                    if let Some(c) = clip_piece(p, &pl.tip, &pl.axis, &lo, &hi) {
                        merge_box(&mut coll_box, piece_box(&c, &pl.tip, &pl.axis));
                        coll_radius = coll_radius.max(c.max_radius());
                        coll_span = (
                            coll_span.0.min(c.heights().0),
                            coll_span.1.max(c.heights().1),
                        );
                        coll_pieces.push((c, *kind));
                    }
                }
            }
        }
        preps.push(Prep {
            cut_box,
            coll_box,
            coll_radius,
            coll_span,
            coll: start..coll_pieces.len(),
        });
    }
    Prepared { coll_pieces, preps }
}

/// Slack (mm) added to every culling bound of [`apply_batch`] so that floating-point
/// rounding of the boxes, bands and ray intervals (≈ 10⁻¹³ mm at 100 mm) can never cull a
/// ray the unculled computation would change.
pub const CULL_SLACK_MM: f64 = 1e-6;

/// Band of the ray plane `(u, v)` within `r` of the projected tool axis line:
/// `|(u − pu)·nu + (v − pv)·nv| ≤ r` with `(nu, nv)` the unit normal of the projected axis.
#[derive(Debug, Clone, Copy)]
struct Band {
    pu: f64,
    pv: f64,
    nu: f64,
    nv: f64,
    r: f64,
}

/// Where one part of one placement can touch material on one grid: its box's ray index
/// range, its extent along the rays and the band around its projected axis. Every ray
/// outside the range or the band, or whose material lies outside the extent, provably meets
/// none of the part's material (see [`apply_batch`]).
#[derive(Debug, Clone, Copy)]
struct Footprint {
    range: Range2,
    band: Option<Band>,
    /// Tip coordinates along u, v and the ray direction d.
    tip: [f64; 3],
    /// Axis components along u, v and d.
    axis: [f64; 3],
    /// Height span of the part's clipped pieces.
    span: (f64, f64),
    /// Radius bound of the part's clipped pieces (with slack).
    r: f64,
    /// Largest offset of a part point from its axis point along d: `r·sqrt(1 − a_d²)`.
    ext_d: f64,
}

/// Heights `h` of `lo..=hi` where the axis coordinate `t + h·a` lies within `r` of `c`
/// (empty: `lo > hi`).
#[inline]
fn axis_window(c: f64, t: f64, a: f64, r: f64, (lo, hi): (f64, f64)) -> (f64, f64) {
    if a.abs() > 1e-12 {
        let (x, y) = ((c - t - r) / a, (c - t + r) / a);
        (lo.max(x.min(y)), hi.min(x.max(y)))
    } else if (c - t).abs() <= r {
        (lo, hi)
    } else {
        (1.0, 0.0)
    }
}

impl Footprint {
    fn new(
        grid: &GridGeometry,
        bx: &Option<([f64; 3], [f64; 3])>,
        radius: f64,
        span: (f64, f64),
        pl: &Placement,
    ) -> Option<Self> {
        let (blo, bhi) = bx.as_ref()?;
        let d = grid.dir();
        let (ua, va) = ((d + 1) % 3, (d + 2) % 3);
        let (i0, i1) = grid.index_range(blo[ua], bhi[ua], false)?;
        let (j0, j1) = grid.index_range(blo[va], bhi[va], true)?;
        let (au, av) = (pl.axis[ua], pl.axis[va]);
        let n = (au * au + av * av).sqrt();
        // A nearly ray-parallel axis projects to (almost) a point: the box is the bound.
        let band = (n > 1e-6).then(|| Band {
            pu: pl.tip[ua],
            pv: pl.tip[va],
            nu: -av / n,
            nv: au / n,
            r: radius + CULL_SLACK_MM,
        });
        let r = radius + CULL_SLACK_MM;
        Some(Self {
            range: Range2 { i0, i1, j0, j1 },
            band,
            tip: [pl.tip[ua], pl.tip[va], pl.tip[d]],
            axis: [au, av, pl.axis[d]],
            span,
            r,
            ext_d: r * (1.0 - pl.axis[d] * pl.axis[d]).max(0.0).sqrt() + CULL_SLACK_MM,
        })
    }

    /// Inclusive column range of row `j` (coordinate `v`) inside the box and the band.
    #[inline]
    fn columns(&self, grid: &GridGeometry, j: usize, v: f64) -> Option<(usize, usize)> {
        if !self.range.has_row(j) {
            return None;
        }
        let (i0, i1) = (self.range.i0, self.range.i1);
        let Some(b) = self.band else {
            return Some((i0, i1));
        };
        let c = (v - b.pv) * b.nv;
        if b.nu.abs() < 1e-9 {
            return (c.abs() <= b.r).then_some((i0, i1));
        }
        let (x, y) = (b.pu + (-b.r - c) / b.nu, b.pu + (b.r - c) / b.nu);
        let (a, e) = grid.index_range(x.min(y), x.max(y), false)?;
        let (a, e) = (a.max(i0), e.min(i1));
        (a <= e).then_some((a, e))
    }

    /// Heights of the part's axis within `r` of row coordinate `v` (see [`axis_window`]).
    #[inline]
    fn row_window(&self, v: f64) -> (f64, f64) {
        axis_window(v, self.tip[1], self.axis[1], self.r, self.span)
    }

    /// `cols` narrowed to the columns `u` whose window (see [`Self::meets`]) can be non-empty:
    /// `u` within `r` of the axis coordinate `tip_u + h·a_u` for some `h` of the row window.
    #[inline]
    fn narrow(
        &self,
        grid: &GridGeometry,
        (i0, i1): (usize, usize),
        (lo, hi): (f64, f64),
    ) -> Option<(usize, usize)> {
        if lo > hi {
            return None;
        }
        let (a, b) = (
            self.tip[0] + self.axis[0] * lo,
            self.tip[0] + self.axis[0] * hi,
        );
        let (a, e) = grid.index_range(a.min(b) - self.r, a.max(b) + self.r, false)?;
        let (a, e) = (a.max(i0), e.min(i1));
        (a <= e).then_some((a, e))
    }

    /// The footprint with its ray range shrunk to the [`TILE`] × [`TILE`] tiles whose
    /// material (bounded by `tiles`) the part can meet; `None` when it meets none. Exact: a
    /// ray whose material meets the part's extent lies in a tile whose bound meets the
    /// part's extent over the whole tile (a superset, see [`Self::extent_over`]).
    /// `(u0, v0)`: coordinates of ray (0, 0). O(tiles of the range).
    fn shrink(mut self, tiles: &TileBounds, origin: (f64, f64), cell: f64) -> Option<Self> {
        self.range = self
            .range
            .shrink(tiles, origin, cell, |(ua, ub), (va, vb)| {
                let row = axis_window(
                    0.5 * (va + vb),
                    self.tip[1],
                    self.axis[1],
                    self.r + 0.5 * (vb - va) + CULL_SLACK_MM,
                    self.span,
                );
                if row.0 > row.1 {
                    return None;
                }
                self.extent_over(ua, ub, row)
            })?;
        Some(self)
    }

    /// The part's extent along the rays of the columns with coordinates in `[ua, ub]` (row
    /// window `row`): the union of [`Self::meets`]'s extents over those columns, widened by
    /// [`CULL_SLACK_MM`]; `None` when no column's window is non-empty.
    #[inline]
    fn extent_over(&self, ua: f64, ub: f64, row: (f64, f64)) -> Option<(f64, f64)> {
        let half = 0.5 * (ub - ua);
        let (lo, hi) = axis_window(
            0.5 * (ua + ub),
            self.tip[0],
            self.axis[0],
            self.r + half + CULL_SLACK_MM,
            row,
        );
        if lo > hi {
            return None;
        }
        let (a, b) = (
            self.tip[2] + self.axis[2] * lo,
            self.tip[2] + self.axis[2] * hi,
        );
        Some((
            a.min(b) - self.ext_d - CULL_SLACK_MM,
            a.max(b) + self.ext_d + CULL_SLACK_MM,
        ))
    }

    /// Whether any material interval of `segs` (the ray at column coordinate `u`) meets the
    /// part's extent along the ray: the part's points on that ray have axis heights in the
    /// row window narrowed by `u`, and lie within `ext_d` of their axis point along d.
    #[inline]
    fn meets(&self, segs: &[[f32; 2]], u: f64, row: (f64, f64)) -> bool {
        let (lo, hi) = axis_window(u, self.tip[0], self.axis[0], self.r, row);
        if lo > hi {
            return false;
        }
        let (a, b) = (
            self.tip[2] + self.axis[2] * lo,
            self.tip[2] + self.axis[2] * hi,
        );
        let (d_lo, d_hi) = (a.min(b) - self.ext_d, a.max(b) + self.ext_d);
        segs.iter()
            .any(|s| f64::from(s[1]) >= d_lo && f64::from(s[0]) <= d_hi)
    }
}

/// Collision overlaps of the clipped non-cutting pieces with one ray's material, kept in
/// `best` (deepest per part slot).
#[allow(clippy::too_many_arguments)]
#[inline]
fn collide_ray(
    ray: &Segments,
    rl: &RayLocal,
    pl: &Placement,
    pieces: &[(Piece, PartKind)],
    k: usize,
    (d, ua, va): (usize, usize, usize),
    (u, v): (f64, f64),
    collision_tol: f64,
    best: &mut [Option<StockHit>; 3],
) {
    for (piece, kind) in pieces {
        if let Some((s, e)) = piece.ray_interval(rl) {
            let (s, e) = (s + pl.tip[d], e + pl.tip[d]);
            let ov = ray.overlap(s, e);
            let slot = match kind {
                PartKind::Shank => 0,
                PartKind::Holder => 1,
                PartKind::RapidMove => 2,
            };
            if ov > collision_tol && best[slot].is_none_or(|h| h.depth < ov) {
                let mut point = [0.0; 3];
                point[ua] = u;
                point[va] = v;
                point[d] = 0.5 * (s + e);
                best[slot] = Some(StockHit {
                    placement: k,
                    part: *kind,
                    depth: ov,
                    point,
                });
            }
        }
    }
}

/// Per-ray work of [`apply_batch_reference`]: collision overlaps of the clipped
/// non-cutting pieces (kept in `best`, deepest per part slot) and removal by the cutting
/// part. Returns the length removed.
#[allow(clippy::too_many_arguments)]
#[inline]
fn ray_work(
    ray: &mut Segments,
    rl: &RayLocal,
    pl: &Placement,
    body: &ToolBody,
    pieces: Option<&[(Piece, PartKind)]>,
    cut: bool,
    k: usize,
    (d, ua, va): (usize, usize, usize),
    (u, v): (f64, f64),
    collision_tol: f64,
    best: &mut [Option<StockHit>; 3],
) -> f64 {
    if let Some(pieces) = pieces {
        collide_ray(
            ray,
            rl,
            pl,
            pieces,
            k,
            (d, ua, va),
            (u, v),
            collision_tol,
            best,
        );
    }
    if cut {
        if let Some((s, e)) = body.cutting.ray_hull(rl) {
            return ray.subtract(s + pl.tip[d], e + pl.tip[d]);
        }
    }
    0.0
}

/// Applies a batch of placements to the stock: removes the cutting part's volume at each
/// non-rapid placement and, when `check_collisions` is set, records shank/holder (and
/// rapid-move) material contacts longer than `collision_tol` (mm).
///
/// Exactly the result of [`apply_batch_reference`] (every ray's intervals bit for bit, the
/// same hits; the removed volume up to the order of a floating-point sum), computed faster:
/// * placements are bucketed by the ray rows their boxes touch (O(rows touched) instead of
///   O(rows × batch)), and rows run in parallel, each applying its placements in order;
/// * on a row only the columns inside the band of radius `R` (largest radius of the part's
///   pieces clipped to the stock box) around the projected tool axis are visited: a ray
///   farther than `R` from the axis line in projection is farther than `R` in space and
///   meets no clipped piece, and the unclipped rest of the tool lies outside the stock box,
///   where no ray holds material;
/// * a ray none of whose material intervals meets the part's extent along the ray is
///   skipped before any geometry. A point of the part on the ray at `(u, v)` is
///   `tip + h·a + w` with `w ⊥ a`, `|w| ≤ R`, so its axis height `h` lies in the window where
///   `|tip_u + h·a_u − u| ≤ R` and `|tip_v + h·a_v − v| ≤ R` (within the clipped pieces'
///   span) and its coordinate along the ray within `R·sqrt(1 − a_d²)` of `tip_d + h·a_d`;
///   material outside that extent is untouched by subtraction and overlap. The unclipped
///   rest of the tool lies outside the stock box, where no ray holds material.
///   For the cutting part the extent follows its profile piece by piece
///   ([`crate::reach`]).
/// * the same test runs on groups of rays first: the extent over a group's column (and row)
///   range contains every member's extent, and the group's material bound
///   (the private `cull` module) contains every member's material, also later in the batch since
///   removal only shrinks material. A placement's ray range is shrunk to the
///   `cull::TILE`² tiles it can meet (from bounds taken at the batch's start)
///   before it is bucketed into rows, and on a row whole `cull::CHUNK`s of rays
///   are skipped. On the default job at 0.1 mm this skips 94 % of the rays the band visits
///   (26.6·10⁹ → 1.6·10⁹ ray visits; removal 102 s → 31 s on two cores).
/// * a chunk whose rays all hold no material inside the cutting part's extent over the
///   chunk is skipped too: each chunk keeps an interval of common air (`cull::AirSpan`,
///   valid for the rest of the batch since air only grows), and a cutter moving through a
///   channel between walls stays inside it.
/// * a ray whose cutter interval lay in a gap of its material keeps a witness
///   ([`crate::witness`]): while the witness point stays inside the cutter and the gap's
///   ends stay outside it, the placement removes nothing there, without an intersection.
///
/// Every bound is widened by [`CULL_SLACK_MM`]. Cost per placement: O(rays of the band
/// inside the box) bound checks plus one ray–solid intersection per ray whose material
/// overlaps the part's extent.
pub fn apply_batch(
    stock: &mut TriDexel,
    bodies: &[ToolBody],
    batch: &[Placement],
    check_collisions: bool,
    collision_tol: f64,
) -> BatchOutcome {
    let cell = stock.cell();
    let Prepared { coll_pieces, preps } = prepare(stock, bodies, batch, check_collisions);
    let margin = witness_margin(stock);
    let mut outcome = BatchOutcome::default();
    for grid in stock.grids_mut().iter_mut() {
        let d = grid.dir();
        let (_, nv) = grid.size();
        let geo = grid.geometry();
        let (u0, v0) = grid.ray_uv(0, 0);
        let (tiles, rows) = grid.tiles_and_rows_mut();
        let feet: Vec<(Option<CutFootprint>, Option<Footprint>)> = batch
            .par_iter()
            .zip(&preps)
            .map(|(pl, p)| {
                let cut = p.cut_box.as_ref().and_then(|bx| {
                    let reach = Reach::new(&bodies[pl.tool].cutting, &pl.tip, &pl.axis, d);
                    CutFootprint::new(&geo, bx, reach)?.shrink(tiles, (u0, v0), cell)
                });
                let coll = Footprint::new(&geo, &p.coll_box, p.coll_radius, p.coll_span, pl)
                    .and_then(|f| f.shrink(tiles, (u0, v0), cell));
                (cut, coll)
            })
            .collect();
        // Placements per row, in batch order (CSR).
        let span = |f: &(Option<CutFootprint>, Option<Footprint>)| -> Option<(usize, usize)> {
            match (f.0.map(|a| a.range), f.1.map(|b| b.range)) {
                (None, None) => None,
                (Some(a), None) | (None, Some(a)) => Some((a.j0, a.j1)),
                (Some(a), Some(b)) => Some((a.j0.min(b.j0), a.j1.max(b.j1))),
            }
        };
        let mut offsets = vec![0usize; nv + 1];
        for f in &feet {
            if let Some((j0, j1)) = span(f) {
                for o in &mut offsets[j0 + 1..=j1 + 1] {
                    *o += 1;
                }
            }
        }
        for j in 0..nv {
            offsets[j + 1] += offsets[j];
        }
        let mut fill = offsets.clone();
        let mut order = vec![0u32; offsets[nv]];
        for (k, f) in feet.iter().enumerate() {
            if let Some((j0, j1)) = span(f) {
                for slot in &mut fill[j0..=j1] {
                    // Batches hold far fewer than 2³² placements (`SimOptions::batch_positions`).
                    order[*slot] = k as u32;
                    *slot += 1;
                }
            }
        }
        let ctx = RowContext {
            geo,
            cell,
            origin: (u0, v0),
            bodies,
            batch,
            preps: &preps,
            coll_pieces: &coll_pieces,
            feet: &feet,
            collision_tol,
            margin,
            tiles,
        };
        let (removed, hits) = rows
            .enumerate()
            .map_init(RowScratch::default, |scratch, (j, row)| {
                ctx.row(scratch, j, row, &order[offsets[j]..offsets[j + 1]])
            })
            .reduce(
                || (0.0, Vec::new()),
                |mut a, mut b| {
                    a.0 += b.0;
                    a.1.append(&mut b.1);
                    a
                },
            );
        outcome.removed_volume += removed * cell * cell / 3.0;
        outcome.hits.extend(hits);
    }
    outcome
}

/// Margin (mm) of the witnesses' point classifications ([`crate::witness`]): 10⁻⁴ mm plus
/// four `f32` epsilons of the largest coordinate of the stock box, far above the rounding
/// of a computed chord (≈ 10⁻¹³ mm; 10⁻⁷ mm at grazing incidence; 10⁻⁶ mm for a torus) and
/// above the rounding of its ends to `f32` (half an ulp, 6·10⁻⁵ mm at 1000 mm).
fn witness_margin(stock: &TriDexel) -> f64 {
    let big = stock
        .min()
        .iter()
        .chain(stock.max().iter())
        .fold(0.0f64, |m, x| m.max(x.abs()));
    1e-4 + 4.0 * f64::from(f32::EPSILON) * big
}

/// Where the cutting part of one placement can remove material on one grid: its box's ray
/// index range (shrunk to the tiles it can reach) and its reach along the rays.
#[derive(Debug, Clone, Copy)]
struct CutFootprint {
    range: Range2,
    reach: Reach,
}

impl CutFootprint {
    fn new(grid: &GridGeometry, (blo, bhi): &([f64; 3], [f64; 3]), reach: Reach) -> Option<Self> {
        let d = grid.dir();
        let (ua, va) = ((d + 1) % 3, (d + 2) % 3);
        let (i0, i1) = grid.index_range(blo[ua], bhi[ua], false)?;
        let (j0, j1) = grid.index_range(blo[va], bhi[va], true)?;
        Some(Self {
            range: Range2 { i0, i1, j0, j1 },
            reach,
        })
    }

    /// The footprint with its ray range shrunk to the tiles whose material bound meets the
    /// reach over the tile (exact: the reach over a tile contains the reach of each of its
    /// rays). O(tiles of the range).
    fn shrink(mut self, tiles: &TileBounds, origin: (f64, f64), cell: f64) -> Option<Self> {
        self.range = self
            .range
            .shrink(tiles, origin, cell, |us, vs| self.reach.extent(us, vs))?;
        Some(self)
    }
}

/// Per-row scratch of [`apply_batch`], reused between rows.
#[derive(Debug, Default)]
struct RowScratch {
    bounds: Vec<ChunkBound>,
    air: Vec<AirSpan>,
    witness: Vec<Witness>,
}

/// What every row of one grid shares in [`apply_batch`].
struct RowContext<'a> {
    geo: GridGeometry,
    cell: f64,
    origin: (f64, f64),
    bodies: &'a [ToolBody],
    batch: &'a [Placement],
    preps: &'a [Prep],
    coll_pieces: &'a [(Piece, PartKind)],
    feet: &'a [(Option<CutFootprint>, Option<Footprint>)],
    collision_tol: f64,
    /// Margin of the witnesses' point classifications (mm, [`witness_margin`]).
    margin: f64,
    /// The grid's tile bounds, where the changed chunks are marked.
    tiles: &'a TileBounds,
}

/// Whether some material interval of `segs` meets `[lo, hi]` (closed).
#[inline]
fn meets_material(segs: &[[f32; 2]], (lo, hi): (f64, f64)) -> bool {
    segs.iter()
        .any(|s| f64::from(s[1]) >= lo && f64::from(s[0]) <= hi)
}

impl RowContext<'_> {
    /// Applies the placements `order` (batch indices, in order) to row `j`; returns the
    /// length removed and the collision hits.
    #[inline]
    fn row(
        &self,
        scratch: &mut RowScratch,
        j: usize,
        row: &mut [Segments],
        order: &[u32],
    ) -> (f64, Vec<StockHit>) {
        let geo = &self.geo;
        let d = geo.dir();
        let (ua, va) = ((d + 1) % 3, (d + 2) % 3);
        let cell = self.cell;
        let (u0, v0) = self.origin;
        let v = v0 + j as f64 * cell;
        let mut removed = 0.0;
        let mut hits: Vec<StockHit> = Vec::new();
        if order.is_empty() {
            // No placement reaches the row: nothing to reset.
            return (removed, hits);
        }
        let chunks = row.len().div_ceil(CHUNK);
        scratch.bounds.clear();
        scratch.bounds.resize(chunks, ChunkBound::STALE);
        scratch.air.clear();
        scratch.air.resize(chunks, AirSpan::NONE);
        scratch.witness.clear();
        scratch.witness.resize(row.len(), Witness::NONE);
        for &k in order {
            let k = k as usize;
            let pl = &self.batch[k];
            let (cut, coll) = &self.feet[k];
            let row_reach = cut
                .as_ref()
                .filter(|f| f.range.has_row(j))
                .and_then(|f| f.reach.row(v));
            let cut_cols = cut.as_ref().zip(row_reach.as_ref()).and_then(|(f, r)| {
                let (a, e) = geo.index_range(r.span.0, r.span.1, false)?;
                let (a, e) = (a.max(f.range.i0), e.min(f.range.i1));
                (a <= e).then_some((a, e))
            });
            let coll_cols = coll.as_ref().and_then(|f| f.columns(geo, j, v));
            let coll_row = coll.map_or((1.0, 0.0), |f| f.row_window(v));
            let coll_cols = coll_cols.and_then(|c| coll.as_ref()?.narrow(geo, c, coll_row));
            let (ia, ib) = match (cut_cols, coll_cols) {
                (None, None) => continue,
                (Some(a), None) | (None, Some(a)) => a,
                (Some(a), Some(b)) => (a.0.min(b.0), a.1.max(b.1)),
            };
            let body = &self.bodies[pl.tool];
            let pieces = &self.coll_pieces[self.preps[k].coll.clone()];
            let dv = v - pl.tip[va];

            let mut best: [Option<StockHit>; 3] = [None; 3];
            let in_cols =
                |c: Option<(usize, usize)>, i: usize| c.is_some_and(|c| i >= c.0 && i <= c.1);
            for c in ia / CHUNK..=ib / CHUNK {
                let (ca, cb) = ((c * CHUNK).max(ia), (c * CHUNK + CHUNK - 1).min(ib));
                let (ra, rb) = (c * CHUNK, row.len().min(c * CHUNK + CHUNK) - 1);
                let Some(b) = scratch.bounds.get_mut(c) else {
                    continue;
                };
                if b.stale {
                    *b = ChunkBound::of(&row[ra..=rb]);
                }
                // The cutting part's extent over the chunk's columns it can reach.
                let cut_ext = cut_cols.and_then(|(x0, x1)| {
                    let (a, e) = (x0.max(ca), x1.min(cb));
                    if a > e {
                        return None;
                    }
                    let us = (u0 + a as f64 * cell, u0 + e as f64 * cell);
                    row_reach.as_ref()?.extent(us).filter(|x| b.meets(*x))
                });
                let chunk_coll = coll_cols.is_some_and(|(x0, x1)| {
                    let (a, e) = (x0.max(ca), x1.min(cb));
                    a <= e
                        && coll.as_ref().is_some_and(|f| {
                            f.extent_over(u0 + a as f64 * cell, u0 + e as f64 * cell, coll_row)
                                .is_some_and(|ext| b.meets(ext))
                        })
                });
                let cut_ext = cut_ext.filter(|x| !scratch.air[c].contains(*x));
                if cut_ext.is_none() && !chunk_coll {
                    continue;
                }
                // Common air of the chunk around the cutting part's extent, rebuilt while
                // the rays are visited (valid when no ray of the chunk meets the extent).
                let mut air = cut_ext.map(AirSpan::around);
                let mut changed = false;
                for (i, ray) in row.iter_mut().enumerate().take(rb + 1).skip(ra) {
                    let segs = ray.as_slice();
                    if let (Some(a), Some(x)) = (air.as_mut(), cut_ext) {
                        if !a.narrow(segs, x) {
                            air = None;
                        }
                    }
                    if i < ca || i > cb || segs.is_empty() {
                        continue;
                    }
                    let u = u0 + i as f64 * cell;
                    let in_coll = chunk_coll
                        && in_cols(coll_cols, i)
                        && coll.is_some_and(|f| f.meets(segs, u, coll_row));
                    let in_cut = cut_ext.is_some_and(|x| meets_material(segs, x))
                        && in_cols(cut_cols, i)
                        && row_reach.as_ref().is_some_and(|r| {
                            r.extent((u, u)).is_some_and(|x| meets_material(segs, x))
                        });
                    if !(in_coll || in_cut) {
                        continue;
                    }

                    let rl = RayLocal::new(d, u - pl.tip[ua], dv, &pl.axis);
                    if in_coll {
                        collide_ray(
                            ray,
                            &rl,
                            pl,
                            pieces,
                            k,
                            (d, ua, va),
                            (u, v),
                            self.collision_tol,
                            &mut best,
                        );
                    }
                    if in_cut {
                        let w = &mut scratch.witness[i];
                        if w.holds(&rl, pl.tip[d], &body.cutting, self.margin) {
                            continue;
                        }
                        let r = match body.cutting.ray_hull(&rl) {
                            Some((s, e)) => {
                                let (s, e) = (s + pl.tip[d], e + pl.tip[d]);
                                let r = ray.subtract(s, e);
                                *w = Witness::after_cut(ray.as_slice(), s, e);
                                r
                            }
                            None => {
                                *w = Witness::NONE;
                                0.0
                            }
                        };

                        changed |= r > 0.0;
                        removed += r;
                    }
                }

                if let Some(a) = air {
                    scratch.air[c] = a;
                }
                if changed {
                    if let Some(b) = scratch.bounds.get_mut(c) {
                        b.stale = true;
                    }
                    // A chunk lies in one tile (`CHUNK` divides `TILE`).
                    self.tiles.mark(ra, j);
                }
            }

            hits.extend(best.into_iter().flatten());
        }
        (removed, hits)
    }
}

/// The reference semantics of [`apply_batch`], without culling or parallelism: placements
/// in order, and for each grid every ray of the placement's clipped box gets the
/// collision overlaps and the cutting interval subtracted. O(placements × box rays); kept
/// to test that the fast path changes nothing.
pub fn apply_batch_reference(
    stock: &mut TriDexel,
    bodies: &[ToolBody],
    batch: &[Placement],
    check_collisions: bool,
    collision_tol: f64,
) -> BatchOutcome {
    let cell = stock.cell();
    let Prepared { coll_pieces, preps } = prepare(stock, bodies, batch, check_collisions);
    let mut outcome = BatchOutcome::default();
    for (k, pl) in batch.iter().enumerate() {
        let body = &bodies[pl.tool];
        let pieces = &coll_pieces[preps[k].coll.clone()];
        for grid in stock.grids_mut().iter_mut() {
            let d = grid.dir();
            let (ua, va) = ((d + 1) % 3, (d + 2) % 3);
            let to_range = |b: &Option<([f64; 3], [f64; 3])>| -> Option<Range2> {
                let (blo, bhi) = b.as_ref()?;
                let (i0, i1) = grid.index_range(blo[ua], bhi[ua], false)?;
                let (j0, j1) = grid.index_range(blo[va], bhi[va], true)?;
                Some(Range2 { i0, i1, j0, j1 })
            };
            let cut = to_range(&preps[k].cut_box);
            let coll = to_range(&preps[k].coll_box);
            let (u0, v0) = grid.ray_uv(0, 0);
            let mut removed = 0.0;
            for (j, row) in grid.rows_seq_mut().enumerate() {
                let cut = cut.filter(|r| r.has_row(j));
                let coll = coll.filter(|r| r.has_row(j));
                let (ia, ib) = match (cut, coll) {
                    (None, None) => continue,
                    (Some(a), None) => (a.i0, a.i1),
                    (None, Some(b)) => (b.i0, b.i1),
                    (Some(a), Some(b)) => (a.i0.min(b.i0), a.i1.max(b.i1)),
                };
                let v = v0 + j as f64 * cell;
                let dv = v - pl.tip[va];
                let mut best: [Option<StockHit>; 3] = [None; 3];
                for (i, ray) in row.iter_mut().enumerate().take(ib + 1).skip(ia) {
                    if ray.is_empty() {
                        continue;
                    }
                    let u = u0 + i as f64 * cell;
                    let rl = RayLocal::new(d, u - pl.tip[ua], dv, &pl.axis);
                    let in_coll = coll.is_some_and(|r| r.has(i));
                    let in_cut = cut.is_some_and(|r| r.has(i));
                    removed += ray_work(
                        ray,
                        &rl,
                        pl,
                        body,
                        in_coll.then_some(pieces),
                        in_cut,
                        k,
                        (d, ua, va),
                        (u, v),
                        collision_tol,
                        &mut best,
                    );
                }
                outcome.hits.extend(best.into_iter().flatten());
            }
            outcome.removed_volume += removed * cell * cell / 3.0;
        }
    }
    outcome
}
