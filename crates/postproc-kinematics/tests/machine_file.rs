//! Machine files: fixtures load; malformed files give errors with file, line and field.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use postproc_kinematics::{AxisId, Kinematics, Machine, MachineError, RotaryMode, TiltAxis};

fn fixture_text(name: &str) -> String {
    std::fs::read_to_string(format!(
        "{}/../../fixtures/machines/{name}.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
}

fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

#[test]
fn fixtures_load_with_their_meaning() {
    let m = Machine::from_toml_str(&fixture_text("xyzac-trt"), "xyzac-trt.toml").unwrap();
    match m.kinematics() {
        Kinematics::TableTable(k) => {
            assert_eq!(k.tilt_axis, TiltAxis::A);
            assert_eq!((k.offset.y, k.offset.z), (20.0, 10.0));
            assert!(!k.conventional_directions);
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(m.letter(AxisId::Tilt), 'A');
    let (lo, hi) = m.axis(AxisId::Tilt).limits();
    assert!((lo.to_degrees() + 100.0).abs() < 1e-9 && (hi.to_degrees() - 50.0).abs() < 1e-9);
    assert_eq!(m.safe_z(), Some(100.0));
    let m = Machine::from_toml_str(&fixture_text("turnmill-bc"), "turnmill-bc.toml").unwrap();
    assert!(
        matches!(m.kinematics(), Kinematics::HeadTable(k) if k.pivot_length == 150.0 && k.tilt_axis == TiltAxis::B)
    );
    let m = Machine::from_toml_str(&fixture_text("headhead-ac"), "headhead-ac.toml").unwrap();
    assert_eq!(m.axis(AxisId::Rotate).mode, RotaryMode::Continuous);
    let words = m.axis_words(&postproc_kinematics::Joints {
        tilt: std::f64::consts::FRAC_PI_2,
        ..Default::default()
    });
    assert_eq!(words[3].0, 'A');
    assert!((words[3].1 - 90.0).abs() < 1e-12);
    Machine::from_toml_str(&fixture_text("xyzbc-trt"), "xyzbc-trt.toml").unwrap();
}

#[test]
fn syntax_error_reports_file_and_line() {
    let text = fixture_text("xyzac-trt").replace("y_offset = 20.0", "y_offset = = 20.0");
    let err = Machine::from_toml_str(&text, "bad.toml").unwrap_err();
    let want = line_of(&text, "y_offset = = 20.0");
    match &err {
        MachineError::Syntax { file, line, .. } => {
            assert_eq!(file, "bad.toml");
            assert_eq!(*line, want);
        }
        other => panic!("{other:?}"),
    }
    assert!(
        err.to_string().starts_with(&format!("bad.toml:{want}:")),
        "{err}"
    );
}

#[test]
fn wrong_type_names_field_and_line() {
    let text = fixture_text("xyzac-trt").replace("z_offset = 10.0", "z_offset = \"ten\"");
    let err = Machine::from_toml_str(&text, "bad.toml").unwrap_err();
    let want = line_of(&text, "z_offset = \"ten\"");
    match &err {
        MachineError::Syntax { line, .. } => assert_eq!(*line, want),
        other => panic!("{other:?}"),
    }
    let text = fixture_text("xyzac-trt").replace("x_rot_point = 0.0", "x_rot_pont = 0.0");
    let err = Machine::from_toml_str(&text, "bad.toml")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("x_rot_pont") && err.contains(&format!(":{}:", line_of(&text, "x_rot_pont"))),
        "{err}"
    );
}

#[test]
fn invalid_values_name_field_and_line() {
    let cases = [
        ("xyzac-trt", "max = 50.0", "max = -150.0", "axes.A.max"),
        (
            "xyzac-trt",
            "tilt_axis = \"A\"",
            "tilt_axis = \"Q\"",
            "kinematics.tilt_axis",
        ),
        (
            "xyzac-trt",
            "type = \"table-table\"",
            "type = \"robot\"",
            "kinematics.type",
        ),
        (
            "turnmill-bc",
            "tilt_sign = 1",
            "tilt_sign = 2",
            "kinematics.tilt_sign",
        ),
        (
            "turnmill-bc",
            "pivot_length = 150.0",
            "pivot_length = -1.0",
            "kinematics.pivot_length",
        ),
        (
            "turnmill-bc",
            "spindle_direction = [1.0, 0.0, 0.0]",
            "spindle_direction = [0.0, 1.0, 0.0]",
            "kinematics.spindle_direction",
        ),
        (
            "xyzac-trt",
            "y_offset = 20.0",
            "y_offset = 20.0\nx_offset = 1.0",
            "kinematics.x_offset",
        ),
        ("xyzac-trt", "safe_z = 100.0", "safe_z = 1000.0", "safe_z"),
        (
            "headhead-ac",
            "mode = \"continuous\"",
            "mode = \"spinning\"",
            "axes.C.mode",
        ),
        (
            "xyzac-trt",
            "max_speed = 1800.0\nmax_acceleration = 300.0\n\n[axes.C]",
            "max_speed = 0.0\nmax_acceleration = 300.0\n\n[axes.C]",
            "axes.A.max_speed",
        ),
    ];
    for (fixture, from, to, field) in cases {
        let text = fixture_text(fixture).replacen(from, to, 1);
        assert_ne!(text, fixture_text(fixture), "{from}");
        let err = Machine::from_toml_str(&text, "m.toml").unwrap_err();
        match &err {
            MachineError::Invalid {
                file,
                line,
                field: f,
                ..
            } => {
                assert_eq!(file, "m.toml");
                assert_eq!(f, field, "{err}");
                let key = format!("{} =", field.rsplit('.').next().unwrap());
                let needle = to.lines().find(|l| l.starts_with(&key)).unwrap();
                assert_eq!(*line, line_of(&text, needle), "{err}");
            }
            other => panic!("{field}: {other:?}"),
        }
    }
}

#[test]
fn missing_axis_is_named() {
    let text = fixture_text("xyzac-trt");
    let cut = text.find("[axes.Y]").unwrap();
    let end = text.find("[axes.Z]").unwrap();
    let text = format!("{}{}", &text[..cut], &text[end..]);
    let err = Machine::from_toml_str(&text, "m.toml")
        .unwrap_err()
        .to_string();
    assert!(err.contains("axes.Y"), "{err}");
    let err = Machine::from_file("/nonexistent/machine.toml")
        .unwrap_err()
        .to_string();
    assert!(err.contains("/nonexistent/machine.toml"), "{err}");
}

mod fuzz {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Random byte edits of a fixture: a typed error or a valid machine, never a panic.
        #[test]
        fn mutated_files_never_panic(pos in 0usize..2000, len in 0usize..8, fill in "[ -~\n]{0,8}", which in 0usize..4) {
            let name = ["xyzac-trt", "xyzbc-trt", "turnmill-bc", "headhead-ac"][which];
            let text = fixture_text(name);
            let mut bytes: Vec<char> = text.chars().collect();
            let p = pos % bytes.len();
            let e = (p + len).min(bytes.len());
            bytes.splice(p..e, fill.chars());
            let mutated: String = bytes.into_iter().collect();
            match Machine::from_toml_str(&mutated, "fuzz.toml") {
                Ok(m) => prop_assert!(m.check_limits(&m.home(), 1e-9).is_ok()),
                Err(e) => prop_assert!(e.to_string().starts_with("fuzz.toml")),
            }
        }
    }
}

#[test]
fn unknown_axis_key_has_its_line() {
    let text = fixture_text("xyzac-trt").replace("[axes.C]", "[axes.W]");
    let err = Machine::from_toml_str(&text, "m.toml").unwrap_err();
    match &err {
        MachineError::Invalid { line, field, .. } => {
            assert_eq!(field, "axes.W");
            assert_eq!(*line, line_of(&text, "[axes.W]"));
        }
        other => panic!("{other:?}"),
    }
}

/// The cycle-time keys: `max_acceleration` per axis (mm/s², deg/s² → rad/s²),
/// `tool_change_s`, `blending`; the `[program]` table is left to `gcode-emit`. Bad values
/// name the field and the line.
#[test]
fn acceleration_tool_change_and_blending_are_read_and_checked() {
    let m = Machine::from_toml_str(&fixture_text("xyzac-trt"), "xyzac-trt.toml").unwrap();
    assert_eq!(m.axis(AxisId::X).max_acceleration, Some(300.0));
    let a = m.axis(AxisId::Tilt).max_acceleration.unwrap();
    assert!((a - 300f64.to_radians()).abs() < 1e-12);
    assert!(m.tool_change_s().is_some());
    assert_eq!(m.blending(), postproc_kinematics::Blending::Parabolic);
    assert!(!m.tool_length_matters());
    let h = Machine::from_toml_str(&fixture_text("headhead-ac"), "headhead-ac.toml").unwrap();
    assert!(h.tool_length_matters());
    let text = fixture_text("xyzac-trt");
    for (from, to, field) in [
        (
            "max_acceleration = 300.0\n",
            "max_acceleration = -1.0\n",
            "axes.X.max_acceleration",
        ),
        (
            "tool_change_s = 5.0\n",
            "tool_change_s = -3.0\n",
            "tool_change_s",
        ),
        (
            "blending = \"parabolic\"\n",
            "blending = \"g64\"\n",
            "blending",
        ),
    ] {
        let bad = text.replacen(from, to, 1);
        assert_ne!(bad, text, "{from}");
        let e = Machine::from_toml_str(&bad, "bad.toml").unwrap_err();
        let needle = to.lines().last().unwrap();
        let want = format!("bad.toml:{}: field `{field}`", line_of(&bad, needle));
        assert!(e.to_string().starts_with(&want), "{e} / {want}");
    }
    // The fixture's [program] table is gcode-emit's to read and check.
    assert!(text.contains("[program]"));
}
