//! Path-level post-processing: cutter locations → joint blocks for one machine, with solution
//! continuity, limit checking, unwinding, reverse-motion smoothing, linearisation control,
//! feeds and the post-processing metrics of the report.

use crate::error::{KinematicsError, PostError};
use crate::feed::inverse_time_feed;
use crate::joints::AxisId;
use crate::joints::Joints;
use crate::kinematics::LIMIT_SLACK;
use crate::linearise::{segment_deviation, subdivide, LinearisationSettings};
use crate::machine::{Machine, RotaryMode};
use crate::reverse_motion::{
    count_path_reverse_motions, remove_reverse_motions, AccessibilityChecker, ReverseMotionOptions,
    ReverseMotionReport,
};
use crate::rotary_motion::{reversal_split, rotary_smoothness, ReversalSplit, RotarySmoothness};
use cam_core::{CutterLocation, Move, MoveKind, ToolPath};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// What to do when a block cannot be reached within the axis limits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LimitPolicy {
    /// Stop with [`PostError::Block`] naming the block index and the axis.
    Error,
    /// Keep the closest solution, mark the block and count it in
    /// [`PostMetrics::limit_violations`].
    Report,
}

/// Options of [`post_path`]. `PostOptions::default()` gives the documented defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct PostOptions {
    /// Tool length, gauge line to tip (mm); enters the transform of head machines only.
    pub tool_length: f64,
    /// Limit handling.
    pub limit_policy: LimitPolicy,
    /// Largest tool-tip deviation (mm) caused by joint interpolation between blocks
    /// (default 0.005); `None`: no subdivision, the metric reports the deviation the joint
    /// interpolation has (for a tool-centre-point controller set
    /// [`PostOptions::tool_centre_point`] instead).
    pub linearisation_tol: Option<f64>,
    /// Interior samples per segment for the deviation (default 8).
    pub linearisation_samples: usize,
    /// Height above the tip (mm) along the tool axis whose deviation is kept within
    /// `linearisation_tol` too (default 0: the tip only). Set it to the top of the cutting
    /// part (the flute length): near the rotary axis' singular direction joint interpolation
    /// turns the axis off its great circle while the tip stays on the line, and the flutes
    /// cut beside the path ([`crate::linearise::segment_deviation`]).
    pub check_height_mm: f64,
    /// Largest bisection depth per block (default 16). Only the pieces still above the
    /// tolerance are bisected again, so the cost grows with the depth only where the tool
    /// axis passes close to the rotary axis' singular direction: there a few hundredths of a
    /// degree of axis motion turn the rotary table by degrees, and at a tip radius of 20 mm a
    /// turn of 2.6° already moves the tip 0.005 mm off the line (measured on the hub outlet
    /// of impeller-8+8: depth 10 left 0.093 mm, depth 13 met 0.005 mm).
    pub max_subdivision_depth: u32,
    /// The controller keeps the tool tip on the programmed line itself (tool-centre-point
    /// control: LinuxCNC TCP kinematics, Fanuc G43.4/G43.5, Sinumerik TRAORI, Heidenhain
    /// M128); default `false`. No block is inserted and every block's linearisation error is
    /// 0 — the tip deviation of joint interpolation does not occur in such a program.
    pub tool_centre_point: bool,
    /// Also subdivide rapid moves (default `false`); a rapid that changes the solution branch
    /// (a reconfiguration, which the posture choice allows on the rapid that starts a group)
    /// cannot follow its straight line and is left as it is.
    pub linearise_rapids: bool,
    /// Unwind continuous rotary axes to (−180°, 180°] on rapid moves (default `true`).
    pub unwind_on_rapid: bool,
    /// Feed (mm/min) of cutting blocks that carry none and follow none (default 1000).
    pub default_feed_mm_per_min: f64,
    /// Posture before the first block (default: the machine's home position).
    pub initial: Option<Joints>,
    /// Reverse-motion removal on the rotary axes (default `None`: only count them).
    pub reverse_motion: Option<ReverseMotionOptions>,
}

impl Default for PostOptions {
    fn default() -> Self {
        Self {
            tool_length: 0.0,
            limit_policy: LimitPolicy::Error,
            linearisation_tol: Some(0.005),
            linearisation_samples: 8,
            check_height_mm: 0.0,
            max_subdivision_depth: 16,
            tool_centre_point: false,
            linearise_rapids: false,
            unwind_on_rapid: true,
            default_feed_mm_per_min: 1000.0,
            initial: None,
            reverse_motion: None,
        }
    }
}

impl PostOptions {
    fn validate(&self) -> Result<(), PostError> {
        let bad = |field: &'static str, message: &str| {
            Err(PostError::InvalidOption {
                field,
                message: message.to_string(),
            })
        };
        if !self.tool_length.is_finite() || self.tool_length < 0.0 {
            return bad("tool_length", "must be finite and >= 0");
        }
        if let Some(t) = self.linearisation_tol {
            if !(t.is_finite() && t > 0.0) {
                return bad("linearisation_tol", "must be finite and > 0");
            }
        }
        if !(self.check_height_mm.is_finite() && self.check_height_mm >= 0.0) {
            return bad("check_height_mm", "must be finite and >= 0");
        }
        if self.linearisation_samples == 0 {
            return bad("linearisation_samples", "must be >= 1");
        }
        if self.max_subdivision_depth > 30 {
            return bad("max_subdivision_depth", "must be <= 30");
        }
        if let Some(r) = &self.reverse_motion {
            r.validate()?;
        }
        if !(self.default_feed_mm_per_min.is_finite() && self.default_feed_mm_per_min > 0.0) {
            return bad("default_feed_mm_per_min", "must be finite and > 0");
        }
        Ok(())
    }
}

/// One output block.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PostedBlock {
    /// Axis values (mm, rad).
    pub joints: Joints,
    /// Cutter location the block reaches (workpiece frame). After reverse-motion smoothing the
    /// axis is the smoothed one; for inserted blocks it is the intended interpolated CL.
    pub cl: CutterLocation,
    /// Kind of the source move.
    pub kind: MoveKind,
    /// Tool-tip feed (mm/min) of non-rapid blocks (source feed, else the last one, else the
    /// default).
    pub feed_mm_per_min: Option<f64>,
    /// Inverse-time feed (G93 `F`, 1/min) of non-rapid blocks.
    pub inverse_time_feed: Option<f64>,
    /// Index of the source move / cutter location.
    pub source_index: usize,
    /// Inserted by linearisation control.
    pub inserted: bool,
    /// A continuous axis was unwound on this (rapid) block.
    pub unwound: bool,
    /// Tip deviation (mm) of the joint-interpolated segment ending at this block (0 for the
    /// first block and for rapids that are not linearised).
    pub linearisation_error_mm: f64,
    /// Limit violation of this block (only with [`LimitPolicy::Report`]).
    pub limit_violation: Option<KinematicsError>,
}

/// Post-processing metrics (field names fixed by the report contract).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct PostMetrics {
    /// Direction changes of the rotary axes (summed over both) along cutting runs before
    /// reverse-motion removal.
    pub reverse_motions_before: usize,
    /// The same after removal (equals `before` without removal).
    pub reverse_motions_after: usize,
    /// Of `reverse_motions_before`, the reversals inside a cut (what paper 004 removes;
    /// [`crate::rotary_motion`]); the rest lie at path ends and links.
    #[serde(default)]
    pub reverse_motions_cutting_before: usize,
    /// Of `reverse_motions_after`, the reversals inside a cut.
    #[serde(default)]
    pub reverse_motions_cutting_after: usize,
    /// Of `reverse_motions_before`, the reversals at path ends and links (a zig-zag's turn,
    /// a plunge or retract: harmless).
    #[serde(default)]
    pub reverse_motions_links_before: usize,
    /// Of `reverse_motions_after`, the reversals at path ends and links.
    #[serde(default)]
    pub reverse_motions_links_after: usize,
    /// The reversals after removal per rotary axis, with the smallest and largest reversing
    /// step inside cuts.
    #[serde(default)]
    pub reversals: ReversalSplit,
    /// Largest angular step and angular acceleration at the programmed feed of the written
    /// blocks, with the machine's limits ([`crate::rotary_motion::rotary_smoothness`]).
    #[serde(default)]
    pub rotary: RotarySmoothness,
    /// Largest deviation (mm) of any joint-interpolated cutting (non-rapid) block after
    /// linearisation control: of the tool tip and of the checked flute height.
    pub max_linearisation_error_mm: f64,
    /// The same over the rapid moves that are linearised (with
    /// [`PostOptions::linearise_rapids`]): they cut nothing, and the read-back verification
    /// checks what the real motion sweeps.
    #[serde(default)]
    pub max_rapid_linearisation_error_mm: f64,
    /// Blocks outside the axis limits (only non-zero with [`LimitPolicy::Report`]).
    pub limit_violations: usize,
    /// Output blocks.
    pub blocks: usize,
    /// Blocks inserted by linearisation control.
    pub inserted_blocks: usize,
    /// Blocks unwound.
    pub unwound_blocks: usize,
    /// Non-rapid source blocks reached from the previous source block by a change of solution
    /// branch (a rotary step above [`RECONFIGURATION_STEP_RAD`] that does not follow the
    /// intended tool-axis sweep, e.g. a tilt-sign flip at a travel limit) that the group-wide
    /// posture choice could not avoid. Large rotary swings that do follow the sweep (near the
    /// singular direction) are not counted: linearisation tracks them.
    pub reconfigurations: usize,
}

/// Result of [`post_path`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PostedPath {
    /// Machine name.
    pub machine: String,
    /// Tool length used (mm).
    pub tool_length: f64,
    /// Blocks in program order.
    pub blocks: Vec<PostedBlock>,
    /// Metrics.
    pub metrics: PostMetrics,
    /// Reverse-motion removal details (when it ran), with the displacement curves.
    pub reverse_motion: Option<ReverseMotionReport>,
}

/// Posts a tool path (see [`post_path`]).
pub fn post_tool_path(
    machine: &Machine,
    path: &ToolPath,
    options: &PostOptions,
) -> Result<PostedPath, PostError> {
    post_path(machine, &path.moves, options)
}

/// Posts bare cutter locations as feed moves at the default feed (see [`post_path`]).
pub fn post_locations(
    machine: &Machine,
    cls: &[CutterLocation],
    options: &PostOptions,
) -> Result<PostedPath, PostError> {
    let moves: Vec<Move> = cls.iter().map(|cl| Move::feed(*cl)).collect();
    post_path(machine, &moves, options)
}

/// Turns moves into joint blocks:
///
/// 1. inverse kinematics block by block, each choosing the solution nearest the previous
///    block (continuity) within the limits ([`Machine::inverse`]); continuous axes are
///    unwound on rapids when asked. The path is split into groups (a move and the non-rapid
///    moves after it); when the greedy choice inside a group meets a limit or needs a
///    reconfiguration, the postures of the whole group are chosen together by dynamic
///    programming over every move's candidate postures (fewest limit violations and
///    reconfigurations, then least rotary travel; `solve_group_optimal`);
/// 2. reverse motions of the rotary axes are counted and, with
///    [`PostOptions::reverse_motion`], removed ([`crate::reverse_motion`]);
/// 3. linearisation control inserts blocks until the joint-interpolated tip deviates at most
///    the tolerance ([`crate::linearise`]);
/// 4. tool-tip and inverse-time feeds ([`crate::feed`]).
///
/// Errors: invalid options; a block outside the limits (with [`LimitPolicy::Error`]) or with
/// an unreachable orientation — [`PostError::Block`] names the source index and the axis.
/// Cost: O(n) inverse solutions plus the subdivision work.
pub fn post_path(
    machine: &Machine,
    moves: &[Move],
    options: &PostOptions,
) -> Result<PostedPath, PostError> {
    post_path_checked(machine, moves, options, None)
}

/// [`post_path`] with a caller-supplied accessibility checker (gouge and collision) that
/// reverse-motion removal uses to re-check changed postures.
pub fn post_path_checked(
    machine: &Machine,
    moves: &[Move],
    options: &PostOptions,
    checker: Option<&dyn AccessibilityChecker>,
) -> Result<PostedPath, PostError> {
    options.validate()?;
    let tl = options.tool_length;
    let mut blocks: Vec<PostedBlock> = Vec::with_capacity(moves.len());
    let mut prev = options.initial.unwrap_or(machine.home());
    let mut last_feed = options.default_feed_mm_per_min;
    let mut start = 0;
    while start < moves.len() {
        // A group: one move (typically a rapid) and the non-rapid moves that follow it.
        let mut end = start + 1;
        while end < moves.len() && moves[end].kind != MoveKind::Rapid {
            end += 1;
        }
        let (mut solved, problems) = solve_group(machine, moves, start..end, &prev, None, options)?;
        if problems > 0 {
            // The greedy choice ran into a limit or a reconfiguration: choose the postures of
            // the whole group at once (fewest problems, then least rotary travel).
            let (best, p) = solve_group_optimal(machine, moves, start..end, &prev, options)?;
            if p < problems {
                solved = best;
            }
        }
        for (k, (j, violation, unwound)) in solved.into_iter().enumerate() {
            let index = start + k;
            let m = &moves[index];
            if let Some(source) = &violation {
                if options.limit_policy == LimitPolicy::Error {
                    return Err(PostError::Block {
                        index,
                        source: source.clone(),
                    });
                }
            }
            let feed = if m.kind == MoveKind::Rapid {
                None
            } else {
                if let Some(f) = m.feed_mm_per_min.filter(|f| f.is_finite() && *f > 0.0) {
                    last_feed = f;
                }
                Some(last_feed)
            };
            blocks.push(PostedBlock {
                joints: j,
                cl: m.cl,
                kind: m.kind,
                feed_mm_per_min: feed,
                inverse_time_feed: None,
                source_index: index,
                inserted: false,
                unwound,
                linearisation_error_mm: 0.0,
                limit_violation: violation,
            });
            prev = j;
        }
        start = end;
    }

    let reverse_motions_before = count_path_reverse_motions(&blocks);
    let split_before = reversal_split(&blocks);
    let reverse_report = match &options.reverse_motion {
        Some(rm) => Some(remove_reverse_motions(
            machine,
            &mut blocks,
            tl,
            rm,
            checker,
        )?),
        None => None,
    };
    let reverse_motions_after = count_path_reverse_motions(&blocks);
    let split_after = reversal_split(&blocks);

    // Linearisation control and feeds.
    let mut out: Vec<PostedBlock> = Vec::with_capacity(blocks.len());
    let mut inserted_blocks = 0;
    let mut max_err: f64 = 0.0;
    let mut max_rapid_err: f64 = 0.0;
    let settings = LinearisationSettings {
        tol: options.linearisation_tol.unwrap_or(f64::INFINITY),
        height: options.check_height_mm,
        samples: options.linearisation_samples,
        max_depth: if options.linearisation_tol.is_some() {
            options.max_subdivision_depth
        } else {
            0
        },
    };
    let mut scratch: Vec<(CutterLocation, Joints, f64)> = Vec::new();
    let initial = options.initial.unwrap_or(machine.home());
    // The deviation of every source segment is independent of the others: evaluate them in
    // parallel, then subdivide only the segments above tolerance.
    let wants = |p: &PostedBlock, b: &PostedBlock| {
        !options.tool_centre_point
            && (b.kind != MoveKind::Rapid
                || (options.linearise_rapids
                    && !is_reconfiguration(machine, tl, &p.cl, &p.joints, &b.cl, &b.joints)))
            && !b.unwound
            && b.limit_violation.is_none()
            && p.limit_violation.is_none()
    };
    let first_dev: Vec<f64> = (0..blocks.len())
        .into_par_iter()
        .map(|i| {
            if i == 0 || !wants(&blocks[i - 1], &blocks[i]) {
                return 0.0;
            }
            let (p, b) = (&blocks[i - 1], &blocks[i]);
            segment_deviation(
                machine,
                &p.joints,
                &b.joints,
                &p.cl,
                &b.cl,
                tl,
                options.linearisation_samples,
                options.check_height_mm,
            )
        })
        .collect();
    for (b, dev) in blocks.into_iter().zip(first_dev) {
        let Some(p) = out.last().cloned() else {
            // the first block starts from the initial posture
            let mut b = b;
            if let Some(f) = b.feed_mm_per_min {
                let len = (b.cl.tip - machine.forward(&initial, tl).tip).norm();
                b.inverse_time_feed = Some(inverse_time_feed(machine, &initial, &b.joints, len, f));
            }
            out.push(b);
            continue;
        };
        // Segments touching a block outside the limits (Report policy) are not subdivided.
        let linearise = wants(&p, &b);
        let mut b = b;
        if linearise && dev <= settings.tol {
            b.linearisation_error_mm = dev;
            if b.kind == MoveKind::Rapid {
                max_rapid_err = max_rapid_err.max(dev);
            } else {
                max_err = max_err.max(dev);
            }
            set_feed(machine, &p, &mut b);
        } else if linearise {
            scratch.clear();
            let sub = subdivide(
                machine,
                &p.cl,
                &p.joints,
                &b.cl,
                &b.joints,
                tl,
                &settings,
                &mut scratch,
            );
            let last = match sub {
                Ok(last) => last,
                Err(e @ KinematicsError::OutOfLimits { .. })
                    if options.limit_policy == LimitPolicy::Report =>
                {
                    // an intermediate posture leaves the travel: keep the block unsubdivided
                    scratch.clear();
                    b.limit_violation = Some(e);
                    segment_deviation(
                        machine,
                        &p.joints,
                        &b.joints,
                        &p.cl,
                        &b.cl,
                        tl,
                        options.linearisation_samples,
                        options.check_height_mm,
                    )
                }
                Err(source) => {
                    return Err(PostError::Block {
                        index: b.source_index,
                        source,
                    })
                }
            };
            let mut from = p.clone();
            for (cl, j, err) in scratch.drain(..) {
                let mut nb = PostedBlock {
                    joints: j,
                    cl,
                    kind: b.kind,
                    feed_mm_per_min: b.feed_mm_per_min,
                    inverse_time_feed: None,
                    source_index: b.source_index,
                    inserted: true,
                    unwound: false,
                    linearisation_error_mm: err,
                    limit_violation: None,
                };
                if let Err(e) = machine.check_limits(&j, crate::kinematics::LIMIT_SLACK) {
                    if options.limit_policy == LimitPolicy::Error {
                        return Err(PostError::Block {
                            index: b.source_index,
                            source: e,
                        });
                    }
                    nb.limit_violation = Some(e);
                }
                set_feed(machine, &from, &mut nb);
                if b.kind == MoveKind::Rapid {
                    max_rapid_err = max_rapid_err.max(err);
                } else {
                    max_err = max_err.max(err);
                }
                inserted_blocks += 1;
                from = nb.clone();
                out.push(nb);
            }
            b.linearisation_error_mm = last;
            if b.kind == MoveKind::Rapid {
                max_rapid_err = max_rapid_err.max(last);
            } else {
                max_err = max_err.max(last);
            }
            set_feed(machine, &from, &mut b);
        } else {
            set_feed(machine, &p, &mut b);
        }
        out.push(b);
    }
    let metrics = PostMetrics {
        reverse_motions_before,
        reverse_motions_after,
        reverse_motions_cutting_before: split_before.cutting(),
        reverse_motions_cutting_after: split_after.cutting(),
        reverse_motions_links_before: split_before.links(),
        reverse_motions_links_after: split_after.links(),
        reversals: split_after,
        rotary: rotary_smoothness(machine, &out),
        max_linearisation_error_mm: max_err,
        max_rapid_linearisation_error_mm: max_rapid_err,
        limit_violations: out.iter().filter(|b| b.limit_violation.is_some()).count(),
        blocks: out.len(),
        inserted_blocks,
        unwound_blocks: out.iter().filter(|b| b.unwound).count(),
        // Between source blocks: the blocks linearisation inserts split a swing into small
        // steps but do not remove it.
        reconfigurations: {
            let source: Vec<&PostedBlock> = out.iter().filter(|b| !b.inserted).collect();
            source
                .windows(2)
                .filter(|w| {
                    w[1].kind != MoveKind::Rapid
                        && is_reconfiguration(
                            machine,
                            tl,
                            &w[0].cl,
                            &w[0].joints,
                            &w[1].cl,
                            &w[1].joints,
                        )
                })
                .count()
        },
    };
    Ok(PostedPath {
        machine: machine.name().to_string(),
        tool_length: tl,
        blocks: out,
        metrics,
        reverse_motion: reverse_report,
    })
}

fn set_feed(machine: &Machine, from: &PostedBlock, b: &mut PostedBlock) {
    if let Some(f) = b.feed_mm_per_min {
        let len = (b.cl.tip - from.cl.tip).norm();
        b.inverse_time_feed = Some(inverse_time_feed(machine, &from.joints, &b.joints, len, f));
    }
}

/// Source indices of the rapid moves of `posted` on which the machine does not follow the
/// programmed straight move but swings: the block was unwound (a continuous rotary axis
/// turned by a multiple of 2π, which joint interpolation performs as a full turn of the head
/// or table), it changes the solution branch ([`is_reconfiguration`]: a rotary step above
/// [`RECONFIGURATION_STEP_RAD`] that the exact inverse kinematics along the move does not
/// reach), or it starts or ends outside the axis limits. Such a rapid is not linearised
/// ([`PostOptions::linearise_rapids`] leaves it as it is), so between its ends the tool sweeps
/// an arc of radius up to the pivot plus tool length (head) or the tip radius (table); a caller
/// that knows the part routes it over a safety surface instead (the job pipeline of
/// `impeller-cam` does). Inserted linearisation blocks are skipped: the index is that of the
/// source move (`PostedBlock::source_index`). Cost O(n) plus one sweep continuation per
/// large rotary step.
pub fn swinging_rapids(machine: &Machine, posted: &PostedPath) -> Vec<usize> {
    let source: Vec<&PostedBlock> = posted.blocks.iter().filter(|b| !b.inserted).collect();
    source
        .windows(2)
        .filter(|w| {
            let (a, b) = (w[0], w[1]);
            b.kind == MoveKind::Rapid
                && (b.unwound
                    || a.limit_violation.is_some()
                    || b.limit_violation.is_some()
                    || is_reconfiguration(
                        machine,
                        posted.tool_length,
                        &a.cl,
                        &a.joints,
                        &b.cl,
                        &b.joints,
                    ))
        })
        .map(|w| w[1].source_index)
        .collect()
}

/// A rotary step larger than this (rad) inside a group counts as a reconfiguration (the
/// machine would swing the table or head around between two neighbouring cutter locations).
pub const RECONFIGURATION_STEP_RAD: f64 = std::f64::consts::FRAC_PI_2;

type Solved = (Joints, Option<KinematicsError>, bool);

/// A candidate of [`solve_group_optimal`] with the best way to reach it: (candidate,
/// problems, branch changes through the pole left outside the linearisation tolerance,
/// rotary travel, index of the predecessor).
type Reached = (Solved, usize, usize, f64, usize);

/// Inverse kinematics of `moves[range]` with continuity from `prev` (the first posture may be
/// forced); returns the postures and the number of problems (blocks outside the limits plus
/// reconfiguration steps).
fn solve_group(
    machine: &Machine,
    moves: &[Move],
    range: std::ops::Range<usize>,
    prev: &Joints,
    first: Option<Joints>,
    options: &PostOptions,
) -> Result<(Vec<Solved>, usize), PostError> {
    let tl = options.tool_length;
    let continuous = matches!(machine.axis(AxisId::Rotate).mode, RotaryMode::Continuous)
        || matches!(machine.axis(AxisId::Tilt).mode, RotaryMode::Continuous);
    let mut out: Vec<Solved> = Vec::with_capacity(range.len());
    let mut problems = 0;
    let mut prev = *prev;
    let mut prev_cl = moves[range.start].cl;
    for index in range.clone() {
        let m = &moves[index];
        let (mut j, violation) = match (index == range.start, first) {
            (true, Some(f)) => (f, None),
            _ => machine
                .inverse_best_effort(&m.cl, tl, Some(&prev))
                .map_err(|source| PostError::Block { index, source })?,
        };
        if index > range.start && m.kind != MoveKind::Rapid {
            if let Some(e) = keep_branch_near_pole(machine, options, &prev_cl, &prev, &m.cl, &j) {
                j = e;
            }
        }
        let mut unwound = false;
        if options.unwind_on_rapid && continuous && m.kind == MoveKind::Rapid {
            unwound = machine.unwind(&mut j);
            if unwound {
                j = machine.joints_for_angles(&m.cl.tip, tl, j.tilt, j.rotate);
            }
        }
        problems += usize::from(violation.is_some());
        if index > range.start && is_reconfiguration(machine, tl, &prev_cl, &prev, &m.cl, &j) {
            problems += 1;
        }
        out.push((j, violation, unwound));
        prev = j;
        prev_cl = m.cl;
    }
    Ok((out, problems))
}

/// The posture that keeps the solution branch where the nearest posture `b` changes it
/// through the singular direction, when that is better for the cut; `None` to keep `b`.
///
/// Near the singular direction a change of branch is a small rotary step (the tilt changes
/// sign through the pole, the rotate axis stays), so the nearest-posture choice takes it.
/// Joint interpolation then swings the axis through the pole instead of around it: the tip
/// stays on its line but the flutes leave the path by about `h·sin δ` at the checked height
/// `h`, where `δ` is how far the intended sweep passes from the pole, and the linearisation
/// of that swing adds midpoints off the sweep. Where the nearest posture changes branch by a
/// small step ([`changes_branch_through_pole`]), both moves are linearised
/// ([`crate::linearise::subdivide`]) and the branch-keeping posture (the end of the exact
/// sweep on the tilt's branch, [`sweep_end_on_branch`], which turns the rotate axis around
/// the pole) is taken when it meets the tolerance, the branch change does not, and it lies
/// within the limits. On impeller-8+8 this took the largest linearisation error of hub
/// finishing from 0.161 mm to 0.007 mm. The swing cannot always be followed: passing a
/// hundredth of a degree from the pole the rotate axis turns by up to 180° within
/// micrometres of tip travel, and the table's swing moves the tip more than bisection to the
/// depth limit resolves; there the branch change stays and its deviation is reported.
/// Rapids are not held to the flute height.
fn keep_branch_near_pole(
    machine: &Machine,
    options: &PostOptions,
    cla: &CutterLocation,
    a: &Joints,
    clb: &CutterLocation,
    b: &Joints,
) -> Option<Joints> {
    let tl = options.tool_length;
    if !changes_branch_through_pole(options, cla, a, clb, b) {
        return None;
    }
    let end = sweep_end_on_branch(machine, tl, cla, a, clb)?;
    if end.rotary_travel(b) < 1e-6 || machine.check_limits(&end, LIMIT_SLACK).is_err() {
        return None;
    }
    let tol = options.linearisation_tol?;
    let flip = linearised_deviation(machine, options, cla, a, clb, b);
    (flip > tol && linearised_deviation(machine, options, cla, a, clb, &end) <= tol).then_some(end)
}

/// The largest deviation (tip and checked flute height) left after linearising the move
/// `a → b` with the options' settings (`∞` when the kinematics fail on the way).
fn linearised_deviation(
    machine: &Machine,
    options: &PostOptions,
    cla: &CutterLocation,
    a: &Joints,
    clb: &CutterLocation,
    b: &Joints,
) -> f64 {
    let settings = LinearisationSettings {
        tol: options.linearisation_tol.unwrap_or(f64::INFINITY),
        height: options.check_height_mm,
        samples: options.linearisation_samples,
        max_depth: options.max_subdivision_depth,
    };
    let mut out = Vec::new();
    match subdivide(
        machine,
        cla,
        a,
        clb,
        b,
        options.tool_length,
        &settings,
        &mut out,
    ) {
        Ok(last) => out.iter().fold(last, |m, x| m.max(x.2)),
        Err(_) => f64::INFINITY,
    }
}

/// Whether the move from `a` (at `cla`) to `b` (at `clb`) is a reconfiguration: a rotary step
/// larger than [`RECONFIGURATION_STEP_RAD`] on either axis that does not follow the intended
/// tool-axis sweep. A large step can be legitimate: where the sweep passes close to the
/// singular direction, a hundredth of a degree of tool axis turns the rotary axis by degrees,
/// and linearisation tracks that swing with exact intermediate postures. A change of the
/// solution branch (e.g. the tilt sign) in the middle of a move cannot be tracked: the tool
/// would swing away from the intended orientations.
/// (A branch change through the pole is a small step; the solution choice keeps the branch
/// there where that serves the cut, see `keep_branch_near_pole`.)
pub fn is_reconfiguration(
    machine: &Machine,
    tool_length: f64,
    cla: &CutterLocation,
    a: &Joints,
    clb: &CutterLocation,
    b: &Joints,
) -> bool {
    large_rotary_step(a, b) && !follows_sweep(machine, tool_length, cla, a, clb, b)
}

/// Smallest angle (rad) between the great-circle arc of tool axes from `a` to `b` and the
/// singular direction `±Z` (the rotary table's or head's axis in the part frame).
pub fn sweep_pole_angle(a: &nalgebra::UnitVector3<f64>, b: &nalgebra::UnitVector3<f64>) -> f64 {
    let end_angle = |v: &nalgebra::UnitVector3<f64>| v.z.abs().clamp(-1.0, 1.0).acos();
    let mut best = end_angle(a).min(end_angle(b));
    let n = a.cross(b);
    let nn = n.norm();
    if nn > 1e-15 {
        let n = n / nn;
        for z in [nalgebra::Vector3::z(), -nalgebra::Vector3::z()] {
            // The point of the great circle nearest the pole, and whether it lies on the arc.
            let p = z - n * z.dot(&n);
            if p.norm() < 1e-15 {
                continue;
            }
            let inside = a.cross(&p).dot(&n) >= 0.0 && p.cross(b).dot(&n) >= 0.0;
            if inside {
                best = best.min(z.dot(&n).abs().clamp(0.0, 1.0).asin());
            }
        }
    }
    best
}

/// Whether the move from `a` to `b` changes the solution branch (the sign of the tilt) by a
/// small rotary step, i.e. through the singular direction, under linearisation control. Such
/// a move only approximates the intended sweep (which passes the pole at some distance); the
/// callers measure it by linearising it.
fn changes_branch_through_pole(
    options: &PostOptions,
    cla: &CutterLocation,
    a: &Joints,
    clb: &CutterLocation,
    b: &Joints,
) -> bool {
    options.linearisation_tol.is_some()
        && cla.axis.angle(&clb.axis) >= 1e-12
        && (a.tilt < 0.0) != (b.tilt < 0.0)
        && !large_rotary_step(a, b)
}

/// A rotary step above [`RECONFIGURATION_STEP_RAD`] on either axis.
fn large_rotary_step(a: &Joints, b: &Joints) -> bool {
    (b.tilt - a.tilt).abs() > RECONFIGURATION_STEP_RAD
        || (b.rotate - a.rotate).abs() > RECONFIGURATION_STEP_RAD
}

/// Largest rotary travel (rad) of one step of [`follows_sweep`]'s continuation.
const SWEEP_STEP_RAD: f64 = 0.05;
/// Most continuation steps [`follows_sweep`] takes before it gives up (not followable).
const SWEEP_MAX_STEPS: usize = 20_000;

/// Whether continuing the exact inverse kinematics from `a` along the intended sweep (tip on
/// the chord, axis on the great circle from `cla` to `clb`) arrives at `b` (within 1e-6 rad);
/// see [`sweep_end`].
fn follows_sweep(
    machine: &Machine,
    tool_length: f64,
    cla: &CutterLocation,
    a: &Joints,
    clb: &CutterLocation,
    b: &Joints,
) -> bool {
    let arrives = |e: Option<Joints>| e.is_some_and(|e| e.rotary_travel(b) < 1e-6);
    let sweeps = |a: &Joints| {
        arrives(sweep_end(machine, tool_length, cla, a, clb))
            || arrives(sweep_end_on_branch(machine, tool_length, cla, a, clb))
    };
    if sweeps(a) {
        return true;
    }
    // At a singular end (tool axis along the rotary axis) the rotate angle is free: the move
    // turns it there, tip and axis fixed (a pure table or head turn, which
    // `linearise::subdivide` linearises first), and sweeps with it held. The continuation
    // from the singular end with its own rotate angle cannot leave the pole (every first
    // step turns the rotate axis by the whole difference), so it starts from the turned one.
    let singular = |cl: &CutterLocation| machine.is_singular(&cl.axis);
    if singular(cla) && !singular(clb) {
        let turned = machine.joints_for_angles(&cla.tip, tool_length, a.tilt, b.rotate);
        return sweeps(&turned);
    }
    if singular(clb) && !singular(cla) {
        // The sweep ends on the pole with some rotate angle; the turn to `b`'s is the pure
        // turn at the end.
        let ends = |e: Option<Joints>| {
            e.is_some_and(|e| {
                (e.tilt - b.tilt).abs() < 1e-6 && singular(&machine.forward(&e, tool_length))
            })
        };
        return ends(sweep_end(machine, tool_length, cla, a, clb))
            || ends(sweep_end_on_branch(machine, tool_length, cla, a, clb));
    }
    false
}

/// The posture at `clb` reached by continuing the exact inverse kinematics from `a` along the
/// intended sweep, each step choosing the posture nearest the previous one; `None` where the
/// branch ends. Steps are halved until each moves the rotary axes by at most
/// [`SWEEP_STEP_RAD`] (near the singular direction they become small in `s`, far from it they
/// grow back to 1/16 of the move); a jump that remains at a step of 1e-12 (the branch leaves
/// the limits, or flips) ends the branch.
fn sweep_end(
    machine: &Machine,
    tool_length: f64,
    cla: &CutterLocation,
    a: &Joints,
    clb: &CutterLocation,
) -> Option<Joints> {
    continue_sweep(machine, tool_length, cla, a, clb, false)
}

/// [`sweep_end`] keeping the sign of the tilt: each step takes the nearest posture on `a`'s
/// tilt branch. Where the sweep passes a few hundredths of a degree from the singular
/// direction, the nearest posture changes branch through the pole (the tilt changes sign,
/// the rotate axis stays) although the sweep does not pass through it; the posture on the
/// branch turns the rotate axis around the pole instead, the motion the intended sweep
/// makes. `None` where the branch ends (limits) or `a`'s tilt is zero.
fn sweep_end_on_branch(
    machine: &Machine,
    tool_length: f64,
    cla: &CutterLocation,
    a: &Joints,
    clb: &CutterLocation,
) -> Option<Joints> {
    if a.tilt == 0.0 {
        return None;
    }
    continue_sweep(machine, tool_length, cla, a, clb, true)
}

/// The continuation of [`sweep_end`] (`on_branch`: of [`sweep_end_on_branch`]).
fn continue_sweep(
    machine: &Machine,
    tool_length: f64,
    cla: &CutterLocation,
    a: &Joints,
    clb: &CutterLocation,
    on_branch: bool,
) -> Option<Joints> {
    let (mut s, mut h, mut cur) = (0.0f64, 1.0 / 16.0, *a);
    for _ in 0..SWEEP_MAX_STEPS {
        if s >= 1.0 {
            return Some(cur);
        }
        let t = (s + h).min(1.0);
        let cl = crate::linearise::interpolate_cl(cla, clb, t);
        let j = if on_branch {
            machine
                .nearest_candidate(&cl, tool_length, &cur, |tilt| {
                    (tilt < 0.0) == (a.tilt < 0.0) && tilt != 0.0
                })
                .ok()??
        } else {
            machine
                .inverse_best_effort(&cl, tool_length, Some(&cur))
                .ok()?
                .0
        };
        if cur.rotary_travel(&j) > SWEEP_STEP_RAD {
            if h <= 1e-12 {
                return None;
            }
            h *= 0.5;
            continue;
        }
        cur = j;
        s = t;
        h = (2.0 * h).min(1.0 / 16.0);
    }
    (s >= 1.0).then_some(cur)
}

/// Solution choice over a whole group by dynamic programming (Viterbi).
///
/// Every move has a few candidate postures ([`Machine::inverse_candidates`]: both tilt signs
/// and the 2π-equivalents within the limits, generated around the best posture of the move
/// before; the closest posture outside the limits when none is inside). A path through the
/// candidates costs, lexicographically, (1) its problems — postures outside the limits and
/// reconfiguration steps between consecutive moves (the first move, the group's rapid, may
/// reconfigure) — (2) its cutting moves that change branch through the pole
/// ([`changes_branch_through_pole`]) and, linearised, miss the linearisation tolerance (the
/// branch-keeping candidate turns the rotate axis around the pole instead, see
/// `keep_branch_near_pole`) — and (3) its rotary travel from `prev`. The cheapest path is
/// exact for this cost over the candidate sets: a forced tilt-sign flip in the middle of a cut
/// (e.g. a tilt limit met by one sign of the solution only) is avoided whenever one
/// configuration serves the whole group. Cost O(n·k²) for n moves and k ≤ 18 candidates per
/// move, plus one linearisation per candidate pair that changes branch through the pole.
fn solve_group_optimal(
    machine: &Machine,
    moves: &[Move],
    range: std::ops::Range<usize>,
    prev: &Joints,
    options: &PostOptions,
) -> Result<(Vec<Solved>, usize), PostError> {
    let tl = options.tool_length;
    let continuous = matches!(machine.axis(AxisId::Rotate).mode, RotaryMode::Continuous)
        || matches!(machine.axis(AxisId::Tilt).mode, RotaryMode::Continuous);
    // Per move: candidates (joints, violation, unwound) and per candidate the best
    // (problems, moves left outside the linearisation tolerance, travel) reaching it and its
    // predecessor.
    let mut layers: Vec<Vec<Reached>> = Vec::with_capacity(range.len());
    let mut reference = *prev;
    for index in range.clone() {
        let m = &moves[index];
        let mut cands: Vec<Solved> = machine
            .inverse_candidates(&m.cl, tl, &reference)
            .map_err(|source| PostError::Block { index, source })?
            .into_iter()
            .map(|j| (j, None, false))
            .collect();
        if cands.is_empty() {
            let (j, v) = machine
                .inverse_best_effort(&m.cl, tl, Some(&reference))
                .map_err(|source| PostError::Block { index, source })?;
            cands.push((j, v, false));
        }
        if options.unwind_on_rapid && continuous && m.kind == MoveKind::Rapid {
            for c in &mut cands {
                let mut j = c.0;
                if machine.unwind(&mut j) {
                    c.0 = machine.joints_for_angles(&m.cl.tip, tl, j.tilt, j.rotate);
                    c.2 = true;
                }
            }
        }
        let layer: Vec<Reached> = match layers.last() {
            None => cands
                .into_iter()
                .map(|c| {
                    let p = usize::from(c.1.is_some());
                    let t = prev.rotary_travel(&c.0);
                    (c, p, 0, t, usize::MAX)
                })
                .collect(),
            Some(before) => {
                // where each predecessor's branch arrives (computed once, only when needed)
                let mut ends: Vec<Option<Option<Joints>>> = vec![None; before.len()];
                let mut branch_ends: Vec<Option<Option<Joints>>> = vec![None; before.len()];
                let mut reconf = |k: usize, b: &Joints, c: &Joints| {
                    let cla = &moves[index - 1].cl;
                    large_rotary_step(b, c)
                        && !ends[k]
                            .get_or_insert_with(|| sweep_end(machine, tl, cla, b, &m.cl))
                            .is_some_and(|e| e.rotary_travel(c) < 1e-6)
                        && !branch_ends[k]
                            .get_or_insert_with(|| sweep_end_on_branch(machine, tl, cla, b, &m.cl))
                            .is_some_and(|e| e.rotary_travel(c) < 1e-6)
                };
                // A cutting move whose sweep passes near the singular direction: which
                // predecessor–candidate pairs linearise within the tolerance (the branch
                // through the pole swings the flutes off the sweep, see
                // `keep_branch_near_pole`).
                let cla = &moves[index - 1].cl;
                let tol = options.linearisation_tol.unwrap_or(f64::INFINITY);
                let misses = |b: &Joints, c: &Joints| {
                    m.kind != MoveKind::Rapid
                        && changes_branch_through_pole(options, cla, b, &m.cl, c)
                        && linearised_deviation(machine, options, cla, b, &m.cl, c) > tol
                };
                cands
                    .into_iter()
                    .map(|c| {
                        let mut best = (usize::MAX, usize::MAX, f64::INFINITY, 0usize);
                        for (k, (b, p, l, t, _)) in before.iter().enumerate() {
                            // A reconfiguration only adds a problem: a pair already worse
                            // without it needs no sweep continuation.
                            let p = p + usize::from(c.1.is_some());
                            if p > best.0 || (p == best.0 && *l > best.1) {
                                continue;
                            }
                            let p = p + usize::from(reconf(k, &b.0, &c.0));
                            let t = t + b.0.rotary_travel(&c.0);
                            if p > best.0 || (p == best.0 && *l > best.1) {
                                continue;
                            }
                            let l = l + usize::from(misses(&b.0, &c.0));
                            if (p, l) < (best.0, best.1)
                                || ((p, l) == (best.0, best.1) && t < best.2)
                            {
                                best = (p, l, t, k);
                            }
                        }
                        (c, best.0, best.1, best.2, best.3)
                    })
                    .collect()
            }
        };
        if let Some(b) = layer
            .iter()
            .min_by(|a, b| (a.1, a.2).cmp(&(b.1, b.2)).then(a.3.total_cmp(&b.3)))
        {
            reference = b.0 .0;
        }
        layers.push(layer);
    }
    let Some(last) = layers.last() else {
        return Ok((Vec::new(), 0));
    };
    let Some((mut at, problems)) = last
        .iter()
        .enumerate()
        .min_by(|(_, a), (_, b)| (a.1, a.2).cmp(&(b.1, b.2)).then(a.3.total_cmp(&b.3)))
        .map(|(k, c)| (k, c.1))
    else {
        return Ok((Vec::new(), 0));
    };
    let mut out: Vec<Solved> = Vec::with_capacity(layers.len());
    for layer in layers.iter().rev() {
        let (c, _, _, _, from) = &layer[at];
        out.push(c.clone());
        at = *from;
    }
    out.reverse();
    Ok((out, problems))
}
