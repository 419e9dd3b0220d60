//! Folders of section tables (`impeller_model::import::tables`): the NASA HECC archive read in
//! place, a small folder of our own (hand, units, counts) and the errors a user meets.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)]

mod import_common;

use impeller_model::import::{
    import_file, read_tables, ImportError, ImportOptions, LengthUnit, SectionShape, TableOptions,
    DEFAULT_FIT_TOL_MM,
};
use impeller_model::ModelError;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

fn tmp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("impeller-tables-{tag}-{}", std::process::id()));
    std::fs::remove_dir_all(&d).ok();
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A small axial-flow-like blade row written as tables in inches: hub r = 2, shroud r = 4,
/// blade sections at r = 2 … 4 whose camber runs over x ∈ [0, 2] at θ = 0.05·x, thickness
/// 0.08·√s(1 − s). Loops start at the trailing edge like the archive's.
fn write_tables(dir: &Path, with_splitter: bool) {
    std::fs::write(
        dir.join("demo_flowpathCoordinates_hub.txt"),
        "x\tr\r\n-1.0\t2.0\r\n1.0\t2.0\r\n3.0\t2.0\r\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("demo_flowpathCoordinates_shroud.txt"),
        "x\tr\r\n-1.0\t4.0\r\n1.0\t4.0\r\n3.0\t4.0\r\n",
    )
    .unwrap();
    let rows: &[&str] = if with_splitter {
        &["main", "splitter"]
    } else {
        &["main"]
    };
    for row in rows {
        for (k, r) in [1.9, 2.5, 3.2, 4.1].into_iter().enumerate() {
            let mut s = String::from("        X           R*THETA          R\n");
            let n = 40;
            // Pressure side TE → LE, then suction side LE → TE (one loop).
            let mut pts = Vec::new();
            for side in [1.0, -1.0] {
                for i in 0..=n {
                    let t = if side > 0.0 {
                        1.0 - i as f64 / n as f64
                    } else {
                        i as f64 / n as f64
                    };
                    let s_ = t * t * (3.0 - 2.0 * t);
                    let x = 2.0 * s_;
                    let h = 0.08 * s_.sqrt() * (1.0 - s_) + 0.004;
                    let theta = 0.05 * x + side * h / r;
                    pts.push((x, r * theta, r));
                }
            }
            for (x, rt, r) in pts {
                writeln!(s, "  {x:.8}  {rt:.8}  {r:.8}").unwrap();
            }
            std::fs::write(
                dir.join(format!("demo_{row}_blade_section_{:02}.txt", k + 1)),
                s,
            )
            .unwrap();
        }
    }
}

fn opts(unit: Option<LengthUnit>, count: Option<usize>) -> TableOptions {
    TableOptions {
        unit,
        blade_count: count,
        ..TableOptions::default()
    }
}

#[test]
fn tables_read_in_inches_keep_the_hand() {
    let dir = tmp_dir("hand");
    write_tables(&dir, true);
    let raw = read_tables(&dir, &opts(Some(LengthUnit::Inch), Some(9))).unwrap();
    assert_eq!(raw.hub.len(), 3);
    assert!((raw.hub[0].y - 2.0 * 25.4).abs() < 1e-9, "{:?}", raw.hub[0]);
    assert_eq!(raw.main_blade_count(), 9);
    assert_eq!(
        raw.splitter_blade_count(),
        9,
        "default: as many as main blades"
    );
    assert_eq!(raw.blades[0].sections.len(), 4);
    // θ grows counter-clockwise looking along +x (= +z): y = −r sin θ. The camber's θ grows
    // with x, so the trailing edge (x = 2 in) lies at negative y.
    let SectionShape::Loop(pts) = &raw.blades[0].sections[0].shape else {
        panic!("a loop")
    };
    let te = pts[0];
    assert!((te.z - 2.0 * 25.4).abs() < 1e-6, "{te:?}");
    assert!(te.y < -0.09 * 1.9 * 25.4 && te.x > 0.0, "{te:?}");
    // Radius kept: √(x² + y²) = R.
    assert!((te.xy().norm() - 1.9 * 25.4).abs() < 1e-9);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn tables_import_and_fit() {
    let dir = tmp_dir("fit");
    write_tables(&dir, false);
    let o = ImportOptions {
        tables: opts(Some(LengthUnit::Inch), Some(9)),
        ..ImportOptions::default()
    };
    let imp = import_file(&dir, &o).unwrap();
    assert_eq!(imp.impeller.main().count(), 9);
    assert!(imp.impeller.splitter().is_none());
    assert!(imp.fitted.max_fit_mm() <= DEFAULT_FIT_TOL_MM);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn tables_need_unit_and_count() {
    let dir = tmp_dir("need");
    write_tables(&dir, false);
    let e = read_tables(&dir, &opts(None, Some(9))).unwrap_err();
    assert!(e.to_string().contains("table_unit"), "{e}");
    let e = read_tables(&dir, &opts(Some(LengthUnit::Inch), None)).unwrap_err();
    assert!(e.to_string().contains("blade_count"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_bad_table_row_names_file_and_line() {
    let dir = tmp_dir("bad");
    write_tables(&dir, false);
    let f = dir.join("demo_main_blade_section_03.txt");
    let mut text = std::fs::read_to_string(&f).unwrap();
    text = text.replacen("  0.", "  0.x", 1);
    std::fs::write(&f, text).unwrap();
    let e = read_tables(&dir, &opts(Some(LengthUnit::Inch), Some(9))).unwrap_err();
    let ImportError::Syntax { file, line, .. } = &e else {
        panic!("{e:?}")
    };
    assert!(file.ends_with("demo_main_blade_section_03.txt"), "{e}");
    assert_eq!(*line, 2, "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn an_import_file_names_a_folder() {
    let dir = tmp_dir("toml");
    let data = dir.join("tables");
    std::fs::create_dir_all(&data).unwrap();
    write_tables(&data, true);
    let toml = dir.join("impeller.toml");
    std::fs::write(
        &toml,
        "name = \"demo\"\n[import]\nfile = \"tables\"\ntable_unit = \"IN\"\nblade_count = 7\n\
         splitter_count = 7\n",
    )
    .unwrap();
    let imp = impeller_model::load(&toml).unwrap();
    assert_eq!(
        (imp.main().count(), imp.splitter().map(|s| s.count())),
        (7, Some(7))
    );
    // A table key on an export file is an error naming its line.
    std::fs::write(dir.join("x.rtzt"), "1\n0\n").unwrap();
    std::fs::write(&toml, "[import]\nfile = \"x.rtzt\"\n\nblade_count = 7\n").unwrap();
    let e = impeller_model::load(&toml).unwrap_err();
    let ModelError::Import(ImportError::Invalid { line, field, .. }) = &e else {
        panic!("{e:?}")
    };
    assert_eq!((*line, field.as_str()), (4, "import.blade_count"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn nasa_hecc_tables_import_in_place() {
    let Some(data) = import_common::shared_data_or_skip("nasa_hecc_tables_import_in_place") else {
        return;
    };
    let o = ImportOptions {
        tables: opts(Some(LengthUnit::Inch), Some(15)),
        ..ImportOptions::default()
    };
    let imp = import_file(&data.join("nasa-hecc"), &o).unwrap();
    let m = &imp.impeller;
    assert_eq!(m.main().count(), 15);
    assert_eq!(m.splitter().map(|s| s.count()), Some(15));
    assert!(imp.fitted.max_fit_mm() <= DEFAULT_FIT_TOL_MM);
    let s = m.summary();
    // 17.0 in blade tip diameter (431.8 mm) from the archive's read-me.
    assert!((s.blade_tip_diameter_mm - 431.8).abs() < 1.0, "{s:?}");
}
