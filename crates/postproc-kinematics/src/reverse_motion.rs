//! Reverse motions of the rotary axes: places along a cutting run where the angular
//! displacement of an axis changes direction (paper 004: such reversals leave tool marks,
//! because the feed drive stops and backlash acts).

use crate::joints::AxisId;
use crate::post::PostedBlock;
use cam_core::MoveKind;

/// Angular steps smaller than this (rad) count as standing still when looking for direction
/// changes.
pub const REVERSE_DEAD_BAND_RAD: f64 = 1e-6;

/// Number of direction changes in a sequence of angles (rad): sign changes between
/// consecutive non-negligible steps (steps within `dead_band` are skipped). O(n).
pub fn count_reverse_motions(angles: &[f64], dead_band: f64) -> usize {
    let mut last_sign = 0.0;
    let mut count = 0;
    for w in angles.windows(2) {
        let d = w[1] - w[0];
        if d.abs() <= dead_band {
            continue;
        }
        let s = d.signum();
        if last_sign != 0.0 && s != last_sign {
            count += 1;
        }
        last_sign = s;
    }
    count
}

/// Index ranges `[start, end)` of the cutting runs of a block list: maximal runs of
/// consecutive non-rapid blocks, each including the block it starts from.
pub fn cutting_runs(blocks: &[PostedBlock]) -> Vec<(usize, usize)> {
    let mut runs = Vec::new();
    let mut i = 0;
    while i < blocks.len() {
        if i + 1 < blocks.len() && blocks[i + 1].kind != MoveKind::Rapid {
            let start = i;
            let mut end = i + 1;
            while end < blocks.len() && blocks[end].kind != MoveKind::Rapid {
                end += 1;
            }
            runs.push((start, end));
            i = end;
        } else {
            i += 1;
        }
    }
    runs
}

/// Reverse motions of one rotary axis over all cutting runs.
pub fn count_axis_reverse_motions(blocks: &[PostedBlock], axis: AxisId) -> usize {
    let mut angles = Vec::new();
    cutting_runs(blocks)
        .into_iter()
        .map(|(s, e)| {
            angles.clear();
            angles.extend(blocks[s..e].iter().map(|b| b.joints.get(axis)));
            count_reverse_motions(&angles, REVERSE_DEAD_BAND_RAD)
        })
        .sum()
}

/// Reverse motions of both rotary axes over all cutting runs.
pub fn count_path_reverse_motions(blocks: &[PostedBlock]) -> usize {
    count_axis_reverse_motions(blocks, AxisId::Tilt)
        + count_axis_reverse_motions(blocks, AxisId::Rotate)
}
