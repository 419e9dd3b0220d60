//! The verifier's design distance behind a blunt trailing edge whose sides splay apart
//! (the NUMECA AutoGrid export of a 12 + 12 impeller, 3 mm trailing-edge face): there both
//! side distances carry a negative sign, and before the edge wedge of
//! `impeller_model::query::blunt_edge_distance` the verifier read points behind the face as
//! up to 3.4 mm inside the blade and withheld a correct hub-finishing program.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

#[path = "../../impeller-model/tests/import_common/mod.rs"]
mod import_common;

use cam_core::Point3;
use impeller_model::Side;
use machining_sim::impeller_design::ImpellerDesign;
use machining_sim::DesignModel;

fn autoblade() -> Option<impeller_model::Impeller> {
    if import_common::skip_without_shared_data() {
        return None;
    }
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/impeller-autoblade-12+12/impeller.toml");
    Some(impeller_model::load(path).unwrap())
}

#[test]
fn behind_a_splayed_trailing_edge_face_is_outside_the_blade() {
    let Some(imp) = autoblade() else { return };
    let design = ImpellerDesign::new(&imp, Default::default()).unwrap();
    let blade = imp.main().blade();
    let (ps, ss) = (blade.side(Side::Pressure), blade.side(Side::Suction));
    let ((_, u1), (v0, v1)) = ps.domain();
    let ((_, w1), _) = ss.domain();
    let mut checked = 0;
    for k in 1..10 {
        let v = v0 + (v1 - v0) * k as f64 / 10.0;
        let (p, s) = (ps.point(u1, v), ss.point(w1, v));
        let gap = (s - p).norm();
        assert!(
            gap > 1.0,
            "the export's trailing edge is blunt: {gap} mm at v = {v}"
        );
        let t = (ps.derivs2(u1, v).su.normalize() + ss.derivs2(w1, v).su.normalize()).normalize();
        let mid = 0.5 * (p + s);
        // Keep to the channel: above the hub, below the shroud.
        if design.hub_signed_distance(&Point3::from(mid)) < 1.0
            || imp.shroud().signed_distance(&mid) > -1.0
        {
            continue;
        }
        for behind in [0.2, 1.0, 3.0] {
            let q = Point3::from(mid + behind * t);
            let d = design.signed_distance(&q);
            // A lower bound of the distance, never inside; the face plane is within a few
            // degrees of normal to the mean tangent.
            assert!(
                d > 0.5 * behind && d <= behind + 1e-6 + gap,
                "{behind} mm behind the face at v = {v}: signed distance {d}"
            );
        }
        // Inside, between the edge points and 0.3 mm ahead of the face.
        let q = Point3::from(mid - 0.3 * t);
        assert!(design.signed_distance(&q) < 0.0, "inside at v = {v}");
        checked += 1;
    }
    assert!(checked >= 5, "only {checked} stations inside the channel");
    // The point the verification reported as a 3 mm overcut (hub finishing, 1 mm dexels):
    // 3.3 mm behind main blade 11's trailing-edge face.
    let reported = Point3::new(18.2534, -201.7466, 9.3653);
    let d = design.signed_distance(&reported);
    assert!(d > 3.0, "{d}");
}

fn rotor37() -> Option<impeller_model::Impeller> {
    if import_common::skip_without_shared_data() {
        return None;
    }
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/nasa-rotor37/impeller.toml");
    Some(impeller_model::load(path).unwrap())
}

#[test]
fn beyond_the_end_of_a_side_the_depth_is_the_blades_own() {
    // NASA Rotor 37's 0.44 mm trailing edges are blunt and skewed: the suction side ends
    // where the pressure side does not, so behind the suction side's end the suction side's
    // signed distance is a distance to its edge curve, not a depth below a face. An end point
    // of the default verification (0.5 mm dexels), entered through the suction side
    // 0.078 mm away, lies 0.0071 mm inside the blade and read 0.043 mm "below" that edge
    // curve; the exact swept envelopes of the program give at most 0.0065 mm of overcut
    // anywhere. Its depth is now the blade's signed distance.
    let Some(imp) = rotor37() else { return };
    let design = ImpellerDesign::new(&imp, Default::default()).unwrap();
    let p = Point3::new(161.22437634970402, -163.36256408691406, 10.75);
    let entry = Point3::new(161.22437634970402, -163.44075727212325, 10.75);
    let sd = design.signed_distance(&p);
    assert!((-0.0072..-0.0070).contains(&sd), "{sd}");
    let depth = design.depth_below(&p, &entry);
    assert!(
        depth <= -sd + 1e-9,
        "depth {depth} below the entry, {sd} signed"
    );
    // Around every blade's trailing edge of the first two, points just inside the blade
    // behind the suction side's end (entered from outside the suction side's edge) read no
    // deeper than the blade's own distance.
    let mut checked = 0;
    for b in 0..2 {
        let blade = imp.main().instance(b);
        let ss = blade.side(Side::Suction);
        let ((_, w1), (v0, v1)) = ss.domain();
        for k in 1..12 {
            let v = v0 + (v1 - v0) * k as f64 / 12.0;
            let e = ss.point(w1, v);
            let d = ss.derivs2(w1, v);
            let along = d.su.normalize();
            let Some(n) = blade.outward_normal(Side::Suction, w1, v) else {
                continue;
            };
            for (ahead, inward) in [(0.02, 0.01), (0.05, 0.02), (0.1, 0.03)] {
                let q = Point3::from(e + along * ahead - n * inward);
                let sd = design.signed_distance(&q);
                if sd >= 0.0 || design.hub_signed_distance(&q) < 1.0 {
                    continue;
                }
                let foot = impeller_model::query::closest_point(ss, &q.coords, Some((w1, v)));
                if impeller_model::query::side_u_edge(&blade, Side::Suction, foot.u).is_none() {
                    continue;
                }
                let entry = Point3::from(q.coords + n * (inward + 0.05));
                let depth = design.depth_below(&q, &entry);
                assert!(
                    depth <= -sd + 1e-9,
                    "blade {b}, v = {v}: depth {depth} against the blade's {}",
                    -sd
                );
                checked += 1;
            }
        }
    }
    assert!(
        checked >= 10,
        "only {checked} points behind the suction side's end"
    );
}
