//! The real public exports in `../shared/data` import with the facts their SOURCE.txt states.

mod import_common;

use impeller_model::import::{read_geomturbo, read_turbogrid, BladeRole, SectionShape};

#[test]
fn rotor37_raw_counts_and_units() {
    if import_common::skip_without_shared_data() {
        return;
    }
    let raw = read_turbogrid(&import_common::rotor37_inf()).unwrap();
    assert_eq!(raw.main_blade_count(), 36);
    assert_eq!(raw.splitter_blade_count(), 0);
    assert_eq!(raw.hub.len(), 211);
    assert_eq!(raw.shroud.len(), 209);
    let b = &raw.blades[0];
    assert_eq!(b.sections.len(), 6);
    for (k, s) in b.sections.iter().enumerate() {
        assert!((s.span.unwrap() - 0.2 * k as f64).abs() < 1e-9);
        match &s.shape {
            SectionShape::Loop(p) => assert_eq!(p.len(), 301),
            other => panic!("expected a loop, got {other:?}"),
        }
    }
    // CM → mm: the first hub point 17.4036479 -2.06644903 -4.19 cm.
    let r0 = 17.4036479f64.hypot(-2.06644903) * 10.0;
    assert!((raw.hub[0].y - r0).abs() < 1e-9 && (raw.hub[0].x + 41.9).abs() < 1e-9);
}

#[test]
fn centrifugal_raw_counts_and_units() {
    if import_common::skip_without_shared_data() {
        return;
    }
    let raw = read_geomturbo(&import_common::centrifugal_geomturbo()).unwrap();
    assert_eq!(raw.main_blade_count(), 12);
    assert_eq!(raw.splitter_blade_count(), 12);
    assert_eq!(raw.blades[0].role, BladeRole::Main);
    assert_eq!(raw.blades[1].role, BladeRole::Splitter);
    assert_eq!(raw.hub.len(), 100);
    assert_eq!(raw.shroud.len(), 100);
    // Metres → mm: the hub starts at z = -0.10345 m, r = 0.0173766 m.
    assert!((raw.hub[0].x + 103.45).abs() < 1e-9 && (raw.hub[0].y - 17.3766).abs() < 1e-9);
    let mut te_r: f64 = 0.0;
    for b in &raw.blades {
        assert_eq!(b.sections.len(), 2);
        for s in &b.sections {
            let SectionShape::Sides { suction, pressure } = &s.shape else {
                panic!("expected sides");
            };
            assert_eq!(suction.len(), 110);
            assert_eq!(pressure.len(), 110);
            for p in suction.iter().chain(pressure) {
                te_r = te_r.max(p.x.hypot(p.y));
            }
        }
    }
    // SOURCE.txt: blade TE radius ≈ 0.20 m.
    assert!((te_r - 200.0).abs() < 2.0, "largest blade radius {te_r} mm");
}

use impeller_model::import::{prepare, RawImpeller, RawSection};

fn z_range(p: &impeller_model::import::PreparedImpeller) -> (f64, f64) {
    p.hub
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), q| {
            (a.min(q.x), b.max(q.x))
        })
}

#[test]
fn centrifugal_prepared_in_workpiece_frame() {
    if import_common::skip_without_shared_data() {
        return;
    }
    let raw = read_geomturbo(&import_common::centrifugal_geomturbo()).unwrap();
    let p = prepare(&raw, None).unwrap();
    assert!(p.flipped, "the file's inlet is at low z");
    let (zmin, zmax) = z_range(&p);
    let z_end = p.hub[p.hub.len() - 1].x;
    assert!(z_end.abs() < 1e-9, "hub outlet end at z = 0, got {z_end}");
    // The file's hub bulges a little (under 1 mm) beyond its outlet end.
    assert!(zmin <= 0.0 && zmin > -1.0, "{zmin}");
    // The turn keeps the hub's axial extent.
    let (rmin, rmax) = raw
        .hub
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), q| {
            (a.min(q.x), b.max(q.x))
        });
    assert!((zmax - zmin - (rmax - rmin)).abs() < 1e-9);
    assert!(
        p.hub[0].x > p.hub[p.hub.len() - 1].x,
        "hub listed from the inlet"
    );
    for b in &p.blades {
        for s in &b.sections {
            for side in [&s.pressure, &s.suction] {
                let (le, te) = (side[0], side[side.len() - 1]);
                assert!(le.z > te.z, "LE toward +Z (inlet)");
                assert!(le.xy().norm() < te.xy().norm(), "TE at the larger radius");
                let r_te = te.xy().norm();
                assert!((r_te - 200.0).abs() < 2.0, "TE radius {r_te} mm");
            }
        }
    }
}

/// The convexity rule that labels unlabelled sides reproduces AutoGrid's own suction and
/// pressure labels on the centrifugal impeller.
#[test]
fn convexity_rule_matches_autogrid_labels() {
    if import_common::skip_without_shared_data() {
        return;
    }
    let raw = read_geomturbo(&import_common::centrifugal_geomturbo()).unwrap();
    let labelled = prepare(&raw, None).unwrap();
    let mut looped: RawImpeller = raw.clone();
    for b in &mut looped.blades {
        for s in &mut b.sections {
            let SectionShape::Sides { suction, pressure } = &s.shape else {
                unreachable!()
            };
            // A loop that starts on the pressure side, so the rule must swap.
            let mut pts: Vec<_> = pressure.clone();
            pts.extend(suction.iter().rev().skip(1));
            *s = RawSection {
                line: s.line,
                span: None,
                shape: SectionShape::Loop(pts),
            };
        }
    }
    let unlabelled = prepare(&looped, None).unwrap();
    for (a, b) in labelled.blades.iter().zip(&unlabelled.blades) {
        for (sa, sb) in a.sections.iter().zip(&b.sections) {
            let mid_a = sa.suction[sa.suction.len() / 2];
            let d = sb
                .suction
                .iter()
                .map(|q| (q - mid_a).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(d < 1e-9, "suction side relabelled (distance {d})");
        }
    }
}

#[test]
fn rotor37_prepared() {
    if import_common::skip_without_shared_data() {
        return;
    }
    let raw = read_turbogrid(&import_common::rotor37_inf()).unwrap();
    let p = prepare(&raw, None).unwrap();
    assert!(p.flipped, "rotor 37's inlet is at low z in the file");
    assert_eq!(p.main_blade_count(), 36);
    for s in &p.blades[0].sections {
        for side in [&s.pressure, &s.suction] {
            assert!(side[0].z > side[side.len() - 1].z);
        }
        // LE and TE shared by both sides of the split loop.
        assert!((s.pressure[0] - s.suction[0]).norm() < 1e-12);
    }
}

/// Pressure and suction are labelled consistently on every section: the pressure side lies
/// on the same θ side of the suction side at mid-chord of every span (a swapped section would
/// twist the skinned sides through each other).
#[test]
fn side_labels_are_consistent_across_sections() {
    if import_common::skip_without_shared_data() {
        return;
    }
    let sources = [
        read_turbogrid(&import_common::rotor37_inf()).unwrap(),
        read_turbogrid(&import_common::sample("tg-cylindrical/sample.inf")).unwrap(),
        impeller_model::import::read_rtzt(
            &import_common::sample("sample-6+6.rtzt"),
            impeller_model::import::LengthUnit::Millimetre,
        )
        .unwrap(),
        read_geomturbo(&import_common::centrifugal_geomturbo()).unwrap(),
    ];
    for raw in &sources {
        let p = prepare(raw, None).unwrap();
        for b in &p.blades {
            let signs: Vec<f64> = b
                .sections
                .iter()
                .map(|s| {
                    let a = s.pressure[s.pressure.len() / 2];
                    let c = s.suction[s.suction.len() / 2];
                    (a.y.atan2(a.x) - c.y.atan2(c.x)).signum()
                })
                .collect();
            assert!(
                signs.iter().all(|&x| x == signs[0]),
                "{}: {}: {signs:?}",
                raw.source.display(),
                b.name
            );
        }
    }
}
