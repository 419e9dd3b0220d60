#![allow(clippy::unwrap_used, clippy::expect_used)]
//! One curve–curve intersection: a 41-point cubic interpolant of a sine arch (1.5 periods)
//! against a full rational circle of radius 1.2 centred on it (6 crossings), tolerance 1e-9.
//! `nurbs/intersect_curves_2d`. Run: `cargo bench -p nurbs --bench intersect -- --quick`.

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::Vector2;
use nurbs::fit::{interpolate_curve, Parametrisation};
use nurbs::intersect::{intersect_curves, IntersectOptions};
use nurbs::NurbsCurve;
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let pts: Vec<Vector2<f64>> = (0..=40)
        .map(|i| {
            let x = -2.0 + 4.0 * i as f64 / 40.0;
            Vector2::new(x, (x * 2.4).sin())
        })
        .collect();
    let spline = interpolate_curve(&pts, 3, Parametrisation::ChordLength, None).unwrap();
    let circle = NurbsCurve::circle_arc(
        Vector2::zeros(),
        Vector2::x(),
        Vector2::y(),
        1.2,
        0.0,
        2.0 * std::f64::consts::PI,
    )
    .unwrap();
    let opts = IntersectOptions::default();
    let n = intersect_curves(&spline, &circle, &opts).unwrap().len();
    assert!(n >= 2, "{n} crossings");
    c.bench_function("nurbs/intersect_curves_2d", |b| {
        b.iter(|| {
            black_box(intersect_curves(
                black_box(&spline),
                black_box(&circle),
                &opts,
            ))
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
