//! Shared fixtures of the integration tests: a five-axis path on the LinuxCNC xyzac-trt
//! sample machine.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use cam_core::{CutterLocation, Move, MoveKind, Point3, ToolPath, Vector3};
use gcode_emit::{ClOperation, Coolant, Spindle};
use postproc_kinematics::Machine;
use std::path::PathBuf;

pub fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/machines")
        .join(name)
}

pub fn xyzac() -> Machine {
    Machine::from_file(fixture("xyzac-trt.toml")).unwrap()
}

/// A swept five-axis flank-like pass: the tip runs along an arc while the tool axis tilts
/// from 10° to 35° from +Z and turns 60° about Z.
pub fn five_axis_op(name: &str, tool: u32, n: usize) -> ClOperation {
    let mut path = ToolPath::new(name, format!("T{tool}"));
    for i in 0..n {
        let s = i as f64 / (n - 1) as f64;
        let phi = (20.0 + 60.0 * s).to_radians();
        let tilt = (10.0 + 25.0 * s).to_radians();
        let tip = Point3::new(30.0 * phi.cos(), 30.0 * phi.sin(), 5.0 - 3.0 * s);
        let axis = Vector3::new(tilt.sin() * phi.cos(), tilt.sin() * phi.sin(), tilt.cos());
        let cl = CutterLocation::new(tip, axis).unwrap();
        path.moves.push(Move {
            kind: if i == 0 {
                MoveKind::Plunge
            } else {
                MoveKind::Feed
            },
            cl,
            feed_mm_per_min: if i == 0 {
                Some(300.0)
            } else if i == 1 {
                Some(800.0)
            } else {
                None
            },
        });
    }
    let mut op = ClOperation::new(path);
    op.tool_number = Some(tool);
    op.spindle = Some(Spindle {
        rpm: 12000.0,
        clockwise: true,
    });
    op.coolant = Coolant::Flood;
    op
}

/// A fixed-axis (3+2) pass: tool axis tilted 30° toward −Y, a short zig-zag.
pub fn indexed_op(name: &str, tool: u32) -> ClOperation {
    let mut path = ToolPath::new(name, format!("T{tool}"));
    let t = 30f64.to_radians();
    let axis = Vector3::new(0.0, -t.sin(), t.cos());
    for (i, (x, y)) in [(0.0, -20.0), (10.0, -20.0), (10.0, -25.0), (0.0, -25.0)]
        .iter()
        .enumerate()
    {
        let cl = CutterLocation::new(Point3::new(*x, *y, 2.0), axis).unwrap();
        path.moves.push(Move {
            kind: MoveKind::Feed,
            cl,
            feed_mm_per_min: if i == 0 { Some(600.0) } else { None },
        });
    }
    let mut op = ClOperation::new(path);
    op.tool_number = Some(tool);
    op.spindle = Some(Spindle {
        rpm: 8000.0,
        clockwise: true,
    });
    op.coolant = Coolant::Mist;
    op
}
