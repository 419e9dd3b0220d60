//! Ordering of channels and blades so that rapids stay short.
//!
//! On an impeller every channel is the previous one turned by one pitch, so machining them in
//! angular sequence from a start channel makes each link the shortest possible (one pitch of
//! rotary travel); `nearest_first` orders arbitrary paths greedily by the distance from one
//! path's last tip to the next path's first tip (O(n²)).

use crate::Point3;
use cam_core::ToolPath;

/// Channels `start, start+1, …` modulo `count`.
pub fn angular_sequence(count: usize, start: usize) -> Vec<usize> {
    (0..count).map(|i| (start + i) % count.max(1)).collect()
}

/// Greedy nearest-next order of `paths` starting from `from`: indices into `paths`.
pub fn nearest_first(paths: &[ToolPath], from: Point3) -> Vec<usize> {
    let mut left: Vec<usize> = (0..paths.len()).collect();
    let mut order = Vec::with_capacity(paths.len());
    let mut at = from;
    while !left.is_empty() {
        let mut best = (f64::INFINITY, 0);
        for (i, &k) in left.iter().enumerate() {
            let d = paths[k]
                .moves
                .first()
                .map_or(f64::INFINITY, |m| (m.cl.tip - at).norm());
            if d < best.0 {
                best = (d, i);
            }
        }
        let k = left.swap_remove(best.1);
        if let Some(m) = paths[k].moves.last() {
            at = m.cl.tip;
        }
        order.push(k);
    }
    order
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angular_sequence_wraps() {
        assert_eq!(angular_sequence(4, 2), vec![2, 3, 0, 1]);
    }
}
