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
    /// A move at the programmed feed that joins two cutting runs without leaving the
    /// material (the step of a zig-zag from one line to the next, a join of two pieces on a
    /// roughing level): it may cut and runs like [`MoveKind::Feed`], but it belongs to no
    /// cutting run, so a change of direction of the rotary axes across it lies at a link,
    /// not inside a cut (`postproc_kinematics::rotary_motion`). G-code and CLDATA do not
    /// carry the difference: a program read back has feed moves there.
    Link,
    /// Exit from material along the tool axis.
    Retract,
}

impl MoveKind {
    /// Whether the move runs at the cutting feed in the material: a cut ([`MoveKind::Feed`])
    /// or a link between two cutting runs ([`MoveKind::Link`]).
    pub fn at_cutting_feed(self) -> bool {
        matches!(self, MoveKind::Feed | MoveKind::Link)
    }
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
    /// A link at the default feed to `cl`, the first location of the next cutting run
    /// ([`MoveKind::Link`]).
    pub fn link(cl: CutterLocation) -> Self {
        Self {
            kind: MoveKind::Link,
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
        self.length_of_mm(|_| true)
    }

    /// Tool-tip travel (mm) of the non-rapid moves only.
    pub fn cutting_length_mm(&self) -> f64 {
        self.length_of_mm(|kind| kind != MoveKind::Rapid)
    }

    /// Tool-tip travel (mm) of the moves whose kind `kinds` accepts (straight segments from
    /// the previous tip point). O(n).
    pub fn length_of_mm(&self, kinds: impl Fn(MoveKind) -> bool) -> f64 {
        self.segments()
            .filter(|(kind, _, _)| kinds(*kind))
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
                    MoveKind::Feed | MoveKind::Link | MoveKind::Retract => {
                        feed.unwrap_or(rates.feed_mm_per_min)
                    }
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

/// Distance (mm) between the segments `p0`–`p1` and `q0`–`q1` (either may be a point): the
/// closest pair by clamping the parameters of the two lines' common perpendicular (Ericson,
/// *Real-Time Collision Detection*, 2005, §5.1.9). O(1).
pub fn segment_segment_distance(p0: &Point3, p1: &Point3, q0: &Point3, q1: &Point3) -> f64 {
    let d1 = p1 - p0;
    let d2 = q1 - q0;
    let r = p0 - q0;
    let a = d1.norm_squared();
    let e = d2.norm_squared();
    let f = d2.dot(&r);
    let (s, t) = if a <= f64::EPSILON * f64::EPSILON && e <= f64::EPSILON * f64::EPSILON {
        (0.0, 0.0)
    } else if a <= f64::EPSILON * f64::EPSILON {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if e <= f64::EPSILON * f64::EPSILON {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let mut s = if denom > 0.0 {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    ((p0 + d1 * s) - (q0 + d2 * t)).norm()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{CutterLocation, Point3};
    use proptest::prelude::*;

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

    fn pt(x: f64, y: f64, z: f64) -> Point3 {
        Point3::new(x, y, z)
    }

    #[test]
    fn segment_distance_closed_forms() {
        // Skew perpendicular segments crossing over each other 2 apart.
        let d = segment_segment_distance(
            &pt(-1.0, 0.0, 0.0),
            &pt(1.0, 0.0, 0.0),
            &pt(0.0, -1.0, 2.0),
            &pt(0.0, 1.0, 2.0),
        );
        assert!((d - 2.0).abs() < 1e-15, "{d}");
        // Parallel, overlapping: the gap between the lines.
        let d = segment_segment_distance(
            &pt(0.0, 0.0, 0.0),
            &pt(4.0, 0.0, 0.0),
            &pt(1.0, 3.0, 0.0),
            &pt(6.0, 3.0, 0.0),
        );
        assert!((d - 3.0).abs() < 1e-15, "{d}");
        // Collinear, apart: end to end.
        let d = segment_segment_distance(
            &pt(0.0, 0.0, 0.0),
            &pt(1.0, 0.0, 0.0),
            &pt(3.5, 0.0, 0.0),
            &pt(5.0, 0.0, 0.0),
        );
        assert!((d - 2.5).abs() < 1e-15, "{d}");
        // A point against a segment, both ways.
        let p = pt(2.0, 2.0, 1.0);
        let d = segment_segment_distance(&p, &p, &pt(0.0, 0.0, 0.0), &pt(4.0, 0.0, 0.0));
        assert!((d - 5f64.sqrt()).abs() < 1e-15, "{d}");
        let d = segment_segment_distance(&pt(0.0, 0.0, 0.0), &pt(4.0, 0.0, 0.0), &p, &p);
        assert!((d - 5f64.sqrt()).abs() < 1e-15, "{d}");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]

        /// The distance is the minimum over the two segments: no sampled pair is closer, and
        /// a fine sampling comes within the sampling's reach of it (1e-2 mm at 1/400 of
        /// segments shorter than 4 mm).
        #[test]
        fn segment_distance_is_the_minimum(
            c in proptest::collection::vec(-2.0f64..2.0, 12),
        ) {
            let (p0, p1) = (pt(c[0], c[1], c[2]), pt(c[3], c[4], c[5]));
            let (q0, q1) = (pt(c[6], c[7], c[8]), pt(c[9], c[10], c[11]));
            let d = segment_segment_distance(&p0, &p1, &q0, &q1);
            let k = 400;
            let mut best = f64::INFINITY;
            for i in 0..=k {
                let x = p0 + (p1 - p0) * (i as f64 / k as f64);
                // Exact distance from a sample to the other segment (nurbs' point-segment distance).
                best = best.min(point_segment_distance(&x, &q0, &q1));
            }
            prop_assert!(d <= best + 1e-12, "{d} > sampled {best}");
            prop_assert!(best - d <= 1e-2, "{d} far below sampled {best}");
        }
    }
}
