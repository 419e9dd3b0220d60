//! Import → export (TurboGrid curve files) → import reproduces the geometry within the fit
//! tolerance.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)]

mod import_common;

use impeller_model::channel::edge_v;
use impeller_model::export::{write_curves, CurveSampling};
use impeller_model::import::{import_file, ImportOptions, Imported};
use impeller_model::{Impeller, Side};
use nurbs::closest::SurfaceProjector;
use std::path::{Path, PathBuf};

fn tmp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("impeller-export-rt-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Largest distance from points of `a` (blade sides between hub and shroud, contours) to
/// the corresponding geometry of `b`.
fn deviation(a: &Impeller, b: &Impeller) -> f64 {
    let mut worst: f64 = 0.0;
    for (ma, mb) in [
        (a.hub().meridional(), b.hub().meridional()),
        (a.shroud().meridional(), b.shroud().meridional()),
    ] {
        for k in 0..=50 {
            let p = ma.point_at_fraction(k as f64 / 50.0);
            worst = worst.max(mb.closest(p).1.abs());
        }
    }
    let rows = [(a.main().blade(), b.main().blade())];
    let split = a
        .splitter()
        .map(|s| s.blade())
        .zip(b.splitter().map(|s| s.blade()));
    for (ba, bb) in rows.into_iter().chain(split) {
        for side in [Side::Pressure, Side::Suction] {
            let sa = ba.side(side);
            let proj = SurfaceProjector::new(bb.side(side));
            let ((u0, u1), (v0, v1)) = sa.domain();
            for i in 1..20 {
                let u = u0 + (u1 - u0) * i as f64 / 20.0;
                let vh = edge_v(ba, side, a.hub(), u).unwrap_or(v0);
                let vs = edge_v(ba, side, a.shroud(), u).unwrap_or(v1);
                for j in 0..=6 {
                    let v = vh + (vs - vh) * j as f64 / 6.0;
                    worst = worst.max(proj.closest_point(&sa.point(u, v)).distance);
                }
            }
        }
    }
    worst
}

fn round_trip(path: &Path, tag: &str, opts: &ImportOptions) -> (Imported, Imported, f64) {
    let first = import_file(path, opts).unwrap();
    let dir = tmp_dir(tag);
    let files = write_curves(&first.impeller, &dir, "export", &CurveSampling::default()).unwrap();
    let second = import_file(&files.inf, opts).unwrap();
    let dev = deviation(&first.impeller, &second.impeller);
    eprintln!(
        "{tag}: round-trip deviation {dev:.2e} mm (fits {:.2e} / {:.2e} mm)",
        first.fitted.max_fit_mm(),
        second.fitted.max_fit_mm()
    );
    // No temporary files are left behind.
    for e in std::fs::read_dir(&dir).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().into_owned();
        assert!(!name.contains(".tmp-"), "{name}");
    }
    let _ = std::fs::remove_dir_all(&dir);
    (first, second, dev)
}

#[test]
fn centrifugal_round_trip() {
    if import_common::skip_without_shared_data() {
        return;
    }
    let opts = ImportOptions::default();
    let (a, b, dev) = round_trip(&import_common::centrifugal_geomturbo(), "cc", &opts);
    let (sa, sb) = (a.impeller.summary(), b.impeller.summary());
    assert_eq!(
        (sa.main_blade_count, sa.splitter_blade_count, sa.blade_kind),
        (sb.main_blade_count, sb.splitter_blade_count, sb.blade_kind)
    );
    assert!(dev <= opts.fit_tol_mm, "{dev}");
}

#[test]
fn rtzt_sample_round_trip() {
    let opts = ImportOptions::default();
    let (_, _, dev) = round_trip(&import_common::sample("sample-6+6.rtzt"), "rtzt", &opts);
    assert!(dev <= opts.fit_tol_mm, "{dev}");
}

#[test]
fn rotor37_round_trip() {
    if import_common::skip_without_shared_data() {
        return;
    }
    let opts = ImportOptions::default();
    let (_, _, dev) = round_trip(&import_common::rotor37_inf(), "r37", &opts);
    assert!(dev <= opts.fit_tol_mm, "{dev}");
}

/// The parametric default impeller (fixture impeller-8+8, blunt trailing edges) through
/// curve files: its import A lies within the fit tolerance of the design, and A → export →
/// import B reproduces A within the fit tolerance.
#[test]
fn parametric_default_round_trip() {
    let design = impeller_model::fixtures::default_impeller().unwrap();
    let opts = ImportOptions::default();
    let dir = tmp_dir("param");
    let files = write_curves(&design, &dir, "export", &CurveSampling::default()).unwrap();
    let a = import_file(&files.inf, &opts).unwrap();
    let dev_design = deviation(&design, &a.impeller);
    let _ = std::fs::remove_dir_all(&dir);
    let files = write_curves(&a.impeller, &dir, "export", &CurveSampling::default()).unwrap();
    let b = import_file(&files.inf, &opts).unwrap();
    let dev = deviation(&a.impeller, &b.impeller);
    eprintln!("impeller-8+8: design → A {dev_design:.2e} mm, A → B {dev:.2e} mm");
    assert_eq!(a.impeller.main().count(), design.main().count());
    assert_eq!(b.impeller.splitter().map(|s| s.count()), Some(8));
    assert!(dev_design <= opts.fit_tol_mm, "{dev_design}");
    assert!(dev <= opts.fit_tol_mm, "{dev}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every parametric fixture through curve files and back: the import path is exercised on
/// every fixture, within the fit tolerance of the design.
#[test]
fn every_parametric_fixture_round_trips() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures");
    let opts = ImportOptions::default();
    let mut seen = 0;
    for entry in std::fs::read_dir(&root).unwrap() {
        let toml = entry.unwrap().path().join("impeller.toml");
        let Ok(text) = std::fs::read_to_string(&toml) else {
            continue;
        };
        if impeller_model::import::is_import_toml(&text) {
            continue; // imported fixtures are covered above
        }
        let design = impeller_model::load(&toml).unwrap();
        let tag = toml
            .parent()
            .unwrap()
            .file_name()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        let dir = tmp_dir(&tag);
        let files = write_curves(&design, &dir, "export", &CurveSampling::default()).unwrap();
        let back = import_file(&files.inf, &opts).unwrap();
        let dev = deviation(&design, &back.impeller);
        eprintln!("{tag}: design → curves → import {dev:.2e} mm");
        assert_eq!(back.impeller.main().count(), design.main().count(), "{tag}");
        assert!(dev <= opts.fit_tol_mm, "{tag}: {dev}");
        let _ = std::fs::remove_dir_all(&dir);
        seen += 1;
    }
    assert!(seen >= 1);
}
