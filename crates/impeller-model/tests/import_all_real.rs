//! Every TurboGrid and `.geomTurbo` export in `../shared/data` imports within the default fit
//! tolerance, and so does the NASA HECC 15 + 15 impeller written as a `.geomTurbo` from its
//! archive tables (the `nasa-hecc` folder holds text tables, not an export: the converter
//! below is the small writer the issue asks for, reading the tables in place).
//!
//! Skips with a message when the data folder is absent, unless `CI=true`.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod import_common;

use impeller_model::import::{import_file, ImportOptions, DEFAULT_FIT_TOL_MM};
use nalgebra::Vector3;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Every export file (`.inf`, `.geomTurbo`) under the data folder.
fn exports(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().and_then(|x| x.to_str()).is_some_and(|x| {
                x.eq_ignore_ascii_case("inf") || x.eq_ignore_ascii_case("geomturbo")
            }) {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

#[test]
fn every_shared_export_imports_within_tolerance() {
    let Some(dir) = import_common::shared_data_or_skip("every_shared_export_imports") else {
        return;
    };
    let files = exports(&dir);
    assert!(
        files.len() >= 2,
        "expected the Rotor 37 and AutoGrid exports, found {files:?}"
    );
    for f in files {
        let imp = import_file(&f, &ImportOptions::default())
            .unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        let worst = imp.fitted.max_fit_mm();
        assert!(worst <= DEFAULT_FIT_TOL_MM, "{}: {worst} mm", f.display());
    }
}

/// Reads a whitespace-separated numeric table, skipping lines that do not start with a number.
fn table(path: &Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter_map(|l| {
            let v: Vec<f64> = l.split_whitespace().map_while(|t| t.parse().ok()).collect();
            (!v.is_empty()).then_some(v)
        })
        .collect()
}

/// One blade section of the HECC tables (`X R·θ R`, inches, one open loop starting at the
/// trailing edge) split at its leading edge (least X) into two sides LE → TE, cartesian
/// inches with Z the axis: (side of larger mean θ, the other).
fn hecc_section(path: &Path) -> (Vec<Vector3<f64>>, Vec<Vector3<f64>>) {
    let pts: Vec<(f64, f64, f64)> = table(path)
        .into_iter()
        .map(|v| (v[0], v[1] / v[2], v[2]))
        .collect();
    let ile = (0..pts.len())
        .min_by(|&a, &b| pts[a].0.total_cmp(&pts[b].0))
        .unwrap();
    let cart = |&(x, t, r): &(f64, f64, f64)| Vector3::new(r * t.cos(), r * t.sin(), x);
    let a: Vec<_> = pts[..=ile].iter().rev().map(cart).collect();
    let b: Vec<_> = pts[ile..].iter().map(cart).collect();
    let mean_t =
        |s: &[Vector3<f64>]| s.iter().map(|p| p.y.atan2(p.x)).sum::<f64>() / s.len() as f64;
    if mean_t(&a) > mean_t(&b) {
        (a, b)
    } else {
        (b, a)
    }
}

fn write_xyz(out: &mut String, pts: &[Vector3<f64>]) {
    writeln!(out, "XYZ\n{}", pts.len()).unwrap();
    for p in pts {
        writeln!(out, "{:.9} {:.9} {:.9}", p.x, p.y, p.z).unwrap();
    }
}

/// Writes the HECC impeller (15 main + 15 splitter, 11 sections each) as a `.geomTurbo`:
/// hub and shroud as `zrcurve`s, each blade's sides as `SECTIONAL` lists, units inches. The
/// larger-θ side leads in the rotation direction (θ grows with rotation in the archive), so
/// it is the pressure side.
fn hecc_geomturbo(dir: &Path) -> String {
    let mut s = String::from("GEOMETRY TURBO\nVERSION 5.5\nNI_BEGIN CHANNEL\n");
    for wall in ["hub", "shroud"] {
        let t = table(&dir.join(format!(
            "HECCvanedCoordinates_flowpathCoordinates_{wall}.txt"
        )));
        writeln!(
            s,
            "NI_BEGIN basic_curve\nNAME {wall}_crv\nNI_BEGIN zrcurve\nZR\n{}",
            t.len()
        )
        .unwrap();
        for v in &t {
            writeln!(s, "{:.9} {:.9}", v[0], v[1]).unwrap();
        }
        writeln!(s, "NI_END zrcurve\nNI_END basic_curve").unwrap();
    }
    for wall in ["hub", "shroud"] {
        writeln!(
            s,
            "NI_BEGIN channel_curve {wall}\nNAME {wall}\nVERTEX CURVE_P {wall}_crv 0\n\
             VERTEX CURVE_P {wall}_crv 1\nNI_END channel_curve"
        )
        .unwrap();
    }
    s.push_str("NI_END CHANNEL\nNI_BEGIN NIROW\nNAME impeller\nPERIODICITY 15\n");
    for (name, file) in [("main blade", "main"), ("splitter 1", "splitter")] {
        let sections: Vec<_> = (1..=11)
            .map(|k| {
                hecc_section(&dir.join(format!(
                    "HECCvanedCoordinates_impeller_{file}_blade_section_{k:02}.txt"
                )))
            })
            .collect();
        writeln!(
            s,
            "NI_BEGIN NIBLADE\nNAME {name}\nNI_BEGIN NIBLADEGEOMETRY\nunits 0.0254\n\
             number_of_blades 15"
        )
        .unwrap();
        for (side, pick) in [("suction", 1), ("pressure", 0)] {
            writeln!(s, "{side}\nSECTIONAL\n{}", sections.len()).unwrap();
            for (k, sec) in sections.iter().enumerate() {
                writeln!(s, "# section {}", k + 1).unwrap();
                write_xyz(&mut s, if pick == 0 { &sec.0 } else { &sec.1 });
            }
        }
        s.push_str("NI_END NIBLADEGEOMETRY\nNI_END NIBLADE\n");
    }
    s.push_str("NI_END NIROW\nNI_END GEOMTURBO\n");
    s
}

#[test]
fn nasa_hecc_as_geomturbo_imports() {
    let Some(data) = import_common::shared_data_or_skip("nasa_hecc_as_geomturbo_imports") else {
        return;
    };
    let text = hecc_geomturbo(&data.join("nasa-hecc"));
    let dir = std::env::temp_dir().join(format!("hecc-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("hecc-15+15.geomTurbo");
    std::fs::write(&file, text).unwrap();
    let imp = import_file(&file, &ImportOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    std::fs::remove_dir_all(&dir).ok();
    let m = &imp.impeller;
    assert_eq!(m.main().count(), 15);
    assert_eq!(m.splitter().map(|s| s.count()), Some(15));
    let worst = imp.fitted.max_fit_mm();
    assert!(worst <= DEFAULT_FIT_TOL_MM, "{worst} mm");
}

/// A hard export of our own: an axial-flow blade whose sections have a round leading edge
/// sampled very densely (parameter s = (k/n)³), a sharp trailing edge (both sides meet at one
/// point), and a different number of points on every section and side.
fn hard_geomturbo() -> String {
    let mut s = String::from(
        "GEOMETRY TURBO\nVERSION 5.5\nNI_BEGIN CHANNEL\nNI_BEGIN basic_curve\nNAME hub_crv\n\
         NI_BEGIN zrcurve\nZR\n3\n-20 20\n20 20\n60 20\nNI_END zrcurve\nNI_END basic_curve\n\
         NI_BEGIN basic_curve\nNAME shroud_crv\nNI_BEGIN zrcurve\nZR\n3\n-20 40\n20 40\n60 40\n\
         NI_END zrcurve\nNI_END basic_curve\nNI_END CHANNEL\nNI_BEGIN NIROW\nNAME r\n\
         PERIODICITY 7\nNI_BEGIN NIBLADE\nNAME main blade\nNI_BEGIN NIBLADEGEOMETRY\n\
         units 0.001\nnumber_of_blades 7\n",
    );
    let radii = [20.0, 25.0, 30.0, 35.0, 40.0];
    for (side, sign) in [("suction", -1.0), ("pressure", 1.0)] {
        writeln!(s, "{side}\nSECTIONAL\n{}", radii.len()).unwrap();
        for (k, &r) in radii.iter().enumerate() {
            let n = 60 + 7 * k + if sign > 0.0 { 3 } else { 0 };
            let pts: Vec<Vector3<f64>> = (0..n)
                .map(|i| {
                    let t = (i as f64 / (n - 1) as f64).powi(3);
                    // Camber θ(z) over z ∈ [0, 40] mm; half thickness √s (1 − s) × 1.2 mm.
                    let z = 40.0 * t;
                    let theta = 0.3 * t * t + 0.002 * r * t;
                    let slope = (0.6 * t + 0.002 * r) * r / 40.0;
                    let h = 1.2 * t.sqrt() * (1.0 - t);
                    let norm = (1.0 + slope * slope).sqrt();
                    // Offset normal to the camber in the (z, r θ) plane.
                    let (dz, drt) = (-slope / norm * h * sign, 1.0 / norm * h * sign);
                    let th = theta + drt / r;
                    Vector3::new(r * th.cos(), r * th.sin(), z + dz)
                })
                .collect();
            writeln!(s, "# section {}", k + 1).unwrap();
            write_xyz(&mut s, &pts);
        }
    }
    s.push_str("NI_END NIBLADEGEOMETRY\nNI_END NIBLADE\nNI_END NIROW\nNI_END GEOMTURBO\n");
    s
}

#[test]
fn own_hard_export_imports_within_tolerance() {
    use impeller_model::import::{prepare, read_geomturbo};
    use nurbs::closest::SurfaceProjector;
    let dir = std::env::temp_dir().join(format!("hard-export-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("hard.geomTurbo");
    std::fs::write(&file, hard_geomturbo()).unwrap();
    let opts = ImportOptions::default();
    let imp = import_file(&file, &opts).unwrap_or_else(|e| panic!("{e}"));
    assert!(imp.fitted.max_fit_mm() <= opts.fit_tol_mm);
    // Independently: every prepared data point lies within the tolerance of its fitted side.
    let raw = read_geomturbo(&file).unwrap();
    let p = prepare(&raw, opts.trim_margin).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    let b = &imp.fitted.blades[0];
    for (surf, pressure) in [(&b.pressure, true), (&b.suction, false)] {
        let proj = SurfaceProjector::new(surf);
        for sec in &p.blades[0].sections {
            let pts = if pressure {
                &sec.pressure
            } else {
                &sec.suction
            };
            for q in pts {
                let d = proj.closest_point(q).distance;
                assert!(d <= opts.fit_tol_mm + 1e-9, "{d} mm");
            }
        }
    }
    // Sharp trailing edge: both sides end at one point.
    let te = |s: &nurbs::NurbsSurface| s.point(1.0, 0.5);
    assert!((te(&b.pressure) - te(&b.suction)).norm() < 0.05);
}

/// The archive's as-manufactured tables (`cold_with_fillets`, with the design-intent hub and
/// shroud) fit their points within 0.1 mm. The splitter's pressure side used to swing out to
/// r ≈ 2.7 m between two data points near its trailing edge (a knot span its section's data
/// barely reach: an ill-conditioned least-squares system whose solution passed every data
/// point); the fit now refuses such a system and stays within the outlet radius. The
/// import is still refused, for what is really wrong with this pair of files: the cold blades
/// stop up to several mm below the hot shroud contour, so they would have no tip.
#[test]
fn cold_blades_below_a_hot_shroud_are_refused_and_their_fit_does_not_swing() {
    use impeller_model::import::{
        fit, import_raw, prepare, read_raw_with, LengthUnit, TableOptions,
    };
    let Some(data) = import_common::shared_data_or_skip("cold_blades_below_a_hot_shroud") else {
        return;
    };
    let hecc = data.join("nasa-hecc");
    let opts = ImportOptions {
        fit_tol_mm: 0.1,
        tables: TableOptions {
            unit: Some(LengthUnit::Inch),
            blade_count: Some(15),
            hub_file: Some(hecc.join("HECCvanedCoordinates_flowpathCoordinates_hub.txt")),
            shroud_file: Some(hecc.join("HECCvanedCoordinates_flowpathCoordinates_shroud.txt")),
            ..TableOptions::default()
        },
        ..ImportOptions::default()
    };
    let raw = read_raw_with(&hecc.join("cold_with_fillets"), &opts).unwrap();
    let fitted = fit(
        &prepare(&raw, opts.trim_margin).unwrap(),
        opts.fit_tol_mm,
        opts.span_extension,
    )
    .unwrap();
    // Outlet radius 8.48 in = 215.4 mm; the span extension may carry a side a few mm past it.
    for b in &fitted.blades {
        assert!(
            b.pressure_fit_mm <= 0.1 && b.suction_fit_mm <= 0.1,
            "{}",
            b.name
        );
        for s in [&b.pressure, &b.suction] {
            for (i, j, p) in import_common::grid_points(s, 1600, 32) {
                assert!(p.x.hypot(p.y) < 230.0, "{} at {i}, {j}: {p:?}", b.name);
            }
        }
    }
    let e = import_raw(&raw, &opts).unwrap_err().to_string();
    assert!(
        e.contains("top edge (span extension included) stops")
            && e.contains("short of the shroud contour"),
        "{e}"
    );
}
