//! Moves and tool paths, with path length and cutting-time estimates.

use crate::{CamError, CutterLocation, Point3};
use serde::{Deserialize, Serialize};

/// What a move does; decides the rate it runs at.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MoveKind {
    /// Positioning at rapid rate, never in contact with material.
    Rapid,
    /// Entry into material along (or close to) the tool axis, at plunge feed.
    Plunge,
    /// Cutting move at the programmed feed.
    Feed,
    /// Exit from material along the tool axis.
    Retract,
}

/// One move of a tool path: the target cutter location and how to get there from the
/// previous one.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Move {
    /// Kind of move.
    pub kind: MoveKind,
    /// Target cutter location.
    pub cl: CutterLocation,
    /// Feed rate (mm/min) for non-rapid moves; `None` keeps the previous/default feed.
    pub feed_mm_per_min: Option<f64>,
}

impl Move {
    /// A rapid move to `cl`.
    pub fn rapid(cl: CutterLocation) -> Self {
        Self {
            kind: MoveKind::Rapid,
            cl,
            feed_mm_per_min: None,
        }
    }
    /// A cutting move to `cl` at the default feed.
    pub fn feed(cl: CutterLocation) -> Self {
        Self {
            kind: MoveKind::Feed,
            cl,
            feed_mm_per_min: None,
        }
    }
}

/// Feed and rapid rates used to estimate cutting time (mm/min).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Rates {
    /// Default cutting feed (mm/min).
    pub feed_mm_per_min: f64,
    /// Plunge feed (mm/min).
    pub plunge_mm_per_min: f64,
    /// Rapid traverse rate (mm/min).
    pub rapid_mm_per_min: f64,
}

impl Default for Rates {
    fn default() -> Self {
        Self {
            feed_mm_per_min: 1000.0,
            plunge_mm_per_min: 300.0,
            rapid_mm_per_min: 10000.0,
        }
    }
}

impl Rates {
    /// Checks that all rates are finite and > 0.
    pub fn validate(&self) -> Result<(), CamError> {
        for (field, value) in [
            ("feed_mm_per_min", self.feed_mm_per_min),
            ("plunge_mm_per_min", self.plunge_mm_per_min),
            ("rapid_mm_per_min", self.rapid_mm_per_min),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(CamError::NonPositive { field, value });
            }
        }
        Ok(())
    }
}

/// The tool path of one operation: an ordered list of moves made with one cutter.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ToolPath {
    /// Operation name (e.g. `plunge_rough`).
    pub name: String,
    /// Name of the cutter (key into the job's tool list).
    pub tool: String,
    /// Moves in execution order; the first move starts from wherever the tool is.
    pub moves: Vec<Move>,
}

impl ToolPath {
    /// An empty path for operation `name` made with `tool`.
    pub fn new(name: impl Into<String>, tool: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            tool: tool.into(),
            moves: Vec::new(),
        }
    }

    /// Total tool-tip travel (mm) over all moves, rapid ones included, measured as straight
    /// segments between consecutive tip points. O(n).
    pub fn path_length_mm(&self) -> f64 {
        self.segments().map(|(_, len, _)| len).sum()
    }

    /// Tool-tip travel (mm) of the non-rapid moves only.
    pub fn cutting_length_mm(&self) -> f64 {
        self.segments()
            .filter(|(kind, _, _)| *kind != MoveKind::Rapid)
            .map(|(_, len, _)| len)
            .sum()
    }

    /// Estimated machining time (s): each segment's length over its rate (the move's own feed
    /// if given, else the default for its kind). Ignores acceleration. O(n).
    pub fn cutting_time_s(&self, rates: &Rates) -> f64 {
        self.segments()
            .map(|(kind, len, feed)| {
                let rate = match kind {
                    MoveKind::Rapid => rates.rapid_mm_per_min,
                    MoveKind::Plunge => feed.unwrap_or(rates.plunge_mm_per_min),
                    MoveKind::Feed | MoveKind::Retract => feed.unwrap_or(rates.feed_mm_per_min),
                };
                if rate > 0.0 {
                    60.0 * len / rate
                } else {
                    0.0
                }
            })
            .sum()
    }

    /// (kind, length, feed) of each move after the first.
    fn segments(&self) -> impl Iterator<Item = (MoveKind, f64, Option<f64>)> + '_ {
        self.moves.windows(2).map(|w| {
            (
                w[1].kind,
                (w[1].cl.tip - w[0].cl.tip).norm(),
                w[1].feed_mm_per_min,
            )
        })
    }
}

/// Distance (mm) from `p` to the segment `[a, b]` (to `a` when the segment is a point):
/// `nurbs::discretise::point_segment_distance` on workpiece points. O(1).
pub fn point_segment_distance(p: &Point3, a: &Point3, b: &Point3) -> f64 {
    nurbs::discretise::point_segment_distance(&p.coords, &a.coords, &b.coords)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{CutterLocation, Point3};

    fn at(x: f64, y: f64, z: f64) -> CutterLocation {
        CutterLocation::vertical(Point3::new(x, y, z))
    }

    #[test]
    fn length_and_time_follow_each_moves_kind_and_feed() {
        let mut p = ToolPath::new("op", "t1");
        p.moves.push(Move::rapid(at(0.0, 0.0, 50.0)));
        p.moves.push(Move::rapid(at(0.0, 0.0, 10.0))); // 40 mm rapid
        p.moves.push(Move {
            kind: MoveKind::Plunge,
            cl: at(0.0, 0.0, 0.0),
            feed_mm_per_min: None,
        }); // 10 mm at the plunge rate
        p.moves.push(Move::feed(at(30.0, 40.0, 0.0))); // 50 mm at the default feed
        p.moves.push(Move {
            kind: MoveKind::Feed,
            cl: at(30.0, 40.0, 20.0),
            feed_mm_per_min: Some(200.0),
        }); // 20 mm at its own feed
        let rates = Rates {
            feed_mm_per_min: 1000.0,
            plunge_mm_per_min: 100.0,
            rapid_mm_per_min: 12000.0,
        };
        assert!((p.path_length_mm() - 120.0).abs() < 1e-12);
        assert!((p.cutting_length_mm() - 80.0).abs() < 1e-12);
        let expected = 60.0 * (40.0 / 12000.0 + 10.0 / 100.0 + 50.0 / 1000.0 + 20.0 / 200.0);
        assert!((p.cutting_time_s(&rates) - expected).abs() < 1e-12);
        assert!(rates.validate().is_ok());
        let bad = Rates {
            rapid_mm_per_min: 0.0,
            ..rates
        };
        assert!(matches!(
            bad.validate(),
            Err(CamError::NonPositive {
                field: "rapid_mm_per_min",
                ..
            })
        ));
    }
}
