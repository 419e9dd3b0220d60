//! Every validation error of the parametric file is reached by a malformed file, and names

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
//! its field and line.

use impeller_model::fixtures::IMPELLER_8_8_TOML as BASE;
use impeller_model::{from_toml_str, load, ModelError};

const FREE: &str = include_str!("../../../fixtures/impeller-5-freeform/impeller.toml");

fn err_of(text: &str) -> ModelError {
    match from_toml_str(text, "test.toml") {
        Ok(_) => panic!("malformed file accepted:\n{text}"),
        Err(e) => e,
    }
}

fn replace(base: &str, from: &str, to: &str) -> String {
    assert!(base.contains(from), "mutation target missing: {from}");
    base.replacen(from, to, 1)
}

const BSPLINE_HUB: &str = "[hub]\ntype = \"bspline\"\ndegree = 2\ncontrol_points_zr_mm = [[43.0, 9.0], [5.0, 9.0], [5.0, 38.5]]\nweights = [1.0, 0.7, 1.0]\n";
const ELLIPSE_HUB: &str =
    "[hub]\ntype = \"quarter_ellipse\"\ninlet_zr_mm = [43.0, 9.0]\noutlet_zr_mm = [5.0, 38.5]\n";
const CYLINDER: &str = "[stock]\ndiameter_mm = 79.0\nheight_mm = 44.0\n";

#[test]
fn every_validation_error_names_its_field_and_line() {
    let bsp = replace(BASE, ELLIPSE_HUB, BSPLINE_HUB);
    // A B-spline hub with the weights of an exact quarter circle-like arc builds.
    assert!(from_toml_str(&bsp, "b.toml").is_ok());
    let prof = |p: &str| replace(BASE, CYLINDER, &format!("[stock]\nprofile_zr_mm = {p}\n"));
    let cases: Vec<(String, &str)> = vec![
        (
            replace(BASE, "name = \"impeller-8+8\"", "name = \" \""),
            "name",
        ),
        (
            replace(BASE, "fillet_radius_mm = 1.0", "fillet_radius_mm = -1.0"),
            "fillet_radius_mm",
        ),
        (
            replace(BASE, "fillet_radius_mm = 1.0", "fillet_radius_mm = nan"),
            "fillet_radius_mm",
        ),
        (
            replace(
                BASE,
                "inlet_zr_mm = [43.0, 9.0]",
                "inlet_zr_mm = [43.0, -9.0]",
            ),
            "hub.inlet_zr_mm",
        ),
        (
            replace(
                BASE,
                "inlet_zr_mm = [43.0, 9.0]",
                "inlet_zr_mm = [inf, 9.0]",
            ),
            "hub.inlet_zr_mm",
        ),
        (
            replace(
                BASE,
                "outlet_zr_mm = [5.0, 38.5]",
                "outlet_zr_mm = [5.0, -38.5]",
            ),
            "hub.outlet_zr_mm",
        ),
        (
            replace(
                BASE,
                "outlet_zr_mm = [5.0, 38.5]",
                "outlet_zr_mm = [43.0, 38.5]",
            ),
            "hub.outlet_zr_mm",
        ),
        (
            replace(
                BASE,
                "outlet_zr_mm = [5.0, 38.5]",
                "outlet_zr_mm = [5.0, 9.0]",
            ),
            "hub.outlet_zr_mm",
        ),
        (
            replace(
                BASE,
                "inlet_zr_mm = [43.0, 22.0]",
                "inlet_zr_mm = [43.0, -1.0]",
            ),
            "shroud.inlet_zr_mm",
        ),
        (replace(&bsp, "degree = 2", "degree = 0"), "hub.degree"),
        (
            replace(&bsp, "degree = 2", "degree = 3"),
            "hub.control_points_zr_mm",
        ),
        (
            replace(&bsp, "[5.0, 9.0], [5.0", "[5.0, -9.0], [5.0"),
            "hub.control_points_zr_mm[1]",
        ),
        (
            replace(&bsp, "weights = [1.0, 0.7, 1.0]", "weights = [1.0, 0.7]"),
            "hub.weights",
        ),
        (
            replace(
                &bsp,
                "weights = [1.0, 0.7, 1.0]",
                "weights = [1.0, 0.0, 1.0]",
            ),
            "hub.weights[1]",
        ),
        (
            replace(BASE, "count = 8\nkind", "count = 0\nkind"),
            "main.count",
        ),
        (
            replace(BASE, "span_extension = 0.08", "span_extension = 0.7"),
            "main.span_extension",
        ),
        (
            replace(
                BASE,
                "thickness_mm = [[0.0, 0.8], [1.0, 0.8]]",
                "thickness_mm = []",
            ),
            "main.thickness_mm",
        ),
        (
            replace(
                BASE,
                "thickness_mm = [[0.0, 0.8], [1.0, 0.8]]",
                "thickness_mm = [[0.0, 0.8], [1.0, 0.0]]",
            ),
            "main.thickness_mm[1][1]",
        ),
        (
            replace(
                BASE,
                "thickness_mm = [[0.0, 0.8], [1.0, 0.8]]",
                "thickness_mm = [[0.0, 0.8], [1.5, 0.8]]",
            ),
            "main.thickness_mm[1][0]",
        ),
        (
            replace(
                BASE,
                "thickness_mm = [[0.0, 0.8], [1.0, 0.8]]",
                "thickness_mm = [[0.5, 0.8], [0.5, 0.8]]",
            ),
            "main.thickness_mm",
        ),
        (
            replace(
                BASE,
                "thickness_mm = [[0.0, 0.8], [1.0, 0.8]]",
                "thickness_mm = [[0.0, 0.1], [0.1, 3.0], [0.2, 0.1], [1.0, 0.1]]",
            ),
            "main.thickness_mm",
        ),
        (
            replace(BASE, "kind = \"ruled\"", "kind = \"free_form\""),
            "main.wrap",
        ),
        (
            replace(FREE, "kind = \"free_form\"", "kind = \"ruled\""),
            "main.wrap",
        ),
        (
            replace(BASE, "span = 0.0", "span = 0.2"),
            "main.wrap[0].span",
        ),
        (
            replace(BASE, "span = 1.0", "span = 0.9"),
            "main.wrap[1].span",
        ),
        (
            replace(BASE, "span = 1.0", "span = 1.5"),
            "main.wrap[1].span",
        ),
        (
            replace(FREE, "span = 0.5", "span = 0.0"),
            "main.wrap[1].span",
        ),
        (
            replace(BASE, "[0.35, 12.0]", "[0.35, nan]"),
            "main.wrap[0].theta_deg[1][1]",
        ),
        (
            replace(BASE, "[0.35, 12.0]", "[0.0, 12.0]"),
            "main.wrap[0].theta_deg",
        ),
        (
            replace(
                BASE,
                "count = 8\nstart_fraction",
                "count = 7\nstart_fraction",
            ),
            "splitter.count",
        ),
        (
            replace(BASE, "start_fraction = 0.38", "start_fraction = 0.0"),
            "splitter.start_fraction",
        ),
        (
            replace(BASE, "pitch_fraction = 0.5", "pitch_fraction = 1.0"),
            "splitter.pitch_fraction",
        ),
        (
            replace(
                BASE,
                "pitch_fraction = 0.5",
                "pitch_fraction = 0.5\nthickness_mm = [[0.0, -1.0]]",
            ),
            "splitter.thickness_mm[0][1]",
        ),
        (replace(BASE, CYLINDER, "[stock]\n"), "stock"),
        (replace(BASE, "height_mm = 44.0\n", ""), "stock.height_mm"),
        (
            replace(BASE, "diameter_mm = 79.0\n", ""),
            "stock.diameter_mm",
        ),
        (
            replace(BASE, "diameter_mm = 79.0", "diameter_mm = 0.0"),
            "stock.diameter_mm",
        ),
        (
            replace(BASE, "height_mm = 44.0", "height_mm = -4.0"),
            "stock.height_mm",
        ),
        (
            replace(BASE, "diameter_mm = 79.0", "diameter_mm = 70.0"),
            "stock.diameter_mm",
        ),
        (
            replace(BASE, "height_mm = 44.0", "height_mm = 40.0"),
            "stock.height_mm",
        ),
        (prof("[[0.0, 40.0]]"), "stock.profile_zr_mm"),
        (prof("[[0.0, 40.0], [0.0, 40.0]]"), "stock.profile_zr_mm[1]"),
        (
            prof("[[0.0, 40.0], [45.0, -1.0]]"),
            "stock.profile_zr_mm[1]",
        ),
        (prof("[[0.0, 30.0], [45.0, 30.0]]"), "stock.profile_zr_mm"),
        (prof("[[0.0, 40.0], [30.0, 40.0]]"), "stock.profile_zr_mm"),
        (
            replace(
                BASE,
                "inlet_zr_mm = [43.0, 22.0]",
                "inlet_zr_mm = [43.0, 5.0]",
            ),
            "shroud",
        ),
    ];
    for (text, field) in cases {
        let e = err_of(&text);
        assert_eq!(e.field(), Some(field), "wrong field for error `{e}`");
        let msg = e.to_string();
        assert!(msg.starts_with("test.toml:"), "{msg}");
        assert!(msg.contains(field), "{msg}");
        if let ModelError::InFile { line, .. } = &e {
            assert!(*line > 0, "no line for {field}: {msg}");
        } else {
            panic!("not located in the file: {msg}");
        }
    }
    // The reported line is the one holding the offending value.
    for (from, to, field) in [
        ("span = 1.0", "span = 0.9", "main.wrap[1].span"),
        (
            "start_fraction = 0.38",
            "start_fraction = 2.0",
            "splitter.start_fraction",
        ),
        (
            "outlet_zr_mm = [11.0, 38.5]",
            "outlet_zr_mm = [11.0, -1.0]",
            "shroud.outlet_zr_mm",
        ),
    ] {
        let text = replace(BASE, from, to);
        let want = text.lines().position(|l| l.contains(to)).unwrap() + 1;
        match err_of(&text) {
            ModelError::InFile { line, source, .. } => {
                assert_eq!(line, want, "{field}");
                assert_eq!(source.field(), Some(field));
            }
            e => panic!("{e}"),
        }
    }
    // A valid profile-shaped blank builds.
    assert!(from_toml_str(&prof("[[0.0, 40.0], [20.0, 40.0], [45.0, 25.0]]"), "p.toml").is_ok());
}

#[test]
fn parse_errors_name_file_and_line() {
    let text = replace(
        BASE,
        "fillet_radius_mm = 1.0",
        "fillet_radius_mm = 1.0\ncolour = \"red\"",
    );
    match err_of(&text) {
        ModelError::Parse { line, message, .. } => {
            assert_eq!(line, 7, "{message}");
            assert!(message.contains("colour"), "{message}");
        }
        e => panic!("unexpected {e}"),
    }
    let text = replace(BASE, "count = 8\nkind", "count = \"eight\"\nkind");
    assert!(matches!(err_of(&text), ModelError::Parse { line: 19, .. }));
    let text = replace(BASE, "type = \"quarter_ellipse\"", "type = \"spiral\"");
    assert!(matches!(err_of(&text), ModelError::Parse { .. }));
    assert!(matches!(
        err_of(&BASE[..BASE.len() / 2]),
        ModelError::Parse { .. }
    ));
}

#[test]
fn load_dispatches_on_extension() {
    let e = load("/nonexistent/impeller.toml").unwrap_err();
    assert!(matches!(e, ModelError::Io { .. }), "{e}");
    assert!(e.to_string().contains("/nonexistent/impeller.toml"));
    let e = load("impeller.step").unwrap_err();
    assert!(matches!(e, ModelError::UnsupportedFormat { .. }), "{e}");
}
