#![allow(clippy::unwrap_used, clippy::expect_used)]
//! Planning one blade side's root path and one hub finishing job on the fixture impeller-8+8
//! (1 mm fillet; tools of its process plan: T7 ball r1 for the root, T6 tapered ball r1 for
//! the hub, clearance sampled at 0.05 mm).
//! - `blade_root/plan_side_24`: 24 stations of main blade 0's pressure side (spine roots,
//!   ball fit, accessibility search, deviations, chord refinement, motion checks).
//! - `hub_finishing/plan_coarse`: the whole operation at `scallop_mm = 0.5`, 4 stations
//!   (3 lanes, 24 lines per channel, copied to 8 channels, residual measured).
//!
//! Run: `cargo bench -p channel-paths --bench finishing -- --warm-up-time 1 --measurement-time 5`.

#[path = "../tests/support/mod.rs"]
mod support;

use cam_plan::OperationSpec;
use channel_paths::blade_root::plan_side;
use criterion::{criterion_group, criterion_main, Criterion};
use impeller_model::Side;

fn bench(c: &mut Criterion) {
    let root = support::Ctx::new("impeller-8+8", 1.0);
    let cl = root.clearance();
    let ctx = plan_ctx!(root, cl);
    let order = root.imp.blades_in_order();
    let n = order.len();
    let mut g = c.benchmark_group("blade_root");
    g.sample_size(10);
    g.bench_function("plan_side_24", |b| {
        b.iter(|| {
            plan_side(
                &ctx,
                "root",
                "main blade 0",
                &order[0],
                Side::Pressure,
                &order[1],
                &order[n - 1],
                24,
                1.5f64.to_radians(),
            )
            .unwrap()
        })
    });
    g.finish();

    let mut hub = support::Ctx::new("impeller-8+8", 1.0);
    hub.tool = support::tapered_t6();
    hub.process.width_of_cut_mm = None;
    let hcl = hub.clearance();
    let hctx = plan_ctx!(hub, hcl);
    let op = channel_paths::build_hub_finishing(&OperationSpec {
        name: "hub".into(),
        kind: channel_paths::HUB_FINISHING.into(),
        tool: "T6".into(),
        process: hub.process,
        params: toml::from_str("scallop_mm = 0.5\nstations = 4").unwrap(),
    })
    .unwrap();
    let mut g = c.benchmark_group("hub_finishing");
    g.sample_size(10);
    g.bench_function("plan_coarse", |b| b.iter(|| op.plan(&hctx).unwrap()));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
