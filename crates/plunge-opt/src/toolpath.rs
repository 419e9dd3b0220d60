//! The tool path of one channel: every plunge as rapid to its start along the axis, plunge at
//! the plunge feed to depth, retract along the axis to the start; row segments (or pilot
//! holes, one per "segment") linked over the job's safety surface ([`cam_plan::Linker`]).
//!
//! Inside a segment the tool moves from one plunge's start to the next one's at rapid: both
//! lie the start clearance above the shroud and the blank along their axes, a plunge step
//! apart. Where that rapid would not keep the tool out of the stock (`rapid_clear`, see
//! [`crate::stock_clearance::StockClearance::rapid_clear`]), and between segments (and at both
//! ends), the tool retracts along its axis to the safety surface, travels on it and comes
//! down along the next axis. O(plunges) plus the rapid checks.

use crate::conventional_axes::Posture;
use cam_core::{CutterLocation, Move, MoveKind, ToolPath};
use cam_plan::{Linker, PlanError};

/// The moves of one channel for `rows` (row segments, each in its feed order, in machining
/// order), and the number of in-segment rapids that `rapid_clear` rejected and that go over
/// the safety surface instead.
pub fn channel_path(
    name: &str,
    tool: &str,
    rows: &[Vec<Posture>],
    linker: &Linker,
    plunge_feed_mm_per_min: f64,
    rapid_clear: &(dyn Fn(&CutterLocation, &CutterLocation) -> bool + Sync),
) -> Result<(ToolPath, usize), PlanError> {
    let mut path = ToolPath::new(name, tool);
    let mut prev: Option<Posture> = None;
    let mut lifted = 0;
    for row in rows {
        for (i, p) in row.iter().enumerate() {
            let over = match prev {
                Some(q) if i > 0 && !rapid_clear(&q.start, &p.start) => {
                    lifted += 1;
                    true
                }
                Some(_) => i == 0,
                None => false,
            };
            match prev {
                None => {
                    path.moves
                        .push(Move::rapid(linker.retract_point(&p.start)?));
                }
                Some(q) if over => {
                    let out = linker.retract_point(&q.start)?;
                    let inn = linker.retract_point(&p.start)?;
                    path.moves.push(Move {
                        kind: MoveKind::Retract,
                        cl: out,
                        feed_mm_per_min: None,
                    });
                    path.moves.extend(linker.travel(&out, &inn));
                }
                Some(_) => {}
            }
            path.moves.push(Move::rapid(p.start));
            path.moves.push(Move {
                kind: MoveKind::Plunge,
                cl: p.cl,
                feed_mm_per_min: Some(plunge_feed_mm_per_min),
            });
            path.moves.push(Move {
                kind: MoveKind::Retract,
                cl: p.start,
                feed_mm_per_min: None,
            });
            prev = Some(*p);
        }
    }
    if let Some(q) = prev {
        path.moves.push(Move {
            kind: MoveKind::Retract,
            cl: linker.retract_point(&q.start)?,
            feed_mm_per_min: None,
        });
    }
    // Drop zero-length rapids (a start that already lies on the safety surface).
    let mut out: Vec<Move> = Vec::with_capacity(path.moves.len());
    for m in path.moves {
        if let Some(l) = out.last() {
            if m.kind == MoveKind::Rapid && (l.cl.tip - m.cl.tip).norm() < 1e-12 {
                continue;
            }
        }
        out.push(m);
    }
    path.moves = out;
    Ok((path, lifted))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::axial_depth::Contact;
    use cam_core::{Point3, UnitVector3, Vector3};
    use cam_plan::SafetySurface;

    fn posture(x: f64) -> Posture {
        let axis = UnitVector3::new_normalize(Vector3::z());
        let cl = |z: f64| CutterLocation {
            tip: Point3::new(x, 0.0, z),
            axis,
        };
        Posture {
            m: 0.5,
            s: 0.5,
            centre: Vector3::new(x, 0.0, 20.0),
            w: Vector3::new(x, 0.0, 100.0),
            cl: cl(20.0),
            start: cl(132.0),
            contact: Contact {
                t: 0.0,
                uv: (0.0, 0.0),
                point: Vector3::new(x, 0.0, 20.0),
                normal: Vector3::z(),
                iterations: 0,
            },
            alpha: 0.0,
        }
    }

    /// Two plunges of one row: the rapid between their starts stays where `rapid_clear`
    /// accepts it; where it rejects it the tool retracts to the safety surface (z = 140),
    /// travels and comes down, and the rejection is counted.
    #[test]
    fn rejected_row_rapid_goes_over_the_safety_surface() {
        let linker = Linker::new(SafetySurface {
            radius_mm: 213.0,
            top_z_mm: 140.0,
        });
        let rows = vec![vec![posture(100.0), posture(106.0)]];
        let highest = |p: &ToolPath, from: usize| {
            p.moves[from..]
                .iter()
                .take_while(|m| m.kind != MoveKind::Plunge)
                .map(|m| m.cl.tip.z)
                .fold(f64::NEG_INFINITY, f64::max)
        };
        let (direct, n) = channel_path("p", "t", &rows, &linker, 100.0, &|_, _| true).unwrap();
        assert_eq!(n, 0);
        // rapid down from the safety surface to start 0, plunge, retract to start 0, rapid to
        // start 1, ...
        assert_eq!(direct.moves[3].kind, MoveKind::Retract);
        assert_eq!(direct.moves[4].kind, MoveKind::Rapid);
        assert!((highest(&direct, 4) - 132.0).abs() < 1e-9);
        let (lifted, n) = channel_path("p", "t", &rows, &linker, 100.0, &|_, _| false).unwrap();
        assert_eq!(n, 1);
        assert_eq!(lifted.moves[4].kind, MoveKind::Retract);
        assert!(highest(&lifted, 4) >= 140.0 - 1e-9);
        assert!(lifted.moves.len() > direct.moves.len());
    }
}
