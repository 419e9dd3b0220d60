//! Our own sample exports (tests/data) parse into the geometry they were written from.

mod import_common;

use impeller_model::import::{
    parse_rtzt, read_rtzt, read_turbogrid, BladeRole, LengthUnit, SectionShape, ThicknessKind,
};
use std::path::Path;

#[test]
fn rtzt_sample_layers_and_flow_path() {
    let raw = read_rtzt(
        &import_common::sample("sample-6+6.rtzt"),
        LengthUnit::Millimetre,
    )
    .unwrap();
    assert_eq!(raw.main_blade_count(), 6);
    assert_eq!(raw.splitter_blade_count(), 6);
    assert_eq!(raw.blades.len(), 2);
    assert_eq!(raw.blades[1].role, BladeRole::Splitter);
    // Hub = all 17 points of the main blade's hub layer, incl. the zero-thickness extension.
    assert_eq!(raw.hub.len(), 17);
    assert!((raw.hub[0].x - 43.0).abs() < 1e-9 && (raw.hub[0].y - 15.0).abs() < 1e-9);
    let SectionShape::Camber {
        points,
        thickness,
        kind,
    } = &raw.blades[0].sections[0].shape
    else {
        panic!("camber expected")
    };
    // Bladed part only: 14 points, the first at the LE (z = 40, r = 15).
    assert_eq!(points.len(), 14);
    assert_eq!(*kind, ThicknessKind::Tangential);
    assert!(thickness.iter().all(|&t| t > 0.0));
    assert!((points[0].z - 40.0).abs() < 1e-9);
    let SectionShape::Camber { kind, .. } = &raw.blades[1].sections[0].shape else {
        panic!("camber expected")
    };
    assert_eq!(*kind, ThicknessKind::Normal);
    assert_eq!(raw.blades[0].sections[1].span, Some(0.5));
    // Units scale every length but no angle.
    let bytes = std::fs::read(import_common::sample("sample-6+6.rtzt")).unwrap();
    let cm = parse_rtzt(Path::new("s.rtzt"), &bytes, LengthUnit::Centimetre).unwrap();
    assert!((cm.hub[0].y - 150.0).abs() < 1e-9);
}

#[test]
fn turbogrid_cylindrical_sample_with_crlf_profiles() {
    let raw = read_turbogrid(&import_common::sample("tg-cylindrical/sample.inf")).unwrap();
    assert_eq!(raw.main_blade_count(), 6);
    assert_eq!(raw.splitter_blade_count(), 6);
    assert_eq!(raw.hub.len(), 31);
    for b in &raw.blades {
        assert_eq!(b.sections.len(), 3);
        for s in &b.sections {
            let SectionShape::Loop(p) = &s.shape else {
                panic!("loop expected")
            };
            assert_eq!(p.len(), 32);
            // Closed loop; points of the hub profile lie on r = 15 at the LE (θ in degrees
            // converted: the first point is at 1.52788745° = 0.02666... rad).
            assert!((p[0] - p[31]).norm() < 1e-12);
        }
    }
    let SectionShape::Loop(p) = &raw.blades[0].sections[0].shape else {
        unreachable!()
    };
    assert!((p[0].y.atan2(p[0].x) - 1.52788745f64.to_radians()).abs() < 1e-9);
    assert!((p[0].x.hypot(p[0].y) - 15.0).abs() < 1e-9);
}
