//! Read-back of an emitted program: every motion block of a G-code program mapped through
//! the machine's forward kinematics with the controller's interpolation, into the cutter
//! locations a stock simulator sweeps.
//!
//! What the controller does between two blocks decides what is cut:
//! * joint output ([`ReadbackMode::Joint`], LinuxCNC identity kinematics, Fanuc/Sinumerik
//!   without TCP): every axis moves linearly from block to block, so the tool follows
//!   `FK(J₀ + s (J₁ − J₀))`, a curve in the workpiece frame;
//! * tool-tip output ([`ReadbackMode::TcpAngles`], LinuxCNC `xyzac-trt-kins` TCP, `TRAORI`,
//!   `G43.4`): X Y Z are the tool tip in the workpiece frame and move linearly, the rotary
//!   angles move linearly and set the tool axis `u(A(s), C(s))`.
//!
//! Every move is read — rapids, approach, retract, rotary pre-positioning and unwinding —
//! and each block is subdivided until the straight chords between consecutive cutter
//! locations follow the controller's path within [`ReadbackOptions::path_tol_mm`]: at the
//! midpoint of every chord the tip deviates at most that far, and the tool axis at most
//! `path_tol_mm / reach_mm` (so a point `reach_mm` up the tool deviates at most
//! `path_tol_mm` more). A simulator interpolating linearly (tool-centre-point, axis vector
//! normalised) between the returned locations then sweeps the controller's motion within
//! that tolerance. Subdivision: uniform, doubling the count until all midpoints pass, at
//! most [`MAX_SUBDIVISIONS`] per block. Cost O(blocks × subdivisions) forward kinematics.
//!
//! Nothing is guessed:
//! * a block moving an axis that has never been programmed is an error naming the line and
//!   the axis — except rapids before the first fully known position (the set-up moves from
//!   wherever the machine stood when the program started: tool change height, rotary
//!   pre-positioning); those are listed in [`Readback::unplaced_start_lines`], never placed
//!   at an invented zero;
//! * `G53` (machine coordinates) is placed only in joint output, where the work offset is
//!   the machine zero the joint values refer to (see the crate docs); in tool-tip output the
//!   workpiece offset is unknown to the program and a `G53` motion is an error.

use crate::gcode_read::{GcodeBlock, GcodeMotion};
use crate::GcodeError;
use cam_core::{CutterLocation, Move, MoveKind, ToolPath};
use postproc_kinematics::{AxisId, Joints, Machine};
use serde::{Deserialize, Serialize};

/// Largest number of chords a single block is cut into.
pub const MAX_SUBDIVISIONS: usize = 4096;

/// How the controller interpolates between blocks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ReadbackMode {
    /// Axis values are the machine joints, interpolated linearly.
    Joint,
    /// X Y Z are the tool tip in the workpiece frame; tip and angles interpolated linearly.
    TcpAngles,
}

/// Options of [`read_back`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReadbackOptions {
    /// Interpolation of the controller.
    pub mode: ReadbackMode,
    /// Tool length (gauge line to tip, mm) for the forward kinematics of head machines.
    pub tool_length_mm: f64,
    /// Largest deviation of the chords from the controller's tip path (mm).
    pub path_tol_mm: f64,
    /// Distance up the tool over which the axis deviation counts (mm; the flute length of the
    /// cutter, or its whole stick-out to cover the shank and holder).
    pub reach_mm: f64,
}

impl Default for ReadbackOptions {
    fn default() -> Self {
        Self {
            mode: ReadbackMode::Joint,
            tool_length_mm: 0.0,
            path_tol_mm: 0.001,
            reach_mm: 50.0,
        }
    }
}

/// A program read back into cutter locations.
#[derive(Debug, Clone, PartialEq)]
pub struct Readback {
    /// One tool path with every placed move (subdivided), in program order.
    pub path: ToolPath,
    /// For each move of `path`, the 1-based program line of the block it belongs to.
    pub lines: Vec<usize>,
    /// Lines of the set-up rapids before the first fully known position (not placed).
    pub unplaced_start_lines: Vec<usize>,
    /// Blocks placed.
    pub blocks: usize,
}

impl Readback {
    /// The program line of move `index` of [`Readback::path`].
    pub fn line_of(&self, index: usize) -> Option<usize> {
        self.lines.get(index).copied()
    }
}

fn axis_name(machine: &Machine, a: AxisId) -> char {
    machine.letter(a)
}

/// Reads `blocks` (from [`crate::read_gcode`]) back into cutter locations (see module docs).
/// `file` names the program in errors. The path is named `name` and uses tool `tool`.
pub fn read_back(
    blocks: &[GcodeBlock],
    machine: &Machine,
    options: &ReadbackOptions,
    file: &str,
    name: &str,
    tool: &str,
) -> Result<Readback, GcodeError> {
    if !(options.path_tol_mm.is_finite() && options.path_tol_mm > 0.0) {
        return Err(GcodeError::InvalidOption {
            field: "path_tol_mm",
            reason: format!("{} must be finite and > 0", options.path_tol_mm),
        });
    }
    if !(options.reach_mm.is_finite() && options.reach_mm >= 0.0) {
        return Err(GcodeError::InvalidOption {
            field: "reach_mm",
            reason: format!("{} must be finite and >= 0", options.reach_mm),
        });
    }
    let err = |line: usize, word: String, reason: String| GcodeError::GcodeParse {
        file: file.to_string(),
        line,
        word,
        reason,
    };
    let letters: Vec<(AxisId, usize)> = AxisId::ALL
        .iter()
        .filter_map(|&a| "XYZABC".find(axis_name(machine, a)).map(|k| (a, k)))
        .collect();
    if letters.len() != 5 {
        return Err(err(
            0,
            String::new(),
            format!(
                "machine `{}` has axis letters outside XYZABC",
                machine.name()
            ),
        ));
    }
    let mut out = Readback {
        path: ToolPath::new(name, tool),
        lines: Vec::new(),
        unplaced_start_lines: Vec::new(),
        blocks: 0,
    };
    // Current joint-space values (mm, rad), known or not.
    let mut cur: [Option<f64>; 5] = [None; 5];
    let mut last: Option<Joints> = None;
    for b in blocks {
        let mut next = cur;
        let mut moved: Vec<AxisId> = Vec::new();
        for &(a, k) in &letters {
            let idx = a as usize;
            let v = b.axes[k].map(|x| if a.is_rotary() { x.to_radians() } else { x });
            if v != cur[idx] {
                if let Some(v) = v {
                    next[idx] = Some(v);
                    moved.push(a);
                }
            }
        }
        if b.machine_coordinates && options.mode == ReadbackMode::TcpAngles {
            return Err(err(
                b.line,
                "G53".into(),
                "a machine-coordinate move in a tool-tip program cannot be placed in the \
                 workpiece frame (the work offset is not in the program)"
                    .into(),
            ));
        }
        let all_known = next.iter().all(Option::is_some);
        if !all_known {
            if last.is_none() && b.motion == GcodeMotion::Rapid {
                out.unplaced_start_lines.push(b.line);
                cur = next;
                continue;
            }
            let missing: String = letters
                .iter()
                .filter(|(a, _)| next[*a as usize].is_none())
                .map(|(a, _)| axis_name(machine, *a))
                .collect();
            return Err(err(
                b.line,
                missing.clone(),
                format!(
                    "axis {missing} is used before it is programmed (its position is unknown, \
                     so the move cannot be verified)"
                ),
            ));
        }
        let j = Joints {
            x: next[0].unwrap_or_default(),
            y: next[1].unwrap_or_default(),
            z: next[2].unwrap_or_default(),
            tilt: next[3].unwrap_or_default(),
            rotate: next[4].unwrap_or_default(),
        };
        if !j.is_finite() {
            return Err(err(
                b.line,
                String::new(),
                "axis values are not finite".into(),
            ));
        }
        cur = next;
        let kind = match b.motion {
            GcodeMotion::Rapid => MoveKind::Rapid,
            GcodeMotion::Linear => MoveKind::Feed,
        };
        out.blocks += 1;
        let Some(prev) = last else {
            out.path.moves.push(Move {
                kind,
                cl: location(machine, options, &j),
                feed_mm_per_min: None,
            });
            out.lines.push(b.line);
            last = Some(j);
            continue;
        };
        let n = subdivisions(machine, options, &prev, &j);
        for k in 1..=n {
            let s = k as f64 / n as f64;
            out.path.moves.push(Move {
                kind,
                cl: location(machine, options, &prev.lerp(&j, s)),
                feed_mm_per_min: None,
            });
            out.lines.push(b.line);
        }
        last = Some(j);
    }
    Ok(out)
}

/// The cutter location of interpolated axis values in `options.mode`.
fn location(machine: &Machine, options: &ReadbackOptions, j: &Joints) -> CutterLocation {
    match options.mode {
        ReadbackMode::Joint => machine.forward(j, options.tool_length_mm),
        ReadbackMode::TcpAngles => {
            let axis = machine
                .forward(
                    &Joints {
                        x: 0.0,
                        y: 0.0,
                        z: 0.0,
                        ..*j
                    },
                    options.tool_length_mm,
                )
                .axis;
            CutterLocation {
                tip: cam_core::Point3::new(j.x, j.y, j.z),
                axis,
            }
        }
    }
}

/// Smallest power-of-two chord count whose chord midpoints all follow the controller's path
/// within the tolerance (tip) and `tol / reach` (axis).
fn subdivisions(machine: &Machine, options: &ReadbackOptions, a: &Joints, b: &Joints) -> usize {
    let tol = options.path_tol_mm;
    let ang_tol = if options.reach_mm > 0.0 {
        tol / options.reach_mm
    } else {
        f64::INFINITY
    };
    let mut n = 1usize;
    loop {
        let mut ok = true;
        let mut p = location(machine, options, a);
        for k in 1..=n {
            let q = location(machine, options, &a.lerp(b, k as f64 / n as f64));
            let m = location(machine, options, &a.lerp(b, (k as f64 - 0.5) / n as f64));
            let chord_mid = (p.tip.coords + q.tip.coords) * 0.5;
            let axis_mid = (p.axis.into_inner() + q.axis.into_inner()).normalize();
            let tip_dev = (m.tip.coords - chord_mid).norm();
            let ax_dev = (m.axis.into_inner() - axis_mid).norm();
            // NaN (antiparallel axes at the chord ends) fails too.
            if tip_dev > tol || ax_dev.is_nan() || ax_dev > ang_tol {
                ok = false;
                break;
            }
            p = q;
        }
        if ok || n >= MAX_SUBDIVISIONS {
            return n;
        }
        n *= 2;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::read_gcode;

    fn machine() -> Machine {
        let text = include_str!("../embedded/machines/xyzac-trt.toml");
        Machine::from_toml_str(text, "xyzac-trt.toml").unwrap()
    }

    #[test]
    fn joint_moves_follow_forward_kinematics_within_tolerance() {
        let m = machine();
        let text = "G53 G0 Z100\nG0 A30 C0\nG0 X10 Y5\nG0 Z40\nG93 G1 X12 Z38 A30 C90 F10\n";
        let blocks = read_gcode(text, "p.ngc").unwrap();
        let opt = ReadbackOptions {
            path_tol_mm: 0.002,
            reach_mm: 20.0,
            ..Default::default()
        };
        let r = read_back(&blocks, &m, &opt, "p.ngc", "prog", "T1").unwrap();
        // G53 Z100 and the rotary pre-positioning come before X/Y are known: set-up moves.
        assert_eq!(r.unplaced_start_lines, vec![1, 2]);
        assert_eq!(r.path.moves.len(), r.lines.len());
        assert!(r.lines.iter().all(|&l| l >= 3));
        // The C turn of 90° is subdivided; every chord midpoint is within the tolerance of
        // the joint-interpolated path.
        let cut: Vec<_> = r
            .path
            .moves
            .iter()
            .zip(&r.lines)
            .filter(|(_, &l)| l == 5)
            .map(|(mv, _)| mv.cl)
            .collect();
        assert!(cut.len() > 8, "{}", cut.len());
        let j0 = Joints {
            x: 10.0,
            y: 5.0,
            z: 40.0,
            tilt: 30f64.to_radians(),
            rotate: 0.0,
        };
        let j1 = Joints {
            x: 12.0,
            y: 5.0,
            z: 38.0,
            tilt: 30f64.to_radians(),
            rotate: 90f64.to_radians(),
        };
        // Dense check: every point of the true path lies within tol of the polyline.
        let mut pts = vec![m.forward(&j0, 0.0).tip];
        pts.extend(cut.iter().map(|c| c.tip));
        for k in 0..=400 {
            let t = m.forward(&j0.lerp(&j1, k as f64 / 400.0), 0.0).tip;
            let d = pts
                .windows(2)
                .map(|w| {
                    let (a, b) = (w[0].coords, w[1].coords);
                    let ab = b - a;
                    let s = ((t.coords - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
                    (t.coords - (a + ab * s)).norm()
                })
                .fold(f64::INFINITY, f64::min);
            assert!(d <= 0.002 + 1e-9, "{d}");
        }
        // The last location is the forward kinematics of the block's joints.
        let last = r.path.moves.last().unwrap().cl;
        assert!((last.tip - m.forward(&j1, 0.0).tip).norm() < 1e-9);
    }

    #[test]
    fn a_feed_move_with_an_unprogrammed_rotary_axis_is_an_error() {
        let m = machine();
        // C never programmed: the old reader took it as 0.
        let blocks = read_gcode("G0 X1 Y2 Z30 A0\nG1 X2 F100\n", "p.ngc").unwrap();
        match read_back(&blocks, &m, &ReadbackOptions::default(), "p.ngc", "p", "T1") {
            Err(GcodeError::GcodeParse { line, word, .. }) => {
                assert_eq!((line, word.as_str()), (2, "C"));
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn g53_is_placed_in_joint_output_and_refused_in_tcp_output() {
        let m = machine();
        let text = "G0 X1 Y2 Z30 A0 C0\nG53 G0 Z100\n";
        let blocks = read_gcode(text, "p.ngc").unwrap();
        let r = read_back(&blocks, &m, &ReadbackOptions::default(), "p.ngc", "p", "T1").unwrap();
        let want = m.forward(
            &Joints {
                x: 1.0,
                y: 2.0,
                z: 100.0,
                tilt: 0.0,
                rotate: 0.0,
            },
            0.0,
        );
        assert!((r.path.moves.last().unwrap().cl.tip - want.tip).norm() < 1e-9);
        let tcp = ReadbackOptions {
            mode: ReadbackMode::TcpAngles,
            ..Default::default()
        };
        match read_back(&blocks, &m, &tcp, "p.ngc", "p", "T1") {
            Err(GcodeError::GcodeParse { line, word, .. }) => {
                assert_eq!((line, word.as_str()), (2, "G53"));
            }
            other => panic!("{other:?}"),
        }
    }
}
