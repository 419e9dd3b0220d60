//! The certified curve search against a dense brute force followed by a local polish, on
//! random rational and polynomial curves (circular arcs, random positive weights) and queries
//! on both sides, near and far (beyond centres of curvature): the answer is never farther
//! than the true minimum by more than 1e-9 mm, and it is certified. Cases: max(`PROPTEST_CASES`
//! or 256, 256), so at least 256 even under `cargo xtask ci` (which sets 64 when unset).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use nalgebra::Vector2;
use nurbs::closest::CurveProjector;
use nurbs::{KnotVector, NurbsCurve};
use proptest::prelude::*;

mod case_floor;

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

#[test]
fn random_curves() {
    case_floor::run(
        file!(),
        "random_curves",
        (
            0u64..1_000_000,
            1usize..=4,
            5usize..=9,
            any::<bool>(),
            -20.0f64..110.0,
            -60.0f64..60.0,
        ),
        |(seed, p, n, rational, x, y)| {
            let c = random_curve(seed, p, n, rational);
            let q = Vector2::new(x, y);
            let r = CurveProjector::new(&c).closest_point(&q);
            let t = brute(&c, &q);
            prop_assert!(
                r.distance <= t + 1e-9,
                "{} > {} (excess {:.3e})",
                r.distance,
                t,
                r.distance - t
            );
            prop_assert!(r.certified);
            prop_assert!(((c.point(r.u) - q).norm() - r.distance).abs() < 1e-9);
            Ok(())
        },
    );
}

#[test]
fn conics_from_any_side() {
    case_floor::run(
        file!(),
        "conics_from_any_side",
        (
            5.0f64..60.0,
            5.0f64..60.0,
            -80.0f64..80.0,
            -80.0f64..80.0,
            proptest::option::of(0.0f64..=1.0),
        ),
        |(rx, ry, x, y, hint)| {
            let c = quarter(rx, ry);
            let q = Vector2::new(x, y);
            let r = CurveProjector::new(&c).closest_point_with_hint(&q, hint);
            let t = brute(&c, &q);
            prop_assert!(r.distance <= t + 1e-9, "{} > {}", r.distance, t);
            prop_assert!(r.certified);
            Ok(())
        },
    );
}

/// The centre of a circular arc is equidistant from all of it: any point is an answer, at
/// the radius.
#[test]
fn centre_of_an_arc() {
    let c = quarter(10.0, 10.0);
    let r = CurveProjector::new(&c).closest_point(&Vector2::new(10.0, 10.0));
    assert!((r.distance - 10.0).abs() < 1e-9, "{}", r.distance);
}

/// `closest_point_within(q, ρ)` is the global closest point when it lies within `ρ` (the same
/// distance as the unbounded search, to round-off) and `None` when it lies beyond `ρ`;
/// bounds are drawn around the true distance, with a margin of 1e-6 mm either side of it
/// (the search may drop a point within its 1e-10 mm certification tolerance of `ρ`).
#[test]
fn bounded_search_finds_exactly_what_lies_within_the_bound() {
    case_floor::run(
        file!(),
        "bounded_search_finds_exactly_what_lies_within_the_bound",
        (
            0u64..1_000_000,
            1usize..=4,
            5usize..=9,
            any::<bool>(),
            -20.0f64..110.0,
            -60.0f64..60.0,
            0.0f64..2.0,
        ),
        |(seed, p, n, rational, x, y, f)| {
            let c = random_curve(seed, p, n, rational);
            let q = Vector2::new(x, y);
            let pr = CurveProjector::new(&c);
            let full = pr.closest_point(&q);
            let rho = f * full.distance;
            if (rho - full.distance).abs() < 1e-6 {
                return Ok(());
            }
            match pr.closest_point_within(&q, rho) {
                Some(w) => {
                    prop_assert!(rho > full.distance, "found beyond the bound {rho}");
                    prop_assert!(
                        (w.distance - full.distance).abs() < 1e-9,
                        "{} vs {}",
                        w.distance,
                        full.distance
                    );
                    prop_assert!(w.certified);
                    prop_assert!(((c.point(w.u) - q).norm() - w.distance).abs() < 1e-9);
                }
                None => prop_assert!(
                    rho < full.distance,
                    "nothing found within {rho} though the curve comes to {}",
                    full.distance
                ),
            }
            Ok(())
        },
    );
}

#[test]
fn bounded_search_refuses_non_finite_input() {
    let pr = CurveProjector::new(&quarter(10.0, 5.0));
    assert!(pr
        .closest_point_within(&Vector2::new(f64::NAN, 0.0), 5.0)
        .is_none());
    assert!(pr
        .closest_point_within(&Vector2::new(1.0, 1.0), f64::NAN)
        .is_none());
    assert!(pr
        .closest_point_within(&Vector2::new(1.0, 1.0), -1.0)
        .is_none());
    let q = Vector2::new(1.0, 1.0);
    let unbounded = pr.closest_point_within(&q, f64::INFINITY).unwrap();
    assert_eq!(unbounded.distance, pr.closest_point(&q).distance);
    assert!(pr
        .closest_point_within(&Vector2::new(1.0, 1.0), 100.0)
        .is_some());
}
