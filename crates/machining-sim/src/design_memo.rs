//! What the impeller design distance computed at the last two points a thread asked about,
//! so that the next questions reuse it instead of computing it again.
//!
//! The verifier asks about points in runs: the cut end points of one ray row lie a cell
//! apart, and the depth of an end point inside the design ([`crate::endpoints`]) asks for
//! the signed distance at the end point, then at the points of its walk back to the entry
//! point, then for the depth below the face nearest to the entry point — which evaluates
//! the hub, the shroud contour, the nearest blade-side triangle and that side's distance at
//! the entry point once more. Two uses:
//!
//! * **Reuse at the same point**: a later question at a bit-identical point (same design)
//!   takes the hub, shroud and side distances and the nearest triangle recorded for it. The
//!   values are those the same functions computed on the same input: results are bit for bit
//!   those of computing them again.
//! * **Bounded nearest-triangle search**: the distance `m` from the last point `q` to its
//!   nearest side-mesh triangle bounds the distance from `p` to its nearest triangle by
//!   `m + |p − q|` (triangle inequality). The BVH search started with that bound (plus a
//!   relative 10⁻⁹ against rounding) prunes every box farther away from the start; it visits
//!   the remaining nodes in the same depth-first order as the unbounded search and keeps the
//!   first triangle of least distance, so it returns the same triangle and projection
//!   (parry's `find_best`, strict comparisons: boxes farther than the bound hold only
//!   triangles farther than the nearest).
//!
//! Per thread (a `thread_local` pair of records, no locking, no allocation); every record
//! carries the design's identity ([`next_design_id`]), so two designs never share one.
//! Which points a thread saw depends on rayon's scheduling, the results do not.

use std::cell::Cell;
use std::sync::atomic::{AtomicU64, Ordering};

/// What was computed at one point (each value `None` when it was not needed there).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Visit {
    /// Identity of the design ([`next_design_id`]).
    pub design: u64,
    /// The point (mm).
    pub p: [f64; 3],
    /// Distance to the nearest triangle of the blade-side mesh and that triangle.
    pub mesh: (f64, u32),
    /// Hub signed distance.
    pub hub: Option<f64>,
    /// Shroud contour signed distance.
    pub shroud: Option<f64>,
    /// Signed distance to the blade side of the nearest triangle (Newton from that
    /// triangle's parameters).
    pub side: Option<f64>,
}

thread_local! {
    /// The two most recent visits of this thread, newest first.
    static RECENT: Cell<[Option<Visit>; 2]> = const { Cell::new([None, None]) };
}

static NEXT_ID: AtomicU64 = AtomicU64::new(1);

/// A fresh design identity.
pub(crate) fn next_design_id() -> u64 {
    NEXT_ID.fetch_add(1, Ordering::Relaxed)
}

/// The recorded visit of `design` at the bit-identical point `p`, if one of the two recent
/// visits is it.
#[inline]
pub(crate) fn recall(design: u64, p: &[f64; 3]) -> Option<Visit> {
    RECENT.with(|r| {
        r.get()
            .into_iter()
            .flatten()
            .find(|v| v.design == design && same_point(&v.p, p))
    })
}

/// An upper bound (mm) on the distance from `p` to the nearest side-mesh triangle of
/// `design`, from the most recent visit of that design (see the module docs), or `None`.
#[inline]
pub(crate) fn mesh_bound(design: u64, p: &[f64; 3]) -> Option<f64> {
    RECENT.with(|r| {
        let v = r.get()[0].filter(|v| v.design == design)?;
        let d =
            ((p[0] - v.p[0]).powi(2) + (p[1] - v.p[1]).powi(2) + (p[2] - v.p[2]).powi(2)).sqrt();
        let b = v.mesh.0 + d;
        // Rounding of both distances (≈ 10⁻¹⁶ relative) far below the slack.
        let b = b + 1e-9 * (1.0 + b + p.iter().fold(0.0f64, |m, x| m.max(x.abs())));
        b.is_finite().then_some(b)
    })
}

/// Records a visit, or merges it into the newest one when that is the same design and point
/// (values already known are kept: they came from the same computation).
#[inline]
pub(crate) fn record(visit: Visit) {
    RECENT.with(|r| {
        let [a, b] = r.get();
        match a {
            Some(mut old) if old.design == visit.design && same_point(&old.p, &visit.p) => {
                old.hub = old.hub.or(visit.hub);
                old.shroud = old.shroud.or(visit.shroud);
                old.side = old.side.or(visit.side);
                r.set([Some(old), b]);
            }
            _ => r.set([Some(visit), a]),
        }
    });
}

/// Adds the hub distance to the newest visit when it is `design` at `p`.
#[inline]
pub(crate) fn note_hub(design: u64, p: &[f64; 3], hub: f64) {
    RECENT.with(|r| {
        let [a, b] = r.get();
        if let Some(mut v) = a.filter(|v| v.design == design && same_point(&v.p, p)) {
            v.hub = Some(hub);
            r.set([Some(v), b]);
        }
    });
}

#[inline]
fn same_point(a: &[f64; 3], b: &[f64; 3]) -> bool {
    a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// Forgets this thread's visits (tests compare against evaluations without the memo).
#[cfg(test)]
pub(crate) fn forget() {
    RECENT.with(|r| r.set([None, None]));
}
