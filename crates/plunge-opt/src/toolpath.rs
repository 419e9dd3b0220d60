//! The tool path of one channel: every plunge as rapid to its start along the axis, plunge at
//! the plunge feed to depth, retract along the axis to the start; rows linked over the job's
//! safety surface ([`cam_plan::Linker`]).
//!
//! Inside a row the tool moves from one plunge's start to the next one's at rapid: both lie
//! the start clearance above the shroud and the blank along their axes, a plunge step apart.
//! Between rows (and at both ends) the tool retracts along its axis to the safety surface,
//! travels on it and comes down along the next axis. O(plunges).

use crate::conventional_axes::Posture;
use cam_core::{Move, MoveKind, ToolPath};
use cam_plan::{Linker, PlanError};

/// The moves of one channel for `rows` (each outlet → inlet, rows in machining order).
pub fn channel_path(
    name: &str,
    tool: &str,
    rows: &[Vec<Posture>],
    linker: &Linker,
    plunge_feed_mm_per_min: f64,
) -> Result<ToolPath, PlanError> {
    let mut path = ToolPath::new(name, tool);
    let mut prev: Option<Posture> = None;
    for row in rows {
        for (i, p) in row.iter().enumerate() {
            match prev {
                None => {
                    path.moves
                        .push(Move::rapid(linker.retract_point(&p.start)?));
                }
                Some(q) if i == 0 => {
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
    Ok(path)
}
