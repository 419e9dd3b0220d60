//! `impeller-cam verify` and `impeller-cam post` as binaries, on the impeller-8+8 fixture's
//! top-ring CL file (a five-axis cut in the blank above the shroud contour: outside the design).
#![allow(clippy::unwrap_used)] // test helpers

mod common;

use common::repo;

use std::process::Command;

fn cli() -> Command {
    Command::new(env!("CARGO_BIN_EXE_impeller-cam"))
}

fn scratch(name: &str) -> common::Scratch {
    common::scratch("impeller-cam-vp", name)
}

#[test]
fn verify_writes_summary_maps_and_a_valid_stl() {
    let out = scratch("verify");
    let st = cli()
        .arg("verify")
        .arg("--impeller")
        .arg(repo().join("fixtures/impeller-8+8/impeller.toml"))
        .arg("--cl")
        .arg(repo().join("fixtures/impeller-8+8/top-ring.cls"))
        .args(["--resolution", "0.5", "--crosscheck", "5", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let overcut = summary["max_overcut_mm"].as_f64().unwrap();
    // The ring never enters the design: no overcut beyond one 0.5 mm cell.
    assert!(overcut <= 0.5, "{overcut}");
    assert_eq!(summary["collisions"], 0, "{summary}");
    assert!(summary["max_residual_mm"].as_f64().unwrap() > 0.0);
    assert_eq!(summary["stats"]["moves"], 74);
    assert!(out.join("maps.json").is_file());
    // Binary STL: 80-byte header, triangle count, 50 bytes per triangle.
    let stl = std::fs::read(out.join("stock.stl")).unwrap();
    assert!(stl.len() > 84);
    let n = u32::from_le_bytes([stl[80], stl[81], stl[82], stl[83]]) as usize;
    assert!(n > 1000, "{n} triangles");
    assert_eq!(stl.len(), 84 + 50 * n);
}

#[test]
fn post_writes_a_program_and_rejects_unknown_dialects_in_one_line() {
    let out = scratch("post");
    let cl = repo().join("fixtures/impeller-8+8/top-ring.cls");
    let machine = repo().join("fixtures/machines/xyzac-trt.toml");
    let prog = out.join("ring.ngc");
    let st = cli()
        .arg("post")
        .arg(&cl)
        .arg("--machine")
        .arg(&machine)
        .args(["--dialect", "linuxcnc", "--out"])
        .arg(&prog)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let text = std::fs::read_to_string(&prog).unwrap();
    assert!(text.contains("G93") && text.contains("M2"), "{text}");
    assert!(
        !text.contains("e-") && !text.contains("E-"),
        "no exponent notation"
    );
    let st = cli()
        .arg("post")
        .arg(&cl)
        .arg("--machine")
        .arg(&machine)
        .args(["--dialect", "mazak", "--out"])
        .arg(out.join("x.nc"))
        .output()
        .unwrap();
    assert_eq!(st.status.code(), Some(1));
    let err = String::from_utf8_lossy(&st.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains("linuxcnc") && err.contains("heidenhain"),
        "{err}"
    );
    assert!(!out.join("x.nc").exists(), "no partial output");
}
