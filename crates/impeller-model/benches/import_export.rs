//! Import and export costs: parsing a `.geomTurbo` held in memory, the whole import (parse,
//! prepare, fit within 0.01 mm, assemble), and tessellating one blade side within 0.01 mm.
//! Uses the 12 + 12 centrifugal export from `../shared/data` when present, else our own
//! `rtzt` sample.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{criterion_group, criterion_main, Criterion};
use impeller_model::export::tessellate;
use impeller_model::import::{
    import_raw, parse_geomturbo, parse_rtzt, ImportOptions, LengthUnit, RawImpeller,
};
use std::hint::black_box;
use std::path::{Path, PathBuf};

fn input() -> (String, Vec<u8>, bool) {
    let crate_dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let shared = crate_dir
        .ancestors()
        .skip(2)
        .map(|a| a.join("shared/data/pynumeca-centrifugal/cc_autoblade.geomTurbo"))
        .find(|p| p.is_file());
    match shared {
        Some(p) => (
            "cc_autoblade.geomTurbo".into(),
            std::fs::read(p).unwrap(),
            true,
        ),
        None => {
            let p = crate_dir.join("tests/data/sample-6+6.rtzt");
            ("sample-6+6.rtzt".into(), std::fs::read(p).unwrap(), false)
        }
    }
}

fn parse(name: &str, bytes: &[u8], geomturbo: bool) -> RawImpeller {
    if geomturbo {
        parse_geomturbo(Path::new(name), bytes).unwrap()
    } else {
        parse_rtzt(Path::new(name), bytes, LengthUnit::Millimetre).unwrap()
    }
}

fn benches(c: &mut Criterion) {
    let (name, bytes, geomturbo) = input();
    c.bench_function(&format!("import_parse/{name}"), |b| {
        b.iter(|| parse(&name, black_box(&bytes), geomturbo))
    });
    let raw = parse(&name, &bytes, geomturbo);
    let opts = ImportOptions::default();
    c.bench_function(&format!("import_fit_assemble/{name}"), |b| {
        b.iter(|| import_raw(black_box(&raw), &opts).unwrap())
    });
    let imp = import_raw(&raw, &opts).unwrap();
    let side = imp.impeller.main().blade().pressure().clone();
    c.bench_function(&format!("tessellate_side_0.01mm/{name}"), |b| {
        b.iter(|| tessellate(black_box(&side), 0.01, "pressure side").unwrap())
    });
}

criterion_group!(import_export, benches);
criterion_main!(import_export);
