#![allow(clippy::unwrap_used, clippy::expect_used)]
//! Cutter-to-surface contact (DESIGN §5): the cutter location touching a surface point and
//! the scallop height between neighbouring passes.
//!
//! `cam_core/contact_location`: one call per iteration, cycling through a ball, a bull nose,
//! a flat end and a tapered ball end at 64 precomputed contact points / normals / axes on a
//! sphere of radius 40 mm (the per-call figure is the median over the cycle).
//! `cam_core/ball_scallop_exact` and `cam_core/bull_nose_scallop_exact`: one exact scallop
//! height (closed-form circle–circle; silhouette bisection) at r = 3 mm / R = 4, r_c = 1 mm,
//! lead 10°, κ = 0.02 /mm, step 1.2 mm.
//! Run: `cargo bench -p cam-core --bench contact -- --quick`.

use cam_core::{
    ball_scallop, bull_nose_scallop, contact_location, CutterShape, Point3, UnitVector3, Vector3,
};
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

fn cases() -> Vec<(CutterShape, Point3, UnitVector3, UnitVector3)> {
    let shapes = [
        CutterShape::BallEnd { radius: 3.0 },
        CutterShape::BullNose {
            radius: 4.0,
            corner_radius: 1.0,
        },
        CutterShape::FlatEnd { radius: 2.5 },
        CutterShape::TaperedBallEnd {
            ball_radius: 1.5,
            half_angle: 3f64.to_radians(),
        },
    ];
    let mut out = Vec::new();
    for k in 0..64 {
        let t = k as f64 / 64.0;
        let n = UnitVector3::new_normalize(Vector3::new(
            0.4 * (6.0 * t).cos(),
            0.4 * (6.0 * t).sin(),
            1.0,
        ));
        let c = Point3::from(n.into_inner() * 40.0);
        let a = UnitVector3::new_normalize(Vector3::new(0.2 * t, -0.1, 1.0));
        out.push((shapes[k % shapes.len()], c, n, a));
    }
    out
}

fn bench(c: &mut Criterion) {
    let cases = cases();
    let mut i = 0usize;
    c.bench_function("cam_core/contact_location", |b| {
        b.iter(|| {
            let (s, p, n, a) = &cases[i % cases.len()];
            i = i.wrapping_add(1);
            black_box(contact_location(black_box(s), *p, *n, *a).unwrap())
        })
    });
    c.bench_function("cam_core/ball_scallop_exact", |b| {
        b.iter(|| {
            black_box(ball_scallop(
                black_box(3.0),
                black_box(0.02),
                black_box(1.2),
            ))
        })
    });
    let lead = 10f64.to_radians();
    c.bench_function("cam_core/bull_nose_scallop_exact", |b| {
        b.iter(|| {
            black_box(bull_nose_scallop(
                black_box(4.0),
                1.0,
                lead,
                black_box(0.02),
                black_box(1.2),
            ))
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
