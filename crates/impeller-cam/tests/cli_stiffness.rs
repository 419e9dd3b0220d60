//! `impeller-cam stiffness` end to end: JSON contract and user errors.
#![allow(clippy::approx_constant)] // 3.14 mm is a published cutter radius, not π.

use std::process::Command;

fn cli() -> Command {
    Command::new(env!("CARGO_BIN_EXE_impeller-cam"))
}

#[test]
fn json_has_the_contract_fields_and_matches_the_closed_form() {
    let out = cli()
        .args([
            "stiffness",
            "--tip-radius",
            "3.14",
            "--half-angle",
            "3",
            "--length",
            "40",
            "--youngs",
            "600",
            "--json",
        ])
        .output()
        .unwrap();
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let k = v["stiffness_n_per_mm"].as_f64().unwrap();
    let exact = v["exact_n_per_mm"].as_f64().unwrap();
    // k = 3πE r R³ / (4L³), R = r + L tan θ, E = 600 000 N/mm².
    let r_big = 3.14 + 40.0 * 3f64.to_radians().tan();
    let closed = 3.0 * std::f64::consts::PI * 600e3 * 3.14 * r_big.powi(3) / (4.0 * 40f64.powi(3));
    assert!((exact / closed - 1.0).abs() < 1e-12);
    assert!((k / closed - 1.0).abs() < 1e-9);
    assert!(v["terms"].as_u64().unwrap() >= 2);
    // Gradient in the command's own parameters: ∂k/∂r (θ, L held), ∂k/∂θ per degree.
    let c = 3.0 * std::f64::consts::PI * 600e3 / (4.0 * 40f64.powi(3));
    let dk_dr = c * (r_big.powi(3) + 3.0 * 3.14 * r_big.powi(2));
    let sec2 = 1.0 / 3f64.to_radians().cos().powi(2);
    let dk_dt_deg = c * 3.0 * 3.14 * r_big.powi(2) * 40.0 * sec2 * std::f64::consts::PI / 180.0;
    let gr = v["d_stiffness_d_radius"].as_f64().unwrap();
    let gt = v["d_stiffness_d_half_angle_deg"].as_f64().unwrap();
    assert!((gr / dk_dr - 1.0).abs() < 1e-6, "{gr} vs {dk_dr}");
    assert!((gt / dk_dt_deg - 1.0).abs() < 1e-6, "{gt} vs {dk_dt_deg}");
}

#[test]
fn invalid_values_exit_1_with_one_line() {
    let out = cli()
        .args(["stiffness", "--tip-radius", "-1", "--length", "40"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    // The command line's own names (it said `bottom_radius` = -1).
    assert!(
        err.contains("--tip-radius -1: must be a radius > 0 mm"),
        "{err}"
    );
    assert!(!err.contains("panicked"));
    let out = cli()
        .args([
            "stiffness",
            "--tip-radius",
            "3",
            "--half-angle",
            "95",
            "--length",
            "40",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8(out.stderr).unwrap();
    // It said `ball_radius` = -0.26.
    assert!(
        err.contains("--half-angle 95: must be an angle in [0, 90) degrees"),
        "{err}"
    );
}
