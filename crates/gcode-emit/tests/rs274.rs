//! Real consumer: LinuxCNC's standalone G-code interpreter `rs274` (Debian `linuxcnc-uspace`)
//! must accept every LinuxCNC program we write, and its canonical moves must equal our joint
//! values to its printed precision (4 decimals).
//!
//! `rs274 -t TOOL.TBL [-i INI] -g FILE` runs the interpreter in batch mode with stdin closed;
//! it prints one canonical call per line (`STRAIGHT_FEED(x, y, z, a, b, c)`), prints errors
//! on stderr and exits non-zero on an error. If `rs274` is missing the tests print that they
//! were skipped; under CI (`CI=true`) they fail instead.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod support;

use gcode_emit::{
    assemble_program, read_gcode, AssembleOptions, Dialect, Feed, LinuxCnc, Motion, NcProgram,
    OutputMode, ProgramOptions,
};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// rs274 prints 4 decimals; our program carries 4 decimals too. Two roundings of half a unit
/// each, plus margin for binary representation.
const PRINT_TOL: f64 = 1.0e-4 + 1e-9;

fn rs274() -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join("rs274"))
        .find(|p| p.is_file())
}

/// Whether this is a CI run (`CI=true`, as CI services set it): then the real consumer is
/// required.
fn under_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| v == "true" || v == "1")
}

fn require_rs274() -> Option<PathBuf> {
    match rs274() {
        Some(p) => Some(p),
        None if under_ci() => panic!(
            "CI=true but LinuxCNC's `rs274` interpreter is not on PATH: install it with \
             `apt-get install -y --no-install-recommends linuxcnc-uspace` (`cargo xtask ci` \
             does)."
        ),
        None => {
            eprintln!(
                "SKIPPED: LinuxCNC's `rs274` is not on PATH, so our LinuxCNC programs were \
                 not run through its interpreter (`cargo xtask ci` installs it; under CI=true \
                 this test fails instead)."
            );
            None
        }
    }
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("gcode-emit-rs274-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// An ini remapping the kinematics-switch M codes (`M428` TCP, `M429` identity, as in
/// LinuxCNC's xyzac-trt sample configuration) to subroutines that only print a message, so
/// the interpreter can run our programs outside a motion controller and the test can see
/// where each switch happens (`MESSAGE("kins identity")` in rs274's canonical output).
fn remap_ini(dir: &Path) -> PathBuf {
    let subs = dir.join("subs");
    std::fs::create_dir_all(&subs).unwrap();
    for (m, what) in [("428", "tcp"), ("429", "identity")] {
        std::fs::write(
            subs.join(format!("{m}remap.ngc")),
            format!("o<{m}remap>sub\n(MSG,kins {what})\no<{m}remap>endsub\n"),
        )
        .unwrap();
    }
    let ini = dir.join("xyzac.ini");
    std::fs::write(
        &ini,
        format!(
            "[RS274NGC]\nSUBROUTINE_PATH = {}\nREMAP = M428 modalgroup=10 ngc=428remap\nREMAP = M429 modalgroup=10 ngc=429remap\n[TRAJ]\nCOORDINATES = XYZAC\nLINEAR_UNITS = mm\nANGULAR_UNITS = deg\n",
            subs.display()
        ),
    )
    .unwrap();
    ini
}

/// An ini of a stock trivkins configuration (`trivkins coordinates=xyzac`: the axes are the
/// joints): no remapped M codes, so a kinematics switch such as `M429` is an error
/// ("M-code greater than 199").
fn trivkins_ini(dir: &Path) -> PathBuf {
    let ini = dir.join("trivkins.ini");
    std::fs::write(
        &ini,
        "[TRAJ]\nCOORDINATES = XYZAC\nLINEAR_UNITS = mm\nANGULAR_UNITS = deg\n",
    )
    .unwrap();
    ini
}

/// Canonical motion lines of rs274's output as (name, [x y z a b c]).
fn canonical_moves(stdout: &str) -> Vec<(String, [f64; 6])> {
    let mut out = Vec::new();
    for line in stdout.lines() {
        for name in ["STRAIGHT_TRAVERSE", "STRAIGHT_FEED"] {
            if let Some(p) = line.find(&format!("{name}(")) {
                let args = &line[p + name.len() + 1..];
                let args = &args[..args.find(')').unwrap()];
                let v: Vec<f64> = args.split(',').map(|s| s.trim().parse().unwrap()).collect();
                assert!(v.len() >= 6, "{line}");
                out.push((name.to_string(), [v[0], v[1], v[2], v[3], v[4], v[5]]));
            }
        }
    }
    out
}

/// rs274 keeps its tool data in a memory-mapped file `$HOME/.tool.mmap`, shared by every
/// interpreter of the user (parallel tests, other programs): each run gets its own HOME.
fn run(rs: &Path, dir: &Path, program: &str, ini: Option<&Path>) -> String {
    let file = dir.join("prog.ngc");
    std::fs::write(&file, program).unwrap();
    let tbl = dir.join("tool.tbl");
    std::fs::write(
        &tbl,
        "T1 P1 Z0 D10 ;rough\nT2 P2 Z0 D6 ;finish\nT3 P3 Z0 D6 ;flank\nT4 P4 Z0 D8 ;pocket\n",
    )
    .unwrap();
    let mut cmd = Command::new(rs);
    cmd.arg("-t").arg(&tbl);
    if let Some(ini) = ini {
        cmd.arg("-i").arg(ini);
    }
    let out = cmd
        .arg("-g")
        .arg(&file)
        .current_dir(dir)
        .env("HOME", dir)
        .stdin(Stdio::null())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(
        out.status.success(),
        "rs274 rejected the program (status {:?}):\n{stderr}\n--- program ---\n{program}",
        out.status
    );
    // rs274 prints only "executing" on stderr when all is well.
    let noise: Vec<&str> = stderr
        .lines()
        .filter(|l| !l.trim().is_empty() && l.trim() != "executing")
        .collect();
    assert!(
        noise.is_empty(),
        "rs274 reported: {noise:?}\n--- program ---\n{program}"
    );
    stdout
}

/// Checks rs274's canonical moves against (a) our own reader's blocks of the same file,
/// one to one, and (b) the program's NC moves (our joint values), in order.
fn check(program_text: &str, stdout: &str, program: &NcProgram) {
    let canon = canonical_moves(stdout);
    let blocks = read_gcode(program_text, "prog.ngc").unwrap();
    assert_eq!(
        canon.len(),
        blocks.len(),
        "one canonical move per motion block"
    );
    let mut compared = 0;
    for ((name, c), b) in canon.iter().zip(&blocks) {
        let rapid = b.motion == gcode_emit::GcodeMotion::Rapid;
        assert_eq!(name == "STRAIGHT_TRAVERSE", rapid, "line {}", b.line);
        if b.machine_coordinates {
            continue; // G53 is printed relative to the active offsets.
        }
        for k in [0, 1, 2, 3, 5] {
            let ours = b.axes[k].unwrap_or(0.0);
            assert!(
                (c[k] - ours).abs() <= PRINT_TOL,
                "line {} axis {k}: rs274 {} vs ours {ours}",
                b.line,
                c[k]
            );
        }
        compared += 1;
    }
    assert!(compared > 10);
    // Every NC move of the program (values before formatting) appears, in order, among the
    // canonical moves within the print tolerance.
    let mut it = canon.iter().filter(|(n, _)| !n.is_empty());
    let mut matched = 0;
    for op in &program.operations {
        let Motion::Simultaneous { moves, .. } = &op.motion else {
            panic!("LinuxCNC writes simultaneous operations")
        };
        for mv in moves {
            let want = [
                mv.xyz[0],
                mv.xyz[1],
                mv.xyz[2],
                mv.rotary[0].deg,
                0.0,
                mv.rotary[1].deg,
            ];
            let found = it
                .by_ref()
                .any(|(_, c)| (0..6).all(|k| (c[k] - want[k]).abs() <= PRINT_TOL));
            assert!(
                found,
                "operation `{}`: move {want:?} not executed by rs274",
                op.name
            );
            matched += 1;
        }
    }
    assert!(matched > 10);
}

#[test]
fn rs274_accepts_joint_output_and_executes_our_joint_values() {
    let Some(rs) = require_rs274() else { return };
    let machine = support::xyzac();
    let ops = vec![
        support::five_axis_op("flank", 3, 12),
        support::indexed_op("pocket", 4),
    ];
    let dialect = LinuxCnc::default();
    let assembled = assemble_program(
        "rs274_joint",
        &ops,
        &machine,
        &dialect,
        &AssembleOptions::default(),
    )
    .unwrap();
    // Joint output uses inverse time on every cutting block.
    for op in &assembled.program.operations {
        let Motion::Simultaneous { mode, moves } = &op.motion else {
            panic!()
        };
        assert_eq!(*mode, OutputMode::Joint);
        assert!(moves
            .iter()
            .all(|m| matches!(m.feed, Feed::Rapid | Feed::InverseTime(_))));
    }
    for numbers in [true, false] {
        let options = ProgramOptions {
            safe_z_machine: machine.safe_z().unwrap_or(0.0),
            line_numbers: if numbers {
                ProgramOptions::default().line_numbers
            } else {
                None
            },
            ..Default::default()
        };
        let text = dialect.write(&assembled.program, &options).unwrap();
        assert!(text.contains("G93") && text.contains("G43 H3") && text.contains("T4 M6"));
        let dir = scratch(if numbers { "joint-n" } else { "joint" });
        let ini = remap_ini(&dir);
        let stdout = run(&rs, &dir, &text, Some(&ini));
        // Identity kinematics is selected before the first motion: joint values mean joints
        // only then, whatever state the controller was left in.
        let identity = stdout
            .find("kins identity")
            .expect("the program selects identity kinematics");
        let first_motion = ["STRAIGHT_TRAVERSE(", "STRAIGHT_FEED("]
            .iter()
            .filter_map(|m| stdout.find(m))
            .min()
            .unwrap();
        assert!(
            identity < first_motion,
            "identity kinematics after a motion"
        );
        assert!(
            stdout.contains("SET_FEED_MODE"),
            "inverse time seen by rs274"
        );
        check(&text, &stdout, &assembled.program);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

/// A machine file saying `[program] kinematics = "trivial"` gives a program a stock trivkins
/// configuration runs, with the same joint moves; the switchkins program (identity selected
/// by `M429` first) is rejected there, so the check is live.
#[test]
fn rs274_runs_trivkins_joint_output_in_a_trivkins_configuration() {
    let Some(rs) = require_rs274() else { return };
    let machine = support::xyzac();
    let ops = vec![
        support::five_axis_op("flank", 3, 12),
        support::indexed_op("pocket", 4),
    ];
    let dialect = LinuxCnc::trivial();
    let assembled = assemble_program(
        "rs274_trivkins",
        &ops,
        &machine,
        &dialect,
        &AssembleOptions::default(),
    )
    .unwrap();
    let options = ProgramOptions {
        safe_z_machine: machine.safe_z().unwrap_or(0.0),
        ..Default::default()
    };
    let text = dialect.write(&assembled.program, &options).unwrap();
    assert!(!text.contains("M429") && !text.contains("M428"));
    let dir = scratch("trivkins");
    let ini = trivkins_ini(&dir);
    let stdout = run(&rs, &dir, &text, Some(&ini));
    check(&text, &stdout, &assembled.program);
    // The switchkins program: rejected by the same configuration.
    let switched = LinuxCnc::default()
        .write(&assembled.program, &options)
        .unwrap();
    std::fs::write(dir.join("switched.ngc"), &switched).unwrap();
    let out = Command::new(&rs)
        .arg("-i")
        .arg(&ini)
        .arg("-g")
        .arg(dir.join("switched.ngc"))
        .env("HOME", &dir)
        .stdin(Stdio::null())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("M-code greater than 199"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn rs274_accepts_tcp_output_with_switchable_kinematics() {
    let Some(rs) = require_rs274() else { return };
    let machine = support::xyzac();
    let ops = vec![
        support::five_axis_op("flank", 3, 12),
        support::indexed_op("pocket", 4),
    ];
    let dialect = LinuxCnc::default();
    let options = AssembleOptions {
        mode: OutputMode::TcpAngles,
        ..Default::default()
    };
    let assembled = assemble_program("rs274_tcp", &ops, &machine, &dialect, &options).unwrap();
    let text = dialect
        .write(
            &assembled.program,
            &ProgramOptions {
                safe_z_machine: 100.0,
                ..Default::default()
            },
        )
        .unwrap();
    assert!(text.contains("M428") && text.contains("M429"));
    // The kinematics switch is a remapped M code of the machine configuration (as in
    // LinuxCNC's xyzac-trt sample config).
    let dir = scratch("tcp");
    let ini = remap_ini(&dir);
    let stdout = run(&rs, &dir, &text, Some(&ini));
    check(&text, &stdout, &assembled.program);
    // In TCP mode X Y Z are the tool tip in the workpiece frame: the CL file's own points.
    let canon = canonical_moves(&stdout);
    for op in &ops {
        for m in &op.path.moves {
            let t = m.cl.tip;
            assert!(
                canon.iter().any(|(_, c)| (c[0] - t.x).abs() <= PRINT_TOL
                    && (c[1] - t.y).abs() <= PRINT_TOL
                    && (c[2] - t.z).abs() <= PRINT_TOL),
                "tip {t:?} not executed"
            );
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn rs274_rejects_what_it_should_so_the_check_is_live() {
    // The harness must be able to fail: a program with an exponent number is an rs274 error.
    let Some(rs) = require_rs274() else { return };
    let dir = scratch("neg");
    let file = dir.join("bad.ngc");
    std::fs::write(&file, "G21\nG0 X1e3\nM2\n").unwrap();
    let out = Command::new(&rs)
        .arg("-g")
        .arg(&file)
        .env("HOME", &dir)
        .stdin(Stdio::null())
        .output()
        .unwrap();
    assert!(!out.status.success());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn rs274_accepts_the_linuxcnc_golden_program() {
    let Some(rs) = require_rs274() else { return };
    let text = std::fs::read_to_string(format!(
        "{}/tests/golden/linuxcnc_joint.ngc",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let dir = scratch("golden");
    let ini = remap_ini(&dir);
    let stdout = run(&rs, &dir, &text, Some(&ini));
    let canon = canonical_moves(&stdout);
    let blocks = read_gcode(&text, "linuxcnc_joint.ngc").unwrap();
    assert_eq!(canon.len(), blocks.len());
    // The inverse-time block N110 (F66.6667 over its XYZ length) is executed as written.
    assert!(canon
        .iter()
        .any(|(n, c)| n == "STRAIGHT_FEED" && c == &[12.5, -5.0, 1.25, -15.0, 0.0, 30.5]));
    std::fs::remove_dir_all(&dir).unwrap();
}
