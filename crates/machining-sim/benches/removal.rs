//! Material removal throughput on the 77 mm fixture's blank (Ø79 × 44 mm) at 0.1 mm:
//! `machining_sim/removal_1k_moves` sweeps 1,000 moves of the synthetic five-axis tapered
//! ball-end workload (shank/holder checked against the stock). The full 100,000-move figure
//! and peak memory come from `examples/removal_100k.rs` (too long for the bench harness).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use impeller_model::fixtures::default_impeller;
use machining_sim::synthetic::{workload_cutter, zigzag_path};
use machining_sim::{blank_of, cut, SimOptions, TriDexel};

fn removal(c: &mut Criterion) {
    let imp = default_impeller().unwrap();
    let blank = blank_of(&imp).unwrap();
    let stock = TriDexel::from_shape(&blank, 0.1).unwrap();
    let path = zigzag_path(
        1_000,
        imp.stock().max_radius() - 1.0,
        imp.stock().z_range().1,
    );
    let ops = vec![(workload_cutter(), path)];
    let opts = SimOptions::default();
    let mut g = c.benchmark_group("machining_sim");
    g.sample_size(10);
    g.bench_function("removal_1k_moves", |b| {
        b.iter_batched(
            || stock.clone(),
            |mut s| cut(&mut s, None, &ops, &opts).unwrap().stats.positions,
            BatchSize::LargeInput,
        )
    });
    g.finish();
}

criterion_group!(benches, removal);
criterion_main!(benches);
