use super::*;
use cam_core::{CutterShape, Point3, Vector3};
use impeller_model::Side;

fn ball_tool(r: f64, flute: f64, stick_out: f64) -> Tool {
    Tool {
        number: 1,
        cutter: Cutter::new(
            "ball",
            CutterShape::BallEnd { radius: r },
            flute,
            r,
            stick_out,
        )
        .unwrap(),
        teeth: 2,
        tool_length_mm: stick_out,
        plunge_edge_length_mm: None,
    }
}

/// A point on the hub surface at mid-meridian, at the polar angle farthest from every
/// blade (scanned over one main pitch in 0.5° steps), and the hub's unit normal there.
fn hub_point_mid_channel(imp: &Impeller, clearance: &DesignClearance<'_>) -> (Point3, Vector3) {
    let (t0, t1) = imp.hub().meridional().domain();
    let t = 0.5 * (t0 + t1);
    let steps = (imp.main().pitch_rad().to_degrees() * 2.0).ceil() as usize;
    let best = (0..steps)
        .map(|k| {
            let phi = (k as f64 * 0.5).to_radians();
            let p = Point3::from(imp.hub().point(t, phi) + imp.hub().normal(t, phi));
            (clearance.blade_signed_distance(&p).0, phi)
        })
        .fold(
            (f64::NEG_INFINITY, 0.0),
            |a, b| if b.0 > a.0 { b } else { a },
        );
    let phi = best.1;
    (
        Point3::from(imp.hub().point(t, phi)),
        imp.hub().normal(t, phi),
    )
}

#[test]
fn gouge_check_accepts_a_ball_resting_on_the_hub_and_rejects_it_lower() {
    let imp = impeller_model::fixtures::default_impeller().unwrap();
    let tool = ball_tool(0.5, 2.0, 3.0);
    let clearance = DesignClearance::new(&imp, &tool, ClearanceOptions::default()).unwrap();
    let (p, n) = hub_point_mid_channel(&imp, &clearance);
    let check = GougeCheck::with(clearance, 0.01);
    let on = CutterLocation::new(p, n).unwrap();
    assert!(check.is_accessible(&on));
    let below = CutterLocation::new(p - n * 0.02, n).unwrap();
    assert!(!check.is_accessible(&below));
}

#[test]
fn gouge_check_rejects_a_plunge_into_a_blade_and_accepts_a_posture_above_the_blank() {
    let imp = impeller_model::fixtures::default_impeller().unwrap();
    let tool = ball_tool(3.0, 20.0, 40.0);
    let clearance = DesignClearance::new(&imp, &tool, ClearanceOptions::default()).unwrap();
    let check = GougeCheck::with(clearance, 0.01);
    let blade = imp.main().blade();
    let (ps, ss) = (blade.side(Side::Pressure), blade.side(Side::Suction));
    let ((u0, u1), (v0, v1)) = ps.domain();
    let (u, v) = (0.5 * (u0 + u1), 0.5 * (v0 + v1));
    let mid = Point3::from(0.5 * (ps.point(u, v) + ss.point(u, v)));
    let radial = Vector3::new(mid.x, mid.y, 0.0);
    for axis in [Vector3::z(), radial, Vector3::new(mid.x, mid.y, 30.0)] {
        let cl = CutterLocation::new(mid, axis).unwrap();
        assert!(!check.is_accessible(&cl), "{axis:?}");
    }
    let top = imp.summary().axial_height_mm;
    let t = 10f64.to_radians();
    let cl = CutterLocation::new(
        Point3::new(30.0, 0.0, top + 2.0),
        Vector3::new(t.sin(), 0.0, t.cos()),
    )
    .unwrap();
    assert!(check.is_accessible(&cl));
}
