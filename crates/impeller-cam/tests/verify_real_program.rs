//! The verification of a real program stays what it was before the verifier was made
//! faster (issue 38): `impeller-cam verify` on `fixtures/impeller-8+8/program-sample.cls`
//! (the first 400 moves of each operation of the default job, five tools, roughing to
//! blade-root finishing, on the uncut blank) at 0.25 mm reads the figures machining-sim gave
//! at commit f3e5115, before the speed-ups (9e4c1da read the same except the maps' overcut
//! sum, 1.079343 mm, before 7d82f66's depth rule at blade top edges): the same final stock (the hash of its surface
//! mesh, the removed volume, the cut end points inside the design), the same collisions and
//! the same maps, overcut and residual.
//!
//! Since the blade-root fillets became design (machining-sim `fillet_design`, 2026-11-28) the
//! design-dependent figures read the filleted design: cut end points inside the design
//! 2083 → 2366 (the blade-root ball, as large as the fillet, ends its rays on the fillet
//! surface), map samples 49 912 → 47 064 (hub and side samples under the fillets left out,
//! the fillet surfaces sampled), their overcut sum 1.0784 → 1.2751 mm and residual sum
//! 113 323.70 → 110 765.89 mm; the stock, the removed volume, the collisions and the largest
//! overcut (0.0408 mm on main2_tip) are unchanged.
//!
//! Since the normal probes read the depth of the removed points on the rays they read
//! (machining-sim `measure`, issue 31, 2026-11-28), a probe beside a blade's top edge no
//! longer credits a ray passing beside it in air: the largest overcut 0.0408 mm on main2_tip
//! (the exact swept envelopes there: 0.0) → 0.0100 mm on main1_fillet_pressure (envelopes
//! 0.0086 mm), the maps' overcut sum 1.2751 → 1.0070 mm; stock, volume, collisions, residual
//! and sample count are unchanged.
//!
//! The speed-ups are exact (culling and caching that change no ray and no distance), so
//! the figures are compared to 10⁻⁹ (relative for the volume), far inside the overcut error
//! bound the report states (0.109 mm here). A change that moves them on purpose (a new
//! removal or measurement method) must show it stays within that bound and update the
//! figures here with the reason.
#![allow(clippy::unwrap_used)] // test helpers

mod common;

use common::repo;

use std::process::Command;

/// FNV-1a, 64 bits (a fixed hash: the figure below must not depend on the Rust version).
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

fn close(a: f64, b: f64, tol: f64, what: &str) {
    assert!((a - b).abs() <= tol, "{what}: {a} against {b} (before)");
}

#[test]
fn verification_of_a_real_program_is_unchanged() {
    let out = common::scratch("impeller-cam-real", "verify");
    let st = Command::new(env!("CARGO_BIN_EXE_impeller-cam"))
        .arg("verify")
        .arg("--impeller")
        .arg(repo().join("fixtures/impeller-8+8/impeller.toml"))
        .arg("--cl")
        .arg(repo().join("fixtures/impeller-8+8/program-sample.cls"))
        .args(["--resolution", "0.25", "--stl-stride", "2", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let read = |name: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(out.join(name)).unwrap()).unwrap()
    };
    let s = read("summary.json");
    let stats = &s["stats"];
    // The stock: every dexel crossing the surface mesh reads at a 0.5 mm lattice, the
    // removed volume, the spilled rays' memory and the cut end points inside the design.
    let stl = std::fs::read(out.join("stock.stl")).unwrap();
    assert_eq!(stl.len(), 16_951_084);
    assert_eq!(
        fnv1a(&stl),
        0x550d_f97d_7d93_1720,
        "final stock surface changed"
    );
    assert_eq!(stats["positions"], 5866);
    assert_eq!(stats["moves"], 2000);
    assert_eq!(stats["stock_memory_bytes"], 6_842_040);
    assert_eq!(stats["endpoints_inside_design"], 2366);
    let v = stats["removed_volume_mm3"].as_f64().unwrap();
    close(v, 28_926.513_760_843_25, 1e-9 * v, "removed volume");
    // The verdict: overcut, residual, their bound and the collisions (rapids of the
    // finishing tools into the uncut blank), move by move.
    close(
        s["max_overcut_mm"].as_f64().unwrap(),
        0.009_976_287_916_065_196,
        1e-9,
        "max overcut",
    );
    assert_eq!(s["max_overcut"]["surface"], "main1_fillet_pressure");
    close(
        s["max_residual_mm"].as_f64().unwrap(),
        3.0,
        1e-9,
        "residual",
    );
    // The simulation's 0.109375 mm plus the design model's stated error, the blade-root
    // fillets' spine fit (9.47e-5 mm; `DesignModel::model_error_mm`, 2026-11-28).
    close(
        s["overcut_error_bound_mm"].as_f64().unwrap(),
        0.109_470_592_115_391_97,
        1e-12,
        "bound",
    );
    assert_eq!(s["collisions"], 10);
    let before = [
        ("blade-semi", 1, 15.805_578_231_811_523),
        ("blade-semi", 156, 1.788_973_808_288_574_2),
        ("blade-semi", 311, 15.805_578_231_811_523),
        ("blade-finish", 1, 2.055_587_768_554_687_5),
        ("blade-root", 1, 6.220_249_176_025_391),
        ("blade-root", 71, 0.226_419_448_852_539_06),
        ("blade-root", 141, 12.543_704_986_572_266),
        ("blade-root", 211, 2.905_443_191_528_320_3),
        ("blade-root", 281, 15.005_310_058_593_75),
        ("blade-root", 351, 2.905_443_191_528_320_3),
    ];
    let list = s["collision_list"].as_array().unwrap();
    assert_eq!(list.len(), before.len());
    for (c, (op, mv, depth)) in list.iter().zip(before) {
        assert_eq!(c["operation"], op, "{c}");
        assert_eq!(c["move_index"], mv, "{c}");
        assert_eq!(c["part"], "rapid_move", "{c}");
        assert_eq!(c["target"], "stock", "{c}");
        close(
            c["depth_mm"].as_f64().unwrap(),
            depth,
            1e-9,
            "collision depth",
        );
    }
    // The maps: every sample's overcut and residual (count and sums).
    let maps = read("maps.json");
    let (mut n, mut overcut, mut residual) = (0usize, 0.0, 0.0);
    for m in maps["surfaces"].as_array().unwrap() {
        for (o, r) in m["overcut_mm"]
            .as_array()
            .unwrap()
            .iter()
            .zip(m["residual_mm"].as_array().unwrap())
        {
            if let (Some(o), Some(r)) = (o.as_f64(), r.as_f64()) {
                n += 1;
                overcut += o;
                residual += r;
            }
        }
    }
    assert_eq!(n, 47_064);
    close(
        overcut,
        1.006_995_037_704_868_6,
        1e-9,
        "sum of map overcuts",
    );
    close(residual, 110_765.886_718_75, 1e-6, "sum of map residuals");
}
