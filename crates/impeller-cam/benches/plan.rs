//! Planning the embedded default job (`fixtures/impeller-8+8/job.toml`): every operation of
//! the job planned through its registered kind, linked and turned into CL operations — the
//! `plan` stage of the pipeline, without post-processing and verification.
//!
//! `cargo bench -p impeller-cam --bench plan -- --warm-up-time 1 --measurement-time 3`
//!
//! The default job is paper 003's process plan on impeller-8+8 (channel roughing, hub
//! finishing, blade semi-finishing, blade finishing, blade-root finishing; operations plan in
//! parallel). Measured 2026-11-27 on two cores: 4.12 s [4.00, 4.23] (goal: under 5 s).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{criterion_group, criterion_main, Criterion};
use impeller_cam::{pipeline, Job};

fn plan_default_job(c: &mut Criterion) {
    let job = Job::default_job().expect("embedded default job");
    let impeller = pipeline::model(&job).expect("impeller");
    let mut group = c.benchmark_group("plan");
    group.sample_size(10);
    group.bench_function(
        format!("default_job_{}_operations", job.operations.len()),
        |b| {
            b.iter(|| {
                let mut notes = Vec::new();
                pipeline::plan(
                    &job,
                    &impeller,
                    impeller_cam::registry::OPERATIONS,
                    &mut notes,
                )
                .expect("plan")
            })
        },
    );
    group.finish();
}

criterion_group!(benches, plan_default_job);
criterion_main!(benches);
