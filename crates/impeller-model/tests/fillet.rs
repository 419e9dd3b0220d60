//! The blade-root fillet on the fixture impellers: every section's rolling ball is the
//! fillet radius from the hub (exact) and from its blade side (global closest point), and
//! the fitted spine and the arcs stay within the fit tolerance of exact sections solved
//! anywhere (not only at the stations the fit used).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use impeller_model::fillet::{BladeFillet, FilletSection, DEFAULT_FILLET_TOL_MM};
use impeller_model::query::blade_side_distance;
use impeller_model::{fixtures, Impeller, Side};

fn check(imp: &Impeller, name: &str) {
    let r = imp.fillet_radius_mm();
    assert!(r > 0.0);
    let hub = imp.hub();
    let mut rows = vec![("main", imp.main().blade())];
    if let Some(s) = imp.splitter() {
        rows.push(("splitter", s.blade()));
    }
    for (row, blade) in rows {
        for side in [Side::Pressure, Side::Suction] {
            let f = BladeFillet::build(hub, blade, side, r, DEFAULT_FILLET_TOL_MM)
                .unwrap_or_else(|e| panic!("{name} {row} {side:?}: {e}"));
            let ((u0, u1), _) = blade.side(side).domain();
            let covered: f64 = f
                .pieces()
                .iter()
                .map(|p| p.u_range().1 - p.u_range().0)
                .sum();
            eprintln!(
                "{name} {row} {side:?}: {} pieces, {} stations, u covered {:.4} of {:.4}, \
                 spine error {:.2e} mm",
                f.pieces().len(),
                f.stations(),
                covered,
                u1 - u0,
                f.fit_error_mm()
            );
            assert!(!f.pieces().is_empty(), "{name} {row} {side:?}: no fillet");
            assert!(
                f.fit_error_mm() <= DEFAULT_FILLET_TOL_MM,
                "{name} {row} {side:?}: spine error {} mm",
                f.fit_error_mm()
            );
            for piece in f.pieces() {
                let (a, b) = piece.u_range();
                // Stations between the fit's (a third of the way between its midpoints).
                for k in 0..97 {
                    let u = a + (b - a) * (k as f64 + 1.0 / 3.0) / 97.0;
                    let s = FilletSection::solve(hub, blade, side, u, r).expect("section");
                    assert!((hub.signed_distance(&s.centre) - r).abs() < 1e-9);
                    let (foot, d) = blade_side_distance(blade, side, &s.centre, None);
                    assert!((d - r).abs() < 1e-6, "{name} {row} {side:?} u {u}: {d}");
                    assert!((foot.point - s.blade_foot()).norm() < 1e-4);
                    let fitted = piece.section_at(u);
                    assert!(
                        (fitted.centre - s.centre).norm() <= DEFAULT_FILLET_TOL_MM,
                        "{name} {row} {side:?} u {u}: spine off by {}",
                        (fitted.centre - s.centre).norm()
                    );
                    for j in 0..=8 {
                        let t = j as f64 / 8.0;
                        let p = s.arc_point(t);
                        assert!(((p - s.centre).norm() - r).abs() < 1e-9);
                        // On the arc the fillet's own distance is 0 (the fitted spine's
                        // error at most).
                        if let Some(d) = f.signed_distance(&p).filter(|_| (4..93).contains(&k)) {
                            assert!(
                                d.abs() <= 2.0 * DEFAULT_FILLET_TOL_MM,
                                "{row} {side:?} u {u} t {t} k {k}: {d} range {a} {b}"
                            );
                        }
                    }
                    // Halfway between the ball centre and the arc's middle: R/2 in the air
                    // (away from the piece's ends, where the spine turns around a blade
                    // edge and such a point's nearest spine point is the end).
                    let mid = 0.5 * (s.centre + s.arc_point(0.5));
                    if (4..93).contains(&k) {
                        let d = f.signed_distance(&mid).expect("in the sector");
                        assert!((d - 0.5 * r).abs() <= 2.0 * DEFAULT_FILLET_TOL_MM, "{d}");
                    }
                }
            }
        }
    }
}

#[test]
fn default_impeller_fillets_roll_on_hub_and_blades() {
    check(
        &fixtures::default_impeller().expect("default"),
        "impeller-8+8",
    );
}

fn fixture(name: &str) -> Impeller {
    let path = format!(
        "{}/../../fixtures/{name}/impeller.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    impeller_model::load(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

#[test]
fn free_form_and_narrow_fixture_fillets_roll_on_hub_and_blades() {
    for name in [
        "impeller-5-freeform",
        "impeller-11+11-freeform",
        "impeller-30-narrow",
        "impeller-plunge-400",
    ] {
        check(&fixture(name), name);
    }
}

/// Every blade of the impeller carries its row's fillet: a point in the corner of main blade
/// k and of splitter k reads, through `ImpellerFillets`, the distance its reference blade's
/// fillet gives to the point turned back by the blade's pitch angle; a point mid-channel
/// reads none.
#[test]
fn every_blade_instance_carries_its_rows_fillet() {
    use impeller_model::fillet::ImpellerFillets;
    let imp = fixtures::default_impeller().unwrap();
    let all = ImpellerFillets::new(&imp, DEFAULT_FILLET_TOL_MM)
        .unwrap()
        .unwrap();
    assert_eq!(all.instance_count(), 16);
    for (row, set) in [(0, imp.main()), (1, imp.splitter().unwrap())] {
        let reference = all.fillet(row, Side::Suction).unwrap();
        let s = FilletSection::solve(imp.hub(), set.blade(), Side::Suction, 0.5, 1.0).unwrap();
        // 0.2 mm inside the fillet on the corner's bisector.
        let into = -(s.hub_normal + s.blade_normal).normalize();
        let p = s.centre + into * 1.2;
        let want = reference.signed_distance(&p).unwrap();
        assert!((want + 0.2).abs() < 1e-3, "{want}");
        for k in 0..set.count() {
            let q = set.rotation(k) * p;
            let (got, foot) = all.closest(&q).unwrap();
            assert!(
                (got - want).abs() < 1e-9,
                "row {row} blade {k}: {got} vs {want}"
            );
            assert!(((foot - q).norm() - 0.2).abs() < 1e-3);
        }
    }
    let mid = imp.hub().point(0.5, 0.15) + imp.hub().normal(0.5, 0.15) * 0.4;
    assert!(all.closest(&mid).is_none());
}

/// `FilletPiece::material_distance_lower` never exceeds the distance to a point of fillet
/// material: material points (those `BladeFillet::signed_distance` reads inside, sampled over
/// the corner sectors of 400 fitted sections, the piece's ends included) against query points
/// around the spine and beyond its ends, on the default impeller's main suction-side fillet.
#[test]
fn the_material_bound_is_below_the_distance_to_every_material_point() {
    let imp = fixtures::default_impeller().unwrap();
    let f = BladeFillet::build(
        imp.hub(),
        imp.main().blade(),
        Side::Suction,
        imp.fillet_radius_mm(),
        DEFAULT_FILLET_TOL_MM,
    )
    .unwrap();
    let piece = &f.pieces()[0];
    let (u0, u1) = piece.u_range();
    let r = f.radius();
    let mut material = Vec::new();
    for k in 0..400 {
        let u = u0 + (u1 - u0) * k as f64 / 399.0;
        let s = piece.section_at(u);
        let (a, b) = (-s.hub_normal, -s.blade_normal);
        for i in 0..12 {
            for j in 0..6 {
                let t = (i as f64 + 0.5) / 12.0;
                let dir = (a * (1.0 - t) + b * t).normalize();
                let rho = r * (1.0 + 0.5 * (j as f64 + 0.5) / 6.0);
                let x = s.centre + dir * rho;
                if f.signed_distance(&x).is_some_and(|d| d < 0.0) {
                    material.push(x);
                }
            }
        }
    }
    assert!(material.len() > 2000, "{} material points", material.len());
    let (c0, c1) = (piece.section_at(u0).centre, piece.section_at(u1).centre);
    let mut checked = 0;
    for k in 0..300 {
        // Around the spine (fractions beyond both ends too), offsets up to 2.5 mm.
        let t = -0.05 + 1.1 * k as f64 / 299.0;
        let u = (u0 + (u1 - u0) * t).clamp(u0, u1);
        let base = piece.section_at(u).centre + (c1 - c0) * (t - t.clamp(0.0, 1.0));
        let w = nalgebra::Vector3::new(
            ((k * 37) % 100) as f64 / 20.0 - 2.5,
            ((k * 61) % 100) as f64 / 20.0 - 2.5,
            ((k * 13) % 100) as f64 / 20.0 - 2.5,
        );
        let p = base + w;
        let bound = piece.material_distance_lower(&p, f64::INFINITY);
        let exact = material
            .iter()
            .map(|x| (p - x).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(bound <= exact + 1e-9, "at {p:?}: bound {bound} > {exact}");
        // Not vacuous: away from the material the bound is most of the distance.
        if exact > 0.5 && bound > 0.5 * exact {
            checked += 1;
        }
    }
    assert!(checked > 100, "{checked} of 300 points bounded usefully");
}
