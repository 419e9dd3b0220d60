//! Data that parse but cannot form an impeller end in `ImportError::Geometry` naming the
//! file and the entity.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)]

mod import_common;

use impeller_model::import::{
    import_raw, parse_geomturbo, prepare, read_rtzt, ImportError, ImportOptions, LengthUnit,
    RawSection, SectionShape,
};
use nalgebra::Vector3;
use std::path::Path;

fn geometry(err: ImportError, entity: &str, reason: &str) {
    match &err {
        ImportError::Geometry {
            entity: e,
            reason: r,
            ..
        } => {
            assert!(e.contains(entity), "{err}");
            assert!(r.contains(reason), "{err}");
        }
        other => panic!("expected a geometry error, got {other:?}"),
    }
    assert!(err.to_string().contains("sample-6+6.rtzt") || err.to_string().contains(".geomTurbo"));
}

fn sample() -> impeller_model::import::RawImpeller {
    read_rtzt(
        &import_common::sample("sample-6+6.rtzt"),
        LengthUnit::Millimetre,
    )
    .unwrap()
}

#[test]
fn degenerate_loop() {
    let mut raw = sample();
    raw.blades[0].sections[1] = RawSection {
        line: 7,
        span: None,
        shape: SectionShape::Loop(vec![Vector3::new(10.0, 0.0, 5.0); 6]),
    };
    let err = prepare(&raw, None).unwrap_err();
    geometry(err, "section 2 (line 7)", "fewer than 4 distinct points");
}

#[test]
fn camber_on_the_axis() {
    let mut raw = sample();
    if let SectionShape::Camber { points, .. } = &mut raw.blades[1].sections[0].shape {
        for p in points.iter_mut() {
            p.x = 0.0;
            p.y = 0.0;
        }
    }
    let err = prepare(&raw, None).unwrap_err();
    geometry(err, "splitter 1", "touches the axis");
}

#[test]
fn coordinates_beyond_any_impeller() {
    if import_common::skip_without_shared_data() {
        return;
    }
    let mut raw = sample();
    raw.hub[3].y = 1e12;
    geometry(
        prepare(&raw, None).unwrap_err(),
        "hub/shroud",
        "beyond 1e9 mm",
    );
    let text = std::fs::read_to_string(import_common::centrifugal_geomturbo()).unwrap();
    let text = text.replacen("0.0477053805615964", "4.77e10", 1);
    let raw = parse_geomturbo(Path::new("x.geomTurbo"), text.as_bytes()).unwrap();
    geometry(
        prepare(&raw, None).unwrap_err(),
        "main blade",
        "beyond 1e9 mm",
    );
}

#[test]
fn edges_that_coincide() {
    // Every hub-section point at the same meridional position.
    let mut raw = sample();
    if let SectionShape::Camber { points, .. } = &mut raw.blades[0].sections[0].shape {
        for (k, p) in points.iter_mut().enumerate() {
            let th = 0.01 * k as f64;
            *p = Vector3::new(20.0 * th.cos(), 20.0 * th.sin(), 30.0);
        }
    }
    geometry(prepare(&raw, None).unwrap_err(), "hub section", "coincide");
}

#[test]
fn invalid_options() {
    let raw = sample();
    let opts = ImportOptions {
        span_extension: 0.9,
        ..ImportOptions::default()
    };
    geometry(
        import_raw(&raw, &opts).unwrap_err(),
        "span extension",
        "within 0–0.5",
    );
    let opts = ImportOptions {
        trim_margin: Some(-1.0),
        ..ImportOptions::default()
    };
    geometry(
        import_raw(&raw, &opts).unwrap_err(),
        "trim margin",
        "fraction >= 0",
    );
    let opts = ImportOptions {
        fillet_radius_mm: -1.0,
        ..ImportOptions::default()
    };
    geometry(
        import_raw(&raw, &opts).unwrap_err(),
        "impeller",
        "fillet_radius_mm",
    );
}

#[test]
fn shroud_below_hub_is_rejected_by_the_model() {
    let mut raw = sample();
    std::mem::swap(&mut raw.hub, &mut raw.shroud);
    let opts = ImportOptions {
        trim_margin: None,
        ..ImportOptions::default()
    };
    geometry(
        import_raw(&raw, &opts).unwrap_err(),
        "impeller",
        "shroud contour",
    );
}

#[test]
fn xyz_channel_curves() {
    if import_common::skip_without_shared_data() {
        return;
    }
    // A basic_curve given as an xyzcurve is reduced to (z, √(x² + y²)).
    let text = std::fs::read_to_string(import_common::centrifugal_geomturbo()).unwrap();
    let hub_start = text.find("NI_BEGIN\tzrcurve").unwrap();
    let hub_end = text.find("NI_END\tzrcurve").unwrap() + "NI_END\tzrcurve".len();
    let xyz = "NI_BEGIN\txyzcurve\n XYZ\n 3\n 0.03 0.04 -0.1\n 0.0 0.06 0.0\n 0.2 0.0 0.12\nNI_END\txyzcurve";
    let text = format!("{}{}{}", &text[..hub_start], xyz, &text[hub_end..]);
    let raw = parse_geomturbo(Path::new("x.geomTurbo"), text.as_bytes()).unwrap();
    assert_eq!(raw.hub.len(), 3);
    assert!((raw.hub[0].x + 100.0).abs() < 1e-9 && (raw.hub[0].y - 50.0).abs() < 1e-9);
}
