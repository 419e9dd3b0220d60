//! A first machining-time estimate of each planned operation from the machine file's rapid
//! rate: every move's tool-tip travel over its rate, split into cutting, links and rapids.
//! The one place a cycle-time model from the machine's axis speeds and accelerations will
//! replace (it ignores acceleration and the rotary axes).
//!
//! - **Rapids** (`MoveKind::Rapid`) run at the machine's rapid rate: the slowest of its linear
//!   axes' `max_speed` (a straight rapid is never faster than its slowest axis allows), or,
//!   when the machine file gives none, the process row's `rapid_mm_per_min`.
//! - **Links** are the non-rapid moves that do not cut along a planned path: plunges and
//!   retracts (`MoveKind::Plunge`, `MoveKind::Retract`), and cutting-kind moves an operation
//!   programs faster than its cutting feed (a move at more than the cutting feed cannot be a
//!   cut of that process: a link at a high feed). They run at their programmed feed.
//! - Everything else cuts, at its programmed feed.
//!
//! No move runs faster than the rapid rate: a feed programmed above it (a high-feed link on
//! a slow machine) is timed at the rapid rate.
//!
//! Metrics (DESIGN §4): `link_length_mm`, `rapid_length_mm`, `air_time_s` (links and rapids)
//! and `total_time_s` (all moves). O(moves).

use cam_core::{MoveKind, Rates, ToolPath};
use postproc_kinematics::{AxisId, Machine};

/// Lengths (mm) and times (s) of one tool path by kind of move.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct TimeSplit {
    /// Cutting moves.
    pub cutting_mm: f64,
    /// Links (plunges, retracts, high-feed moves).
    pub link_mm: f64,
    /// Rapids.
    pub rapid_mm: f64,
    /// Cutting time.
    pub cutting_s: f64,
    /// Link time.
    pub link_s: f64,
    /// Rapid time.
    pub rapid_s: f64,
}

impl TimeSplit {
    /// Time outside the cutting moves (s).
    pub fn air_s(&self) -> f64 {
        self.link_s + self.rapid_s
    }

    /// All of it (s).
    pub fn total_s(&self) -> f64 {
        self.cutting_s + self.air_s()
    }
}

/// The machine's rapid rate (mm/min): the smallest `max_speed` of its linear axes, `None`
/// when none is given.
pub fn machine_rapid_mm_per_min(machine: &Machine) -> Option<f64> {
    [AxisId::X, AxisId::Y, AxisId::Z]
        .iter()
        .filter_map(|&a| machine.axis(a).max_speed)
        .filter(|v| v.is_finite() && *v > 0.0)
        .reduce(f64::min)
}

/// The split of `path` (module docs): feeds as programmed (`rates` where a move has none),
/// rapids at `rapid_mm_per_min`.
pub fn split(path: &ToolPath, rates: &Rates, rapid_mm_per_min: f64) -> TimeSplit {
    let mut out = TimeSplit::default();
    let time = |len: f64, rate: f64| {
        let rate = rate.min(rapid_mm_per_min);
        if rate > 0.0 {
            60.0 * len / rate
        } else {
            0.0
        }
    };
    for w in path.moves.windows(2) {
        let m = &w[1];
        let len = (m.cl.tip - w[0].cl.tip).norm();
        match m.kind {
            MoveKind::Rapid => {
                out.rapid_mm += len;
                out.rapid_s += time(len, rapid_mm_per_min);
            }
            MoveKind::Plunge => {
                let f = m.feed_mm_per_min.unwrap_or(rates.plunge_mm_per_min);
                out.link_mm += len;
                out.link_s += time(len, f);
            }
            MoveKind::Retract => {
                let f = m.feed_mm_per_min.unwrap_or(rates.feed_mm_per_min);
                out.link_mm += len;
                out.link_s += time(len, f);
            }
            MoveKind::Feed => {
                let f = m.feed_mm_per_min.unwrap_or(rates.feed_mm_per_min);
                if f > rates.feed_mm_per_min {
                    out.link_mm += len;
                    out.link_s += time(len, f);
                } else {
                    out.cutting_mm += len;
                    out.cutting_s += time(len, f);
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use cam_core::{CutterLocation, Move, Point3, Vector3};

    fn at(x: f64) -> CutterLocation {
        CutterLocation::new(Point3::new(x, 0.0, 0.0), Vector3::z()).unwrap()
    }

    /// A path of 10 mm cut at 600 mm/min, a 6 mm plunge at 300, a 12 mm retract at a
    /// programmed 6000, a 4 mm link at a programmed 1200 (above the cutting feed) and 30 mm
    /// of rapids at 10 000 mm/min: each part's length and time by hand; on a machine whose
    /// rapid rate is 3000 mm/min the retract runs at 3000.
    #[test]
    fn split_by_kind_of_move() {
        let rates = Rates {
            feed_mm_per_min: 600.0,
            plunge_mm_per_min: 300.0,
            rapid_mm_per_min: 5000.0,
        };
        let mut path = ToolPath::new("op", "t");
        path.moves = vec![
            Move::rapid(at(0.0)),
            Move::rapid(at(30.0)),
            Move {
                kind: MoveKind::Plunge,
                cl: at(36.0),
                feed_mm_per_min: None,
            },
            Move::feed(at(46.0)),
            Move {
                kind: MoveKind::Feed,
                cl: at(50.0),
                feed_mm_per_min: Some(1200.0),
            },
            Move {
                kind: MoveKind::Retract,
                cl: at(62.0),
                feed_mm_per_min: Some(6000.0),
            },
        ];
        let s = split(&path, &rates, 10_000.0);
        assert!((s.rapid_mm - 30.0).abs() < 1e-12 && (s.rapid_s - 0.18).abs() < 1e-12);
        assert!((s.cutting_mm - 10.0).abs() < 1e-12 && (s.cutting_s - 1.0).abs() < 1e-12);
        assert!((s.link_mm - 22.0).abs() < 1e-12);
        assert!((s.link_s - (1.2 + 0.2 + 0.12)).abs() < 1e-12, "{s:?}");
        assert!((s.total_s() - (1.0 + 1.52 + 0.18)).abs() < 1e-12);
        let slow = split(&path, &rates, 3000.0);
        assert!((slow.link_s - (1.2 + 0.2 + 0.24)).abs() < 1e-12, "{slow:?}");
        assert!((slow.rapid_s - 0.6).abs() < 1e-12);
    }
}
