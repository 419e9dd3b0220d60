//! The machine's travel, checked right after planning: every operation's moves posted on the
//! job's machine (the posture choice of the real post, see
//! [`crate::pipeline::machine_links`]) and every block whose joints leave an axis' travel
//! counted, with the range each axis would need. A job the machine cannot hold stops there
//! with one message naming every such operation (it used to stop in the post at the first
//! block, `operation 'rough' move 0: axis A = 85.914555 outside its limits`, with no count
//! and no range). Such a run posts nothing: the violations go to `report.json`
//! (`post.travel`), the report and the terminal, and the run fails with exit 3
//! ([`crate::verdict`]). The post's posture choice prefers postures within the travel (of
//! the two solutions of a five-axis machine and the 2π-equivalents of a rotary axis), and
//! the planners' axis searches (hub finishing, blade-root finishing, point milling) skip tool
//! axes the rotary travel cannot give ([`MachineReach`]); the operations whose axes the
//! geometry fixes (flank passes along the rulings, plunge and channel roughing) are left to
//! this check.

use postproc_kinematics::{KinematicsError, Machine, PostedBlock};

/// The tool axes a machine can present within its rotary travel
/// ([`Machine::orientation_reachable`]), for the planners' axis searches
/// ([`cam_plan::PlanContext::reaches`]).
#[derive(Debug)]
pub struct MachineReach(pub Machine);

impl cam_plan::AxisReach for MachineReach {
    fn reaches(&self, axis: &cam_core::Vector3) -> bool {
        cam_core::UnitVector3::try_new(*axis, 1e-12)
            .is_some_and(|a| self.0.orientation_reachable(&a))
    }
}
use std::fmt::Write as _;

/// The range one axis would need (mm, or degrees for rotary axes).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct AxisNeed {
    /// Axis letter.
    pub axis: char,
    /// Smallest value needed outside the travel.
    pub min_needed: f64,
    /// Largest value needed outside the travel.
    pub max_needed: f64,
    /// The axis' travel.
    pub travel: (f64, f64),
}

/// The blocks of one operation outside the machine's travel.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct TravelViolations {
    /// Operation name.
    pub operation: String,
    /// Blocks outside the travel.
    pub blocks: usize,
    /// Blocks posted in all.
    pub of_blocks: usize,
    /// First and last path move (0-based) with a block outside the travel.
    pub moves: (usize, usize),
    /// Per axis, the range needed.
    pub axes: Vec<AxisNeed>,
}

impl TravelViolations {
    /// The violations among `blocks` posted for `operation` of `moves` path moves (the
    /// framed moves: source index 0 is the assembly's approach, `k` the path's move `k − 1`,
    /// `moves + 1` the final retract; those two count as the first and last move); `None`
    /// when every block lies within the travel. O(n).
    pub fn of(operation: &str, moves: usize, blocks: &[PostedBlock]) -> Option<Self> {
        let mut out = Self {
            operation: operation.to_string(),
            blocks: 0,
            of_blocks: blocks.len(),
            moves: (usize::MAX, 0),
            axes: Vec::new(),
        };
        for b in blocks {
            let Some(KinematicsError::OutOfLimits {
                axis,
                value,
                min,
                max,
            }) = &b.limit_violation
            else {
                continue;
            };
            out.blocks += 1;
            let m = b
                .source_index
                .saturating_sub(1)
                .min(moves.saturating_sub(1));
            out.moves = (out.moves.0.min(m), out.moves.1.max(m));
            match out.axes.iter_mut().find(|a| a.axis == *axis) {
                Some(a) => {
                    a.min_needed = a.min_needed.min(*value);
                    a.max_needed = a.max_needed.max(*value);
                }
                None => out.axes.push(AxisNeed {
                    axis: *axis,
                    min_needed: *value,
                    max_needed: *value,
                    travel: (*min, *max),
                }),
            }
        }
        (out.blocks > 0).then_some(out)
    }

    /// `operation "rough": 1234 of 5678 blocks (moves 0–5677) leave the travel: A needs
    /// -85.915 to 85.915 (travel -30 to 30)`.
    pub fn describe(&self) -> String {
        let mut s = format!(
            "operation \"{}\": {} of {} blocks (moves {}–{}) leave the travel:",
            self.operation, self.blocks, self.of_blocks, self.moves.0, self.moves.1
        );
        for (i, a) in self.axes.iter().enumerate() {
            let _ = write!(
                s,
                "{} {} needs {:.3} to {:.3} (travel {} to {})",
                if i == 0 { "" } else { "," },
                a.axis,
                a.min_needed,
                a.max_needed,
                a.travel.0,
                a.travel.1
            );
        }
        s
    }
}

/// The error of a job whose operations leave the travel of `machine` (named `machine`).
pub fn travel_error(machine: &str, violations: &[TravelViolations]) -> String {
    let list: Vec<String> = violations.iter().map(TravelViolations::describe).collect();
    format!(
        "machine {machine} cannot hold the planned tool paths within its travel \
         (rotary axes in degrees): {}; widen the axis limits in the machine file, use a \
         machine whose axes reach these postures, or change those operations' tool axes",
        list.join("; ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use cam_core::{CutterLocation, MoveKind, Point3};
    use postproc_kinematics::Joints;

    fn block(source_index: usize, violation: Option<(char, f64)>) -> PostedBlock {
        PostedBlock {
            joints: Joints::default(),
            cl: CutterLocation::vertical(Point3::origin()),
            kind: MoveKind::Feed,
            feed_mm_per_min: None,
            inverse_time_feed: None,
            source_index,
            inserted: false,
            unwound: false,
            linearisation_error_mm: 0.0,
            limit_violation: violation.map(|(axis, value)| KinematicsError::OutOfLimits {
                axis,
                value,
                min: -30.0,
                max: 30.0,
            }),
        }
    }

    #[test]
    fn counts_blocks_moves_and_the_range_each_axis_needs() {
        let blocks = [
            block(0, None),
            block(3, Some(('A', 85.9))),
            block(4, Some(('A', -40.0))),
            block(7, Some(('C', 31.0))),
            block(8, None),
        ];
        let v = TravelViolations::of("rough", 7, &blocks).unwrap();
        assert_eq!((v.blocks, v.of_blocks, v.moves), (3, 5, (2, 6)));
        assert_eq!(
            v.describe(),
            "operation \"rough\": 3 of 5 blocks (moves 2–6) leave the travel: A needs -40.000 \
             to 85.900 (travel -30 to 30), C needs 31.000 to 31.000 (travel -30 to 30)"
        );
        assert!(TravelViolations::of("ok", 6, &blocks[..1]).is_none());
    }
}
