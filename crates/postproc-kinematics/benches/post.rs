//! Posting 100,000 cutter locations on each fixture machine (inverse kinematics with solution
//! choice, reverse-motion count, linearisation control at 0.005 mm, inverse-time feeds).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use cam_core::{CutterLocation, Move};
use criterion::{criterion_group, criterion_main, Criterion};
use postproc_kinematics::{post_path, AxisId, Machine, PostOptions, RotaryMode};
use std::hint::black_box;

const N: usize = 100_000;

/// A smooth five-axis path inside the machine's travel: the tilt swings around the middle of
/// its range, C turns through up to ±300°, the tip spirals over an impeller-sized region.
fn path(m: &Machine) -> Vec<Move> {
    let (tlo, thi) = m.axis(AxisId::Tilt).limits();
    let tmid = 0.5 * (tlo + thi);
    let tamp = 0.3 * (thi - tlo).min(2.0);
    let crange = match m.axis(AxisId::Rotate).mode {
        RotaryMode::Continuous => 300f64.to_radians(),
        RotaryMode::Limited { min, max } => 0.8 * min.abs().min(max.abs()).min(300f64.to_radians()),
    };
    (0..N)
        .map(|i| {
            let s = i as f64 / (N - 1) as f64;
            let tilt = tmid + tamp * (6.0 * std::f64::consts::PI * s).sin();
            let rotate = -crange + 2.0 * crange * s;
            let axis = m.tool_axis(tilt, rotate);
            let r = 20.0 + 15.0 * s;
            let a = 40.0 * std::f64::consts::PI * s;
            let tip = cam_core::Point3::new(r * a.cos(), r * a.sin(), 10.0 + 20.0 * s);
            let mut mv = Move::feed(CutterLocation { tip, axis });
            mv.feed_mm_per_min = Some(1200.0);
            mv
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("postproc");
    g.sample_size(10);
    for name in ["xyzac-trt", "xyzbc-trt", "turnmill-bc", "headhead-ac"] {
        let file = format!(
            "{}/../../fixtures/machines/{name}.toml",
            env!("CARGO_MANIFEST_DIR")
        );
        let m = Machine::from_file(&file).unwrap();
        let tool = 60.0;
        let moves = path(&m);
        let opts = PostOptions {
            tool_length: tool,
            ..Default::default()
        };
        let posted = post_path(&m, &moves, &opts).unwrap();
        eprintln!(
            "{name}: {} blocks ({} inserted), max linearisation error {:.5} mm",
            posted.metrics.blocks,
            posted.metrics.inserted_blocks,
            posted.metrics.max_linearisation_error_mm
        );
        g.bench_function(format!("100k_{name}"), |b| {
            b.iter(|| post_path(&m, black_box(&moves), &opts).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
