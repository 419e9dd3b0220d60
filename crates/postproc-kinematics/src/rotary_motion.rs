//! Rotary-axis motion of a posted path as the machine sees it: where the rotary axes change
//! direction (split into reversals *inside a cut*, which paper 004 removes because the feed
//! drive stops there and leaves a mark, and reversals *at path ends and links*, the turn of a
//! zig-zag or a retract, which are harmless), the largest angular step between blocks, and
//! the largest angular acceleration at the programmed feed against the machine's limits.
//!
//! **Reversals.** Along each axis the non-negligible steps (above
//! [`REVERSE_DEAD_BAND_RAD`]) are followed over the whole block list; a reversal is a step `k`
//! whose sign differs from that of the previous non-negligible step `p`
//! ([`crate::reverse_motion::count_reverse_motions`] counts the same places per cutting run).
//! It lies *inside a cut* when the moves into every block from `p` to `k` are feed moves
//! ([`MoveKind::Feed`]) and the tool tip keeps its direction of travel over them: no two
//! consecutive tip displacements (longer than [`TIP_STILL_MM`]) of those moves turn by more
//! than [`PATH_CORNER_RAD`]. Otherwise it lies *at a path end or link*: a rapid, plunge,
//! retract or link at feed ([`MoveKind::Link`], which the planner puts between two cutting
//! runs it joins without leaving the material) takes part, or the tip path turns a corner
//! (the end of a zig-zag line and the feed step to the next line, in a path whose planner
//! did not mark its links, such as imported CL data). The *step* of a
//! reversal is `|Δ|` of its reversing step `k`. A reversal of the rotate axis inside a cut
//! lies *near the pole* when the tool axis comes within [`POLE_TILT_RAD`] of the rotate
//! axis (the workpiece's ±Z) over the motion of its two steps, blocks `p − 1..=k` (the
//! first step starts at `p − 1`: a C that swings through the pole and then stands still
//! reverses after the pole, at blocks clear of it). There the rotate axis is all but
//! undetermined by the tool axis (a change `δ` of the axis turns it by up to `δ / sin(γ)`,
//! `γ` the angle between the tool axis and C, so a wiggle of the planned axis within its
//! accuracy turns it by degrees), and where the path crosses the pole the rotate axis must
//! swing whatever the plan.
//!
//! **Steps and accelerations.** Over consecutive non-rapid blocks `i − 1 → i` the time of a
//! block is `Δtᵢ = 1 / F⁻¹ᵢ` with `F⁻¹ᵢ` its inverse-time feed (1/min), which is the tip path
//! at the programmed feed with the rotary travel the post folds into it; the angular speed
//! `ωᵢ = Δθᵢ / Δtᵢ` and the acceleration at block `i` is
//! `αᵢ = (ωᵢ₊₁ − ωᵢ) / ((Δtᵢ + Δtᵢ₊₁)/2)`, the central difference of the commanded speed
//! (what the machine must deliver to follow the program without slowing down; a machine
//! whose limit is lower slows the feed there). Blocks shorter than [`MIN_BLOCK_S`] are
//! merged into the next for this estimate (an inserted linearisation point does not make a
//! second derivative out of rounding).
//!
//! Cost O(n) per path.

use crate::joints::AxisId;
use crate::machine::Machine;
use crate::post::PostedBlock;
use crate::reverse_motion::REVERSE_DEAD_BAND_RAD;
use cam_core::MoveKind;
use serde::{Deserialize, Serialize};

/// A turn of the tip's direction of travel (rad) above which a reversal counts as at a path
/// corner (the end of a zig-zag line) rather than inside a cut: 45°, far above the few degrees
/// consecutive moves of a cutting pass turn by, far below the ~90°–180° of a line end.
pub const PATH_CORNER_RAD: f64 = std::f64::consts::FRAC_PI_4;

/// Tip displacements shorter than this (mm) carry no direction of travel.
pub const TIP_STILL_MM: f64 = 1e-6;

/// Angle (rad) between the tool axis and the rotate axis within which a reversal of the
/// rotate axis counts as near the pole: 1° (the name keeps the table-table reading, where
/// that angle is the tilt).
pub const POLE_TILT_RAD: f64 = 0.017_453_292_519_943_295;

/// Shortest block time (s) used for the acceleration estimate: shorter blocks are merged
/// with the next.
pub const MIN_BLOCK_S: f64 = 1e-4;

/// Reversals of one rotary axis, split by where they lie.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct AxisReversals {
    /// Reversals inside a cut.
    pub cutting: usize,
    /// Reversals at path ends and links.
    pub links: usize,
    /// Smallest reversing step of the reversals inside a cut (rad; 0 when there is none).
    pub cutting_step_min: f64,
    /// Largest reversing step of the reversals inside a cut (rad).
    pub cutting_step_max: f64,
    /// Of the reversals inside a cut, those of the rotate axis near the pole (module docs).
    #[serde(default)]
    pub cutting_near_pole: usize,
}

/// Reversals of both rotary axes.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct ReversalSplit {
    /// The tilting axis.
    pub tilt: AxisReversals,
    /// C.
    pub rotate: AxisReversals,
}

impl ReversalSplit {
    /// Reversals inside cuts, both axes.
    pub fn cutting(&self) -> usize {
        self.tilt.cutting + self.rotate.cutting
    }
    /// Reversals at path ends and links, both axes.
    pub fn links(&self) -> usize {
        self.tilt.links + self.rotate.links
    }
    /// Smallest and largest reversing step inside cuts over both axes (rad; zeros when none).
    pub fn cutting_steps(&self) -> (f64, f64) {
        let axes = [self.tilt, self.rotate];
        let with: Vec<&AxisReversals> = axes.iter().filter(|a| a.cutting > 0).collect();
        if with.is_empty() {
            return (0.0, 0.0);
        }
        (
            with.iter()
                .map(|a| a.cutting_step_min)
                .fold(f64::INFINITY, f64::min),
            with.iter().map(|a| a.cutting_step_max).fold(0.0, f64::max),
        )
    }
}

/// Whether the tip keeps its direction of travel over the moves into blocks `from..=to`
/// (module docs).
fn tip_keeps_direction(blocks: &[PostedBlock], from: usize, to: usize) -> bool {
    let mut last: Option<cam_core::Vector3> = None;
    for i in from.max(1)..=to {
        let d = blocks[i].cl.tip - blocks[i - 1].cl.tip;
        let n = d.norm();
        if n <= TIP_STILL_MM {
            continue;
        }
        let d = d / n;
        if let Some(l) = last {
            if l.dot(&d).clamp(-1.0, 1.0).acos() > PATH_CORNER_RAD {
                return false;
            }
        }
        last = Some(d);
    }
    true
}

/// Whether the block's tool axis lies within [`POLE_TILT_RAD`] of the rotate axis (module
/// docs). Every kinematic chain of [`crate::Machine`] turns C about the workpiece frame's Z
/// (a table C under the part, or a head C about the machine's Z), so that is the workpiece
/// axis ±Z, whatever tilt angle reaches it (0 on a table-table machine, ±90° on a
/// horizontal-spindle turn-mill head).
fn near_pole(b: &PostedBlock) -> bool {
    b.cl.axis.z.abs() >= POLE_TILT_RAD.cos()
}

/// The reversals of one axis over a block list (module docs).
pub fn axis_reversals(blocks: &[PostedBlock], axis: AxisId) -> AxisReversals {
    let mut out = AxisReversals {
        cutting_step_min: f64::INFINITY,
        ..AxisReversals::default()
    };
    // (index of the last non-negligible step, its sign)
    let mut last: Option<(usize, f64)> = None;
    for k in 1..blocks.len() {
        if blocks[k].kind == MoveKind::Rapid {
            // A rapid positions the tool: the direction starts afresh after it.
            last = None;
            continue;
        }
        let d = blocks[k].joints.get(axis) - blocks[k - 1].joints.get(axis);
        if d.abs() <= REVERSE_DEAD_BAND_RAD {
            continue;
        }
        let s = d.signum();
        if let Some((p, sp)) = last {
            if s != sp {
                let all_feed = blocks[p..=k].iter().all(|b| b.kind == MoveKind::Feed);
                if all_feed && tip_keeps_direction(blocks, p, k) {
                    out.cutting += 1;
                    if axis == AxisId::Rotate
                        && blocks[p.saturating_sub(1)..=k].iter().any(near_pole)
                    {
                        out.cutting_near_pole += 1;
                    }
                    out.cutting_step_min = out.cutting_step_min.min(d.abs());
                    out.cutting_step_max = out.cutting_step_max.max(d.abs());
                } else {
                    out.links += 1;
                }
            }
        }
        last = Some((k, s));
    }
    if out.cutting == 0 {
        out.cutting_step_min = 0.0;
    }
    out
}

/// The reversals of both rotary axes (module docs).
pub fn reversal_split(blocks: &[PostedBlock]) -> ReversalSplit {
    ReversalSplit {
        tilt: axis_reversals(blocks, AxisId::Tilt),
        rotate: axis_reversals(blocks, AxisId::Rotate),
    }
}

/// Largest angular step and angular acceleration of the rotary axes along the cutting
/// blocks of a path (module docs), with the machine's limits.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct RotarySmoothness {
    /// Largest step of either rotary axis between consecutive non-rapid blocks (rad).
    pub max_step: f64,
    /// Largest angular acceleration at the programmed feed, tilting axis (rad/s²).
    pub max_acceleration_tilt: f64,
    /// The same for C (rad/s²).
    pub max_acceleration_rotate: f64,
    /// The machine's acceleration limit of the tilting axis (rad/s²), when its file gives it.
    pub limit_tilt: Option<f64>,
    /// The same for C.
    pub limit_rotate: Option<f64>,
    /// Blocks at which the acceleration at programmed feed exceeds the machine's limit of an
    /// axis (the machine slows the feed there).
    pub blocks_over_limit: usize,
}

/// [`RotarySmoothness`] of posted blocks (feeds set).
pub fn rotary_smoothness(machine: &Machine, blocks: &[PostedBlock]) -> RotarySmoothness {
    let mut out = RotarySmoothness {
        limit_tilt: machine.axis(AxisId::Tilt).max_acceleration,
        limit_rotate: machine.axis(AxisId::Rotate).max_acceleration,
        ..RotarySmoothness::default()
    };
    // Merged steps of the current cutting stretch: (Δtilt, ΔC, Δt s).
    let mut steps: Vec<(f64, f64, f64)> = Vec::new();
    let mut pending = (0.0, 0.0, 0.0);
    let flush = |steps: &mut Vec<(f64, f64, f64)>, out: &mut RotarySmoothness| {
        for w in steps.windows(2) {
            let (a, b) = (w[0], w[1]);
            let dt = 0.5 * (a.2 + b.2);
            let acc_t = (b.0 / b.2 - a.0 / a.2).abs() / dt;
            let acc_c = (b.1 / b.2 - a.1 / a.2).abs() / dt;
            out.max_acceleration_tilt = out.max_acceleration_tilt.max(acc_t);
            out.max_acceleration_rotate = out.max_acceleration_rotate.max(acc_c);
            let over = |acc: f64, lim: Option<f64>| lim.is_some_and(|l| acc > l);
            if over(acc_t, out.limit_tilt) || over(acc_c, out.limit_rotate) {
                out.blocks_over_limit += 1;
            }
        }
        steps.clear();
    };
    for k in 1..blocks.len() {
        let b = &blocks[k];
        let dt = b
            .inverse_time_feed
            .filter(|f| b.kind != MoveKind::Rapid && f.is_finite() && *f > 0.0)
            .map(|f| 60.0 / f);
        let Some(dt) = dt else {
            flush(&mut steps, &mut out);
            pending = (0.0, 0.0, 0.0);
            continue;
        };
        let dtilt = b.joints.tilt - blocks[k - 1].joints.tilt;
        let drot = b.joints.rotate - blocks[k - 1].joints.rotate;
        out.max_step = out.max_step.max(dtilt.abs()).max(drot.abs());
        pending = (pending.0 + dtilt, pending.1 + drot, pending.2 + dt);
        if pending.2 >= MIN_BLOCK_S {
            steps.push(pending);
            pending = (0.0, 0.0, 0.0);
        }
    }
    flush(&mut steps, &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::joints::Joints;
    use cam_core::{CutterLocation, Point3, Vector3};

    /// The tool axis of a table-table machine at tilt `t`, C `c`: `t` from +Z.
    fn axis_at(t: f64, c: f64) -> Vector3 {
        Vector3::new(t.sin() * c.cos(), t.sin() * c.sin(), t.cos())
    }

    fn block(x: f64, y: f64, c: f64, kind: MoveKind) -> PostedBlock {
        PostedBlock {
            joints: Joints {
                x,
                y,
                z: 0.0,
                tilt: 0.3,
                rotate: c,
            },
            cl: CutterLocation::new(Point3::new(x, y, 0.0), axis_at(0.3, c)).unwrap(),
            kind,
            feed_mm_per_min: Some(600.0),
            inverse_time_feed: Some(600.0),
            source_index: 0,
            inserted: false,
            unwound: false,
            linearisation_error_mm: 0.0,
            limit_violation: None,
        }
    }

    /// A zig-zag of two lines: C rises along the first, falls along the second (one reversal
    /// at the line end, a link) and chatters once inside the second (a cutting reversal of
    /// step 0.01 rad followed by its return).
    #[test]
    fn zigzag_end_is_a_link_chatter_is_a_cut() {
        let mut b = vec![block(0.0, 0.0, 0.0, MoveKind::Rapid)];
        for i in 1..=5 {
            b.push(block(i as f64, 0.0, 0.02 * i as f64, MoveKind::Feed));
        }
        // the step to the next line and the way back
        b.push(block(5.0, 1.0, 0.09, MoveKind::Feed));
        let cs = [0.08, 0.07, 0.08, 0.06, 0.05];
        for (i, c) in cs.iter().enumerate() {
            b.push(block(4.0 - i as f64, 1.0, *c, MoveKind::Feed));
        }
        let r = axis_reversals(&b, AxisId::Rotate);
        assert_eq!(r.links, 1, "{r:?}");
        assert_eq!(r.cutting, 2, "{r:?}");
        assert!((r.cutting_step_min - 0.01).abs() < 1e-12);
        assert!((r.cutting_step_max - 0.02).abs() < 1e-12);
        assert_eq!(axis_reversals(&b, AxisId::Tilt), AxisReversals::default());
        // The split adds up to the post's count over cutting runs.
        let split = reversal_split(&b);
        assert_eq!(
            split.cutting() + split.links(),
            crate::reverse_motion::count_path_reverse_motions(&b)
        );
    }

    /// The same chatter with the tilt passing within 1° of the pole counts as near the pole;
    /// 2° away it does not.
    #[test]
    fn chatter_at_the_pole_is_near_the_pole() {
        let line = |tilt_mid: f64| {
            let cs = [0.0, 0.02, 0.04, 0.03, 0.05, 0.07];
            let tilts = [0.3, 0.2, tilt_mid, tilt_mid, 0.2, 0.3];
            let mut b: Vec<PostedBlock> = cs
                .iter()
                .enumerate()
                .map(|(i, c)| block(i as f64, 0.0, *c, MoveKind::Feed))
                .collect();
            for (blk, t) in b.iter_mut().zip(tilts) {
                blk.joints.tilt = t;
                blk.cl = CutterLocation::new(blk.cl.tip, axis_at(t, blk.joints.rotate)).unwrap();
            }
            axis_reversals(&b, AxisId::Rotate)
        };
        let near = line(0.5f64.to_radians());
        assert_eq!((near.cutting, near.cutting_near_pole), (2, 2), "{near:?}");
        let away = line(2f64.to_radians());
        assert_eq!((away.cutting, away.cutting_near_pole), (2, 0), "{away:?}");
    }

    /// C swings through the pole, stands still, then turns back a little once the axis is
    /// clear of the pole: the reversal's first step starts at the pole, so it lies near the
    /// pole though every block from that step's end on is clear of it (hub finishing on the
    /// turn-mill: the one reversal the planner's count did not cover).
    #[test]
    fn a_swing_through_the_pole_counts_at_the_pole() {
        let tilts = [0.3, 0.1, 0.005, 0.1, 0.2, 0.3, 0.4];
        let cs = [0.0, 0.01, 0.02, 3.0, 3.0, 3.0, 2.99];
        let b: Vec<PostedBlock> = cs
            .iter()
            .zip(tilts)
            .enumerate()
            .map(|(i, (c, t))| {
                let mut blk = block(i as f64, 0.0, *c, MoveKind::Feed);
                blk.joints.tilt = t;
                blk.cl = CutterLocation::new(blk.cl.tip, axis_at(t, *c)).unwrap();
                blk
            })
            .collect();
        let r = axis_reversals(&b, AxisId::Rotate);
        assert_eq!((r.cutting, r.cutting_near_pole), (1, 1), "{r:?}");
    }

    /// On a horizontal-spindle turn-mill head the pole lies at a tilt of 90°: the tool axis
    /// along the workpiece's Z decides, not the tilt angle.
    #[test]
    fn the_pole_is_where_the_tool_axis_meets_the_rotate_axis() {
        let cs = [0.0, 0.02, 0.04, 0.03, 0.05, 0.07];
        let line = |off_pole_deg: f64| {
            let b: Vec<PostedBlock> = cs
                .iter()
                .enumerate()
                .map(|(i, c)| {
                    let mut blk = block(i as f64, 0.0, *c, MoveKind::Feed);
                    let t = if (2..4).contains(&i) {
                        off_pole_deg.to_radians()
                    } else {
                        0.3
                    };
                    // u = Rz(−C)·Ry(B)·x̂ with B = 90° − t: the axis t from +Z.
                    blk.joints.tilt = std::f64::consts::FRAC_PI_2 - t;
                    blk.cl = CutterLocation::new(blk.cl.tip, axis_at(t, -c)).unwrap();
                    blk
                })
                .collect();
            axis_reversals(&b, AxisId::Rotate)
        };
        let near = line(0.5);
        assert_eq!((near.cutting, near.cutting_near_pole), (2, 2), "{near:?}");
        let away = line(2.0);
        assert_eq!((away.cutting, away.cutting_near_pole), (2, 0), "{away:?}");
    }

    /// A link at feed between two cutting runs makes a reversal across it a link, even where
    /// the tip keeps its direction (two pieces of a roughing level joined end to end); the same
    /// moves as plain feed moves make it a reversal inside a cut.
    #[test]
    fn reversal_across_a_link_at_feed_is_a_link() {
        let path = |join: MoveKind| {
            vec![
                block(0.0, 0.0, 0.0, MoveKind::Feed),
                block(1.0, 0.0, 0.1, MoveKind::Feed),
                block(2.0, 0.0, 0.05, join),
                block(3.0, 0.0, 0.0, MoveKind::Feed),
            ]
        };
        let r = axis_reversals(&path(MoveKind::Link), AxisId::Rotate);
        assert_eq!((r.cutting, r.links), (0, 1), "{r:?}");
        let r = axis_reversals(&path(MoveKind::Feed), AxisId::Rotate);
        assert_eq!((r.cutting, r.links), (1, 0), "{r:?}");
    }

    /// A retract between two cuts makes the reversal a link.
    #[test]
    fn reversal_across_a_retract_is_a_link() {
        let b = vec![
            block(0.0, 0.0, 0.0, MoveKind::Feed),
            block(1.0, 0.0, 0.1, MoveKind::Feed),
            block(2.0, 0.0, 0.05, MoveKind::Retract),
            block(3.0, 0.0, 0.0, MoveKind::Feed),
        ];
        let r = axis_reversals(&b, AxisId::Rotate);
        assert_eq!((r.cutting, r.links), (0, 1));
    }

    /// C turning at constant speed has no acceleration; one step of twice the speed in the
    /// middle gives ±Δω/Δt at its ends.
    #[test]
    fn acceleration_at_programmed_feed() {
        // 600/min inverse time: 0.1 s per block.
        let mut b: Vec<PostedBlock> = (0..6)
            .map(|i| block(i as f64, 0.0, 0.01 * i as f64, MoveKind::Feed))
            .collect();
        let m = crate::Machine::from_toml_str(
            "name = \"t\"\n[kinematics]\ntype = \"table-table\"\ntilt_axis = \"A\"\n[axes.X]\nmin = -500.0\nmax = 500.0\n[axes.Y]\nmin = -500.0\nmax = 500.0\n[axes.Z]\nmin = -500.0\nmax = 500.0\n[axes.A]\nmin = -120.0\nmax = 120.0\nmax_acceleration = 300.0\n[axes.C]\nmode = \"continuous\"\n",
            "t.toml",
        )
        .unwrap();
        let s = rotary_smoothness(&m, &b);
        assert!(s.max_acceleration_rotate < 1e-9, "{s:?}");
        assert!((s.max_step - 0.01).abs() < 1e-12);
        for (i, x) in b.iter_mut().enumerate().skip(3) {
            x.joints.rotate = 0.01 * i as f64 + 0.01;
        }
        let s = rotary_smoothness(&m, &b);
        // ω: 0.1 rad/s → 0.2 rad/s over 0.1 s: 1 rad/s².
        assert!((s.max_acceleration_rotate - 1.0).abs() < 1e-9, "{s:?}");
        assert!((s.limit_tilt.unwrap() - 300f64.to_radians()).abs() < 1e-9);
        assert_eq!(s.limit_rotate, None);
    }
}
