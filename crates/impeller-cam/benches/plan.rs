//! Planning the embedded default job (`fixtures/impeller-8+8/job.toml`): every operation of
//! the job planned through its registered kind, linked and turned into CL operations — the
//! `plan` stage of the pipeline, without post-processing and verification.
//!
//! `cargo bench -p impeller-cam --bench plan -- --warm-up-time 1 --measurement-time 3`
//!
//! Until operation crates are registered the default job has no `[[operations]]`, and the
//! figure is the cost of reading its CL files alone.
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
