//! Shared helpers of the import/export tests: where the public design exports live.
#![allow(dead_code, clippy::panic, clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;

/// Environment variable naming the folder of the public design exports (overrides the
/// search for `shared/data` beside the repository).
pub const DATA_DIR_VAR: &str = "IMPELLER_DATA_DIR";

/// The public design exports: the folder named by `IMPELLER_DATA_DIR`, else `shared/data`
/// beside the repository (read in place, never copied). The repository may be a git
/// worktree nested one level deeper, so every ancestor of the crate folder is tried for a
/// `shared/data` child, starting with `../../../shared/data`. `None` when absent.
pub fn find_shared_data() -> Option<PathBuf> {
    if let Some(d) = std::env::var_os(DATA_DIR_VAR) {
        let d = PathBuf::from(d);
        return d.is_dir().then_some(d);
    }
    let crate_dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    crate_dir
        .ancestors()
        .skip(2)
        .map(|a| a.join("shared/data"))
        .find(|d| d.join("README.md").is_file())
}

/// Whether this is a CI run (`CI=true`): the public exports are then required.
pub fn under_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| v == "true" || v == "1")
}

/// `true` (after printing that the test was skipped) when the public design exports are
/// absent outside CI; under CI their absence fails the test. Tests that read the exports
/// start with `if import_common::skip_without_shared_data() { return; }`.
pub fn skip_without_shared_data() -> bool {
    if find_shared_data().is_some() {
        return false;
    }
    if under_ci() {
        panic!(
            "CI=true but the public design exports are missing: set {DATA_DIR_VAR} or place \
             them in `shared/data` beside the repository (see \
             fixtures/impeller-autoblade-12+12/README.md)"
        );
    }
    eprintln!(
        "SKIPPED: the public design exports are not here (no {DATA_DIR_VAR}, no \
         `shared/data` beside the repository); this test reads them and did not run"
    );
    true
}

/// The public design exports folder; panics with a clear message when absent (call
/// [`skip_without_shared_data`] first).
pub fn shared_data() -> PathBuf {
    match find_shared_data() {
        Some(d) => d,
        None => panic!(
            "the public design exports are missing: set {DATA_DIR_VAR} or place them in \
             `shared/data` beside the repository (see fixtures/impeller-autoblade-12+12/README.md)"
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

/// The points of `s` on a `(nu + 1) × (nv + 1)` grid over its whole domain, with their grid
/// indices: where a fitted surface is searched for a swing between its data.
pub fn grid_points(
    s: &nurbs::NurbsSurface,
    nu: usize,
    nv: usize,
) -> impl Iterator<Item = (usize, usize, nalgebra::Vector3<f64>)> + '_ {
    let ((u0, u1), (v0, v1)) = s.domain();
    (0..=nu).flat_map(move |i| {
        (0..=nv).map(move |j| {
            let (u, v) = (
                u0 + (u1 - u0) * i as f64 / nu as f64,
                v0 + (v1 - v0) * j as f64 / nv as f64,
            );
            (i, j, s.point(u, v))
        })
    })
}
