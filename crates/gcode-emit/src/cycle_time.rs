//! How long an assembled program runs on the machine, per operation and in all: cutting,
//! links (moves between cuts at feed), rapids and tool changes.
//!
//! The program's motion is replayed in joint space as the dialects write it (see each
//! dialect's module docs): per operation a retract of Z to the machine's safe height
//! (`G53 G0 Z<safe>` and its equivalents), the tool change when the tool changes (the
//! machine's `tool_change_s`), the rotary axes pre-positioned alone, in joint output the X Y
//! rapid to the first block, then the posted blocks (approach, the path with its
//! linearisation blocks, retract); after the last operation the final retract. The machine
//! starts at its home position. Each block's time comes from
//! [`postproc_kinematics::MotionTimer`] (trapezoidal per axis, the slowest axis sets the
//! block, parabolic blending or exact stop as the machine file says); a feed block's
//! programmed duration is its inverse-time value `1/F` (which already respects the axis
//! speeds). The spindle, coolant and tool blocks of each operation stop the motion. A 3+2
//! operation's joints are recomputed from its plane's rotary angles and tips.
//!
//! Attribution: a block's time is how much it extends the program (its duration less its
//! overlap with the block before), so the parts sum to the total exactly. Kinds: feed and
//! plunge moves cut; retracts at feed are links; rapids (the program frame's moves included)
//! are rapids. Lengths are tool-tip chords (workpiece frame; the frame's moves through the
//! forward kinematics). O(blocks), no allocation per block.

use crate::assemble::{AssembleOptions, AssembledProgram};
use crate::program::{Feed, Motion, OutputMode};
use crate::{ClOperation, GcodeError};
use cam_core::{MoveKind, Point3};
use postproc_kinematics::{Blending, Joints, Machine, MotionTimer};
use serde::Serialize;

/// Time and travel of one operation (s, mm).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct OperationTime {
    /// Operation name.
    pub name: String,
    /// Tool number.
    pub tool_number: u32,
    /// Time of the cutting moves (feed and plunge).
    pub cutting_s: f64,
    /// Time of the links at feed (retracts between cuts).
    pub link_s: f64,
    /// Time of the rapids (the program frame's included).
    pub rapid_s: f64,
    /// Tool change time before the operation (0 when the tool stays).
    pub tool_change_s: f64,
    /// Everything: cutting + links + rapids + tool change.
    pub total_s: f64,
    /// Tool-tip travel of the cutting moves.
    pub cutting_length_mm: f64,
    /// Tool-tip travel between cuts: links at feed and rapids.
    pub link_length_mm: f64,
    /// Tool-tip travel of the rapids.
    pub rapid_length_mm: f64,
}

impl OperationTime {
    /// Time in the air: links at feed and rapids (s).
    pub fn air_s(&self) -> f64 {
        self.link_s + self.rapid_s
    }
}

/// Time of a whole program.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct ProgramTime {
    /// Per operation, in program order.
    pub operations: Vec<OperationTime>,
    /// Sum of the operations' cutting times (s).
    pub cutting_s: f64,
    /// Sum of the links at feed (s).
    pub link_s: f64,
    /// Sum of the rapids (s).
    pub rapid_s: f64,
    /// Sum of the tool changes (s).
    pub tool_change_s: f64,
    /// The program's running time (s).
    pub total_s: f64,
    /// The tool change time used per change (s).
    pub tool_change_each_s: f64,
    /// Whether blocks blend (parabolic) or stop (exact stop).
    pub blending: &'static str,
    /// Axes whose acceleration the machine file does not give (accelerating instantly).
    pub unlimited_acceleration: Vec<char>,
}

/// What a block is for the attribution.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Part {
    Cutting,
    Link,
    Rapid,
}

/// A block to replay: joints, tool tip, programmed duration (s; `None` for rapids), part.
type Block = (Joints, Point3, Option<f64>, Part);

fn part(kind: MoveKind) -> Part {
    match kind {
        // A link at feed runs in the material at the cutting feed, as the cut it joins.
        MoveKind::Feed | MoveKind::Link | MoveKind::Plunge => Part::Cutting,
        MoveKind::Retract => Part::Link,
        MoveKind::Rapid => Part::Rapid,
    }
}

/// Replays one operation's blocks and adds them to `t`.
struct Replay<'a> {
    machine: &'a Machine,
    timer: MotionTimer,
    at: Joints,
    tip: Point3,
    tool_length: f64,
}

impl Replay<'_> {
    fn go(
        &mut self,
        to: Joints,
        tip: Option<Point3>,
        programmed_s: Option<f64>,
        what: Part,
        t: &mut OperationTime,
    ) {
        let dt = self.timer.block(&self.at, &to, programmed_s);
        let tip = tip.unwrap_or_else(|| self.machine.forward(&to, self.tool_length).tip);
        let len = (tip - self.tip).norm();
        match what {
            Part::Cutting => {
                t.cutting_s += dt;
                t.cutting_length_mm += len;
            }
            Part::Link => {
                t.link_s += dt;
                t.link_length_mm += len;
            }
            Part::Rapid => {
                t.rapid_s += dt;
                t.rapid_length_mm += len;
                t.link_length_mm += len;
            }
        }
        self.at = to;
        self.tip = tip;
    }
}

/// The running time of `program` (assembled from `operations` with `options`) on
/// `machine`, retracting to machine Z `safe_z_machine` (see the module docs).
///
/// Errors: an axis of the machine without `max_speed`; a 3+2 operation whose plane has no
/// rotary angles.
pub fn program_time(
    machine: &Machine,
    program: &AssembledProgram,
    operations: &[ClOperation],
    options: &AssembleOptions,
    safe_z_machine: f64,
) -> Result<ProgramTime, GcodeError> {
    let timer = MotionTimer::new(machine).map_err(|e| GcodeError::InvalidOption {
        field: "machine",
        reason: e.to_string(),
    })?;
    let home = machine.home();
    let mut r = Replay {
        machine,
        timer,
        at: home,
        tip: machine.forward(&home, options.post.tool_length).tip,
        tool_length: options.post.tool_length,
    };
    let change = machine.tool_change_s().unwrap_or(0.0);
    let mut out = ProgramTime {
        tool_change_each_s: change,
        blending: match machine.blending() {
            Blending::Parabolic => "parabolic",
            Blending::ExactStop => "exact_stop",
        },
        unlimited_acceleration: MotionTimer::unlimited_acceleration(machine),
        ..ProgramTime::default()
    };
    let mut tool: Option<u32> = None;
    for (i, (nc, cl)) in program
        .program
        .operations
        .iter()
        .zip(operations)
        .enumerate()
    {
        let mut t = OperationTime {
            name: nc.name.clone(),
            tool_number: nc.tool.number,
            ..OperationTime::default()
        };
        r.tool_length = cl.tool_length_mm.unwrap_or(options.post.tool_length);
        // The blocks: (joints, tip, programmed duration, part).
        let blocks: Vec<Block> = match program.operations.iter().find(|p| p.index == i) {
            Some(p) => p
                .blocks
                .iter()
                .map(|b| {
                    let programmed = match b.kind {
                        MoveKind::Rapid => None,
                        _ => b.inverse_time_feed.map(|f| 60.0 / f),
                    };
                    (b.joints, b.cl.tip, programmed, part(b.kind))
                })
                .collect(),
            None => indexed_blocks(machine, nc, cl, &r)?,
        };
        // Retract to the safe height, tool change, spindle and coolant (the motion stops).
        let mut up = r.at;
        up.z = safe_z_machine;
        r.go(up, None, None, Part::Rapid, &mut t);
        if tool != Some(nc.tool.number) {
            t.tool_change_s = r.timer.dwell(change);
            tool = Some(nc.tool.number);
        } else {
            r.timer.stop();
        }
        if let Some(&(first, ..)) = blocks.first() {
            let mut pre = r.at;
            pre.tilt = first.tilt;
            pre.rotate = first.rotate;
            r.go(pre, None, None, Part::Rapid, &mut t);
            if options.mode == OutputMode::Joint || matches!(nc.motion, Motion::Indexed { .. }) {
                pre.x = first.x;
                pre.y = first.y;
                r.go(pre, None, None, Part::Rapid, &mut t);
            }
        }
        for (j, tip, programmed, what) in blocks {
            r.go(j, Some(tip), programmed, what, &mut t);
        }
        r.timer.stop();
        out.operations.push(t);
    }
    if let Some(last) = out.operations.last_mut() {
        let mut up = r.at;
        up.z = safe_z_machine;
        r.go(up, None, None, Part::Rapid, last);
        r.timer.stop();
    }
    for t in &mut out.operations {
        t.total_s = t.cutting_s + t.link_s + t.rapid_s + t.tool_change_s;
        out.cutting_s += t.cutting_s;
        out.link_s += t.link_s;
        out.rapid_s += t.rapid_s;
        out.tool_change_s += t.tool_change_s;
    }
    out.total_s = r.timer.elapsed_s();
    Ok(out)
}

/// The blocks of a 3+2 operation: the joints of each tip at the plane's rotary angles, the
/// kinds of the framed source moves (approach, path, retract), mm/min feeds as durations.
fn indexed_blocks(
    machine: &Machine,
    nc: &crate::NcOperation,
    cl: &ClOperation,
    r: &Replay<'_>,
) -> Result<Vec<Block>, GcodeError> {
    let Motion::Indexed { rotary, tips, .. } = &nc.motion else {
        return Ok(Vec::new());
    };
    let (Some(tilt), Some(rotate)) = (rotary.first(), rotary.get(1)) else {
        return Err(GcodeError::InvalidOption {
            field: "rotary",
            reason: format!("3+2 operation `{}` has no plane angles", nc.name),
        });
    };
    let (tilt, rotate) = (tilt.deg.to_radians(), rotate.deg.to_radians());
    let kinds = std::iter::once(MoveKind::Rapid)
        .chain(cl.path.moves.iter().map(|m| m.kind))
        .chain(std::iter::once(MoveKind::Rapid));
    let mut prev = r.tip;
    let mut out = Vec::with_capacity(tips.len());
    for ((p, feed), kind) in tips.iter().zip(kinds) {
        let j = machine.joints_for_angles(p, r.tool_length, tilt, rotate);
        let programmed = match feed {
            Feed::PerMinute(f) if *f > 0.0 => Some(60.0 * (p - prev).norm() / f),
            Feed::InverseTime(f) if *f > 0.0 => Some(60.0 / f),
            _ => None,
        };
        let kind = if matches!(feed, Feed::Rapid) {
            MoveKind::Rapid
        } else {
            kind
        };
        out.push((j, *p, programmed, part(kind)));
        prev = *p;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::{assemble_program, LinuxCnc};
    use cam_core::{CutterLocation, Move, ToolPath};

    /// A table-table machine (A about X at the origin, so a vertical tool's joints are its
    /// tip) with the LinuxCNC xyzac-trt sample configuration's limits and a 5 s tool change.
    fn machine(blending: &str) -> Machine {
        Machine::from_toml_str(
            &format!(
                "name = \"t\"\nsafe_z = 100.0\ntool_change_s = 5.0\nblending = \"{blending}\"\n\
                 [kinematics]\ntype = \"table-table\"\ntilt_axis = \"A\"\n\
                 [axes.X]\nmin = -500.0\nmax = 500.0\nmax_speed = 1200.0\nmax_acceleration = 300.0\n\
                 [axes.Y]\nmin = -500.0\nmax = 500.0\nmax_speed = 1200.0\nmax_acceleration = 300.0\n\
                 [axes.Z]\nmin = -500.0\nmax = 500.0\nmax_speed = 1200.0\nmax_acceleration = 300.0\n\
                 [axes.A]\nmin = -120.0\nmax = 120.0\nmax_speed = 1800.0\nmax_acceleration = 300.0\n\
                 [axes.C]\nmode = \"continuous\"\nmax_speed = 1800.0\nmax_acceleration = 300.0\n"
            ),
            "t.toml",
        )
        .unwrap()
    }

    fn at(x: f64, y: f64, z: f64) -> CutterLocation {
        CutterLocation::vertical(Point3::new(x, y, z))
    }

    /// A square of side 40 mm at z = 0 cut at 600 mm/min with a vertical tool, reached by a
    /// rapid from above: every block's time is closed-form, and at exact stop the blocks
    /// add up: `T(d, v) = d/v + v/a` for each straight block (v the axis speed for rapids,
    /// the feed otherwise, a = 300 mm/s²), the tool change 5 s.
    #[test]
    fn a_hand_built_program_takes_its_closed_form_time() {
        let m = machine("exact_stop");
        let mut path = ToolPath::new("square", "T1");
        path.moves.push(Move::rapid(at(0.0, 0.0, 5.0)));
        let feed = |p: CutterLocation| Move {
            kind: MoveKind::Feed,
            cl: p,
            feed_mm_per_min: Some(600.0),
        };
        path.moves.push(feed(at(0.0, 0.0, 0.0)));
        path.moves.push(feed(at(40.0, 0.0, 0.0)));
        path.moves.push(feed(at(40.0, 40.0, 0.0)));
        path.moves.push(feed(at(0.0, 40.0, 0.0)));
        path.moves.push(feed(at(0.0, 0.0, 0.0)));
        let mut op = ClOperation::new(path);
        op.tool_number = Some(1);
        let options = AssembleOptions {
            retract_mm: 10.0,
            ..AssembleOptions::default()
        };
        let ops = [op];
        let a = assemble_program("sq", &ops, &m, &LinuxCnc::trivial(), &options).unwrap();
        let t = program_time(&m, &a, &ops, &options, 100.0).unwrap();
        let acc = 300.0;
        let tr = |d: f64, v: f64| {
            if d <= 0.0 {
                0.0
            } else if v * v / acc <= d {
                d / v + v / acc
            } else {
                2.0 * (d / acc).sqrt()
            }
        };
        let rapid = 20.0; // mm/s
        let f = 10.0; // 600 mm/min
                      // From home (0, 0, 0): Z up to 100, tool change, (no rotary or XY move), approach
                      // rapid down to the lifted point z = 15, rapid to z = 5, feed to z = 0, the square,
                      // retract rapid to z = 10, final retract to z = 100.
        let want_rapid = tr(100.0, rapid)
            + tr(85.0, rapid)
            + tr(10.0, rapid)
            + tr(10.0, rapid)
            + tr(90.0, rapid);
        let want_cut = tr(5.0, f) + 4.0 * tr(40.0, f);
        let want = want_rapid + want_cut + 5.0;
        assert!(
            (t.total_s - want).abs() <= 1e-9 * want,
            "{} vs {want}",
            t.total_s
        );
        let op = &t.operations[0];
        assert!((op.cutting_s - want_cut).abs() < 1e-9, "{op:?}");
        assert!((op.rapid_s - want_rapid).abs() < 1e-9, "{op:?}");
        assert_eq!(op.tool_change_s, 5.0);
        assert!((op.cutting_length_mm - 165.0).abs() < 1e-9);
        assert!((op.rapid_length_mm - 295.0).abs() < 1e-9, "{op:?}");
        assert!((op.total_s - t.total_s).abs() < 1e-9);
        // Blending never makes the program slower, and keeps the parts summing to the total.
        let m = machine("parabolic");
        let b = program_time(&m, &a, &ops, &options, 100.0).unwrap();
        assert!(b.total_s < t.total_s, "{} vs {}", b.total_s, t.total_s);
        let parts = b.cutting_s + b.link_s + b.rapid_s + b.tool_change_s;
        assert!((parts - b.total_s).abs() < 1e-9);
        // A second operation with the same tool changes no tool.
        let two = [ops[0].clone(), ops[0].clone()];
        let a = assemble_program("sq2", &two, &m, &LinuxCnc::trivial(), &options).unwrap();
        let t2 = program_time(&m, &a, &two, &options, 100.0).unwrap();
        assert_eq!(t2.tool_change_s, 5.0);
        assert_eq!(t2.operations[1].tool_change_s, 0.0);
    }
}
