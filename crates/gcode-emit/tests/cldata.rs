#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
//! APT CLDATA reader and writer: a realistic file, round trips, errors with file/line/field,
//! and a never-panic property over random and mutated files.

use cam_core::{CutterLocation, CutterShape, Move, MoveKind, Point3, ToolPath, Vector3};
use gcode_emit::{
    read_cl, write_cl, ClOperation, ClProgram, ClReadOptions, ClWriteOptions, Coolant, GcodeError,
    Spindle,
};
use proptest::prelude::*;

const SAMPLE: &str = include_str!("data/sample.cls");

fn read(text: &str) -> Result<ClProgram, GcodeError> {
    read_cl(text, "test.cls", &ClReadOptions::default())
}

#[test]
fn sample_file_reads_into_operations_with_cutters_and_technology() {
    let p = read(SAMPLE).unwrap();
    assert_eq!(p.part_name.as_deref(), Some("IMPELLER_DEMO"));
    assert_eq!(p.operations.len(), 2);

    let op = &p.operations[0];
    assert_eq!(op.path.name, "FLANK_FINISH");
    assert_eq!(op.tool_number, Some(3));
    assert_eq!(op.path.tool, "T3");
    assert_eq!(op.coolant, Coolant::Flood);
    assert_eq!(
        op.spindle,
        Some(Spindle {
            rpm: 12000.0,
            clockwise: true
        })
    );
    assert_eq!(op.comments, vec!["FLANK FINISH MAIN BLADE 1".to_string()]);
    assert!(op.multax);
    // 7-parameter tapered ball: r = 3, b = 5°; the continuation line gave h = 40.
    let c = op.cutter.as_ref().unwrap();
    match c.shape {
        CutterShape::TaperedBallEnd {
            ball_radius,
            half_angle,
        } => {
            assert_eq!(ball_radius, 3.0);
            assert!((half_angle - 5f64.to_radians()).abs() < 1e-12);
        }
        other => panic!("wrong shape {other:?}"),
    }
    assert_eq!(c.flute_length, 40.0);
    let m = &op.path.moves;
    assert_eq!(m.len(), 4);
    assert_eq!(m[0].kind, MoveKind::Rapid);
    assert_eq!(m[0].feed_mm_per_min, None);
    assert_eq!(m[1].kind, MoveKind::Feed);
    assert_eq!(m[1].feed_mm_per_min, Some(300.0));
    // 3-value GOTO keeps the previous axis.
    assert_eq!(m[1].cl.axis.into_inner(), Vector3::z());
    assert_eq!(m[2].feed_mm_per_min, Some(800.0));
    // Continued GOTO with an inline `$$` comment.
    assert_eq!(m[3].cl.tip, Point3::new(14.0, 2.0, 18.5));
    assert!((m[3].cl.axis.x - 0.3420201).abs() < 1e-6);
    assert!((m[3].cl.axis.norm() - 1.0).abs() < 1e-15);

    let op = &p.operations[1];
    assert_eq!(op.path.name, "HUB_FINISH");
    assert_eq!(
        op.cutter.as_ref().unwrap().shape,
        CutterShape::BallEnd { radius: 3.0 }
    );
    assert_eq!(
        op.spindle,
        Some(Spindle {
            rpm: 9000.0,
            clockwise: false
        })
    );
    assert_eq!(op.coolant, Coolant::Mist);
    // FEDRAT/IPM converts to mm/min.
    assert!((op.path.moves[1].feed_mm_per_min.unwrap() - 508.0).abs() < 1e-9);

    // CIRCLE, OPSTOP, the short CUTTER's missing height and the GOTO after FINI are warnings
    // with their lines.
    let lines: Vec<usize> = p.warnings.iter().map(|w| w.line).collect();
    assert!(lines.contains(&20), "{:?}", p.warnings);
    assert!(lines.contains(&21), "{:?}", p.warnings);
    assert!(lines.contains(&25), "{:?}", p.warnings);
    assert!(lines.contains(&35), "{:?}", p.warnings);
    assert!(p.warnings.iter().any(|w| w.message.contains("after FINI")));
}

#[test]
fn inch_units_scale_lengths_and_feeds() {
    let p = read("UNITS/INCHES\nCUTTER/0.5\nFEDRAT/10\nGOTO/1,2,3,0,0,1\n").unwrap();
    let m = &p.operations[0].path.moves[0];
    assert!((m.cl.tip - Point3::new(25.4, 50.8, 76.2)).norm() < 1e-12);
    assert!((m.feed_mm_per_min.unwrap() - 254.0).abs() < 1e-12);
    assert_eq!(
        p.operations[0].cutter.as_ref().unwrap().shape,
        CutterShape::FlatEnd { radius: 6.35 }
    );
}

fn demo_program() -> ClProgram {
    let mut path = ToolPath::new("flank, pass 1", "T7");
    let mut angle: f64 = 0.0;
    for i in 0..20 {
        let tip = Point3::new(
            1.0 / 3.0 + i as f64 * 0.7,
            -2.0e-7 * i as f64,
            15.0 - 0.1 * i as f64,
        );
        let axis = Vector3::new(angle.sin(), 0.2 * angle.cos(), 1.0);
        let cl = CutterLocation::new(tip, axis).unwrap();
        let kind = match i {
            0 => MoveKind::Rapid,
            1 => MoveKind::Plunge,
            19 => MoveKind::Retract,
            _ => MoveKind::Feed,
        };
        let feed = match i {
            0 => None,
            1 => Some(250.0),
            5 => Some(1234.5678),
            _ => None,
        };
        path.moves.push(Move {
            kind,
            cl,
            feed_mm_per_min: feed,
        });
        angle += 0.05;
    }
    let mut op = ClOperation::new(path);
    op.tool_number = Some(7);
    op.cutter = Some(
        cam_core::Cutter::new(
            "T7",
            CutterShape::TaperedBallEnd {
                ball_radius: 2.5,
                half_angle: 3f64.to_radians(),
            },
            35.0,
            4.0,
            50.0,
        )
        .unwrap(),
    );
    op.spindle = Some(Spindle {
        rpm: 15000.0,
        clockwise: true,
    });
    op.coolant = Coolant::ThroughTool;
    op.comments = vec!["first pass".into()];
    ClProgram {
        part_name: Some("DEMO".into()),
        operations: vec![op],
        warnings: vec![],
    }
}

#[test]
fn write_then_read_round_trips_exactly() {
    let p = demo_program();
    let text = write_cl(&p, &ClWriteOptions::default()).unwrap();
    assert!(
        !text.contains("e-") && !text.contains("e+"),
        "exponent in\n{text}"
    );
    let q = read(&text).unwrap();
    assert!(q.warnings.is_empty(), "{:?}", q.warnings);
    assert_eq!(q.operations.len(), 1);
    let (a, b) = (&p.operations[0], &q.operations[0]);
    assert_eq!(b.path.name, "flank  pass 1");
    assert_eq!(b.tool_number, a.tool_number);
    assert_eq!(b.spindle, a.spindle);
    assert_eq!(b.coolant, a.coolant);
    assert_eq!(b.comments, a.comments);
    assert_eq!(
        b.cutter.as_ref().unwrap().shape.radius_at(1.0),
        a.cutter.as_ref().unwrap().shape.radius_at(1.0)
    );
    assert_eq!(a.path.moves.len(), b.path.moves.len());
    let mut eff = None;
    for (ma, mb) in a.path.moves.iter().zip(&b.path.moves) {
        assert_eq!(ma.cl.tip, mb.cl.tip, "tips are bit-exact");
        assert_eq!(ma.cl.axis, mb.cl.axis, "axes are bit-exact");
        assert_eq!(ma.kind == MoveKind::Rapid, mb.kind == MoveKind::Rapid);
        if ma.kind != MoveKind::Rapid {
            eff = ma.feed_mm_per_min.or(eff);
            assert_eq!(mb.feed_mm_per_min, eff);
        }
    }
    // Writing what was read gives the same text again.
    assert_eq!(write_cl(&q, &ClWriteOptions::default()).unwrap(), text);
}

#[test]
fn fixed_decimals_round_trip_within_half_a_unit() {
    let p = demo_program();
    let text = write_cl(&p, &ClWriteOptions { decimals: Some(5) }).unwrap();
    let q = read(&text).unwrap();
    for (ma, mb) in p.operations[0]
        .path
        .moves
        .iter()
        .zip(&q.operations[0].path.moves)
    {
        assert!((ma.cl.tip - mb.cl.tip).abs().max() <= 0.5e-5 + 1e-12);
        assert!((ma.cl.axis.into_inner() - mb.cl.axis.into_inner()).norm() < 2e-5);
    }
}

fn parse_err(text: &str) -> (usize, String, usize) {
    match read(text) {
        Err(GcodeError::ClParse {
            file,
            line,
            record,
            field,
            ..
        }) => {
            assert_eq!(file, "test.cls");
            (line, record, field)
        }
        other => panic!("expected ClParse, got {other:?}"),
    }
}

#[test]
fn malformed_records_name_line_record_and_field() {
    assert_eq!(
        parse_err("MULTAX\nGOTO/1,2,x,0,0,1\n"),
        (2, "GOTO".into(), 3)
    );
    assert_eq!(parse_err("GOTO/1,2,3,0,0,NaN\n"), (1, "GOTO".into(), 6));
    assert_eq!(parse_err("GOTO/1,2,3,0,0,1e999\n"), (1, "GOTO".into(), 6));
    assert_eq!(parse_err("GOTO/1,2\n"), (1, "GOTO".into(), 0));
    assert_eq!(parse_err("GOTO/1,2,3,0,0,0\n"), (1, "GOTO".into(), 4));
    assert_eq!(parse_err("\n\nFEDRAT/MMPM,-5\n"), (3, "FEDRAT".into(), 1));
    assert_eq!(parse_err("FEDRAT/MMPR,0.1\n"), (1, "FEDRAT".into(), 1));
    assert_eq!(parse_err("LOADTL/2.5\n"), (1, "LOADTL".into(), 1));
    assert_eq!(
        parse_err("CUTTER/6,3,0,3,0,0,30,1\n"),
        (1, "CUTTER".into(), 0)
    );
    assert_eq!(parse_err("COOLNT/SOUP\n"), (1, "COOLNT".into(), 1));
    assert_eq!(parse_err("SPINDL/RPM,0\n"), (1, "SPINDL".into(), 1));
    // A continuation whose record starts on line 2 and never ends.
    assert_eq!(parse_err("MULTAX\nGOTO/1,2,$\n").0, 2);
    // A bad value on a continuation line is reported at the record's first line.
    assert_eq!(parse_err("GOTO/1,$\n2,zz\n"), (1, "GOTO".into(), 3));
}

#[test]
fn unsupported_cutter_is_a_warning_and_keeps_the_apt_numbers() {
    let p = read("CUTTER/10,1,2,1,0,5,20\nGOTO/0,0,0\n").unwrap();
    let op = &p.operations[0];
    assert!(op.cutter.is_none());
    assert!((op.apt_cutter.unwrap().beta - 5f64.to_radians()).abs() < 1e-15);
    assert!(p
        .warnings
        .iter()
        .any(|w| w.line == 1 && w.message.contains("tapered bull nose")));
}

#[test]
fn file_errors_name_the_file() {
    let e = gcode_emit::read_cl_file(
        std::path::Path::new("/nonexistent/x.cls"),
        &ClReadOptions::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("/nonexistent/x.cls"), "{e}");
}

#[test]
fn written_file_is_complete_and_no_temp_file_is_left() {
    let dir = std::env::temp_dir().join(format!("gcode-emit-cl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("out.cls");
    gcode_emit::write_cl_file(&path, &demo_program(), &ClWriteOptions::default()).unwrap();
    let names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 1, "{names:?}");
    let q = gcode_emit::read_cl_file(&path, &ClReadOptions::default()).unwrap();
    assert_eq!(q.operations[0].path.moves.len(), 20);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Every path the reader accepts is valid: finite tips, unit axes, positive finite feeds.
fn assert_valid(p: &ClProgram) {
    for op in &p.operations {
        assert!(!op.path.moves.is_empty());
        for m in &op.path.moves {
            let t = m.cl.tip;
            assert!(t.x.is_finite() && t.y.is_finite() && t.z.is_finite());
            assert!((m.cl.axis.norm() - 1.0).abs() < 1e-9);
            if let Some(f) = m.feed_mm_per_min {
                assert!(f.is_finite() && f > 0.0);
            }
        }
        if let Some(c) = &op.cutter {
            c.validate().unwrap();
        }
    }
}

fn mutate(base: &str, ops: &[(u8, usize, u8)]) -> String {
    let mut bytes = base.as_bytes().to_vec();
    for &(kind, pos, byte) in ops {
        if bytes.is_empty() {
            break;
        }
        let at = pos % bytes.len();
        match kind % 5 {
            0 => bytes.truncate(at),
            1 => bytes[at] ^= byte,
            2 => {
                // Replace the number around `at` with a poison value.
                let poison: &[u8] = match byte % 4 {
                    0 => b"NaN",
                    1 => b"inf",
                    2 => b"1e999",
                    _ => b"-0",
                };
                bytes.splice(at..at, poison.iter().copied());
            }
            3 => {
                bytes.insert(at, b"$,/\n"[byte as usize % 4]);
            }
            _ => {
                bytes.remove(at);
            }
        }
    }
    String::from_utf8_lossy(&bytes).into_owned()
}

proptest! {
    #[test]
    fn mutated_files_give_an_error_or_a_valid_program(
        ops in proptest::collection::vec((any::<u8>(), any::<usize>(), any::<u8>()), 0..8)
    ) {
        let text = mutate(SAMPLE, &ops);
        if let Ok(p) = read(&text) {
            assert_valid(&p);
        }
    }

    #[test]
    fn random_records_give_an_error_or_a_valid_program(
        lines in proptest::collection::vec(
            (prop::sample::select(vec!["GOTO", "FEDRAT", "CUTTER", "LOADTL", "SPINDL", "COOLNT", "RAPID",
                "MULTAX", "TLAXIS", "UNITS", "TOOL PATH", "END-OF-PATH", "FINI", "PPRINT", "FROM", "XYZZY"]),
             proptest::collection::vec(prop_oneof![
                any::<f64>().prop_map(|v| v.to_string()),
                (-1e3f64..1e3).prop_map(|v| v.to_string()),
                prop::sample::select(vec!["MM", "INCHES", "ON", "OFF", "CLW", "MMPM", "RPM", "", "$", "NaN"]).prop_map(String::from),
             ], 0..8)),
            0..30)
    ) {
        let text: String = lines
            .iter()
            .map(|(w, p)| format!("{w}/{}\n", p.join(",")))
            .collect();
        if let Ok(p) = read(&text) {
            assert_valid(&p);
        }
    }
}

#[test]
fn tool_paths_with_cutters_write_and_read_back() {
    let p = demo_program();
    let op = &p.operations[0];
    let q = ClProgram::from_tool_paths(
        Some("JOB".into()),
        [(op.path.clone(), op.cutter.clone(), Some(7))],
    );
    let r = read(&write_cl(&q, &ClWriteOptions::default()).unwrap()).unwrap();
    assert_eq!(r.part_name.as_deref(), Some("JOB"));
    let c = r.operations[0].cutter.as_ref().unwrap();
    assert_eq!(c.flute_length, 35.0);
    assert!(
        (c.shape.radius_at(3.0) - op.cutter.as_ref().unwrap().shape.radius_at(3.0)).abs() < 1e-12
    );
    assert_eq!(r.operations[0].path.moves.len(), op.path.moves.len());
}

#[test]
fn nx_tldata_mill_defines_the_cutter() {
    let p =
        read("TLDATA/MILL,10.0000,2.0000,50.0000,0.0000,0.0000\nGOTO/0,0,0\nTLDATA/DRILL,5,118\n")
            .unwrap();
    let c = p.operations[0].cutter.as_ref().unwrap();
    assert_eq!(
        c.shape,
        CutterShape::BullNose {
            radius: 5.0,
            corner_radius: 2.0
        }
    );
    assert_eq!(c.flute_length, 50.0);
    assert!(p
        .warnings
        .iter()
        .any(|w| w.line == 3 && w.message.contains("DRILL")));
    assert_eq!(parse_err("TLDATA/MILL,x\n"), (1, "TLDATA".into(), 2));
    assert_eq!(parse_err("TLDATA/MILL\n"), (1, "TLDATA".into(), 2));
}

#[test]
fn windows_files_with_bom_and_crlf_read_like_unix_ones() {
    let unix = read(SAMPLE).unwrap();
    let win = format!("\u{feff}{}", SAMPLE.replace('\n', "\r\n"));
    assert_eq!(read(&win).unwrap(), unix);
}

/// `LOADTL/n,LENGTH,l` gives the gauge length (in the file's units) that head machines need
/// in their kinematics; it is written back and a change of length starts a new operation.
#[test]
fn loadtl_length_is_the_tool_gauge_length() {
    let text = "UNITS/INCHES\nMULTAX/ON\nLOADTL/3,LENGTH,4.5\nFEDRAT/IPM,10\n\
                GOTO/1,0,0,0,0,1\nGOTO/2,0,0,0,0,1\nLOADTL/3\nGOTO/3,0,0,0,0,1\nFINI\n";
    let p = read(text).unwrap();
    assert_eq!(p.operations.len(), 2);
    assert_eq!(p.operations[0].tool_length_mm, Some(4.5 * 25.4));
    assert_eq!(p.operations[1].tool_length_mm, None);
    assert!(p.warnings.is_empty(), "{:?}", p.warnings);
    let back = read(&write_cl(&p, &ClWriteOptions::default()).unwrap()).unwrap();
    assert_eq!(back.operations[0].tool_length_mm, Some(4.5 * 25.4));
    match read("LOADTL/3,LENGTH,-2\n") {
        Err(GcodeError::ClParse { line, field, .. }) => assert_eq!((line, field), (1, 3)),
        other => panic!("{other:?}"),
    }
    // Other modifiers are reported as not used.
    let p = read("MULTAX/ON\nLOADTL/3,ADJUST,3\nGOTO/1,0,0,0,0,1\nFINI\n").unwrap();
    assert_eq!(p.warnings.len(), 1);
}
