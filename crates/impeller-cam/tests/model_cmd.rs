//! `impeller-cam model`: JSON summary of a fixture, exit code 1 with one line on user errors.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::process::Command;

fn cli() -> Command {
    Command::new(env!("CARGO_BIN_EXE_impeller-cam"))
}

#[test]
fn prints_the_fixture_summary_as_json() {
    let path = format!(
        "{}/../../fixtures/impeller-8+8/impeller.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let out = cli().args(["model", &path, "--json"]).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["main_blade_count"], 8);
    assert_eq!(v["splitter_blade_count"], 8);
    for key in [
        "blade_tip_diameter_mm",
        "axial_height_mm",
        "min_channel_width_hub_mm",
        "min_channel_width_shroud_mm",
        "min_blade_thickness_mm",
    ] {
        assert!(v[key].as_f64().unwrap() > 0.0, "{key}");
    }
    assert!((v["blade_tip_diameter_mm"].as_f64().unwrap() - 77.0).abs() < 0.2);
}

#[test]
fn user_errors_exit_1_with_one_line() {
    let dir = std::env::temp_dir().join(format!("impeller-cam-model-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "name = \"x\"\nfillet_radius_mm = -1\n").unwrap();
    for args in [
        vec!["model".to_string(), "/nonexistent/x.toml".to_string()],
        vec!["model".to_string(), "x.step".to_string()],
        vec!["model".to_string(), bad.display().to_string()],
    ] {
        let out = cli().args(&args).output().unwrap();
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.starts_with("error: "), "{err}");
        assert!(!err.contains("panicked"));
    }
    std::fs::remove_dir_all(&dir).ok();
}
