//! Criterion benchmarks of the distance-function core on the reference surface of issue 2:
//! bicubic, 12 × 12 control points `P(i,j) = (x, y, 8·sin(x/17)·cos(y/23) + 0.002·x·y)`,
//! `x = 100·i/11`, `y = 100·j/11` (mm), clamped uniform knots on [0, 1], unit weights.
//!
//! * `nurbs/eval` — `NurbsSurface::point` at 20 000 seeded `(u, v)`, one per iteration;
//! * `nurbs/derivs2` — `NurbsSurface::derivs2` at the same parameters;
//! * `nurbs/closest_point_cold` — `SurfaceProjector::closest_point` (no hint) for the 20 000
//!   seeded queries `S(u,v) + (0,0,d)`, `d ~ U[−5, 5]` mm (the points of
//!   `examples/closest_point_queries.rs`), one query per iteration;
//! * `nurbs/closest_point_warm` — `closest_point_with_hint` with the previous answer as hint,
//!   on 20 000 queries ordered along a path: 100 serpentine rows `v = r/99`, 200 steps in `u`
//!   per row (≈ 0.5 mm apart), offset `d = 5·sin(0.05·k)` mm along the path.
//!
//! Each iteration is one query (criterion's per-iteration time = time per query).
//! Run: `cargo bench -p nurbs --bench nurbs` (add `-- --quick` for a short run).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::Vector3;
use nurbs::closest::SurfaceProjector;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

#[path = "common/reference.rs"]
mod reference;
use reference::{reference_surface, SEED};

const COUNT: usize = 20_000;

fn bench(c: &mut Criterion) {
    let surface = reference_surface();
    let projector = SurfaceProjector::new(&surface);
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    let mut params = Vec::with_capacity(COUNT);
    let queries: Vec<Vector3<f64>> = (0..COUNT)
        .map(|_| {
            let u: f64 = rng.random_range(0.0..=1.0);
            let v: f64 = rng.random_range(0.0..=1.0);
            let d: f64 = rng.random_range(-5.0..=5.0);
            params.push((u, v));
            surface.point(u, v) + Vector3::new(0.0, 0.0, d)
        })
        .collect();
    let mut path = Vec::with_capacity(COUNT);
    for r in 0..100 {
        for s in 0..200 {
            let k = path.len();
            let t = s as f64 / 199.0;
            let u = if r % 2 == 0 { t } else { 1.0 - t };
            let v = r as f64 / 99.0;
            let d = 5.0 * (0.05 * k as f64).sin();
            path.push(surface.point(u, v) + Vector3::new(0.0, 0.0, d));
        }
    }

    let mut group = c.benchmark_group("nurbs");
    group.measurement_time(Duration::from_secs(3));
    group.warm_up_time(Duration::from_secs(1));
    let mut i = 0;
    group.bench_function("eval", |b| {
        b.iter(|| {
            let (u, v) = params[i];
            i = (i + 1) % COUNT;
            black_box(surface.point(black_box(u), black_box(v)))
        })
    });
    let mut i = 0;
    group.bench_function("derivs2", |b| {
        b.iter(|| {
            let (u, v) = params[i];
            i = (i + 1) % COUNT;
            black_box(surface.derivs2(black_box(u), black_box(v)))
        })
    });
    let mut i = 0;
    group.bench_function("closest_point_cold", |b| {
        b.iter(|| {
            let q = &queries[i];
            i = (i + 1) % COUNT;
            black_box(projector.closest_point(black_box(q)))
        })
    });
    let mut i = 0;
    let mut hint = None;
    group.bench_function("closest_point_warm", |b| {
        b.iter(|| {
            let q = &path[i];
            i = (i + 1) % COUNT;
            let a = projector.closest_point_with_hint(black_box(q), hint);
            hint = Some((a.u, a.v));
            black_box(a)
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
