//! The real public exports in `../shared/data` import with the facts their SOURCE.txt states.

mod import_common;

use impeller_model::import::{read_geomturbo, read_turbogrid, BladeRole, SectionShape};

#[test]
fn rotor37_raw_counts_and_units() {
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
