//! Verification throughput on the 77 mm fixture's blank (Ø79 × 44 mm), synthetic five-axis
//! tapered ball-end workload (shank/holder checked against the stock):
//!
//! * `machining_sim/removal_1k_moves`: 1,000 moves at 0.1 mm (kept for its history);
//! * `machining_sim/removal_10k_moves_0.1mm`, `…_0.05mm`: the first 10,000 moves (the
//!   top layers, where every move cuts a full-depth slot), throughput in moves; a move costs
//!   what it cuts, so this is not a tenth of a 100,000-move path's time: that figure and
//!   peak memory come from `examples/removal_100k.rs`, too long for the bench harness;
//! * `machining_sim/measure_design_points`: the measurement ([`machining_sim::measure`]:
//!   normal probes at every design sample plus the depth of every cut end point) of the
//!   default impeller's design after those 10,000 moves at 0.1 mm, throughput in design
//!   samples (per million samples: 10⁶ / throughput).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use impeller_model::fixtures::default_impeller;
use machining_sim::synthetic::{workload_cutter, zigzag_path};
use machining_sim::{
    blank_of, cut, DesignModel, ImpellerDesign, ImpellerSampling, SimOptions, TriDexel,
};

fn removal(c: &mut Criterion) {
    let imp = default_impeller().unwrap();
    let blank = blank_of(&imp).unwrap();
    let (radius, top) = (imp.stock().max_radius() - 1.0, imp.stock().z_range().1);
    let opts = SimOptions::default();
    let mut g = c.benchmark_group("machining_sim");
    g.sample_size(10);
    let stock = TriDexel::from_shape(&blank, 0.1).unwrap();
    let ops = vec![(workload_cutter(), zigzag_path(1_000, radius, top))];
    g.bench_function("removal_1k_moves", |b| {
        b.iter_batched(
            || stock.clone(),
            |mut s| cut(&mut s, None, &ops, &opts).unwrap().stats.positions,
            BatchSize::LargeInput,
        )
    });
    let moves = 10_000;
    let ops = vec![(workload_cutter(), zigzag_path(moves, radius, top))];
    g.throughput(Throughput::Elements(moves as u64));
    for cell in [0.1, 0.05] {
        let stock = TriDexel::from_shape(&blank, cell).unwrap();
        g.bench_function(format!("removal_10k_moves_{cell}mm"), |b| {
            b.iter_batched(
                || stock.clone(),
                |mut s| cut(&mut s, None, &ops, &opts).unwrap().stats.positions,
                BatchSize::LargeInput,
            )
        });
    }
    let design = ImpellerDesign::new(&imp, ImpellerSampling::default()).unwrap();
    let grids = design.surface_grids();
    let samples: usize = grids.iter().map(|g| g.points.len()).sum();
    let initial = TriDexel::from_shape(&blank, 0.1).unwrap();
    let mut stock = initial.clone();
    cut(&mut stock, None, &ops, &opts).unwrap();
    g.throughput(Throughput::Elements(samples as u64));
    g.bench_function("measure_design_points", |b| {
        b.iter(|| {
            machining_sim::measure::measure(&stock, &initial, &design, &grids, 3.0).endpoints_inside
        })
    });
    g.finish();
}

criterion_group!(benches, removal);
criterion_main!(benches);
