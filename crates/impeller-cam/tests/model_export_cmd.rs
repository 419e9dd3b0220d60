//! `impeller-cam model --stl FILE --curves DIR`: exports that read back.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::process::Command;

fn cli() -> Command {
    Command::new(env!("CARGO_BIN_EXE_impeller-cam"))
}

#[test]
fn stl_and_curves_of_the_default_impeller() {
    let dir = std::env::temp_dir().join(format!("impeller-cam-export-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let stl = dir.join("impeller.stl");
    let curves = dir.join("curves");
    let out = cli()
        .args(["model", "--json", "--chord-tol", "0.05", "--stl"])
        .arg(&stl)
        .arg("--curves")
        .arg(&curves)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // stdout stays pure JSON; the export notes go to stderr.
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["main_blade_count"], 8);
    let bytes = std::fs::read(&stl).unwrap();
    let n = u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as usize;
    assert!(n > 0 && bytes.len() == 84 + 50 * n);
    // The curve set reads back with the same blade counts and tip diameter.
    let out = cli()
        .args(["model", "--json"])
        .arg(curves.join("impeller.inf"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let w: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(w["main_blade_count"], 8);
    assert_eq!(w["splitter_blade_count"], 8);
    let (a, b) = (
        v["blade_tip_diameter_mm"].as_f64().unwrap(),
        w["blade_tip_diameter_mm"].as_f64().unwrap(),
    );
    assert!((a - b).abs() < 0.5, "{a} vs {b}");
    // An unwritable STL path: exit 1, one line, nothing left behind.
    let out = cli()
        .args(["model", "--stl"])
        .arg(dir.join("no/such/dir/x.stl"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(!err.contains("panicked"));
    let _ = std::fs::remove_dir_all(&dir);
}
