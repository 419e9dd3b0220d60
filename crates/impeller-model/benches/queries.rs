//! Point queries on the default impeller, group `impeller_model`: blade-side signed distance
//! cold (`blade_side_cold`: no hint) and warm (`blade_side_warm`: hint = the previous answer
//! along a path), hub and shroud signed distance (meridional contour, cached certified
//! projector), the local closest point with a hint; and building the model (group `model`).
//! Run with a filter, e.g. `cargo bench -p impeller-model --bench queries -- hub`.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{criterion_group, criterion_main, Criterion};
use impeller_model::query::{blade_side_distance, closest_point};
use impeller_model::{fixtures, Side};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;

fn queries(c: &mut Criterion) {
    let imp = fixtures::default_impeller().unwrap();
    let blade = imp.main().blade();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    // Points within 3 mm of the blade's suction side.
    let pts: Vec<(Vector3<f64>, (f64, f64))> = (0..256)
        .map(|_| {
            let (u, v) = (rng.random::<f64>(), rng.random::<f64>());
            let n = blade.outward_normal(Side::Suction, u, v).unwrap();
            let p = blade.suction().point(u, v) + n * (rng.random::<f64>() * 6.0 - 3.0);
            (p, (u, v))
        })
        .collect();
    blade.projector(Side::Suction);
    let mut i = 0;
    let mut g = c.benchmark_group("impeller_model");
    g.bench_function("blade_side_cold", |b| {
        b.iter(|| {
            i = (i + 1) % pts.len();
            black_box(blade_side_distance(blade, Side::Suction, &pts[i].0, None))
        })
    });
    // A path of queries 1 mm off the side, 0.2 % of u apart: each warm-starts from the
    // previous answer (the way an operation walks a tool path).
    let path: Vec<Vector3<f64>> = (0..400)
        .map(|k| {
            let (u, v) = (0.1 + 0.002 * k as f64, 0.4 + 0.0005 * k as f64);
            let n = blade.outward_normal(Side::Suction, u, v).unwrap();
            blade.suction().point(u, v) + n
        })
        .collect();
    let mut prev: Option<(f64, f64)> = None;
    let mut j = 0;
    g.bench_function("blade_side_warm", |b| {
        b.iter(|| {
            j = (j + 1) % path.len();
            if j == 0 {
                prev = None;
            }
            let (sp, d) = blade_side_distance(blade, Side::Suction, &path[j], prev);
            prev = Some((sp.u, sp.v));
            black_box(d)
        })
    });
    g.bench_function("blade_side_closest_point_local_hint", |b| {
        b.iter(|| {
            i = (i + 1) % pts.len();
            black_box(closest_point(blade.suction(), &pts[i].0, Some(pts[i].1)))
        })
    });
    g.bench_function("hub_signed_distance", |b| {
        b.iter(|| {
            i = (i + 1) % pts.len();
            black_box(imp.hub().signed_distance(&pts[i].0))
        })
    });
    g.bench_function("shroud_signed_distance", |b| {
        b.iter(|| {
            i = (i + 1) % pts.len();
            black_box(imp.shroud().signed_distance(&pts[i].0))
        })
    });
    g.finish();
    let mut g = c.benchmark_group("model");
    g.sample_size(10);
    g.bench_function("build_default_impeller", |b| {
        b.iter(|| black_box(fixtures::default_impeller().unwrap()))
    });
    g.finish();
}

criterion_group!(benches, queries);
criterion_main!(benches);
