//! Every parse and validation error of the importers is reached by a malformed file, and the
//! error names the file, the line and what was expected.

use impeller_model::import::{
    parse_geomturbo, parse_rtzt, read_geomturbo, read_turbogrid, turbogrid_from_bytes, ImportError,
    LengthUnit,
};
use std::path::Path;

const INF: &str = "!== sample\nAxis of Rotation: Z\nNumber of Blade Sets: 7\nGeometry Units: MM\n\
Hub Data File: hub.curve\nShroud Data File: shroud.curve\nProfile Data File: profile.curve\n";
const HUB: &str = "10 0 0\n12 0 5\n20 0 10\n";
const SHROUD: &str = "20 0 0\n22 0 5\n30 0 10\n";
const PROFILE: &str = "# Profile 1 at 0%\n11 0 1\n13 0.5 3\n15 0 6\n13 -0.5 3\n11 0 1\n\
# Profile 2 at 100.0%\n21 0 1\n23 0.5 3\n25 0 6\n23 -0.5 3\n21 0 1\n";

const GEOM: &str = "GEOMETRY TURBO\nVERSION 5.5\nNI_BEGIN CHANNEL\nNI_BEGIN basic_curve\n\
NAME hub_crv\nNI_BEGIN zrcurve\nZR\n+3\n0 10\n5 12\n10 20\nNI_END zrcurve\nNI_END basic_curve\n\
NI_BEGIN basic_curve\nNAME shroud_crv\nNI_BEGIN zrcurve\nZR\n3\n0 20\n5 22\n10 30\n\
NI_END zrcurve\nNI_END basic_curve\nNI_BEGIN channel_curve hub\nVERTEX CURVE_P hub_crv 0\n\
VERTEX CURVE_P hub_crv 1\nNI_END channel_curve\nNI_BEGIN channel_curve shroud\n\
VERTEX CURVE_P shroud_crv 0\nNI_END channel_curve\nNI_END CHANNEL\nNI_BEGIN NIROW\nNAME row 1\n\
PERIODICITY 7\nNI_BEGIN NIBLADE\nNAME main\nNI_BEGIN NIBLADEGEOMETRY\nunits 0.001\n\
number_of_blades 7\nsuction\nSECTIONAL\n2\n# section 1\nXYZ\n2\n11 0 1\n15 1 6\nXYZ\n2\n21 0 1\n\
25 1 6\npressure\nSECTIONAL\n2\nXYZ\n2\n11 0 1\n15 0.5 6\nXYZ\n2\n21 0 1\n25 0.5 6\n\
NI_END NIBLADEGEOMETRY\nNI_END NIBLADE\nNI_END NIROW\nNI_END GEOMTURBO\n";

const RTZT: &str = "7\n0\n0\n2\nT\n0 3\n10 0 1 0.5\n12 0.1 5 0.8\n20 0.2 10 0.5\n\
1 3 a\n20 0 1 0.5\n22 0.1 5 0.8\n30 0.2 10 0.5\n";

#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Syntax,
    Eof,
    Invalid,
}

fn check(err: ImportError, kind: Kind, line: usize, needle: &str, case: &str) {
    let msg = err.to_string();
    let ok = match (&err, kind) {
        (ImportError::Syntax { line: l, .. }, Kind::Syntax)
        | (ImportError::UnexpectedEof { line: l, .. }, Kind::Eof)
        | (ImportError::Invalid { line: l, .. }, Kind::Invalid) => *l == line,
        _ => false,
    };
    assert!(ok, "{case}: expected {kind:?} at line {line}, got {err:?}");
    assert!(
        msg.contains(needle),
        "{case}: {msg:?} should mention {needle:?}"
    );
    assert!(msg.contains(':'), "{case}: message names the file: {msg}");
}

fn replaced(base: &str, from: &str, to: &str, case: &str) -> String {
    assert!(base.contains(from), "{case}: base text lacks {from:?}");
    base.replacen(from, to, 1)
}

fn tg(inf: &str, hub: &str, profile: &str) -> Result<(), ImportError> {
    turbogrid_from_bytes(
        (Path::new("s.inf"), inf.as_bytes()),
        (Path::new("hub.curve"), hub.as_bytes()),
        (Path::new("shroud.curve"), SHROUD.as_bytes()),
        &[(Path::new("profile.curve"), profile.as_bytes())],
    )
    .map(|_| ())
}

#[test]
fn base_texts_are_valid() {
    tg(INF, HUB, PROFILE).unwrap();
    let g = parse_geomturbo(Path::new("g.geomTurbo"), GEOM.as_bytes()).unwrap();
    assert_eq!(g.main_blade_count(), 7);
    // units 0.001 m = 1 mm.
    assert!((g.hub[2].y - 20.0).abs() < 1e-12);
    parse_rtzt(Path::new("r.rtzt"), RTZT.as_bytes(), LengthUnit::Millimetre).unwrap();
}

#[test]
fn turbogrid_inf_errors() {
    let cases: &[(&str, &str, Kind, usize, &str)] = &[
        (
            "Axis of Rotation: Z",
            "Axis of Rotation Z",
            Kind::Syntax,
            2,
            "Key: value",
        ),
        (
            "Axis of Rotation: Z",
            "Axis of Rotation: Q",
            Kind::Syntax,
            2,
            "X, Y or Z",
        ),
        (
            "Blade Sets: 7",
            "Blade Sets: seven",
            Kind::Syntax,
            3,
            "non-negative integer",
        ),
        (
            "Blade Sets: 7",
            "Blade Sets: 0",
            Kind::Invalid,
            3,
            "at least 1",
        ),
        (
            "Units: MM",
            "Units: furlong",
            Kind::Syntax,
            4,
            "Geometry Units",
        ),
        (
            "Units: MM",
            "Units: MM\nGeometry Units: CM",
            Kind::Invalid,
            5,
            "given twice",
        ),
        (
            "Units: MM",
            "Units: MM\nCoordinate Type: polar",
            Kind::Syntax,
            5,
            "Cartesian or Cylindrical",
        ),
        (
            "Units: MM",
            "Units: MM\nAngle Units: grad",
            Kind::Syntax,
            5,
            "Radians or Degrees",
        ),
        (
            "Hub Data File: hub.curve",
            "Hub Data File:",
            Kind::Syntax,
            5,
            "FILE NAME",
        ),
        (
            "Units: MM",
            "Units: MM\nBlade x Profile Data File: a",
            Kind::Syntax,
            5,
            "blade index",
        ),
        (
            "Units: MM",
            "Units: MM\nBlade 3 Profile Data File: a",
            Kind::Invalid,
            5,
            "blade index 3",
        ),
        (
            "Units: MM",
            "Units: MM\nBlade 0 Profile Data File: a",
            Kind::Invalid,
            8,
            "given twice",
        ),
        (
            "Units: MM",
            "Units: MM\nBlade 1 Data File:",
            Kind::Syntax,
            5,
            "FILE NAME",
        ),
        (
            "Axis of Rotation: Z\n",
            "",
            Kind::Eof,
            6,
            "Axis of Rotation",
        ),
        (
            "Number of Blade Sets: 7\n",
            "",
            Kind::Eof,
            6,
            "Number of Blade Sets",
        ),
        ("Geometry Units: MM\n", "", Kind::Eof, 6, "Geometry Units"),
        (
            "Hub Data File: hub.curve\n",
            "",
            Kind::Eof,
            6,
            "Hub Data File",
        ),
        (
            "Shroud Data File: shroud.curve\n",
            "",
            Kind::Eof,
            6,
            "Shroud Data File",
        ),
        (
            "Profile Data File: profile.curve\n",
            "",
            Kind::Eof,
            6,
            "Profile Data File",
        ),
        (
            "Units: MM",
            "Units: MM\nNumber of Blades Per Set: 2",
            Kind::Eof,
            8,
            "Blade 1 Profile Data File",
        ),
    ];
    for (from, to, kind, line, needle) in cases {
        let case = format!("inf {from:?} -> {to:?}");
        let err = tg(&replaced(INF, from, to, &case), HUB, PROFILE).unwrap_err();
        check(err, *kind, *line, needle, &case);
    }
    // Two blades per set but only one profile file handed over.
    let inf2 = INF.replace(
        "Units: MM",
        "Units: MM\nNumber of Blades Per Set: 2\nBlade 1 Profile Data File: s.curve",
    );
    let err = tg(&inf2, HUB, PROFILE).unwrap_err();
    assert!(
        matches!(err, ImportError::Invalid { .. })
            && err.to_string().contains("2 blade(s) per set")
    );
    // Non-UTF-8 bytes.
    let err = turbogrid_from_bytes(
        (Path::new("s.inf"), b"Axis of Rotation: Z\n\xff\xfe\n"),
        (Path::new("h"), b""),
        (Path::new("s"), b""),
        &[],
    )
    .unwrap_err();
    check(err, Kind::Syntax, 2, "UTF-8", "non-UTF-8");
}

#[test]
fn turbogrid_curve_and_profile_errors() {
    let hub_cases: &[(&str, &str, Kind, usize, &str)] = &[
        ("12 0 5", "12 0", Kind::Syntax, 2, "3 numbers (x y z)"),
        ("12 0 5", "12 0 5 7", Kind::Syntax, 2, "3 numbers"),
        ("12 0 5", "12 zero 5", Kind::Syntax, 2, "3 numbers"),
        ("12 0 5", "12 NaN 5", Kind::Invalid, 2, "invalid y"),
        (
            "12 0 5\n20 0 10\n",
            "",
            Kind::Eof,
            1,
            "at least 2 curve points",
        ),
    ];
    for (from, to, kind, line, needle) in hub_cases {
        let case = format!("hub {from:?} -> {to:?}");
        let err = tg(INF, &replaced(HUB, from, to, &case), PROFILE).unwrap_err();
        check(err, *kind, *line, needle, &case);
    }
    let profile_cases: &[(&str, &str, Kind, usize, &str)] = &[
        (
            "# Profile 1 at 0%",
            "# Profile one",
            Kind::Syntax,
            1,
            "profile number",
        ),
        (
            "# Profile 1 at 0%",
            "# Profile 1 on 0%",
            Kind::Syntax,
            1,
            "# Profile k at s%",
        ),
        (
            "# Profile 1 at 0%",
            "# Profile 1 at low",
            Kind::Syntax,
            1,
            "span percentage",
        ),
        (
            "# Profile 1 at 0%",
            "# Profile 1 at 120%",
            Kind::Invalid,
            1,
            "not within 0–100%",
        ),
        (
            "# Profile 1 at 0%\n",
            "",
            Kind::Syntax,
            1,
            "`# Profile 1` line before",
        ),
        (
            "13 0.5 3\n15 0 6\n",
            "",
            Kind::Invalid,
            1,
            "at least 4 points",
        ),
        (
            "15 0 6",
            "15 inf 6",
            Kind::Invalid,
            4,
            "not a finite number",
        ),
        (
            "# Profile 2 at 100.0%",
            "# comment",
            Kind::Eof,
            12,
            "at least 2 profiles",
        ),
    ];
    for (from, to, kind, line, needle) in profile_cases {
        let case = format!("profile {from:?} -> {to:?}");
        let err = tg(INF, HUB, &replaced(PROFILE, from, to, &case)).unwrap_err();
        check(err, *kind, *line, needle, &case);
    }
}

#[test]
fn geomturbo_errors() {
    let cases: &[(&str, &str, Kind, usize, &str)] = &[
        ("GEOMETRY TURBO", "GEOMETRY", Kind::Syntax, 1, "GEOMETRY TURBO"),
        ("NI_BEGIN CHANNEL", "NI_BEGIN", Kind::Syntax, 3, "block type"),
        ("NI_END zrcurve", "NI_END basic_curve", Kind::Syntax, 12, "NI_END zrcurve"),
        ("+3", "three", Kind::Syntax, 8, "number of curve points"),
        ("+3", "1", Kind::Invalid, 8, "at least 2"),
        ("5 12", "5 twelve", Kind::Syntax, 10, "2 numbers (z r)"),
        ("10 20\n", "10 20\n0 1\n", Kind::Syntax, 12, "NI_END zrcurve (the point count"),
        ("NI_END zrcurve\nNI_END basic_curve\n", "ZR\n2\n1 1\n2 2\nNI_END zrcurve\nNI_END basic_curve\n", Kind::Invalid, 12, "second point list"),
        ("VERTEX CURVE_P hub_crv 0", "VERTEX hub_crv", Kind::Syntax, 25, "VERTEX CURVE_P"),
        ("VERTEX CURVE_P hub_crv 1", "VERTEX CURVE_P nothing 1", Kind::Invalid, 26, "no basic_curve named"),
        ("PERIODICITY 7", "PERIODICITY many", Kind::Syntax, 34, "PERIODICITY"),
        ("PERIODICITY 7", "PERIODICITY 0", Kind::Invalid, 34, "at least 1"),
        ("PERIODICITY 7", "PERIODICITY 8", Kind::Invalid, 39, "differs from the row's PERIODICITY 8"),
        ("units 0.001", "units m", Kind::Syntax, 38, "1 numbers (units)"),
        ("units 0.001", "units -1", Kind::Invalid, 38, "positive scale factor"),
        ("number_of_blades 7", "number_of_blades 0", Kind::Invalid, 39, "at least 1"),
        ("number_of_blades 7", "number_of_blades x", Kind::Syntax, 39, "number_of_blades"),
        ("suction\nSECTIONAL", "suction\nSECTIONS", Kind::Syntax, 41, "SECTIONAL after `suction`"),
        ("SECTIONAL\n2\n# section 1", "SECTIONAL\n1\n# section 1", Kind::Invalid, 42, "at least 2"),
        ("# section 1\nXYZ", "# section 1\nZRTH", Kind::Syntax, 44, "XYZ starting suction section 1"),
        ("15 1 6", "15 1 6 9", Kind::Syntax, 47, "3 numbers (x y z)"),
        ("NI_END NIBLADEGEOMETRY", "suction\nSECTIONAL\n2\nXYZ\n2\n1 0 0\n2 0 0\nXYZ\n2\n1 0 0\n2 0 0\nNI_END NIBLADEGEOMETRY", Kind::Invalid, 63, "side given twice"),
        ("pressure\nSECTIONAL\n2", "pressure\nSECTIONAL\n3", Kind::Syntax, 63, "XYZ starting pressure section 3"),
        ("pressure\nSECTIONAL\n2\n", "pressure\nSECTIONAL\n3\nXYZ\n2\n1 0 0\n2 0 0\n", Kind::Invalid, 35, "2 suction sections but 3 pressure"),
        ("NI_END NIROW\n", "", Kind::Syntax, 65, "NI_END nirow"),
        ("NI_BEGIN NIBLADEGEOMETRY", "NI_BEGIN NIBLADEGEOM", Kind::Syntax, 63, "NI_END nibladegeom"),
    ];
    for (from, to, kind, line, needle) in cases {
        let case = format!("geomTurbo {from:?} -> {to:?}");
        let text = replaced(GEOM, from, to, &case);
        match parse_geomturbo(Path::new("g.geomTurbo"), text.as_bytes()) {
            Err(err) => check(err, *kind, *line, needle, &case),
            Ok(_) => panic!("{case}: parsed"),
        }
    }
    // Neither PERIODICITY nor number_of_blades.
    let text = GEOM
        .replace("PERIODICITY 7\n", "")
        .replace("number_of_blades 7\n", "");
    let err = parse_geomturbo(Path::new("g"), text.as_bytes()).unwrap_err();
    check(
        err,
        Kind::Invalid,
        34,
        "neither the row's PERIODICITY",
        "no blade count",
    );
    // Without a `channel_curve shroud` block the curve named like `shroud` is used ...
    let text = GEOM.replace("channel_curve shroud", "channel_curve casing");
    let g = parse_geomturbo(Path::new("g"), text.as_bytes()).unwrap();
    assert!((g.shroud[0].y - 20.0).abs() < 1e-12);
    // ... and without either there is no shroud.
    let text = text.replace("NAME shroud_crv", "NAME casing");
    let err = parse_geomturbo(Path::new("g"), text.as_bytes()).unwrap_err();
    check(err, Kind::Eof, 66, "channel_curve shroud", "no shroud");
    // No NIROW at all.
    let text = GEOM.replace("NIROW", "NISTAGE");
    let err = parse_geomturbo(Path::new("g"), text.as_bytes()).unwrap_err();
    check(err, Kind::Eof, 66, "NIROW", "no row");
    let start = GEOM.find("units").unwrap();
    let end = GEOM.find("NI_END NIBLADEGEOMETRY").unwrap();
    let text = format!("{}{}", &GEOM[..start], &GEOM[end..]);
    let err = parse_geomturbo(Path::new("g"), text.as_bytes()).unwrap_err();
    check(
        err,
        Kind::Invalid,
        32,
        "no blade with suction/pressure",
        "row without geometry",
    );
    let err = parse_geomturbo(Path::new("g"), b"").unwrap_err();
    check(err, Kind::Eof, 0, "GEOMETRY TURBO", "empty file");
    // ZR inside a zrcurve block that is not within a basic_curve.
    let text = "GEOMETRY TURBO\nNI_BEGIN zrcurve\nZR\n2\n0 1\n1 2\nNI_END zrcurve\n";
    let err = parse_geomturbo(Path::new("g"), text.as_bytes()).unwrap_err();
    check(err, Kind::Syntax, 3, "inside a basic_curve", "orphan ZR");
}

#[test]
fn rtzt_errors() {
    let cases: &[(&str, &str, Kind, usize, &str)] = &[
        (
            "7\n0\n0\n2",
            "seven\n0\n0\n2",
            Kind::Syntax,
            1,
            "number of blades",
        ),
        ("7\n0\n0\n2", "0\n0\n0\n2", Kind::Invalid, 1, "at least 1"),
        (
            "7\n0\n0\n2",
            "7\nnone\n0\n2",
            Kind::Syntax,
            2,
            "number of splitters",
        ),
        (
            "7\n0\n0\n2",
            "7\n0\nhalf\n2",
            Kind::Syntax,
            3,
            "pitch fraction",
        ),
        (
            "7\n0\n0\n2",
            "7\n0\n0\nmany",
            Kind::Syntax,
            4,
            "number of layers",
        ),
        ("7\n0\n0\n2", "7\n0\n0\n1", Kind::Invalid, 4, "at least 2"),
        (
            "0 3\n",
            "0\n",
            Kind::Syntax,
            6,
            "span fraction, number of points",
        ),
        ("0 3\n", "low 3\n", Kind::Syntax, 6, "span fraction"),
        ("0 3\n", "1.5 3\n", Kind::Invalid, 6, "not within 0–1"),
        ("1 3 a", "0 3 a", Kind::Invalid, 10, "increasing span"),
        ("0 3\n", "0 x\n", Kind::Syntax, 6, "number of points"),
        ("0 3\n10 0 1 0.5\n", "0 1\n", Kind::Invalid, 6, "at least 2"),
        ("1 3 a", "1 3 q", Kind::Syntax, 10, "layer usage flags"),
        (
            "12 0.1 5 0.8",
            "12 0.1 5",
            Kind::Syntax,
            8,
            "4 numbers (r theta z thickness)",
        ),
        (
            "12 0.1 5 0.8",
            "-12 0.1 5 0.8",
            Kind::Invalid,
            8,
            "invalid r",
        ),
        (
            "12 0.1 5 0.8",
            "12 0.1 5 -0.8",
            Kind::Invalid,
            8,
            "invalid thickness",
        ),
        (
            "12 0.1 5 0.8",
            "12 NaN 5 0.8",
            Kind::Invalid,
            8,
            "invalid theta",
        ),
        (
            "10 0 1 0.5\n12 0.1 5 0.8\n20 0.2 10 0.5",
            "10 0 1 0\n12 0.1 5 0\n20 0.2 10 0",
            Kind::Invalid,
            6,
            "zero thickness everywhere",
        ),
        (
            "10 0 1 0.5\n12 0.1 5 0.8",
            "10 0 1 0\n12 0.1 5 0",
            Kind::Invalid,
            6,
            "fewer than 2 points",
        ),
        (
            "30 0.2 10 0.5\n",
            "30 0.2 10 0.5\n1\n",
            Kind::Syntax,
            14,
            "end of file",
        ),
        ("30 0.2 10 0.5\n", "", Kind::Eof, 12, "point 3 of 3"),
        (
            "7\n0\n",
            "7\n1\n",
            Kind::Eof,
            13,
            "pitch fraction of the splitter 1",
        ),
    ];
    for (from, to, kind, line, needle) in cases {
        let case = format!("rtzt {from:?} -> {to:?}");
        let text = replaced(RTZT, from, to, &case);
        let err =
            parse_rtzt(Path::new("r.rtzt"), text.as_bytes(), LengthUnit::Millimetre).unwrap_err();
        check(err, *kind, *line, needle, &case);
    }
    // A splitter's pitch fraction must lie within 0–1.
    let text = RTZT.replacen("7\n0\n", "7\n1\n", 1)
        + "1.5\n2\n0 2\n1 0 1 1\n2 0 2 1\n1 2\n1 0 1 1\n2 0 2 1\n";
    let err = parse_rtzt(Path::new("r"), text.as_bytes(), LengthUnit::Millimetre).unwrap_err();
    check(err, Kind::Invalid, 14, "not within 0–1", "splitter pitch");
    // CRLF is the same file.
    let crlf = RTZT.replace('\n', "\r\n");
    parse_rtzt(Path::new("r"), crlf.as_bytes(), LengthUnit::Millimetre).unwrap();
}

#[test]
fn missing_files_are_io_errors() {
    let err = read_geomturbo(Path::new("/nonexistent/x.geomTurbo")).unwrap_err();
    assert!(matches!(err, ImportError::Io { .. }));
    assert!(err.to_string().contains("/nonexistent/x.geomTurbo"));
    let err = read_turbogrid(Path::new("/nonexistent/a.inf")).unwrap_err();
    assert!(matches!(err, ImportError::Io { .. }));
}
