//! Golden programs: one hand-written expected program per dialect (tests/golden/), written
//! word by word from the controllers' programming conventions, compared byte for byte with
//! what the dialect writes for the same NC program. Plus the dialect-level error cases.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use cam_core::{Point3, UnitVector3, Vector3};
use gcode_emit::{
    dialect_by_name, Coolant, Dialect, Fanuc, Feed, GcodeError, HeidenhainConversational,
    HeidenhainIso, LinuxCnc, Motion, NcMove, NcOperation, NcProgram, OutputMode, ProgramOptions,
    RotaryWord, Sinumerik, Spindle, ToolCall, DIALECT_NAMES,
};

fn rot(a: f64, c: f64) -> Vec<RotaryWord> {
    vec![
        RotaryWord {
            letter: 'A',
            deg: a,
        },
        RotaryWord {
            letter: 'C',
            deg: c,
        },
    ]
}

fn mv(xyz: [f64; 3], a: f64, c: f64, vec: [f64; 3], feed: Feed) -> NcMove {
    NcMove {
        xyz,
        rotary: rot(a, c),
        tool_vector: Some(vec),
        feed,
    }
}

const Z: [f64; 3] = [0.0, 0.0, 1.0];

fn tilted() -> [f64; 3] {
    [0.1, -0.2, (1.0f64 - 0.05).sqrt()]
}

/// First operation: five moves in `mode`; `inverse` selects inverse-time feeds.
fn rough(mode: OutputMode) -> NcOperation {
    let inv = mode == OutputMode::Joint;
    let f = |pm: f64, it: f64| {
        if inv {
            Feed::InverseTime(it)
        } else {
            Feed::PerMinute(pm)
        }
    };
    NcOperation {
        name: "rough".into(),
        tool: ToolCall {
            number: 1,
            name: "T1".into(),
            spindle: Some(Spindle {
                rpm: 10000.0,
                clockwise: true,
            }),
            coolant: Coolant::Flood,
        },
        motion: Motion::Simultaneous {
            mode,
            moves: vec![
                mv([10.0, -5.0, 50.0], 0.0, 0.0, Z, Feed::Rapid),
                mv([10.0, -5.0, 2.0], 0.0, -0.0, Z, f(500.0, 10.0)),
                mv(
                    [12.5, -5.0, 1.25],
                    -15.0,
                    30.5,
                    tilted(),
                    f(800.0, 200.0 / 3.0),
                ),
                mv([15.0, -4.0004, 1.25], -15.0, 30.5, tilted(), f(800.0, 40.0)),
                mv([15.0, -4.0004, 40.0], -15.0, 30.5, tilted(), Feed::Rapid),
            ],
        },
    }
}

fn finish_tool() -> ToolCall {
    ToolCall {
        number: 2,
        name: "FLAT6".into(),
        spindle: Some(Spindle {
            rpm: 6000.0,
            clockwise: false,
        }),
        coolant: Coolant::Off,
    }
}

fn finish_simultaneous(mode: OutputMode) -> NcOperation {
    let feed = if mode == OutputMode::Joint {
        Feed::InverseTime(20.0)
    } else {
        Feed::PerMinute(300.0)
    };
    let (v0, v1) = if mode == OutputMode::TcpVector {
        (Z, tilted())
    } else {
        (tilted(), tilted())
    };
    NcOperation {
        name: "finish".into(),
        tool: finish_tool(),
        motion: Motion::Simultaneous {
            mode,
            moves: vec![
                mv([15.0, -4.0004, 40.0], -15.0, 30.5, v0, Feed::Rapid),
                mv([15.0, -4.0004, 0.5], -15.0, 30.5, v1, feed),
                mv([15.0, -4.0004, 40.0], -15.0, 30.5, v1, Feed::Rapid),
            ],
        },
    }
}

fn finish_indexed() -> NcOperation {
    let t = 30f64.to_radians();
    NcOperation {
        name: "finish".into(),
        tool: finish_tool(),
        motion: Motion::Indexed {
            tool_axis: UnitVector3::new_normalize(Vector3::new(0.0, -t.sin(), t.cos())),
            rotary: rot(-30.0, 0.0),
            tips: vec![
                (Point3::new(0.0, -20.0, 2.0), Feed::Rapid),
                (Point3::new(0.0, -20.0, 0.0), Feed::PerMinute(300.0)),
                (Point3::new(10.0, -20.0, 0.0), Feed::PerMinute(300.0)),
                (Point3::new(10.0, -20.0, 10.0), Feed::Rapid),
            ],
        },
    }
}

fn program(ops: Vec<NcOperation>) -> NcProgram {
    NcProgram {
        name: "golden".into(),
        operations: ops,
    }
}

fn options() -> ProgramOptions {
    ProgramOptions {
        safe_z_machine: 100.0,
        ..Default::default()
    }
}

fn golden(file: &str) -> String {
    std::fs::read_to_string(format!(
        "{}/tests/golden/{file}",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
}

fn assert_same(ours: &str, file: &str) {
    let want = golden(file);
    for (i, (a, b)) in ours.lines().zip(want.lines()).enumerate() {
        assert_eq!(a, b, "{file} line {}", i + 1);
    }
    assert_eq!(
        ours.lines().count(),
        want.lines().count(),
        "{file}: line count\n{ours}"
    );
}

#[test]
fn linuxcnc_joint_output_matches_golden() {
    let p = program(vec![
        rough(OutputMode::Joint),
        finish_simultaneous(OutputMode::Joint),
    ]);
    assert_same(
        &LinuxCnc::default().write(&p, &options()).unwrap(),
        "linuxcnc_joint.ngc",
    );
}

#[test]
fn fanuc_tcp_angles_and_vectors_match_golden() {
    let p = program(vec![
        rough(OutputMode::TcpAngles),
        finish_simultaneous(OutputMode::TcpVector),
    ]);
    assert_same(&Fanuc.write(&p, &options()).unwrap(), "fanuc_tcp.nc");
}

#[test]
fn fanuc_joint_inverse_time_and_g68_2_match_golden() {
    let p = program(vec![rough(OutputMode::Joint), finish_indexed()]);
    assert_same(
        &Fanuc.write(&p, &options()).unwrap(),
        "fanuc_joint_g68_2.nc",
    );
}

#[test]
fn sinumerik_traori_and_cycle800_match_golden() {
    let p = program(vec![rough(OutputMode::TcpAngles), finish_indexed()]);
    assert_same(
        &Sinumerik::default().write(&p, &options()).unwrap(),
        "sinumerik_traori_cycle800.mpf",
    );
}

#[test]
fn heidenhain_m128_and_plane_spatial_match_golden() {
    let p = program(vec![rough(OutputMode::TcpAngles), finish_indexed()]);
    assert_same(
        &HeidenhainIso.write(&p, &options()).unwrap(),
        "heidenhain_m128_plane.i",
    );
}

#[test]
fn line_numbers_are_optional_except_on_heidenhain() {
    let p = program(vec![rough(OutputMode::Joint)]);
    let o = ProgramOptions {
        line_numbers: None,
        ..options()
    };
    let text = LinuxCnc::default().write(&p, &o).unwrap();
    assert!(text.lines().all(|l| !l.starts_with('N')), "{text}");
    assert!(text.contains("\nG93 G1 Z2 F10\n"));
    let p = program(vec![rough(OutputMode::TcpAngles)]);
    let text = HeidenhainIso.write(&p, &o).unwrap();
    assert!(text.contains("\nN10 G17 G90 G40 *\n"), "{text}");
}

#[test]
fn dialect_limits_are_typed_errors() {
    let indexed = program(vec![finish_indexed()]);
    // LinuxCNC has no tilted-plane function.
    assert!(matches!(
        LinuxCnc::default().write(&indexed, &options()),
        Err(GcodeError::Unsupported { .. })
    ));
    let joint = program(vec![rough(OutputMode::Joint)]);
    assert!(matches!(
        HeidenhainIso.write(&joint, &options()),
        Err(GcodeError::Unsupported { .. })
    ));
    let vector = program(vec![finish_simultaneous(OutputMode::TcpVector)]);
    assert!(matches!(
        LinuxCnc::default().write(&vector, &options()),
        Err(GcodeError::Unsupported { .. })
    ));
    // NaN anywhere is an error naming operation, block and word — never "NaN" in a program.
    let mut bad = rough(OutputMode::TcpAngles);
    if let Motion::Simultaneous { moves, .. } = &mut bad.motion {
        moves[2].xyz[1] = f64::NAN;
    }
    for name in DIALECT_NAMES {
        let d = dialect_by_name(name).unwrap();
        match d.write(&program(vec![bad.clone()]), &options()) {
            Err(GcodeError::NonFinite {
                operation,
                block,
                word,
                ..
            }) => {
                assert_eq!(
                    (operation.as_str(), block, word.as_str()),
                    ("rough", 2, "Y"),
                    "{name}"
                );
            }
            other => panic!("{name}: {other:?}"),
        }
    }
    let o = ProgramOptions {
        work_offset: 7,
        ..options()
    };
    assert!(matches!(
        LinuxCnc::default().write(&joint, &o),
        Err(GcodeError::InvalidOption {
            field: "work_offset",
            ..
        })
    ));
}

#[test]
fn unknown_dialect_lists_the_valid_ones() {
    let e = dialect_by_name("haas").unwrap_err();
    assert_eq!(
        e.to_string(),
        "unknown dialect `haas`; valid dialects: linuxcnc, fanuc, sinumerik, heidenhain, \
         heidenhain_conversational"
    );
    for n in DIALECT_NAMES {
        assert_eq!(dialect_by_name(&n.to_uppercase()).unwrap().name(), n);
    }
}

#[test]
fn program_file_is_written_whole_through_a_temporary() {
    let dir = std::env::temp_dir().join(format!("gcode-emit-golden-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("p.ngc");
    let p = program(vec![rough(OutputMode::Joint)]);
    gcode_emit::write_program_file(&path, &LinuxCnc::default(), &p, &options()).unwrap();
    assert_eq!(
        std::fs::read_to_string(&path).unwrap(),
        LinuxCnc::default().write(&p, &options()).unwrap()
    );
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
    // A failing write leaves nothing behind.
    let mut bad = rough(OutputMode::Joint);
    if let Motion::Simultaneous { moves, .. } = &mut bad.motion {
        moves[1].xyz[0] = f64::INFINITY;
    }
    let path2 = dir.join("q.ngc");
    assert!(gcode_emit::write_program_file(
        &path2,
        &LinuxCnc::default(),
        &program(vec![bad]),
        &options()
    )
    .is_err());
    assert!(!path2.exists());
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A user-defined dialect built from the public helpers only.
#[derive(Debug)]
struct Minimal;

impl Dialect for Minimal {
    fn name(&self) -> &'static str {
        "minimal"
    }
    fn extension(&self) -> &'static str {
        "txt"
    }
    fn supports(&self, mode: OutputMode) -> bool {
        mode == OutputMode::TcpAngles
    }
    fn supports_indexed(&self) -> bool {
        false
    }
    fn write(&self, program: &NcProgram, o: &ProgramOptions) -> Result<String, GcodeError> {
        use gcode_emit::dialect::{At, BlockWriter, MotionStyle, MotionWriter};
        use gcode_emit::NumberFormat;
        let f = NumberFormat::fixed(3);
        let mut w = BlockWriter::new(o.line_numbers, ";");
        let mut mw = MotionWriter::new(MotionStyle {
            rapid: "G0",
            linear: "G1",
            feed_modes: ("G93", "G94"),
            vector_words: ["I", "J", "K"],
            linear_fmt: f,
            angular_fmt: f,
            feed_fmt: NumberFormat::trimmed(0),
            inverse_fmt: f,
        });
        for op in &program.operations {
            let Motion::Simultaneous { mode, moves } = &op.motion else {
                return Err(GcodeError::Unsupported {
                    dialect: "minimal",
                    what: "3+2".into(),
                });
            };
            for (i, m) in moves.iter().enumerate() {
                mw.write(
                    &mut w,
                    m,
                    *mode,
                    "",
                    At {
                        op: &op.name,
                        block: i,
                    },
                )?;
            }
        }
        Ok(w.finish())
    }
}

#[test]
fn users_can_add_their_own_dialect() {
    let p = program(vec![rough(OutputMode::TcpAngles)]);
    let text = Minimal
        .write(
            &p,
            &ProgramOptions {
                line_numbers: None,
                ..options()
            },
        )
        .unwrap();
    assert_eq!(
        text.lines().take(3).collect::<Vec<_>>(),
        [
            "G0 X10.000 Y-5.000 Z50.000 A0.000 C0.000;",
            "G1 Z2.000 F500;",
            "X12.500 Z1.250 A-15.000 C30.500 F800;"
        ]
    );
}

#[test]
fn slow_inverse_time_blocks_keep_significant_digits() {
    let mut op = rough(OutputMode::Joint);
    if let Motion::Simultaneous { moves, .. } = &mut op.motion {
        moves[1].feed = Feed::InverseTime(0.000_123_456);
    }
    let text = LinuxCnc::default()
        .write(&program(vec![op]), &options())
        .unwrap();
    assert!(text.contains("G93 G1 Z2 F0.0001235\n"), "{text}");
}

#[test]
fn heidenhain_conversational_matches_golden() {
    let p = program(vec![rough(OutputMode::TcpAngles), finish_indexed()]);
    let text = HeidenhainConversational::default()
        .write(&p, &options())
        .unwrap();
    if std::env::var_os("GOLDEN_PRINT").is_some() {
        println!("{text}");
    }
    assert_same(&text, "heidenhain_conversational.h");
}

/// The machine's program frame reaches every dialect: its header blocks after the setup
/// block, footer blocks and end code at the end, its coolant codes, block numbers that wrap
/// at the control's largest number; a trivkins LinuxCNC program has no kinematics switch
/// (a stock configuration rejects `M429`) and refuses tool-tip output.
#[test]
fn the_program_frame_shapes_every_dialect() {
    let mut op = rough(OutputMode::Joint);
    op.tool.coolant = Coolant::ThroughTool;
    let p = program(vec![op]);
    let mut o = ProgramOptions {
        header: vec!["G64 P0.01".into()],
        footer: vec!["G53 G0 Y0".into()],
        program_end: Some("M30".into()),
        line_numbers: Some(gcode_emit::LineNumbers {
            start: 1,
            step: 1,
            wrap: Some(9),
        }),
        ..options()
    };
    o.coolant_codes.through = "M88".into();
    let text = LinuxCnc::trivial().write(&p, &o).unwrap();
    assert!(!text.contains("M429") && !text.contains("M428"), "{text}");
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[2], "N1 G21 G17 G90 G94 G40 G49 G54", "{text}");
    assert_eq!(lines[3], "N2 G64 P0.01", "{text}");
    assert!(text.contains(" M88\n"), "{text}");
    let n = lines.len();
    assert!(lines[n - 3].ends_with(" G53 G0 Y0"), "{text}");
    assert!(
        lines[n - 2].ends_with(" M30") && lines[n - 1] == "%",
        "{text}"
    );
    // Numbers run 1..=9 and start again.
    let numbers: Vec<u32> = lines
        .iter()
        .filter_map(|l| l.strip_prefix('N'))
        .map(|l| l.split(' ').next().unwrap().parse().unwrap())
        .collect();
    assert!(numbers.iter().all(|&k| (1..=9).contains(&k)), "{numbers:?}");
    assert!(numbers.windows(2).any(|w| w == [9, 1]), "{numbers:?}");
    // The switchkins default still selects identity kinematics first.
    assert!(LinuxCnc::default()
        .write(&p, &options())
        .unwrap()
        .contains("N20 M429\n"));
    let tcp = program(vec![rough(OutputMode::TcpAngles)]);
    assert!(matches!(
        LinuxCnc::trivial().write(&tcp, &options()),
        Err(GcodeError::Unsupported { .. })
    ));
    // The other dialects take the same frame.
    let mut op = rough(OutputMode::TcpAngles);
    op.tool.coolant = Coolant::ThroughTool;
    let p = program(vec![op]);
    for d in [
        "fanuc",
        "sinumerik",
        "heidenhain",
        "heidenhain_conversational",
    ] {
        let text = dialect_by_name(d).unwrap().write(&p, &o).unwrap();
        assert!(text.contains("G64 P0.01"), "{d}: {text}");
        assert!(text.contains("G53 G0 Y0"), "{d}: {text}");
        assert!(text.contains("M88"), "{d}: {text}");
        let end = text.find("M30").unwrap();
        assert!(text.find("G53 G0 Y0").unwrap() < end, "{d}: {text}");
    }
    // A header block must be one line.
    let bad = ProgramOptions {
        header: vec!["G64\nM3".into()],
        ..options()
    };
    assert!(matches!(
        LinuxCnc::trivial().write(&p, &bad),
        Err(GcodeError::InvalidOption {
            field: "header",
            ..
        })
    ));
}
