#![allow(clippy::unwrap_used, clippy::expect_used)]
//! Signed distance to the swept envelope of a conical ball-end cutter on a flank-milling
//! setting: r = 3 mm, half angle 3°, 30 cutter locations interpolated by cubic B-spline
//! guiding curves (tip-side guide at the ball centre, upper guide 25 mm up the axis), query
//! points on a synthetic ruled blade surface lying along the cutter's flank (within
//! a few tenths of a mm of the envelope), visited along the blade.
//!
//! `cam_core/signed_distance_warm`: one query per iteration, hinted with the previous
//! point's minimiser. `cam_core/signed_distance_cold`: one query per iteration, global
//! seeding. Run: `cargo bench -p cam-core --bench envelope -- --quick`.

use cam_core::{
    CutterShape, EnvelopeOptions, EnvelopeParam, GuideCurve, Point3, SphereFamily, SweptEnvelope,
    Vector3,
};
use criterion::{criterion_group, criterion_main, Criterion};
use nurbs::fit::{interpolate_curve, Parametrisation};
use nurbs::NurbsSurface;
use std::hint::black_box;

const N_CL: usize = 30;

fn interp(points: &[Vector3]) -> nurbs::Curve3 {
    interpolate_curve(points, 3, Parametrisation::Uniform, None).unwrap()
}

fn setup() -> (SweptEnvelope, Vec<Point3>) {
    let r = 3.0;
    let theta = 3f64.to_radians();
    let shape = CutterShape::TaperedBallEnd {
        ball_radius: r,
        half_angle: theta,
    };
    let fam = SphereFamily::from_shape(&shape, 30.0).unwrap();
    // Synthetic flank path: the tip climbs along a curved hub line, the axis leans and twists.
    let mut tips = Vec::new();
    let mut axes = Vec::new();
    for k in 0..N_CL {
        let u = k as f64 / (N_CL - 1) as f64;
        let ang = 0.6 * u;
        let rad = 40.0 + 30.0 * u;
        tips.push(Vector3::new(
            rad * ang.cos(),
            rad * ang.sin(),
            12.0 - 8.0 * u * u,
        ));
        axes.push(Vector3::new(0.25 - 0.5 * u, 0.1 + 0.3 * u * u, 1.0).normalize());
    }
    let p0: Vec<Vector3> = tips.iter().zip(&axes).map(|(t, a)| t + a * r).collect();
    let p1: Vec<Vector3> = tips
        .iter()
        .zip(&axes)
        .map(|(t, a)| t + a * (r + 25.0))
        .collect();
    let g0 = GuideCurve::from_curve(&interp(&p0)).unwrap();
    let g1 = GuideCurve::from_curve(&interp(&p1)).unwrap();
    let env = SweptEnvelope::new(fam, g0, g1, r, EnvelopeOptions::default()).unwrap();
    // Blade: ruled surface through the flank contact lines at heights 4 and 24 mm, on the
    // side of the cutter facing away from the path's curvature centre, slightly waved.
    let (mut low, mut high) = (Vec::new(), Vec::new());
    for k in 0..60 {
        let s = k as f64 / 59.0;
        let cl = env.cutter_location(s).unwrap();
        let ds = env.cutter_location((s + 1e-4).min(1.0)).unwrap().tip
            - env.cutter_location((s - 1e-4).max(0.0)).unwrap().tip;
        let side = cl.axis.cross(&ds).normalize();
        let wave = 0.05 * (9.0 * s).sin();
        for (h, out) in [(4.0, &mut low), (24.0, &mut high)] {
            let n = side * theta.cos() - cl.axis.into_inner() * theta.sin();
            out.push(cl.axis_point(h).coords + side * shape.radius_at(h) + n * wave);
        }
    }
    let blade = NurbsSurface::ruled(&interp(&low), &interp(&high)).unwrap();
    // Query points along the blade: 100 stations in u, 10 along each ruling, serpentine.
    let mut pts = Vec::new();
    for i in 0..100 {
        let u = i as f64 / 99.0;
        for j in 0..10 {
            let j = if i % 2 == 0 { j } else { 9 - j };
            pts.push(Point3::from(blade.point(u, j as f64 / 9.0)));
        }
    }
    (env, pts)
}

fn bench(c: &mut Criterion) {
    let (env, pts) = setup();
    // Sanity (outside the timing): warm and cold agree, points are near the envelope.
    let mut hint: Option<EnvelopeParam> = None;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let (mut cold_it, mut warm_it) = (0, 0);
    for p in &pts {
        let cold = env.signed_distance(p, None).unwrap();
        let warm = env.signed_distance(p, hint).unwrap();
        hint = Some(warm.param);
        assert!((cold.distance - warm.distance).abs() < 1e-9);
        lo = lo.min(cold.distance);
        hi = hi.max(cold.distance);
        cold_it += cold.iterations;
        warm_it += warm.iterations;
    }
    assert!(lo > -0.5 && hi < 0.5, "blade points are near the envelope");
    eprintln!(
        "{} points, signed distance in [{lo:.4}, {hi:.4}] mm; Newton iterations per point: \
         cold {:.2}, warm {:.2}",
        pts.len(),
        cold_it as f64 / pts.len() as f64,
        warm_it as f64 / pts.len() as f64
    );

    cpu_time_report(&env, &pts);

    let mut i = 0usize;
    let mut hint: Option<EnvelopeParam> = None;
    c.bench_function("cam_core/signed_distance_warm", |b| {
        b.iter(|| {
            let r = env.signed_distance(black_box(&pts[i]), hint).unwrap();
            hint = Some(r.param);
            i = (i + 1) % pts.len();
            black_box(r.distance)
        })
    });
    let mut i = 0usize;
    c.bench_function("cam_core/signed_distance_cold", |b| {
        b.iter(|| {
            let r = env.signed_distance(black_box(&pts[i]), None).unwrap();
            i = (i + 1) % pts.len();
            black_box(r.distance)
        })
    });
    let mut i = 0usize;
    let mut hint: Option<EnvelopeParam> = None;
    c.bench_function("cam_core/signed_distance_warm_with_gradient", |b| {
        b.iter(|| {
            let (r, g) = env
                .signed_distance_with_gradient(black_box(&pts[i]), hint)
                .unwrap();
            hint = Some(r.param);
            i = (i + 1) % pts.len();
            black_box((r.distance, g.shape[0]))
        })
    });
}

/// On-CPU nanoseconds of this thread (Linux `/proc/thread-self/schedstat`), if available.
fn cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

/// The machine running the benchmarks may be shared: besides criterion's wall-clock figures,
/// print the on-CPU time per query, which excludes time spent waiting for a core.
fn cpu_time_report(env: &SweptEnvelope, pts: &[Point3]) {
    let rounds = 20;
    let (Some(c0), t0) = (cpu_ns(), std::time::Instant::now()) else {
        return;
    };
    let mut hint: Option<EnvelopeParam> = None;
    for _ in 0..rounds {
        for p in pts {
            hint = Some(env.signed_distance(black_box(p), hint).unwrap().param);
        }
    }
    let (Some(c1), t1) = (cpu_ns(), std::time::Instant::now()) else {
        return;
    };
    for _ in 0..rounds {
        for p in pts {
            black_box(env.signed_distance(black_box(p), None).unwrap());
        }
    }
    let Some(c2) = cpu_ns() else { return };
    let n = (rounds * pts.len()) as f64;
    eprintln!(
        "on-CPU time per point: warm {:.3} µs (wall {:.3}), cold {:.3} µs (wall {:.3})",
        (c1 - c0) as f64 / n / 1e3,
        (t1 - t0).as_secs_f64() / n * 1e6,
        (c2 - c1) as f64 / n / 1e3,
        t1.elapsed().as_secs_f64() / n * 1e6,
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
