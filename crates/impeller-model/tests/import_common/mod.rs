//! Shared helpers of the import/export tests: where the public design exports live.
#![allow(dead_code, clippy::panic, clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;

/// `../shared/data` beside the repository root (read in place, never copied). The
/// repository may be a git worktree nested one level deeper, so every ancestor of the crate
/// folder is tried for a `shared/data` child, starting with `../../../shared/data`.
pub fn shared_data() -> PathBuf {
    let crate_dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let found = crate_dir
        .ancestors()
        .skip(2)
        .map(|a| a.join("shared/data"))
        .find(|d| d.join("README.md").is_file());
    match found {
        Some(d) => d,
        None => panic!(
            "the public design exports are missing: expected the folder {} (the repository \
             root's sibling `shared/data`, see fixtures/impeller-autoblade-12+12/README.md)",
            crate_dir.join("../../../shared/data").display()
        ),
    }
}

/// The shared data folder, or `None` after printing why the calling test `test` is skipped
/// when it is absent. Under `CI=true` an absent folder fails the test instead: CI must run
/// every real-data test.
pub fn shared_data_or_skip(test: &str) -> Option<PathBuf> {
    let crate_dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let found = crate_dir
        .ancestors()
        .skip(2)
        .map(|a| a.join("shared/data"))
        .find(|d| d.join("README.md").is_file());
    if found.is_none() {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "CI=true but the shared design exports (`shared/data` beside the repository) are \
             missing"
        );
        eprintln!("skipping {test}: no shared/data folder beside the repository");
    }
    found
}

/// Rotor 37 TurboGrid `.inf`.
pub fn rotor37_inf() -> PathBuf {
    shared_data().join("pyturbogrid-rotor37/BladeGen.inf")
}

/// The 12 + 12 centrifugal `.geomTurbo`.
pub fn centrifugal_geomturbo() -> PathBuf {
    shared_data().join("pynumeca-centrifugal/cc_autoblade.geomTurbo")
}

/// Our own sample files.
pub fn sample(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}
