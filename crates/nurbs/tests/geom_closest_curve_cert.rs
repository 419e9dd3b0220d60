//! The certified curve search against a dense brute force followed by a local polish, on
//! random rational and polynomial curves (circular arcs, random positive weights) and queries
//! on both sides, near and far (beyond centres of curvature): the answer is never farther
//! than the true minimum by more than 1e-9 mm, and it is certified.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::Vector2;
use nurbs::closest::CurveProjector;
use nurbs::{KnotVector, NurbsCurve};
use proptest::prelude::*;

/// Dense sample, then golden-section polish around the best sample (an upper bound of the
/// true minimum, within round-off of it for samples finer than the curve's features).
fn brute(c: &NurbsCurve<2>, q: &Vector2<f64>) -> f64 {
    let (a, b) = c.domain();
    let n = 4000;
    let f = |u: f64| (c.point(u) - q).norm();
    let (mut bu, mut bd) = (a, f64::INFINITY);
    for k in 0..=n {
        let u = a + (b - a) * k as f64 / n as f64;
        let d = f(u);
        if d < bd {
            bd = d;
            bu = u;
        }
    }
    let h = (b - a) / n as f64;
    let (mut lo, mut hi) = ((bu - h).max(a), (bu + h).min(b));
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..100 {
        let x1 = hi - g * (hi - lo);
        let x2 = lo + g * (hi - lo);
        if f(x1) < f(x2) {
            hi = x2;
        } else {
            lo = x1;
        }
    }
    bd.min(f(0.5 * (lo + hi)))
}

fn random_curve(seed: u64, p: usize, n_ctrl: usize, rational: bool) -> NurbsCurve<2> {
    let mut s = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    let mut rnd = move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let ctrl: Vec<Vector2<f64>> = (0..n_ctrl)
        .map(|i| Vector2::new(10.0 * i as f64 + 6.0 * rnd(), 30.0 * rnd() - 15.0))
        .collect();
    let w = rational.then(|| (0..n_ctrl).map(|_| 0.2 + 3.0 * rnd()).collect());
    let k = KnotVector::clamped_uniform(p, n_ctrl)
        .unwrap()
        .knots()
        .to_vec();
    NurbsCurve::new(p, k, ctrl, w).unwrap()
}

/// A hub-like contour: a rational quadratic quarter ellipse (exact conic).
fn quarter(rx: f64, ry: f64) -> NurbsCurve<2> {
    let ctrl = vec![
        Vector2::new(rx, 0.0),
        Vector2::new(0.0, 0.0),
        Vector2::new(0.0, ry),
    ];
    let w = std::f64::consts::FRAC_1_SQRT_2;
    NurbsCurve::new(
        2,
        vec![0., 0., 0., 1., 1., 1.],
        ctrl,
        Some(vec![1.0, w, 1.0]),
    )
    .unwrap()
}

fn cases() -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|c| c.parse().ok())
        .unwrap_or(256)
        .max(256)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases()))]

    #[test]
    fn random_curves(seed in 0u64..1_000_000, p in 1usize..=4, n in 5usize..=9,
                     rational in any::<bool>(), x in -20.0f64..110.0, y in -60.0f64..60.0) {
        let c = random_curve(seed, p, n, rational);
        let q = Vector2::new(x, y);
        let r = CurveProjector::new(&c).closest_point(&q);
        let t = brute(&c, &q);
        prop_assert!(r.distance <= t + 1e-9, "{} > {} (excess {:.3e})", r.distance, t, r.distance - t);
        prop_assert!(r.certified);
        prop_assert!(((c.point(r.u) - q).norm() - r.distance).abs() < 1e-9);
    }

    #[test]
    fn conics_from_any_side(rx in 5.0f64..60.0, ry in 5.0f64..60.0, x in -80.0f64..80.0, y in -80.0f64..80.0,
                            hint in proptest::option::of(0.0f64..=1.0)) {
        let c = quarter(rx, ry);
        let q = Vector2::new(x, y);
        let r = CurveProjector::new(&c).closest_point_with_hint(&q, hint);
        let t = brute(&c, &q);
        prop_assert!(r.distance <= t + 1e-9, "{} > {}", r.distance, t);
        prop_assert!(r.certified);
    }
}

/// The centre of a circular arc is equidistant from all of it: any point is an answer, at
/// the radius.
#[test]
fn centre_of_an_arc() {
    let c = quarter(10.0, 10.0);
    let r = CurveProjector::new(&c).closest_point(&Vector2::new(10.0, 10.0));
    assert!((r.distance - 10.0).abs() < 1e-9, "{}", r.distance);
}
