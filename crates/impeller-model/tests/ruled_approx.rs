//! Ruled and sub-ruled approximation of free-form blade sides (paper 001).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use impeller_model::query::closest_point;
use impeller_model::ruled::{
    prolong_rulings, ruled_approximation, sub_ruled_strips, DeviationSide,
};
use impeller_model::{fixtures, load, Blade, Impeller, Side};

fn fixture(name: &str) -> Impeller {
    load(format!(
        "{}/../../fixtures/{name}/impeller.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
}

/// Signed deviation of the true side from a ruled surface by dense sampling (independent of
/// the library's grid and refinement): closest point from a global start, sign from the side's
/// outward normal.
fn dense_extremes(
    blade: &Blade,
    side: Side,
    r: &nurbs::NurbsSurface,
    (a, b): (f64, f64),
) -> (f64, f64) {
    let (mut hi, mut lo) = (f64::NEG_INFINITY, f64::INFINITY);
    for i in 0..=200 {
        for j in 0..=40 {
            let (u, v) = (i as f64 / 200.0, a + (b - a) * j as f64 / 40.0);
            let p = blade.side(side).point(u, v);
            let sp = closest_point(r, &p, Some((u, (v - a) / (b - a))));
            let n = r.normal(sp.u, sp.v).unwrap() * blade.outward_sign(side);
            let e = if (p - sp.point).dot(&n) >= 0.0 {
                sp.distance
            } else {
                -sp.distance
            };
            hi = hi.max(e);
            lo = lo.min(e);
        }
    }
    (hi, lo)
}

#[test]
fn ruled_approximation_matches_dense_sampling_and_shares_edges() {
    let imp = fixture("impeller-5-freeform");
    let blade = imp.main().blade();
    for side in [Side::Pressure, Side::Suction] {
        let range = blade.hub_shroud_v(side);
        let ra = ruled_approximation(blade, side, range).unwrap();
        // Shares the hub and shroud edge curves exactly.
        for i in 0..=20 {
            let u = i as f64 / 20.0;
            assert!((ra.surface.point(u, 0.0) - blade.side(side).point(u, range.0)).norm() < 1e-9);
            assert!((ra.surface.point(u, 1.0) - blade.side(side).point(u, range.1)).norm() < 1e-9);
        }
        let (hi, lo) = dense_extremes(blade, side, &ra.surface, range);
        let dense_max = hi.max(0.0).max(-lo);
        assert!(
            ra.max_deviation_mm >= dense_max - 1e-7,
            "{} < {dense_max}",
            ra.max_deviation_mm
        );
        assert!(
            ra.max_deviation_mm - dense_max < 2e-3,
            "{} vs {dense_max}",
            ra.max_deviation_mm
        );
        assert!(ra.allowance_mm >= hi - 1e-7 && ra.allowance_mm - hi.max(0.0) < 2e-3);
        assert!(ra.max_inward_mm >= -lo - 1e-7 && ra.max_inward_mm + lo.min(0.0) < 2e-3);
        let expect_side = if ra.allowance_mm >= ra.max_inward_mm {
            DeviationSide::Outside
        } else {
            DeviationSide::Inside
        };
        assert_eq!(ra.deviation_side, expect_side);
        assert!(ra.max_deviation_mm > 0.1, "a free-form blade is not ruled");
    }
}

#[test]
fn imported_blades_get_their_span_range_from_hub_and_shroud() {
    let imp = fixtures::default_impeller().unwrap();
    let b = imp.main().blade();
    // The same sides without design data, as an importer would hand them over.
    let bare =
        Blade::from_sides(b.kind(), b.pressure().clone(), b.suction().clone(), None).unwrap();
    assert_eq!(bare.hub_shroud_v(Side::Suction), (0.0, 1.0));
    let (lo, hi) = imp.span_v_range(&bare, Side::Suction).unwrap();
    let (dh, ds) = b.hub_shroud_v(Side::Suction);
    // The design rows lie on hub and shroud at the camber; the sides' edges are within the
    // extension of them.
    assert!(lo <= dh + 1e-3 && (lo - dh).abs() < 0.05, "{lo} vs {dh}");
    assert!(hi >= ds - 1e-3 && (hi - ds).abs() < 0.05, "{hi} vs {ds}");
    for i in 0..=10 {
        let u = i as f64 / 10.0;
        let p = bare.suction().point(u, lo);
        assert!(imp.hub().signed_distance(&p) <= 1e-9);
        let q = bare.suction().point(u, hi);
        assert!(imp.shroud().signed_distance(&q) >= -1e-9);
    }
}

#[test]
fn ruled_blade_is_its_own_ruled_approximation() {
    let imp = fixtures::default_impeller().unwrap();
    let blade = imp.main().blade();
    let ra = ruled_approximation(blade, Side::Suction, blade.hub_shroud_v(Side::Suction)).unwrap();
    assert!(ra.max_deviation_mm < 1e-8, "{}", ra.max_deviation_mm);
}

#[test]
fn sub_ruled_strips_meet_the_tolerance_and_are_fewest() {
    let imp = fixture("impeller-5-freeform");
    let blade = imp.main().blade();
    let side = Side::Pressure;
    let (a, b) = blade.hub_shroud_v(side);
    let tol = 0.1;
    let strips = sub_ruled_strips(blade, side, (a, b), tol).unwrap();
    assert!(
        strips.len() >= 2,
        "one ruled surface cannot meet {tol} mm here"
    );
    // Contiguous from the shroud (b) down to the hub (a).
    assert!((strips[0].v_range.1 - b).abs() < 1e-15);
    assert!((strips[strips.len() - 1].v_range.0 - a).abs() < 1e-15);
    for w in strips.windows(2) {
        assert_eq!(w[0].v_range.0, w[1].v_range.1);
    }
    for (k, s) in strips.iter().enumerate() {
        assert!(s.max_deviation_mm <= tol);
        let (hi, lo) = dense_extremes(blade, side, &s.surface, s.v_range);
        assert!(
            hi.max(-lo) <= tol * 1.02,
            "strip {k}: dense deviation {}",
            hi.max(-lo)
        );
        // Maximal: widening any strip but the last one breaks the tolerance.
        if k + 1 < strips.len() {
            let wider = (s.v_range.0 - 0.02 * (b - a), s.v_range.1);
            let ra = ruled_approximation(blade, side, wider).unwrap();
            assert!(ra.max_deviation_mm > tol, "strip {k} could be wider");
        }
    }
    assert!(sub_ruled_strips(blade, side, (a, b), 0.0).is_err());
}

/// Prolonged rulings lie on the same lines: the prolonged surface at w′ is the original at
/// w = −below + w′·(1 + below + above), within 1e-9 mm, on a free-form blade's ruled
/// approximation; bad fractions are errors.
#[test]
fn prolonged_rulings_extend_the_same_lines() {
    let imp = fixture("impeller-5-freeform");
    let blade = imp.main().blade();
    let ra =
        ruled_approximation(blade, Side::Pressure, blade.hub_shroud_v(Side::Pressure)).unwrap();
    let (below, above) = (0.7, 1.3);
    let long = prolong_rulings(&ra.surface, below, above).unwrap();
    let ((u0, u1), _) = ra.surface.domain();
    for i in 0..=20 {
        let u = u0 + (u1 - u0) * i as f64 / 20.0;
        let (a, b) = (ra.surface.point(u, 0.0), ra.surface.point(u, 1.0));
        for k in 0..=10 {
            let wp = k as f64 / 10.0;
            let w = -below + wp * (1.0 + below + above);
            let want = a + (b - a) * w;
            let got = long.point(u, wp);
            assert!(
                (got - want).norm() < 1e-9,
                "u {u} w' {wp}: {}",
                (got - want).norm()
            );
        }
    }
    assert!(prolong_rulings(&ra.surface, -0.1, 0.0).is_err());
    assert!(prolong_rulings(&ra.surface, f64::NAN, 0.0).is_err());
}
