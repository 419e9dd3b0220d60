//! Feed blocks cut as swept segments ([`crate::swept`]) instead of sampled positions, and
//! how their cuts interleave with the positions where the shank and holder are checked.
//!
//! **Which blocks.** A block is treated as a pure translation of the cutter from its start
//! tip to its end tip with the end's axis when, at the block's start and at each of its
//! samples on the actual motion, the largest displacement of a cutting point between the
//! actual location and the translated one ([`crate::merge::cutting_displacement`]:
//! `|Δtip| + H·|Δaxis|` plus the flute radius times `|Δaxis|`) stays within a quarter of the
//! sweep tolerance. The swept solid then lies within that distance of the true one (a
//! two-sided Hausdorff bound, between samples under the same assumption as `merge`: the
//! motion between samples is the interpolation they were taken from), inside the sweep
//! tolerance that the reported error bound already carries
//! ([`crate::endpoints::overcut_error_bound`]); where the axis does not turn at all (the
//! common case of this path) the swept solid is the true one and the union of sampled
//! positions' under-read of up to the sweep tolerance is gone. A run of blocks is cut
//! this way only when every block qualifies; otherwise it keeps its sampled positions.
//!
//! **Pieces.** A run whose samples all stay within the budget of its chord (start tip to
//! end tip, end axis) is cut as that chord, else each block of a run whose blocks all
//! qualify on their own. Each piece is cut as sub-segments no longer than the cutting
//! part's largest radius, so that the culling bounds of a segment ([`crate::reach`]) stay
//! as tight as a position's: the union of the sub-segments' swept solids is the piece's.
//! The caller keeps the sampled positions when the sub-segments would outnumber them
//! (short blocks of a turning axis merged by `merge`): both are within the error bound,
//! and a swept cut costs about two positions' intersections.
//!
//! **Order with the checks.** The sampled positions are kept as check-only placements (the
//! shank and holder are checked there, exactly as before). A check at a position must see
//! the material as it is when the position is reached. The non-cutting parts sit at axis
//! heights `h' ≥ H` and the flutes at `h ≤ H`; a flute point at fraction `j` coincides with
//! a non-cutting point at fraction `k` only if `(j − k)·(δ·a) = h' − h ≥ 0` (δ the block's
//! translation, a the axis). When `δ·a ≤ 0` no later flute position reaches a check's
//! parts, so the sub-segment is cut before its checks; when `δ·a > 0` no earlier one does,
//! so it is cut after them. Either way each check sees what it saw with sampled cuts, up to
//! the scallops the sampled union left (which only the exact sweep removes).
//!
//! Cost: O(samples) per block to qualify it, O(1) per sub-segment.

use crate::merge::{cutting_displacement, CuttingReach, Run};
use crate::removal::{Placement, Role};
use cam_core::CutterLocation;

/// A straight piece of pure translation: start tip, end tip, unit axis, and the last
/// move index it covers.
pub type Piece = ([f64; 3], [f64; 3], [f64; 3], usize);

/// Whether the motion from `start` through `samples` stays within `budget_mm` (cutting
/// displacement, module docs) of the translation from `start.tip` to `end.tip` with
/// `end.axis`, each sample compared with its projection onto the chord.
fn fits(
    start: &CutterLocation,
    end: &CutterLocation,
    samples: &[CutterLocation],
    reach: &CuttingReach,
    budget_mm: f64,
) -> bool {
    let d = end.tip - start.tip;
    let len2 = d.norm_squared();
    let lin = |q: &CutterLocation| {
        let s = if len2 > 0.0 {
            ((q.tip - start.tip).dot(&d) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        CutterLocation {
            tip: start.tip + d * s,
            axis: end.axis,
        }
    };
    std::iter::once(start)
        .chain(samples)
        .chain(std::iter::once(end))
        .all(|q| {
            let e = cutting_displacement(reach, &lin(q), q);
            !e.is_nan() && e <= budget_mm
        })
}

/// The pieces of pure translation `run` is cut as (module docs): the run's chord when the
/// whole run fits it, else each block when every block fits its own, else none (the run
/// keeps its sampled positions). `sub` samples per block.
pub fn translations(run: &Run, reach: &CuttingReach, sub: usize, budget_mm: f64) -> Vec<Piece> {
    let (Some(start), Some(&(last_mi, _, end, _))) = (run.start, run.blocks.last()) else {
        return Vec::new();
    };
    if run.samples().len() != sub * run.blocks.len() {
        return Vec::new();
    }
    let arr = |c: &CutterLocation| [c.tip.x, c.tip.y, c.tip.z];
    let ax = |c: &CutterLocation| [c.axis.x, c.axis.y, c.axis.z];
    if fits(&start, &end, run.samples(), reach, budget_mm) {
        return vec![(arr(&start), arr(&end), ax(&end), last_mi)];
    }
    let mut out = Vec::with_capacity(run.blocks.len());
    for (b, (mi, from, to, _)) in run.blocks.iter().enumerate() {
        if !fits(
            from,
            to,
            &run.samples()[b * sub..(b + 1) * sub],
            reach,
            budget_mm,
        ) {
            return Vec::new();
        }
        out.push((arr(from), arr(to), ax(to), *mi));
    }
    out
}

/// Number of sub-segments of at most `max_len_mm` that [`interleave`] cuts `pieces` in.
pub fn cut_count(pieces: &[Piece], max_len_mm: f64) -> usize {
    pieces
        .iter()
        .map(|(a, b, _, _)| {
            let l = (0..3).map(|k| (b[k] - a[k]).powi(2)).sum::<f64>().sqrt();
            ((l / max_len_mm.max(1e-9)).ceil() as usize).clamp(1, 1_000_000)
        })
        .sum()
}

/// Emits `pieces` (see [`translations`]) of tool `tool` as swept cuts in sub-segments of
/// at most `max_len_mm`, interleaved with the check-only placements `checks` (the run's
/// sampled positions in order, with their (operation, move) labels in `labels`; empty when
/// the stock checks are off) in the order of the module docs. `op` labels the cuts.
pub fn interleave(
    pieces: &[Piece],
    checks: &[Placement],
    labels: &[(usize, usize)],
    (op, tool): (usize, usize),
    max_len_mm: f64,
    batch: &mut Vec<Placement>,
    meta: &mut Vec<(usize, usize)>,
) {
    let mut next = 0;
    for &(t0, t1, axis, last_mi) in pieces {
        let delta = [0, 1, 2].map(|k| t1[k] - t0[k]);
        let len2: f64 = delta.iter().map(|x| x * x).sum();
        let n = cut_count(&[(t0, t1, axis, last_mi)], max_len_mm);
        let down = delta[0] * axis[0] + delta[1] * axis[1] + delta[2] * axis[2] <= 0.0;
        // The piece's checks, in order, with their fraction along the piece.
        let mut c = next;
        while next < checks.len() && labels[next].1 <= last_mi {
            next += 1;
        }
        let fraction = |p: &Placement| {
            if len2 <= 0.0 {
                1.0
            } else {
                (0..3).map(|k| (p.tip[k] - t0[k]) * delta[k]).sum::<f64>() / len2
            }
        };
        let at = |f: f64| [0, 1, 2].map(|k| t0[k] + f * delta[k]);
        for j in 1..=n {
            let a = at((j - 1) as f64 / n as f64);
            let b = if j == n { t1 } else { at(j as f64 / n as f64) };
            let cut = Placement {
                tip: b,
                axis,
                tool,
                rapid: false,
                sweep: [0, 1, 2].map(|k| b[k] - a[k]),
                role: Role::Cut,
            };
            let end = if j == n {
                next
            } else {
                let lim = j as f64 / n as f64;
                let mut e = c;
                while e < next && fraction(&checks[e]) <= lim {
                    e += 1;
                }
                e
            };
            if down {
                batch.push(cut);
                meta.push((op, last_mi));
            }
            for k in c..end {
                let mut p = checks[k];
                p.role = Role::Check;
                batch.push(p);
                meta.push(labels[k]);
            }
            if !down {
                batch.push(cut);
                meta.push((op, last_mi));
            }
            c = end;
        }
    }
}
