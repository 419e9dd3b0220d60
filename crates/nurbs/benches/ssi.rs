//! Criterion benchmark of one surface–surface intersection: two perpendicular cylinders
//! (radii 5 and 3 mm, 20 mm long, axes z and x), whole domains, default options except
//! `max_step = seed_size = 1 mm`: two closed loops, seeding + marching + fitting.
//! Run: `cargo bench -p nurbs --bench ssi`.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::Vector3;
use nurbs::surface_intersect::{intersect_surfaces, ParamBox, SsiOptions};
use nurbs::{NurbsCurve, NurbsSurface};

fn cylinder(axis: Vector3<f64>, seam: Vector3<f64>, r: f64) -> NurbsSurface {
    let p = seam * r;
    let line = NurbsCurve::new(
        1,
        vec![0., 0., 1., 1.],
        vec![p - axis * 10.0, p + axis * 10.0],
        None,
    )
    .unwrap();
    NurbsSurface::revolution(&line, Vector3::zeros(), axis, std::f64::consts::TAU).unwrap()
}

fn bench(c: &mut Criterion) {
    let a = cylinder(Vector3::z(), -Vector3::y(), 5.0);
    let b = cylinder(Vector3::x(), Vector3::y(), 3.0);
    let o = SsiOptions {
        max_step: 1.0,
        seed_size: 1.0,
        ..Default::default()
    };
    c.bench_function("nurbs/ssi_perpendicular_cylinders", |bn| {
        bn.iter(|| {
            let x = intersect_surfaces(
                black_box(&a),
                ParamBox::of(&a),
                black_box(&b),
                ParamBox::of(&b),
                &o,
            )
            .unwrap();
            black_box(x.branches.len())
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
