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
//!    linearisation control only for joint output, where the controller interpolates joints;
//!    inverse-time feeds), and each posted block becomes an [`NcMove`]: joint values in
//!    [`OutputMode::Joint`] (all cutting blocks in inverse time), tool tip + axis angles in
//!    [`OutputMode::TcpAngles`], tool tip + tool vector in [`OutputMode::TcpVector`].
//!
//! Cost: that of [`post_path`], O(n) otherwise.

use crate::dialect::Dialect;
use crate::program::{
    Feed, Motion, NcMove, NcOperation, NcProgram, OutputMode, RotaryWord, ToolCall,
};
use crate::{ClOperation, GcodeError};
use cam_core::{CutterLocation, Move, MoveKind};
use postproc_kinematics::{
    post_path, AxisId, Joints, Machine, PostMetrics, PostOptions, PostedBlock,
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
    let mut posture: Option<Joints> = options.post.initial;
    for op in operations {
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
        if fixed && indexed_ok {
            // Post the moves anyway: checks every block against the axis limits and gives
            // the machine angles of the plane.
            let mut check = post.clone();
            check.linearisation_tol = None;
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
            post.linearisation_tol = None;
        }
        let posted = post_path(machine, &moves, &post).map_err(|e| match e {
            postproc_kinematics::PostError::Block { index, source } => {
                kin_err(index, source.to_string())
            }
            other => kin_err(0, other.to_string()),
        })?;
        posture = posted.blocks.last().map(|b| b.joints).or(posture);
        let nc_moves = posted
            .blocks
            .iter()
            .map(|b| nc_move(machine, b, options.mode))
            .collect();
        metrics.push((path.name.clone(), posted.metrics));
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

/// One posted block as an NC move in `mode`.
pub fn nc_move(machine: &Machine, b: &PostedBlock, mode: OutputMode) -> NcMove {
    let rapid = b.kind == MoveKind::Rapid;
    let (xyz, feed) = match mode {
        OutputMode::Joint => (
            [b.joints.x, b.joints.y, b.joints.z],
            if rapid {
                Feed::Rapid
            } else {
                // post_path gives an inverse-time value for every non-rapid block.
                Feed::InverseTime(b.inverse_time_feed.unwrap_or(0.0))
            },
        ),
        OutputMode::TcpAngles | OutputMode::TcpVector => (
            [b.cl.tip.x, b.cl.tip.y, b.cl.tip.z],
            if rapid {
                Feed::Rapid
            } else {
                Feed::PerMinute(b.feed_mm_per_min.unwrap_or(0.0))
            },
        ),
    };
    NcMove {
        xyz,
        rotary: rotary_words(machine, &b.joints),
        tool_vector: Some([b.cl.axis.x, b.cl.axis.y, b.cl.axis.z]),
        feed,
    }
}
