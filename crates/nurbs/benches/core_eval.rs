//! Evaluation kernels on the reference surface (bicubic, 12 × 12 control points,
//! P(i,j) = (100 i/11, 100 j/11, 8 sin(x/17) cos(y/23) + 0.002 x y), clamped uniform knots):
//! `point` and `derivs2` at 1024 seeded random parameters per iteration batch, plus a
//! rational variant (random weights in [0.5, 2]) and a cubic space curve.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use nalgebra::Vector3;
use nurbs::{KnotVector, NurbsCurve, NurbsSurface};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;

fn reference_surface(rational: bool) -> NurbsSurface {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut ctrl = Vec::with_capacity(144);
    let mut w = Vec::with_capacity(144);
    for i in 0..12 {
        for j in 0..12 {
            let x = 100.0 * i as f64 / 11.0;
            let y = 100.0 * j as f64 / 11.0;
            let z = 8.0 * (x / 17.0).sin() * (y / 23.0).cos() + 0.002 * x * y;
            ctrl.push(Vector3::new(x, y, z));
            w.push(rng.random_range(0.5..2.0));
        }
    }
    let k = KnotVector::clamped_uniform(3, 12).unwrap();
    NurbsSurface::from_flat(k.clone(), k, ctrl, rational.then_some(w)).unwrap()
}

fn params(n: usize) -> Vec<(f64, f64)> {
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    (0..n)
        .map(|_| (rng.random_range(0.0..1.0), rng.random_range(0.0..1.0)))
        .collect()
}

fn bench(c: &mut Criterion) {
    let uv = params(1024);
    let mut g = c.benchmark_group("core");
    g.throughput(Throughput::Elements(uv.len() as u64));
    for (name, s) in [
        ("non_rational", reference_surface(false)),
        ("rational", reference_surface(true)),
    ] {
        g.bench_with_input(BenchmarkId::new("surface_point", name), &s, |b, s| {
            b.iter(|| {
                for &(u, v) in &uv {
                    black_box(s.point(black_box(u), black_box(v)));
                }
            })
        });
        g.bench_with_input(BenchmarkId::new("surface_derivs2", name), &s, |b, s| {
            b.iter(|| {
                for &(u, v) in &uv {
                    black_box(s.derivs2(black_box(u), black_box(v)));
                }
            })
        });
    }
    let curve = reference_surface(false).iso_curve_at_v(0.37).unwrap();
    let curve: NurbsCurve<3> = curve;
    g.bench_function("curve_point_cubic", |b| {
        b.iter(|| {
            for &(u, _) in &uv {
                black_box(curve.point(black_box(u)));
            }
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
