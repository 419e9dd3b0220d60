//! CL operations → machine → program → read back → forward kinematics: the program reproduces
//! the cutter locations; structure rules (retract along the tool axis, safe Z before any
//! reorientation, 3+2 detection) and kinematic errors naming operation and move.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod support;

use cam_core::{CutterLocation, Point3, Vector3};
use gcode_emit::{
    assemble_program, read_gcode, AssembleOptions, Dialect, GcodeError, GcodeMotion, LinuxCnc,
    Motion, OutputMode, ProgramOptions, Sinumerik,
};
use postproc_kinematics::Machine;
use proptest::prelude::*;

/// Angular words carry 4 decimals (0.5e-4° → 0.9 µrad) and linear words 4 decimals; at radii
/// up to ~60 mm the tip error stays below 1e-4 mm.
const TIP_TOL: f64 = 2e-4;
const AXIS_TOL: f64 = 5e-6;

fn distance_to_line(p: &Point3, a: &Point3, u: &Vector3) -> f64 {
    let d = p - a;
    (d - u * d.dot(u)).norm()
}

fn roundtrip_through_program(machine: &Machine) {
    let ops = vec![support::five_axis_op("flank", 3, 15)];
    let dialect = LinuxCnc::default();
    let a = assemble_program("rt", &ops, machine, &dialect, &AssembleOptions::default()).unwrap();
    let text = dialect
        .write(&a.program, &ProgramOptions::default())
        .unwrap();
    let blocks = read_gcode(&text, "rt.ngc").unwrap();
    let cls: Vec<CutterLocation> = blocks
        .iter()
        .filter(|b| !b.machine_coordinates)
        .filter_map(|b| gcode_emit::gcode_read::joints_of(b, machine))
        .map(|j| machine.forward(&j, 0.0))
        .collect();
    assert!(cls.len() >= ops[0].path.moves.len());
    // Every source CL is reached by some block of the program.
    for m in &ops[0].path.moves {
        let best = cls
            .iter()
            .map(|c| {
                (
                    (c.tip - m.cl.tip).norm(),
                    (c.axis.into_inner() - m.cl.axis.into_inner()).norm(),
                )
            })
            .fold((f64::INFINITY, f64::INFINITY), |acc, x| {
                if x.0 < acc.0 {
                    x
                } else {
                    acc
                }
            });
        assert!(
            best.0 < TIP_TOL && best.1 < AXIS_TOL,
            "{}: CL {:?} reached within {best:?}",
            machine.name(),
            m.cl.tip
        );
    }
    // Linearisation control may insert blocks, never drop them.
    let feeds = blocks
        .iter()
        .filter(|b| b.motion == GcodeMotion::Linear)
        .count();
    assert!(feeds >= ops[0].path.moves.len());
}

#[test]
fn joint_programs_reproduce_the_cutter_locations_on_table_table_machines() {
    for f in ["xyzac-trt.toml", "xyzbc-trt.toml"] {
        let m = Machine::from_file(support::fixture(f)).unwrap();
        roundtrip_through_program(&m);
    }
}

#[test]
fn operations_retract_along_the_tool_axis_and_reorient_only_at_safe_z() {
    let machine = support::xyzac();
    let ops = vec![
        support::five_axis_op("flank", 3, 8),
        support::five_axis_op("flank2", 3, 8),
    ];
    let opts = AssembleOptions {
        mode: OutputMode::TcpAngles,
        retract_mm: 12.0,
        ..Default::default()
    };
    let a = assemble_program("r", &ops, &machine, &LinuxCnc::default(), &opts).unwrap();
    for (op, src) in a.program.operations.iter().zip(&ops) {
        let Motion::Simultaneous { moves, .. } = &op.motion else {
            panic!()
        };
        let first = &src.path.moves[0].cl;
        let last = &src.path.moves.last().unwrap().cl;
        let approach = Point3::from(moves[0].xyz);
        let retract = Point3::from(moves.last().unwrap().xyz);
        assert!(distance_to_line(&approach, &first.tip, &first.axis) < 1e-9);
        assert!(((approach - first.tip).dot(&first.axis) - 12.0).abs() < 1e-9);
        assert!(distance_to_line(&retract, &last.tip, &last.axis) < 1e-9);
        assert!(((retract - last.tip).dot(&last.axis) - 12.0).abs() < 1e-9);
    }
    // In the text: after the first operation's retract, the next rotary change comes only
    // after a machine-coordinate retract to safe Z.
    let text = LinuxCnc::default()
        .write(
            &a.program,
            &ProgramOptions {
                safe_z_machine: 100.0,
                ..Default::default()
            },
        )
        .unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let second = lines.iter().position(|l| l.contains("(flank2")).unwrap();
    let safe = lines[second..]
        .iter()
        .position(|l| l.contains("G53 G0 Z100"))
        .unwrap()
        + second;
    let first_rot = lines[second..]
        .iter()
        .position(|l| l.contains(" A"))
        .unwrap()
        + second;
    assert!(safe < first_rot, "{text}");
    // The kinematics switch back to identity happens before the machine-coordinate retract.
    let off = lines[..second]
        .iter()
        .rposition(|l| l.contains("M429"))
        .unwrap();
    assert!(off < safe);
}

#[test]
fn fixed_axis_operations_become_tilted_planes_where_the_dialect_has_them() {
    let machine = support::xyzac();
    let ops = vec![support::indexed_op("pocket", 4)];
    let sin = assemble_program(
        "p",
        &ops,
        &machine,
        &Sinumerik::default(),
        &AssembleOptions {
            mode: OutputMode::TcpAngles,
            ..Default::default()
        },
    )
    .unwrap();
    let Motion::Indexed {
        tool_axis,
        rotary,
        tips,
    } = &sin.program.operations[0].motion
    else {
        panic!("indexed expected")
    };
    assert!((tool_axis.into_inner() - ops[0].path.moves[0].cl.axis.into_inner()).norm() < 1e-15);
    assert_eq!(tips.len(), ops[0].path.moves.len() + 2);
    // The machine angles reproduce the axis.
    let j = machine
        .inverse(&ops[0].path.moves[0].cl, 0.0, None)
        .unwrap();
    assert!((rotary[0].deg - j.tilt.to_degrees()).abs() < 1e-9);
    let lin = assemble_program(
        "p",
        &ops,
        &machine,
        &LinuxCnc::default(),
        &AssembleOptions::default(),
    )
    .unwrap();
    assert!(matches!(
        lin.program.operations[0].motion,
        Motion::Simultaneous { .. }
    ));
}

#[test]
fn unreachable_blocks_name_the_operation_and_move() {
    let machine = support::xyzac();
    let mut op = support::five_axis_op("flank", 3, 6);
    // Tilt the 4th move's axis 80° (A travel ends at -100°/+50°; C can turn, so make it
    // point down instead: unreachable by any A within the limits).
    op.path.moves[3].cl =
        CutterLocation::new(Point3::new(10.0, 0.0, 0.0), Vector3::new(0.0, 0.3, -1.0)).unwrap();
    match assemble_program(
        "bad",
        &[op],
        &machine,
        &LinuxCnc::default(),
        &AssembleOptions::default(),
    ) {
        Err(GcodeError::Kinematics {
            operation,
            index,
            reason,
        }) => {
            assert_eq!(operation, "flank");
            assert_eq!(index, 3, "{reason}");
        }
        other => panic!("{other:?}"),
    }
}

proptest! {
    /// The G-code reader never panics: random bytes and mutated programs give blocks or a
    /// typed error.
    #[test]
    fn gcode_reader_never_panics(s in "[GXYZACFMN0-9. ;()%#\\[\\]\n-]{0,200}") {
        let _ = read_gcode(&s, "fuzz.ngc");
    }
}

#[test]
fn tilted_plane_operations_are_checked_against_the_axis_limits() {
    let machine = support::xyzac();
    let mut op = support::indexed_op("pocket", 4);
    for m in &mut op.path.moves {
        m.cl.tip.x += 1000.0; // X travel is ±200 mm
    }
    let r = assemble_program(
        "p",
        &[op],
        &machine,
        &Sinumerik::default(),
        &AssembleOptions {
            mode: OutputMode::TcpAngles,
            ..Default::default()
        },
    );
    match r {
        Err(GcodeError::Kinematics {
            operation, reason, ..
        }) => {
            assert_eq!(operation, "pocket");
            assert!(reason.contains("axis X"), "{reason}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_operations_tool_length_reaches_the_kinematics_of_a_head_machine() {
    // On the head-head machine the joints depend on the gauge length: a program posted with
    // the operation's 120 mm tool, read back through the forward kinematics with 120 mm,
    // reproduces the cutter locations; posted with the options' default (0 mm) it does not.
    let machine = Machine::from_file(support::fixture("headhead-ac.toml")).unwrap();
    let dialect = LinuxCnc::default();
    let tip_error = |op: &gcode_emit::ClOperation| {
        let a = assemble_program(
            "tl",
            std::slice::from_ref(op),
            &machine,
            &dialect,
            &AssembleOptions::default(),
        )
        .unwrap();
        let text = dialect
            .write(&a.program, &ProgramOptions::default())
            .unwrap();
        let blocks = read_gcode(&text, "tl.ngc").unwrap();
        let cls: Vec<CutterLocation> = blocks
            .iter()
            .filter(|b| !b.machine_coordinates)
            .filter_map(|b| gcode_emit::gcode_read::joints_of(b, &machine))
            .map(|j| machine.forward(&j, 120.0))
            .collect();
        op.path
            .moves
            .iter()
            .map(|m| {
                cls.iter()
                    .map(|c| (c.tip - m.cl.tip).norm())
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0, f64::max)
    };
    let mut op = support::five_axis_op("flank", 3, 15);
    op.tool_length_mm = Some(120.0);
    // 4-decimal angles on a 120 mm lever (≈ 1e-4 mm each) plus 4-decimal lengths: 5e-4 mm
    assert!(tip_error(&op) < 5e-4, "{}", tip_error(&op));
    op.tool_length_mm = None;
    assert!(tip_error(&op) > 1.0, "{}", tip_error(&op));
}
