//! From cutter-location operations and a machine to an [`NcProgram`] for a dialect.
//!
//! Per operation:
//! 1. the path is framed by an approach and a retract *along the tool axis*: a rapid to
//!    `first.tip + d·first.axis` before the first move and a move to `last.tip + d·last.axis`
//!    after the last (`d` = [`AssembleOptions::retract_mm`]); the dialect then retracts the
//!    spindle to the machine's safe Z before any tool change or reorientation;
//! 2. an operation whose tool axis is constant (within [`AssembleOptions::fixed_axis_tol_rad`])
//!    becomes a 3+2 tilted-plane operation when the dialect has one (its blocks are still
//!    posted, so the axis limits are checked and the plane's machine angles are known);
//! 3. otherwise the moves go through `postproc-kinematics`' [`post_path`] (inverse kinematics
//!    with continuity from the previous operation's last posture, limits, unwinding;
//!    linearisation control only for joint output, where the controller interpolates joints,
//!    of the tip and of the top of the flutes of an operation with a cutter
//!    ([`PostOptions::check_height_mm`] raised to its flute length);
//!    inverse-time feeds), and each posted block becomes an [`NcMove`]: joint values in
//!    [`OutputMode::Joint`] (all cutting blocks in inverse time), tool tip + axis angles in
//!    [`OutputMode::TcpAngles`], tool tip + tool vector in [`OutputMode::TcpVector`].
//!    With [`PostOptions::reverse_motion`] set, reverse motions of the rotary axes are removed
//!    ([`postproc_kinematics::reverse_motion`]) and every changed posture is re-checked with
//!    the operation's [`AccessibilityChecker`] ([`assemble_program_checked`],
//!    [`assemble_program_with_access`]); each simultaneous operation's axis displacement
//!    curves before and after removal come back in [`AssembledProgram::operations`].
//!
//! Cost: that of [`post_path_checked`], O(n) otherwise.

use crate::dialect::Dialect;
use crate::program::{
    Feed, Motion, NcMove, NcOperation, NcProgram, OutputMode, RotaryWord, ToolCall,
};
use crate::{ClOperation, GcodeError};
use cam_core::{CutterLocation, Move, MoveKind};
use postproc_kinematics::{
    post_path, post_path_checked, AccessibilityChecker, AxisId, DisplacementCurves, Joints,
    Machine, PostMetrics, PostOptions, PostedBlock, ReverseMotionOptions, ReverseMotionReport,
};

/// Options of [`assemble_program`].
#[derive(Debug, Clone, PartialEq)]
pub struct AssembleOptions {
    /// Output mode of simultaneous operations.
    pub mode: OutputMode,
    /// Write constant-axis operations as 3+2 tilted planes when the dialect can.
    pub indexed_when_fixed_axis: bool,
    /// Largest angle (rad) between tool axes of one operation for it to count as fixed-axis.
    pub fixed_axis_tol_rad: f64,
    /// Approach / retract distance along the tool axis at each operation's ends (mm, ≥ 0).
    pub retract_mm: f64,
    /// Post-processing options (tool length, limit policy, linearisation tolerance, default
    /// feed). `linearisation_tol` is used for joint output only; `initial` is overwritten
    /// to chain operations.
    pub post: PostOptions,
    /// Tool number for operations whose CL file gave none.
    pub default_tool_number: u32,
}

impl Default for AssembleOptions {
    fn default() -> Self {
        Self {
            mode: OutputMode::Joint,
            indexed_when_fixed_axis: true,
            fixed_axis_tol_rad: 1e-9,
            retract_mm: 10.0,
            post: PostOptions::default(),
            default_tool_number: 1,
        }
    }
}

/// A program and the post-processing metrics of each simultaneous operation.
#[derive(Debug, Clone, PartialEq)]
pub struct AssembledProgram {
    /// The program.
    pub program: NcProgram,
    /// (operation name, metrics) of every operation that went through kinematics.
    pub metrics: Vec<(String, PostMetrics)>,
    /// The posted blocks and axis displacement curves of every operation that went through
    /// kinematics (same order as `metrics`).
    pub operations: Vec<PostedOperation>,
}

/// One simultaneous operation after post-processing.
#[derive(Debug, Clone, PartialEq)]
pub struct PostedOperation {
    /// Operation name.
    pub name: String,
    /// Index of the operation in the input slice.
    pub index: usize,
    /// Post-processing metrics (same as in [`AssembledProgram::metrics`]).
    pub metrics: PostMetrics,
    /// Whether reverse-motion removal ran on this operation.
    pub reverse_motion_removal: bool,
    /// Details of reverse-motion removal when it ran.
    pub reverse_motion: Option<ReverseMotionReport>,
    /// Axis displacement curves (mm, deg against tool-tip path length) of the blocks before
    /// reverse-motion removal and before linearisation control (equal to `after` when no
    /// removal ran).
    pub before: DisplacementCurves,
    /// The curves after removal (before linearisation control).
    pub after: DisplacementCurves,
    /// The output blocks (approach and retract included, linearisation blocks inserted).
    pub blocks: Vec<PostedBlock>,
}

/// How reverse-motion removal treats one operation in [`assemble_program_with_access`].
#[derive(Clone, Copy)]
pub enum OperationAccess<'a> {
    /// Removal as [`PostOptions::reverse_motion`] says, changed postures not re-checked.
    Unchecked,
    /// Removal as [`PostOptions::reverse_motion`] says, every changed posture re-checked by
    /// the checker (gouge and collision); a run that cannot be made accessible keeps its
    /// original postures.
    Checked(&'a dyn AccessibilityChecker),
    /// Removal with these options instead of [`PostOptions::reverse_motion`] (e.g. turning a
    /// ball end about its centre, [`ReverseMotionOptions::keeping_contact`]), every changed
    /// posture re-checked by the checker.
    CheckedWith(&'a dyn AccessibilityChecker, &'a ReverseMotionOptions),
    /// No removal for this operation (reverse motions are only counted).
    CountOnly,
}

impl std::fmt::Debug for OperationAccess<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Unchecked => "Unchecked",
            Self::Checked(_) => "Checked(..)",
            Self::CheckedWith(..) => "CheckedWith(..)",
            Self::CountOnly => "CountOnly",
        })
    }
}

/// Builds the program of `operations` on `machine` for `dialect` (see the module docs).
///
/// Errors: a mode the dialect cannot write; an empty operation; a block outside the machine
/// limits or unreachable ([`GcodeError::Kinematics`] naming the operation and move index).
pub fn assemble_program(
    name: &str,
    operations: &[ClOperation],
    machine: &Machine,
    dialect: &dyn Dialect,
    options: &AssembleOptions,
) -> Result<AssembledProgram, GcodeError> {
    assemble_program_checked(name, operations, machine, dialect, options, None)
}

/// [`assemble_program`] whose reverse-motion removal (when [`PostOptions::reverse_motion`]
/// is set) re-checks every changed posture of every operation with `checker`
/// ([`post_path_checked`]); `None` = no re-check.
pub fn assemble_program_checked(
    name: &str,
    operations: &[ClOperation],
    machine: &Machine,
    dialect: &dyn Dialect,
    options: &AssembleOptions,
    checker: Option<&dyn AccessibilityChecker>,
) -> Result<AssembledProgram, GcodeError> {
    let access = match checker {
        Some(c) => OperationAccess::Checked(c),
        None => OperationAccess::Unchecked,
    };
    let access = vec![access; operations.len()];
    assemble_program_with_access(name, operations, machine, dialect, options, &access)
}

/// [`assemble_program`] with one [`OperationAccess`] per operation (`access.len()` must equal
/// `operations.len()`): operations machined with different cutters need different
/// accessibility checkers, and an operation whose cutter is unknown cannot be checked.
pub fn assemble_program_with_access(
    name: &str,
    operations: &[ClOperation],
    machine: &Machine,
    dialect: &dyn Dialect,
    options: &AssembleOptions,
    access: &[OperationAccess<'_>],
) -> Result<AssembledProgram, GcodeError> {
    if access.len() != operations.len() {
        return Err(GcodeError::InvalidOption {
            field: "access",
            reason: format!(
                "{} entries for {} operations",
                access.len(),
                operations.len()
            ),
        });
    }
    if !(options.retract_mm.is_finite() && options.retract_mm >= 0.0) {
        return Err(GcodeError::InvalidOption {
            field: "retract_mm",
            reason: format!("{} must be finite and >= 0", options.retract_mm),
        });
    }
    let indexed_ok = options.indexed_when_fixed_axis && dialect.supports_indexed();
    if !dialect.supports(options.mode) {
        return Err(GcodeError::Unsupported {
            dialect: dialect.name(),
            what: format!("{:?} output", options.mode),
        });
    }
    let mut ops = Vec::with_capacity(operations.len());
    let mut metrics = Vec::new();
    let mut posted_ops = Vec::new();
    let mut posture: Option<Joints> = options.post.initial;
    for (op_index, (op, op_access)) in operations.iter().zip(access).enumerate() {
        let path = &op.path;
        let (Some(first), Some(last)) = (path.moves.first(), path.moves.last()) else {
            return Err(GcodeError::Kinematics {
                operation: path.name.clone(),
                index: 0,
                reason: "operation has no moves".into(),
            });
        };
        let mut moves = Vec::with_capacity(path.moves.len() + 2);
        moves.push(Move::rapid(lift(&first.cl, options.retract_mm)));
        moves.extend_from_slice(&path.moves);
        moves.push(Move {
            kind: MoveKind::Rapid,
            cl: lift(&last.cl, options.retract_mm),
            feed_mm_per_min: None,
        });
        let tool = ToolCall {
            number: op.tool_number.unwrap_or(options.default_tool_number),
            name: path.tool.clone(),
            spindle: op.spindle,
            coolant: op.coolant,
        };
        let kin_err = |index: usize, reason: String| GcodeError::Kinematics {
            operation: path.name.clone(),
            // Index into the CL file's moves (the approach is index 0 here).
            index: index.saturating_sub(1),
            reason,
        };
        let fixed = moves
            .windows(2)
            .all(|w| w[0].cl.axis.angle(&w[1].cl.axis) <= options.fixed_axis_tol_rad);
        let mut post = options.post.clone();
        post.initial = posture;
        if let Some(tl) = op.tool_length_mm {
            post.tool_length = tl;
        }
        // The flutes cut along their whole length: keep the top of the cutting part on its
        // path too (joint interpolation near the singular direction swings the axis while
        // the tip stays on its line).
        if let Some(c) = &op.cutter {
            post.check_height_mm = post.check_height_mm.max(c.flute_length);
        }
        if fixed && indexed_ok {
            // Post the moves anyway: checks every block against the axis limits and gives
            // the machine angles of the plane.
            let mut check = post.clone();
            check.linearisation_tol = None;
            check.reverse_motion = None;
            let posted = post_path(machine, &moves, &check).map_err(|e| match e {
                postproc_kinematics::PostError::Block { index, source } => {
                    kin_err(index, source.to_string())
                }
                other => kin_err(0, other.to_string()),
            })?;
            let Some(j) = posted.blocks.first().map(|b| b.joints) else {
                return Err(kin_err(0, "no blocks posted".into()));
            };
            posture = posted.blocks.last().map(|b| b.joints).or(posture);
            let mut feed = options.post.default_feed_mm_per_min;
            let tips = moves
                .iter()
                .map(|m| {
                    let f = match m.kind {
                        MoveKind::Rapid => Feed::Rapid,
                        _ => {
                            feed = m.feed_mm_per_min.unwrap_or(feed);
                            Feed::PerMinute(feed)
                        }
                    };
                    (m.cl.tip, f)
                })
                .collect();
            ops.push(NcOperation {
                name: path.name.clone(),
                tool,
                motion: Motion::Indexed {
                    tool_axis: first.cl.axis,
                    rotary: rotary_words(machine, &j),
                    tips,
                },
            });
            continue;
        }
        if options.mode != OutputMode::Joint {
            // The controller interpolates the tip on the line (TCP): nothing to linearise.
            post.linearisation_tol = None;
            post.tool_centre_point = true;
        }
        let checker = match op_access {
            OperationAccess::Checked(c) => Some(*c),
            OperationAccess::CheckedWith(c, o) => {
                post.reverse_motion = Some(**o);
                Some(*c)
            }
            OperationAccess::Unchecked => None,
            OperationAccess::CountOnly => {
                post.reverse_motion = None;
                None
            }
        };
        let posted = post_path_checked(machine, &moves, &post, checker).map_err(|e| match e {
            postproc_kinematics::PostError::Block { index, source } => {
                kin_err(index, source.to_string())
            }
            other => kin_err(0, other.to_string()),
        })?;
        posture = posted.blocks.last().map(|b| b.joints).or(posture);
        let nc_moves = posted
            .blocks
            .iter()
            .enumerate()
            .map(|(k, b)| nc_move(machine, b, options.mode, &path.name, k))
            .collect::<Result<Vec<_>, _>>()?;
        metrics.push((path.name.clone(), posted.metrics));
        let (before, after) = match &posted.reverse_motion {
            Some(r) => (r.before.clone(), r.after.clone()),
            None => {
                // Without removal the curves are those of the source blocks (linearisation
                // blocks left out, as in the removal report).
                let source: Vec<PostedBlock> = posted
                    .blocks
                    .iter()
                    .filter(|b| !b.inserted)
                    .cloned()
                    .collect();
                let c = DisplacementCurves::of_blocks(machine, &source);
                (c.clone(), c)
            }
        };
        posted_ops.push(PostedOperation {
            name: path.name.clone(),
            index: op_index,
            metrics: posted.metrics,
            reverse_motion_removal: posted.reverse_motion.is_some(),
            reverse_motion: posted.reverse_motion,
            before,
            after,
            blocks: posted.blocks,
        });
        ops.push(NcOperation {
            name: path.name.clone(),
            tool,
            motion: Motion::Simultaneous {
                mode: options.mode,
                moves: nc_moves,
            },
        });
    }
    Ok(AssembledProgram {
        program: NcProgram {
            name: name.to_string(),
            operations: ops,
        },
        metrics,
        operations: posted_ops,
    })
}

fn lift(cl: &CutterLocation, d: f64) -> CutterLocation {
    CutterLocation {
        tip: cl.tip + cl.axis.into_inner() * d,
        axis: cl.axis,
    }
}

/// The tilt and rotary words (degrees) of a posture.
pub fn rotary_words(machine: &Machine, j: &Joints) -> Vec<RotaryWord> {
    [AxisId::Tilt, AxisId::Rotate]
        .iter()
        .map(|&a| RotaryWord {
            letter: machine.letter(a),
            deg: j.get(a).to_degrees(),
        })
        .collect()
}

/// One posted block as an NC move in `mode`. A cutting block without its feed (inverse
/// time in [`OutputMode::Joint`], mm/min otherwise) is an error naming the operation and
/// the block: a controller reads `F0` as "no motion" or an alarm, never as intended.
pub fn nc_move(
    machine: &Machine,
    b: &PostedBlock,
    mode: OutputMode,
    operation: &str,
    block: usize,
) -> Result<NcMove, GcodeError> {
    let rapid = b.kind == MoveKind::Rapid;
    let missing = |what| GcodeError::MissingFeed {
        operation: operation.to_string(),
        block,
        what,
    };
    let (xyz, feed) = match mode {
        OutputMode::Joint => (
            [b.joints.x, b.joints.y, b.joints.z],
            if rapid {
                Feed::Rapid
            } else {
                Feed::InverseTime(b.inverse_time_feed.ok_or_else(|| missing("inverse-time"))?)
            },
        ),
        OutputMode::TcpAngles | OutputMode::TcpVector => (
            [b.cl.tip.x, b.cl.tip.y, b.cl.tip.z],
            if rapid {
                Feed::Rapid
            } else {
                Feed::PerMinute(b.feed_mm_per_min.ok_or_else(|| missing("mm/min"))?)
            },
        ),
    };
    Ok(NcMove {
        xyz,
        rotary: rotary_words(machine, &b.joints),
        tool_vector: Some([b.cl.axis.x, b.cl.axis.y, b.cl.axis.z]),
        feed,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::LinuxCnc;
    use cam_core::{Point3, ToolPath, Vector3};
    use postproc_kinematics::ReverseMotionOptions;
    use std::sync::atomic::{AtomicUsize, Ordering};

    fn machine() -> Machine {
        let text = include_str!("../embedded/machines/xyzac-trt.toml");
        Machine::from_toml_str(text, "xyzac-trt.toml").unwrap()
    }

    /// A ring pass (r = 30 mm, z = 20 mm) whose tool axis, tilted 10° from +Z, turns with the
    /// tip's azimuth φ plus a local swing −A·u·exp(−u²), u = (φ − 60°)/5°, A = 10°: the
    /// azimuth runs backwards near φ = 60°, so C reverses twice.
    fn swing_op() -> ClOperation {
        let mut path = ToolPath::new("swing", "T1");
        let tilt = 10f64.to_radians();
        for k in 0..=60 {
            let phi = (2.0 * k as f64).to_radians();
            let u = (2.0 * k as f64 - 60.0) / 5.0;
            let az = phi - (10.0 * u * (-u * u).exp()).to_radians();
            let tip = Point3::new(30.0 * phi.cos(), 30.0 * phi.sin(), 20.0);
            let axis = Vector3::new(tilt.sin() * az.cos(), tilt.sin() * az.sin(), tilt.cos());
            let cl = CutterLocation::new(tip, axis).unwrap();
            path.moves.push(if k == 0 {
                Move::rapid(cl)
            } else {
                Move::feed(cl)
            });
        }
        ClOperation::new(path)
    }

    fn options() -> AssembleOptions {
        AssembleOptions {
            post: PostOptions {
                reverse_motion: Some(ReverseMotionOptions::default()),
                ..PostOptions::default()
            },
            ..AssembleOptions::default()
        }
    }

    /// A cutting block without its feed is refused (it used to be written `F0`).
    #[test]
    fn a_cutting_block_without_feed_is_an_error_not_f0() {
        let m = machine();
        let cl = CutterLocation::vertical(Point3::new(1.0, 2.0, 3.0));
        let mut b = PostedBlock {
            joints: Joints {
                x: 1.0,
                y: 2.0,
                z: 3.0,
                tilt: 0.0,
                rotate: 0.0,
            },
            cl,
            kind: MoveKind::Feed,
            feed_mm_per_min: None,
            inverse_time_feed: None,
            source_index: 4,
            inserted: false,
            unwound: false,
            linearisation_error_mm: 0.0,
            limit_violation: None,
        };
        for mode in [OutputMode::Joint, OutputMode::TcpAngles] {
            match nc_move(&m, &b, mode, "finish", 7) {
                Err(GcodeError::MissingFeed {
                    operation, block, ..
                }) => assert_eq!((operation.as_str(), block), ("finish", 7)),
                other => panic!("{mode:?}: {other:?}"),
            }
        }
        b.inverse_time_feed = Some(12.5);
        b.feed_mm_per_min = Some(800.0);
        assert_eq!(
            nc_move(&m, &b, OutputMode::Joint, "finish", 7)
                .unwrap()
                .feed,
            Feed::InverseTime(12.5)
        );
        b.kind = MoveKind::Rapid;
        b.inverse_time_feed = None;
        assert_eq!(
            nc_move(&m, &b, OutputMode::Joint, "finish", 7)
                .unwrap()
                .feed,
            Feed::Rapid
        );
    }

    #[test]
    fn checked_removal_leaves_no_reverse_motion_and_checks_changed_postures() {
        let ops = [swing_op()];
        let calls = AtomicUsize::new(0);
        let accept = |_: &CutterLocation| {
            calls.fetch_add(1, Ordering::Relaxed);
            true
        };
        let a = assemble_program_checked(
            "rm",
            &ops,
            &machine(),
            &LinuxCnc::default(),
            &options(),
            Some(&accept),
        )
        .unwrap();
        let m = a.metrics[0].1;
        assert!(m.reverse_motions_before >= 2, "{m:?}");
        assert_eq!(m.reverse_motions_after, 0, "{m:?}");
        assert!(
            calls.load(Ordering::Relaxed) > 0,
            "the checker saw the changed postures"
        );
        let p = &a.operations[0];
        assert!(p.reverse_motion_removal && p.reverse_motion.is_some());
        assert_eq!(p.before.values.len(), p.after.values.len());
        assert_ne!(p.before.values, p.after.values);
        // The smoothed C column (index 4) moves one way along the cutting run (between the
        // approach and the retract rapids).
        let n = p.after.values.len();
        let c: Vec<f64> = p.after.values[1..n - 1].iter().map(|v| v[4]).collect();
        let steps: Vec<f64> = c.windows(2).map(|w| w[1] - w[0]).collect();
        assert!(
            steps.iter().all(|d| *d >= -1e-6) || steps.iter().all(|d| *d <= 1e-6),
            "{c:?}"
        );
        // Tips are kept by the smoothing: every source tip is still reached.
        for (mv, b) in ops[0]
            .path
            .moves
            .iter()
            .zip(p.blocks.iter().filter(|b| !b.inserted).skip(1))
        {
            assert!((mv.cl.tip - b.cl.tip).norm() < 1e-9);
        }
    }

    #[test]
    fn rejecting_checker_keeps_the_original_postures() {
        let ops = [swing_op()];
        let reject = |_: &CutterLocation| false;
        let a = assemble_program_checked(
            "rm",
            &ops,
            &machine(),
            &LinuxCnc::default(),
            &options(),
            Some(&reject),
        )
        .unwrap();
        let m = a.metrics[0].1;
        assert!(m.reverse_motions_before >= 2);
        assert_eq!(m.reverse_motions_after, m.reverse_motions_before);
        let r = a.operations[0].reverse_motion.as_ref().unwrap();
        assert!(
            r.runs_kept >= 1 && !r.inaccessible_blocks.is_empty(),
            "{r:?}"
        );
        // CountOnly: no removal at all, curves before = after.
        let a = assemble_program_with_access(
            "rm",
            &ops,
            &machine(),
            &LinuxCnc::default(),
            &options(),
            &[OperationAccess::CountOnly],
        )
        .unwrap();
        let p = &a.operations[0];
        assert!(!p.reverse_motion_removal);
        assert_eq!(p.metrics.reverse_motions_after, m.reverse_motions_before);
        assert_eq!(p.before, p.after);
        assert!(matches!(
            assemble_program_with_access(
                "rm",
                &ops,
                &machine(),
                &LinuxCnc::default(),
                &options(),
                &[],
            ),
            Err(GcodeError::InvalidOption {
                field: "access",
                ..
            })
        ));
    }
}
