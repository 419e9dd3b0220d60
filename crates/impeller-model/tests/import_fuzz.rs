//! Random bytes and mutated (truncated, byte-flipped, NaN-injected) copies of every sample
//! export, fed to every importer: always a typed error or a valid result, never a panic.
//! The real exports are read from `../shared/data` at test time (when present; required
//! under CI) and mutated in memory.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)]

mod import_common;

use impeller_model::import::{
    import_raw, parse_geomturbo, parse_rtzt, turbogrid_from_bytes, ImportOptions, LengthUnit,
    RawImpeller,
};
use proptest::prelude::*;
use proptest::sample::Index;
use std::path::Path;
use std::sync::OnceLock;

struct Corpus {
    /// The public `.geomTurbo` export (absent on a fresh clone without the data).
    geomturbo: Option<Vec<u8>>,
    rtzt: Vec<u8>,
    /// (inf, hub, shroud, profiles) of our cylindrical sample, then Rotor 37 when present.
    turbogrid: Vec<[Vec<u8>; 5]>,
}

fn corpus() -> &'static Corpus {
    static C: OnceLock<Corpus> = OnceLock::new();
    C.get_or_init(|| {
        let rd = |p: std::path::PathBuf| {
            std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
        };
        let cyl = import_common::sample("tg-cylindrical");
        let mut turbogrid = vec![[
            rd(cyl.join("sample.inf")),
            rd(cyl.join("hub.curve")),
            rd(cyl.join("shroud.curve")),
            rd(cyl.join("main.curve")),
            rd(cyl.join("splitter.curve")),
        ]];
        // The public exports join the corpus when present (required under CI).
        let shared = !import_common::skip_without_shared_data();
        if shared {
            let r37 = import_common::shared_data().join("pyturbogrid-rotor37");
            turbogrid.push([
                rd(r37.join("BladeGen.inf")),
                rd(r37.join("hub.curve")),
                rd(r37.join("shroud.curve")),
                rd(r37.join("profile.curve")),
                Vec::new(),
            ]);
        }
        Corpus {
            geomturbo: shared.then(|| rd(import_common::centrifugal_geomturbo())),
            rtzt: rd(import_common::sample("sample-6+6.rtzt")),
            turbogrid,
        }
    })
}

/// A mutation of a byte string.
#[derive(Debug, Clone)]
enum Mutation {
    Truncate(Index),
    Flip(Index, u8),
    InjectNan(Index),
    Random(Vec<u8>),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        any::<Index>().prop_map(Mutation::Truncate),
        (any::<Index>(), any::<u8>()).prop_map(|(i, b)| Mutation::Flip(i, b)),
        any::<Index>().prop_map(Mutation::InjectNan),
        prop::collection::vec(any::<u8>(), 0..512).prop_map(Mutation::Random),
    ]
}

fn apply(bytes: &[u8], m: &Mutation) -> Vec<u8> {
    let mut out = bytes.to_vec();
    match m {
        Mutation::Truncate(i) => {
            if !out.is_empty() {
                out.truncate(i.index(out.len()));
            }
        }
        Mutation::Flip(i, b) => {
            if !out.is_empty() {
                let k = i.index(out.len());
                out[k] ^= b | 1;
            }
        }
        Mutation::InjectNan(i) => {
            // Replace the number that contains position i with NaN.
            if !out.is_empty() {
                let k = i.index(out.len());
                let is_num =
                    |c: u8| c.is_ascii_digit() || matches!(c, b'.' | b'-' | b'+' | b'e' | b'E');
                let (mut a, mut b) = (k, k);
                while a > 0 && is_num(out[a - 1]) {
                    a -= 1;
                }
                while b < out.len() && is_num(out[b]) {
                    b += 1;
                }
                out.splice(a..b, b"NaN".iter().copied());
            }
        }
        Mutation::Random(r) => out = r.clone(),
    }
    out
}

/// What a successful import must satisfy: finite data, counts ≥ 1, ≥ 2 sections per blade;
/// and the whole pipeline (prepare, fit, assemble) ends in a typed error or a valid model
/// whose reported fit deviation is finite and whose blade counts are the file's.
fn valid(raw: &RawImpeller) {
    assert!(raw.main_blade_count() >= 1);
    assert!(raw.hub.len() >= 2 && raw.shroud.len() >= 2);
    assert!(raw
        .hub
        .iter()
        .chain(&raw.shroud)
        .all(|p| p.iter().all(|v| v.is_finite())));
    for b in &raw.blades {
        assert!(b.count >= 1 && b.sections.len() >= 2);
    }
    if let Ok(imp) = import_raw(raw, &ImportOptions::default()) {
        assert!(imp.fitted.max_fit_mm().is_finite());
        assert_eq!(imp.impeller.main().count(), raw.main_blade_count());
        assert_eq!(
            imp.impeller.splitter().map_or(0, |s| s.count()),
            raw.splitter_blade_count()
        );
    }
}

proptest! {
    #[test]
    fn geomturbo_never_panics(m in mutation()) {
        let Some(base) = &corpus().geomturbo else {
            return Ok(());
        };
        let bytes = apply(base, &m);
        if let Ok(raw) = parse_geomturbo(Path::new("fuzz.geomTurbo"), &bytes) {
            valid(&raw);
        }
    }

    #[test]
    fn rtzt_never_panics(m in mutation()) {
        let bytes = apply(&corpus().rtzt, &m);
        if let Ok(raw) = parse_rtzt(Path::new("fuzz.rtzt"), &bytes, LengthUnit::Millimetre) {
            valid(&raw);
        }
    }

    #[test]
    fn turbogrid_never_panics(set in 0usize..2, file in 0usize..5, m in mutation()) {
        let sets = &corpus().turbogrid;
        let files = &sets[set % sets.len()];
        let mut bytes: Vec<Vec<u8>> = files.to_vec();
        bytes[file] = apply(&files[file], &m);
        let n_profiles = if files[4].is_empty() { 1 } else { 2 };
        let profiles: Vec<(&Path, &[u8])> = bytes[3..3 + n_profiles]
            .iter()
            .map(|b| (Path::new("profile.curve"), b.as_slice()))
            .collect();
        let res = turbogrid_from_bytes(
            (Path::new("fuzz.inf"), &bytes[0]),
            (Path::new("hub.curve"), &bytes[1]),
            (Path::new("shroud.curve"), &bytes[2]),
            &profiles,
        );
        if let Ok(raw) = res {
            valid(&raw);
        }
    }
}
