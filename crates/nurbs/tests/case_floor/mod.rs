//! Property tests with a floor on their case count: max(`PROPTEST_CASES` or 256, 256).
//! `cargo xtask ci` sets `PROPTEST_CASES=64` when unset; the certified-query properties keep
//! 256 cases there, while a larger value (a nightly run with `PROPTEST_CASES=10000`) raises
//! them. They run on a [`TestRunner`] rather than in `proptest!`, because that macro lets
//! `PROPTEST_CASES` replace the configured count.
//!
//! (impeller-model's tests keep a copy of this module: a test module cannot be shared across
//! crates that are packaged on their own.)

use proptest::prelude::*;
use proptest::test_runner::{TestCaseError, TestRunner};

/// Number of cases: max(`PROPTEST_CASES` or 256, 256).
pub fn cases() -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|c| c.parse().ok())
        .unwrap_or(256)
        .max(256)
}

/// Runs `test` on `strategy` with [`cases`] cases, the other settings from proptest's
/// defaults and environment, regressions persisted beside `source_file` (pass `file!()`);
/// panics with the minimal failing input.
pub fn run<S: Strategy>(
    source_file: &'static str,
    name: &'static str,
    strategy: S,
    test: impl Fn(S::Value) -> Result<(), TestCaseError>,
) {
    let config = ProptestConfig {
        cases: cases(),
        source_file: Some(source_file),
        test_name: Some(name),
        ..ProptestConfig::default()
    };
    let mut runner = TestRunner::new(config);
    if let Err(e) = runner.run(&strategy, test) {
        panic!("{name}: {e}");
    }
}
