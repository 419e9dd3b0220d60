//! The blade-root fillets in a ball's clearance (`cam_plan::FilletMargin`) on
//! impeller-11+11-freeform (fillet radius 1.5 mm): a Ø3 ball hanging over a fillet's outlet
//! end beyond the hub's rim, which the sharp design reads clear, is found to cut the fillet
//! (the point-milling posture that gouged 0.08 mm there), and a ball riding a blade side
//! above the fillet is not held off by the bound.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use cam_core::{Cutter, CutterLocation, CutterShape, Point3, Vector3};
use cam_plan::{
    ClearanceOptions, DesignClearance, DesignPart, FilletMargin, PassCheck, PassFloors, Tool,
};
use impeller_model::Impeller;
use std::sync::OnceLock;

fn impeller() -> &'static Impeller {
    static IMP: OnceLock<Impeller> = OnceLock::new();
    IMP.get_or_init(|| {
        impeller_model::load(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../fixtures/impeller-11+11-freeform/impeller.toml"
        ))
        .unwrap()
    })
}

fn margin() -> &'static FilletMargin {
    static F: OnceLock<FilletMargin> = OnceLock::new();
    F.get_or_init(|| FilletMargin::new(impeller()).unwrap().unwrap())
}

fn ball_tool() -> Tool {
    let cutter = Cutter::new("b3", CutterShape::BallEnd { radius: 1.5 }, 20.0, 3.0, 40.0).unwrap();
    Tool {
        number: 1,
        cutter,
        teeth: 2,
        tool_length_mm: 100.0,
        plunge_edge_length_mm: None,
    }
}

/// The ball centre of the gouging posture: 0.7 mm beyond the hub's outlet rim (r = 70 mm),
/// 1.5 mm off a blade's suction side.
const BEYOND_RIM: [f64; 3] = [1.044, -70.715, 8.315];
const R: f64 = 1.5;

#[test]
fn a_ball_over_a_fillets_end_is_caught_and_really_overlaps_the_fillet() {
    let tool = ball_tool();
    let q = DesignClearance::new(impeller(), &tool, ClearanceOptions::default()).unwrap();
    let c = Vector3::from(BEYOND_RIM);
    let p = Point3::from(c);
    // The sharp design reads the ball (nearly) clear: hub and blade both about R away.
    let hub = q.hub_signed_distance(&p);
    let blade = q.blade_signed_distance(&p).0;
    assert!(
        hub >= R - 0.01 && blade >= R - 0.01,
        "hub {hub}, blade {blade}"
    );
    // The fillet bound does not.
    let f = margin().clearance(&q, &c, R, 0.0);
    assert!(f < -0.05, "fillet clearance {f}");
    // And the overlap is real: fillet material (the verifier's fillet distance negative)
    // lies within 1.45 mm of the centre.
    let fillets = margin().fillets();
    let mut inside = 0;
    for i in 0..40 {
        for j in 0..80 {
            let (th, ph) = (
                std::f64::consts::PI * (i as f64 + 0.5) / 40.0,
                std::f64::consts::TAU * j as f64 / 80.0,
            );
            let dir = Vector3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
            let x = c + dir * (R - 0.05);
            if fillets.closest(&x).is_some_and(|(d, _)| d < 0.0) {
                inside += 1;
            }
        }
    }
    assert!(inside > 0, "no fillet material within {} mm", R - 0.05);
}

#[test]
fn a_ball_beside_a_side_above_the_fillet_is_not_held_off() {
    // 5.7 mm above the hub, 1.5 mm off a splitter's pressure side: the material bound was
    // 1.395 mm (the corner's sector, 6.6 mm wide at the suction side's acute root, reached
    // into the walls); the fillets are farther than the ball's radius.
    let tool = ball_tool();
    let q = DesignClearance::new(impeller(), &tool, ClearanceOptions::default()).unwrap();
    let c = Vector3::new(22.807946157, 58.545506228, 13.172013242);
    let f = margin().clearance(&q, &c, R, 0.0);
    assert!(f >= 0.0, "fillet clearance {f}");
}

#[test]
fn pass_checks_with_fillets_refuse_the_posture_and_the_motion_into_it() {
    let tool = ball_tool();
    let q = DesignClearance::new(impeller(), &tool, ClearanceOptions::default()).unwrap();
    let floors = PassFloors {
        blades_mm: -0.01,
        hub_mm: -0.01,
        motion_tol_mm: 0.01,
    };
    let plain = PassCheck::new(&q, floors, 0.0);
    let check = PassCheck::new(&q, floors, 0.0).with_fillets(Some(margin()));
    // The axis leans away from hub and side: up, outward and along the side's normal
    // (the blade distance's gradient, central differences).
    let c0 = Vector3::from(BEYOND_RIM);
    let bd = |v: Vector3| q.blade_signed_distance(&Point3::from(v)).0;
    let h = 1e-5;
    let n = Vector3::new(
        bd(c0 + Vector3::x() * h) - bd(c0 - Vector3::x() * h),
        bd(c0 + Vector3::y() * h) - bd(c0 - Vector3::y() * h),
        bd(c0 + Vector3::z() * h) - bd(c0 - Vector3::z() * h),
    )
    .normalize();
    let axis = n + Vector3::z() + Vector3::new(c0.x, c0.y, 0.0).normalize() * 0.5;
    let at =
        |c: Vector3| CutterLocation::new(Point3::from(c - axis.normalize() * R), axis).unwrap();
    let gouge = at(Vector3::from(BEYOND_RIM));
    let v = check.posture(0, &gouge).expect("the fillet is cut");
    assert_eq!(v.design_part, DesignPart::Fillet);
    assert!(v.depth_mm() > 0.04, "{v:?}");
    // Without the fillets the sharp design lets it through (or finds less than the fillet).
    assert!(plain
        .posture(0, &gouge)
        .is_none_or(|w| w.design_part != DesignPart::Fillet));
    // A motion from 3 mm farther out to the gouging posture crosses into the fillet; one
    // that stays out is certified.
    let out = at(Vector3::from(BEYOND_RIM) + Vector3::new(0.0, -3.0, 1.0));
    let out2 = at(Vector3::from(BEYOND_RIM) + Vector3::new(0.0, -3.0, 3.0));
    let f = margin();
    assert!(f
        .certify_motion(&q, &out, &gouge, R, R, -0.01, 0.01, 48)
        .is_err());
    assert!(f
        .certify_motion(&q, &out, &out2, R, R, -0.01, 0.01, 48)
        .is_ok());
}
