//! Material removal on the tri-dexel stock and in-process collision detection of the
//! non-cutting parts, for a batch of cutter positions.
//!
//! For each grid, rows of rays are processed in parallel (rayon); inside a row the positions
//! are applied in their machining order, so every ray sees exactly the sequential history and
//! the result does not depend on the batch size or thread count. Per position only the rays
//! inside the projection of the part's bounding box (clipped to the stock lattice) are
//! visited; empty rays are skipped before any geometry. Per ray the cutter's interval is the
//! closed-form ray–solid-of-revolution intersection of [`crate::tool_solid`], subtracted from
//! the ray's material list.
//!
//! Collisions are detected against the stock *as it is when the position is reached*: the
//! shank and holder pieces (and, for rapid moves, the whole tool) are intersected with each
//! ray and any material overlap longer than the collision tolerance is a hit. Depth reported
//! = longest overlap along a ray (≥ the normal penetration for the ray direction closest to
//! the contact normal).
//!
//! Cost per position: O(A/h²) rays per grid, A the part's projected area; memory: none
//! beyond the hit list (allocation-free kernel except when a two-interval ray splits into
//! three).

use crate::dexel::TriDexel;
use crate::tool_solid::{Piece, RayLocal, RevolvedSolid};
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

/// Applies a batch of placements to the stock: removes the cutting part's volume at each
/// non-rapid placement and, when `check_collisions` is set, records shank/holder (and
/// rapid-move) material contacts longer than `collision_tol` (mm).
pub fn apply_batch(
    stock: &mut TriDexel,
    bodies: &[ToolBody],
    batch: &[Placement],
    check_collisions: bool,
    collision_tol: f64,
) -> BatchOutcome {
    let lo = stock.min();
    let hi = stock.max();
    let cell = stock.cell();
    // Clipped pieces per placement.
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
                        coll_pieces.push((c, *kind));
                    }
                }
            }
        }
        preps.push(Prep {
            cut_box,
            coll_box,
            coll: start..coll_pieces.len(),
        });
    }

    let mut outcome = BatchOutcome::default();
    for grid in stock.grids_mut().iter_mut() {
        let d = grid.dir();
        let (ua, va) = ((d + 1) % 3, (d + 2) % 3);
        let to_range = |b: &Option<([f64; 3], [f64; 3])>| -> Option<Range2> {
            let (blo, bhi) = b.as_ref()?;
            let (i0, i1) = grid.index_range(blo[ua], bhi[ua], false)?;
            let (j0, j1) = grid.index_range(blo[va], bhi[va], true)?;
            Some(Range2 { i0, i1, j0, j1 })
        };
        let ranges: Vec<(Option<Range2>, Option<Range2>)> = preps
            .iter()
            .map(|p| (to_range(&p.cut_box), to_range(&p.coll_box)))
            .collect();
        let (u0, v0) = grid.ray_uv(0, 0);
        let (removed, hits) = grid
            .rows_mut()
            .enumerate()
            .map(|(j, row)| {
                let v = v0 + j as f64 * cell;
                let mut removed = 0.0;
                let mut hits: Vec<StockHit> = Vec::new();
                for (k, pl) in batch.iter().enumerate() {
                    let (cut, coll) = ranges[k];
                    let cut = cut.filter(|r| r.has_row(j));
                    let coll = coll.filter(|r| r.has_row(j));
                    let (ia, ib) = match (cut, coll) {
                        (None, None) => continue,
                        (Some(a), None) => (a.i0, a.i1),
                        (None, Some(b)) => (b.i0, b.i1),
                        (Some(a), Some(b)) => (a.i0.min(b.i0), a.i1.max(b.i1)),
                    };
                    let body = &bodies[pl.tool];
                    let pieces = &coll_pieces[preps[k].coll.clone()];
                    let dv = v - pl.tip[va];
                    let mut best: [Option<StockHit>; 3] = [None; 3];
                    for (i, ray) in row.iter_mut().enumerate().take(ib + 1).skip(ia) {
                        if ray.is_empty() {
                            continue;
                        }
                        let u = u0 + i as f64 * cell;
                        let rl = RayLocal::new(d, u - pl.tip[ua], dv, &pl.axis);
                        if coll.is_some_and(|r| r.has(i)) {
                            for (piece, kind) in pieces {
                                if let Some((s, e)) = piece.ray_interval(&rl) {
                                    let (s, e) = (s + pl.tip[d], e + pl.tip[d]);
                                    let ov = ray.overlap(s, e);
                                    let slot = match kind {
                                        PartKind::Shank => 0,
                                        PartKind::Holder => 1,
                                        PartKind::RapidMove => 2,
                                    };
                                    if ov > collision_tol && best[slot].is_none_or(|h| h.depth < ov)
                                    {
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
                        if cut.is_some_and(|r| r.has(i)) {
                            if let Some((s, e)) = body.cutting.ray_hull(&rl) {
                                removed += ray.subtract(s + pl.tip[d], e + pl.tip[d]);
                            }
                        }
                    }
                    hits.extend(best.into_iter().flatten());
                }
                (removed, hits)
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
