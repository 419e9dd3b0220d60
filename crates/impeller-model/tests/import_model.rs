//! The real exports become impellers whose summaries match their SOURCE.txt facts.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)]

mod import_common;

use impeller_model::import::{import_file, ImportOptions};
use impeller_model::BladeKind;

#[test]
fn centrifugal_12_plus_12_imports() {
    if import_common::skip_without_shared_data() {
        return;
    }
    let imp = import_file(
        &import_common::centrifugal_geomturbo(),
        &ImportOptions::default(),
    )
    .unwrap();
    let s = imp.impeller.summary();
    eprintln!("{s:#?}\nfit {:.2e} mm", imp.fitted.max_fit_mm());
    assert_eq!(s.main_blade_count, 12);
    assert_eq!(s.splitter_blade_count, 12);
    assert_eq!(s.blade_kind, BladeKind::Ruled);
    // SOURCE.txt: blade TE radius ≈ 0.20 m; the sides extend 5 % of the span beyond the shroud.
    assert!(
        (s.blade_tip_diameter_mm - 400.0).abs() < 6.0,
        "{}",
        s.blade_tip_diameter_mm
    );
    assert!(s.min_channel_width_hub_mm > 0.0 && s.min_channel_width_shroud_mm > 0.0);
    assert!(s.min_blade_thickness_mm > 0.0);
    assert!(imp.fitted.max_fit_mm() <= ImportOptions::default().fit_tol_mm);
}

#[test]
fn rotor37_imports() {
    if import_common::skip_without_shared_data() {
        return;
    }
    let imp = import_file(&import_common::rotor37_inf(), &ImportOptions::default()).unwrap();
    let s = imp.impeller.summary();
    eprintln!("{s:#?}\nfit {:.2e} mm", imp.fitted.max_fit_mm());
    assert_eq!(s.main_blade_count, 36);
    assert_eq!(s.splitter_blade_count, 0);
    assert_eq!(s.blade_kind, BladeKind::FreeForm);
    assert!(imp.fitted.max_fit_mm() <= ImportOptions::default().fit_tol_mm);
}

/// A fit that misses its data by more than the tolerance is an error naming the entity and
/// the deviation (the fits fall back to interpolation, so this guards the singular cases).
#[test]
fn deviation_beyond_tolerance_is_an_error() {
    use impeller_model::import::{check_tolerance, ImportError};
    let imp = import_file(
        &import_common::sample("sample-6+6.rtzt"),
        &ImportOptions::default(),
    )
    .unwrap();
    check_tolerance(&imp.fitted).unwrap();
    let mut bad = imp.fitted.clone();
    bad.blades[1].suction_fit_mm = 0.25;
    let err = check_tolerance(&bad).unwrap_err();
    let ImportError::Geometry { entity, reason, .. } = &err else {
        panic!("{err:?}")
    };
    assert_eq!(entity, "blade \"splitter 1\" suction side");
    assert!(reason.contains("0.2500 mm"), "{reason}");
}
