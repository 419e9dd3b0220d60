//! How the chunks of one channel — each cut without leaving its level ([`super::locate`],
//! which already joined the chunks of a level where it could) — are joined into the
//! channel's path, levels from the shroud down, and at which rate the joining moves run.
//!
//! The next chunk is the one of the current level (or, when it has none left, of the next
//! level) whose start lies nearest the tool, cut backwards when its end lies nearer (unless
//! every path is cut one way). Between levels it is reached without leaving the channel when
//! that is short and safe: a **step down**, the straight move from the end of a level to the
//! start of the next when it is at most one depth of cut plus [`STEP_DOWN_INTERVALS`] path
//! intervals long and the
//! whole tool is certified clear of the design along it as the cutting motions are
//! ([`cam_plan::DesignClearance::segment_clearance`], within half the machining tolerance):
//! a plunge at the plunge feed through the one slab between the levels. Every level's lanes
//! are ordered so that it ends where the next begins (module docs of [`super::locate`]).
//!
//! Otherwise the tool retracts over the safety surface and approaches the next chunk
//! ([`cam_plan::PlanContext::link`]). A retract that runs along the tool axis of a tool whose
//! radius never shrinks from the tip up sweeps nothing beyond the volume the tool already
//! occupies, where it was cutting, but the cylinder above its holder; when that cylinder
//! stays outside the blank ([`cam_plan::Linker::retract_sweeps_no_stock`]) the retract cuts
//! nothing and runs at the link feed (`link_feed_mm_per_min`; a linear move, not a rapid: a
//! rapid is not guaranteed to follow a straight line on every controller, and this one
//! starts beside the blades). The approach stays a rapid down to the blank and a plunge at
//! the plunge feed below it (the linker does not know what the earlier levels left there).
//!
//! Cost: O(chunks²) distance tests per level and one motion check per step down tried.

use super::posture::SEGMENT_QUERIES;
use cam_core::{CutterLocation, Move, MoveKind};
use cam_plan::{PlanContext, PlanError};

/// Longest step down (mm): one depth of cut plus this many path intervals, so that the
/// move runs within two paths of the level above (cleared there) while it cuts through the
/// slab between the levels.
pub(super) const STEP_DOWN_INTERVALS: f64 = 2.0;

/// A chunk of one level: moves cut without leaving the level, with the planar points of its
/// ends.
#[derive(Debug, Clone)]
pub(super) struct Chunk {
    pub(super) moves: Vec<Move>,
    pub(super) first_q: [f64; 2],
    pub(super) last_q: [f64; 2],
}

impl Chunk {
    /// Whether the chunk may be cut backwards: only cutting moves and links at feed (a lifted
    /// one-way link is not reversed).
    fn reversible(&self) -> bool {
        self.moves
            .iter()
            .all(|m| matches!(m.kind, MoveKind::Feed | MoveKind::Link))
    }

    /// The chunk cut backwards (same locations, same certified motions, reverse order): the
    /// motion into a location of the reversed chunk is the one that left it, so it keeps that
    /// move's kind (a link stays a link).
    fn reversed(&self) -> Self {
        let n = self.moves.len();
        let moves = (0..n)
            .rev()
            .map(|i| {
                let kind = match self.moves.get(i + 1) {
                    Some(next) if next.kind == MoveKind::Link => MoveKind::Link,
                    _ => MoveKind::Feed,
                };
                Move {
                    kind,
                    cl: self.moves[i].cl,
                    feed_mm_per_min: None,
                }
            })
            .collect();
        Self {
            moves,
            first_q: self.last_q,
            last_q: self.first_q,
        }
    }
}

/// One level's chunks and its path interval (mm).
pub(super) struct LevelChunks {
    pub(super) chunks: Vec<Chunk>,
    pub(super) step: f64,
}

/// What joining one channel made.
#[derive(Debug, Default)]
pub(super) struct Joined {
    pub(super) moves: Vec<Move>,
    /// Retracts over the safety surface between chunks.
    pub(super) retracts: usize,
    /// Step downs between levels.
    pub(super) step_downs: usize,
}

/// Joins the chunks of `levels` (shroud → hub) into one path (module docs). `reversible`:
/// whether a chunk may be cut backwards (not with one-way linking).
pub(super) fn join(
    ctx: &PlanContext<'_>,
    levels: &[LevelChunks],
    doc: f64,
    reversible: bool,
) -> Result<Joined, PlanError> {
    let tol = 0.5 * ctx.tolerances.machining_tol;
    let certified = |a: &CutterLocation, b: &CutterLocation| {
        ctx.clearance
            .segment_clearance(a, b, 0.0, tol, SEGMENT_QUERIES)
            .is_ok()
    };
    let mut out = Joined::default();
    // The tool's last location and the level it is on.
    let mut at: Option<(CutterLocation, usize)> = None;
    for (li, level) in levels.iter().enumerate() {
        let mut remaining: Vec<Chunk> = level.chunks.clone();
        while !remaining.is_empty() {
            // The chunk (and direction) starting nearest the tool; the first in lane order
            // to begin with.
            let (idx, rev) = match &at {
                None => (0, false),
                Some((cl, _)) => {
                    let mut best = (0, false, f64::INFINITY);
                    for (i, c) in remaining.iter().enumerate() {
                        for rev in [false, true] {
                            if rev && !(reversible && c.reversible()) {
                                continue;
                            }
                            let start = if rev { c.moves.last() } else { c.moves.first() };
                            let Some(start) = start else { continue };
                            let d = (start.cl.tip - cl.tip).norm();
                            if d < best.2 {
                                best = (i, rev, d);
                            }
                        }
                    }
                    (best.0, best.1)
                }
            };
            let chunk = remaining.remove(idx);
            let chunk = if rev { chunk.reversed() } else { chunk };
            let (Some(first), Some(last)) = (chunk.moves.first(), chunk.moves.last()) else {
                continue;
            };
            match at {
                None => out.moves.extend(chunk.moves.iter().copied()),
                Some((from, from_level)) => {
                    let d = (first.cl.tip - from.tip).norm();
                    let step_down = from_level != li
                        && d <= doc + STEP_DOWN_INTERVALS * level.step
                        && certified(&from, &first.cl);
                    if step_down {
                        out.step_downs += 1;
                        out.moves.push(Move {
                            kind: MoveKind::Plunge,
                            cl: first.cl,
                            feed_mm_per_min: None,
                        });
                    } else {
                        out.retracts += 1;
                        out.moves.extend(ctx.link(&from, &first.cl, doc)?);
                    }
                    out.moves.extend(chunk.moves.iter().skip(1).copied());
                }
            }
            at = Some((last.cl, li));
        }
    }
    Ok(out)
}

/// Sets the link feed on the retracts of `moves` that cut nothing (module docs): a retract
/// along the previous location's tool axis, for a tool whose radius never shrinks from the
/// tip up, whose sweep beyond the tool's own volume stays outside the blank. Returns how
/// many run at the link feed and how many stay at the cutting feed.
pub(super) fn retract_feeds(
    ctx: &PlanContext<'_>,
    moves: &mut [Move],
    link_feed: f64,
) -> (usize, usize) {
    let profile = cam_plan::linking::widening_profile(&ctx.tool.cutter);
    let (mut fast, mut slow) = (0, 0);
    for k in 1..moves.len() {
        if moves[k].kind != MoveKind::Retract {
            continue;
        }
        let from = moves[k - 1].cl;
        let to = moves[k].cl;
        let same_axis = (to.axis.into_inner() - from.axis.into_inner()).norm() < 1e-9;
        let clear = same_axis
            && profile.is_some_and(|p| ctx.linker.retract_sweeps_no_stock(&from, &to.tip, p));
        if clear {
            moves[k].feed_mm_per_min = Some(link_feed);
            fast += 1;
        } else {
            slow += 1;
        }
    }
    (fast, slow)
}
