//! Blade-root finishing on the fixtures: ball centres at ball-radius distance from hub and
//! blade side, accessible, no overcut; a clear error or a plan on the narrow impeller.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod support;

use cam_plan::OperationSpec;
use channel_paths::blade_root::plan_side;
use impeller_model::{query::blade_side_distance, Side};

fn spec(params: &str) -> OperationSpec {
    OperationSpec {
        name: "root".into(),
        kind: channel_paths::BLADE_ROOT_FINISHING.into(),
        tool: "ball-r1".into(),
        process: support::process(),
        params: toml::from_str(params).unwrap(),
    }
}

#[test]
fn centres_are_at_ball_radius_from_hub_and_blade_and_accessible() {
    // Ball radius = the 1 mm fillet (paper 003 T7): the centre is on both offset surfaces.
    let c = support::Ctx::new("impeller-8+8", 1.0);
    let cl = c.clearance();
    let ctx = plan_ctx!(c, cl);
    let order = c.imp.blades_in_order();
    let n = order.len();
    for side in [Side::Pressure, Side::Suction] {
        let pos = plan_side(
            &ctx,
            "root",
            "main blade 0",
            &order[0],
            side,
            &order[1],
            &order[n - 1],
            8,
            1.5f64.to_radians(),
        )
        .unwrap();
        // 8 uniform stations, refined where the chord strays from the root curve.
        assert!(pos.len() > 8, "{} positions", pos.len());
        // Between two positions the ball centre runs on their chord: its midpoint stays within
        // machining_tol of both offset surfaces (the distances are 1-Lipschitz, so a chord
        // within tol of the root curve keeps them within tol of the ball radius).
        // (Midpoints within a ball radius of the hub's inlet plane are left out: beyond the
        // end of the hub contour its signed distance is not the offset surface's.)
        let tol = c.tol.machining_tol;
        let hub = c.imp.hub().meridional();
        let z_inlet = hub
            .point_at_fraction(0.0)
            .x
            .max(hub.point_at_fraction(1.0).x);
        let mut checked = 0;
        for w in pos.windows(2) {
            let mid = 0.5 * (w[0].centre + w[1].centre);
            if mid.z > z_inlet - 1.0 {
                continue;
            }
            checked += 1;
            let dh = c.imp.hub().signed_distance(&mid);
            let (_, db) = blade_side_distance(&order[0], side, &mid, None);
            assert!(
                (dh - 1.0).abs() <= tol + 1e-9,
                "chord midpoint hub distance {dh}"
            );
            assert!(
                (db - 1.0).abs() <= tol + 1e-9,
                "chord midpoint blade distance {db}"
            );
        }
        assert!(checked >= 6, "{checked} chords checked");
        for p in pos.iter().filter(|p| p.centre.z <= z_inlet - 1.0) {
            let dh = c.imp.hub().signed_distance(&p.centre);
            let (_, db) = blade_side_distance(&order[0], side, &p.centre, None);
            assert!((dh - 1.0).abs() < 1e-6, "hub distance {dh}");
            assert!((db - 1.0).abs() < 1e-6, "blade distance {db}");
            assert!(p.clearance >= -c.tol.machining_tol, "{}", p.clearance);
            assert!(p.overcut < 1e-6, "{}", p.overcut);
            assert!((p.axis.norm() - 1.0).abs() < 1e-12);
        }
    }
}

#[test]
fn full_plan_on_impeller_8_8_has_no_overcut() {
    let c = support::Ctx::new("impeller-8+8", 1.0);
    let cl = c.clearance();
    let ctx = plan_ctx!(c, cl);
    let op = channel_paths::build_blade_root_finishing(&spec("stations = 3")).unwrap();
    let planned = op.plan(&ctx).unwrap();
    // 8 main + 8 splitter blades, two sides each.
    assert_eq!(planned.paths.len(), 32);
    let over = planned
        .metrics
        .get("max_overcut_mm")
        .unwrap()
        .as_f64()
        .unwrap();
    let under = planned
        .metrics
        .get("max_undercut_mm")
        .unwrap()
        .as_f64()
        .unwrap();
    assert!(over < 1e-6, "{over}");
    assert!(
        under < 1e-6,
        "ball = fillet leaves the fillet exactly: {under}"
    );
    let clear = planned
        .metrics
        .get("min_blade_clearance_mm")
        .unwrap()
        .as_f64()
        .unwrap();
    assert!(clear >= -c.tol.machining_tol, "{clear}");
}

#[test]
fn unknown_keys_and_bad_values_are_errors() {
    assert!(channel_paths::build_blade_root_finishing(&spec("statons = 3")).is_err());
    assert!(channel_paths::build_blade_root_finishing(&spec("step_deg = 0.0")).is_err());
}

#[test]
fn narrow_impeller_is_finished_or_names_the_largest_ball() {
    let c = support::Ctx::new("impeller-30-narrow", 1.0);
    let cl = c.clearance();
    let ctx = plan_ctx!(c, cl);
    let op = channel_paths::build_blade_root_finishing(&spec("stations = 5")).unwrap();
    match op.plan(&ctx) {
        Ok(p) => {
            let over = p.metrics.get("max_overcut_mm").unwrap().as_f64().unwrap();
            assert!(over < 1e-6, "{over}");
        }
        Err(e) => {
            let msg = e.to_string();
            eprintln!("{msg}");
            assert!(
                msg.contains("blade") && msg.contains("largest ball radius"),
                "{msg}"
            );
        }
    }
}
