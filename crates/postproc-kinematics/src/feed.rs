//! Feed of simultaneous five-axis moves: the tool-tip (TCP) feed in mm/min and the
//! inverse-time value (G93: the block takes `1/F` minutes).
//!
//! The block time is the larger of the tip path time at the programmed feed and, for every
//! axis with a speed limit, the time the axis needs for its displacement at its largest
//! speed, so no axis is asked to exceed its speed.

use crate::joints::{AxisId, Joints};
use crate::machine::Machine;

/// Shortest block time (min) used for inverse-time feed of blocks that do not move at all;
/// keeps `F` finite.
pub const MIN_BLOCK_TIME_MIN: f64 = 1e-6;

/// Time (min) of a block from `j0` to `j1` whose tool tip travels `tip_length_mm` at
/// `feed_mm_per_min`, respecting every axis' largest speed.
pub fn block_time_min(
    machine: &Machine,
    j0: &Joints,
    j1: &Joints,
    tip_length_mm: f64,
    feed_mm_per_min: f64,
) -> f64 {
    let mut t = if feed_mm_per_min > 0.0 {
        tip_length_mm / feed_mm_per_min
    } else {
        0.0
    };
    for a in AxisId::ALL {
        if let Some(v) = machine.axis(a).max_speed {
            t = t.max((j1.get(a) - j0.get(a)).abs() / v);
        }
    }
    t.max(MIN_BLOCK_TIME_MIN)
}

/// Inverse-time feed value (1/min) of a block: `1 / block_time_min`.
pub fn inverse_time_feed(
    machine: &Machine,
    j0: &Joints,
    j1: &Joints,
    tip_length_mm: f64,
    feed_mm_per_min: f64,
) -> f64 {
    1.0 / block_time_min(machine, j0, j1, tip_length_mm, feed_mm_per_min)
}
