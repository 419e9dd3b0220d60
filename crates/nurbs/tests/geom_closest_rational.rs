//! The surface projector on random *rational* surfaces — surfaces of revolution (exact
//! circles, weights cos(Δθ/2)) and general nets with random positive weights — against a
//! dense brute force followed by a local polish: the answer (cold, and warm from a random
//! hint) is never farther than the brute force by more than 1e-9 mm (the brute force is an
//! upper bound of the true minimum), lies on the surface at the reported distance, and is
//! flagged certified. Cases: max(`PROPTEST_CASES` or 256, 256), so
//! at least 256 even under `cargo xtask ci` (which sets 64 when unset).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use nalgebra::Vector3;
use nurbs::closest::{PointQuery, SurfaceProjector};
use nurbs::{KnotVector, NurbsCurve, NurbsSurface};
use proptest::prelude::*;

mod case_floor;

/// Deterministic pseudo-random numbers in [0, 1) from a seed.
fn rng(seed: u64) -> impl FnMut() -> f64 {
    let mut s = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A random profile in the xz half plane (x ≥ 5) revolved about Z by `angle`.
fn revolved(seed: u64, p: usize, n: usize, angle: f64) -> NurbsSurface {
    let mut r = rng(seed);
    let ctrl: Vec<Vector3<f64>> = (0..n)
        .map(|i| Vector3::new(5.0 + 30.0 * r(), 0.0, 8.0 * i as f64 + 4.0 * r()))
        .collect();
    let w: Vec<f64> = (0..n).map(|_| 0.5 + 1.5 * r()).collect();
    let k = KnotVector::clamped_uniform(p, n).unwrap().knots().to_vec();
    let profile = NurbsCurve::new(p, k, ctrl, Some(w)).unwrap();
    NurbsSurface::revolution(&profile, Vector3::zeros(), Vector3::z(), angle).unwrap()
}

/// A random bumpy net with random positive weights in [0.2, 3.2].
fn weighted(seed: u64, p: usize, n: usize) -> NurbsSurface {
    let mut r = rng(seed);
    let ctrl: Vec<Vec<Vector3<f64>>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    Vector3::new(
                        10.0 * i as f64 + 3.0 * r(),
                        10.0 * j as f64 + 3.0 * r(),
                        16.0 * r() - 8.0,
                    )
                })
                .collect()
        })
        .collect();
    let w: Vec<Vec<f64>> = (0..n)
        .map(|_| (0..n).map(|_| 0.2 + 3.0 * r()).collect())
        .collect();
    let k = KnotVector::clamped_uniform(p, n).unwrap().knots().to_vec();
    NurbsSurface::new(p, p, k.clone(), k, ctrl, Some(w)).unwrap()
}

/// Bound-constrained Newton polish of |S − q|² from `(u, v)` (backtracking, 60 steps).
fn polish(s: &NurbsSurface, q: &Vector3<f64>, mut u: f64, mut v: f64) -> f64 {
    let ((u0, u1), (v0, v1)) = s.domain();
    let mut f = (s.point(u, v) - q).norm_squared();
    for _ in 0..60 {
        let d = s.derivs2(u, v);
        let r = d.p - q;
        let (gu, gv) = (r.dot(&d.su), r.dot(&d.sv));
        let (a, b, c) = (
            d.su.norm_squared() + r.dot(&d.suu),
            d.su.dot(&d.sv) + r.dot(&d.suv),
            d.sv.norm_squared() + r.dot(&d.svv),
        );
        let det = a * c - b * b;
        let (mut du, mut dv) = if a > 0.0 && det > 0.0 {
            ((-gu * c + gv * b) / det, (-gv * a + gu * b) / det)
        } else {
            (
                -gu / d.su.norm_squared().max(1e-300),
                -gv / d.sv.norm_squared().max(1e-300),
            )
        };
        let mut improved = false;
        for _ in 0..30 {
            let (un, vn) = ((u + du).clamp(u0, u1), (v + dv).clamp(v0, v1));
            let fnew = (s.point(un, vn) - q).norm_squared();
            if fnew < f {
                u = un;
                v = vn;
                f = fnew;
                improved = true;
                break;
            }
            du *= 0.5;
            dv *= 0.5;
        }
        if !improved {
            break;
        }
    }
    f.sqrt()
}

/// Best of a dense n × n grid, then the polish from the four best grid points.
fn brute(s: &NurbsSurface, q: &Vector3<f64>) -> f64 {
    let n = 121;
    let ((u0, u1), (v0, v1)) = s.domain();
    let mut grid: Vec<(f64, f64, f64)> = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            let u = u0 + (u1 - u0) * i as f64 / (n - 1) as f64;
            let v = v0 + (v1 - v0) * j as f64 / (n - 1) as f64;
            grid.push(((s.point(u, v) - q).norm(), u, v));
        }
    }
    grid.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut best = grid[0].0;
    for &(_, u, v) in grid.iter().take(4) {
        best = best.min(polish(s, q, u, v));
    }
    best
}

fn check(s: &NurbsSurface, q: Vector3<f64>, hint: (f64, f64)) -> Result<(), TestCaseError> {
    let proj = SurfaceProjector::new(s);
    let truth = brute(s, &q);
    let a = proj.closest_point(&q);
    prop_assert!(
        a.distance <= truth + 1e-9,
        "cold {} > brute {} (excess {:.3e})",
        a.distance,
        truth,
        a.distance - truth
    );
    prop_assert!((s.point(a.u, a.v) - a.point).norm() <= 1e-9);
    prop_assert!(((a.point - q).norm() - a.distance).abs() <= 1e-9);
    let ((u0, u1), (v0, v1)) = s.domain();
    let h = (u0 + hint.0 * (u1 - u0), v0 + hint.1 * (v1 - v0));
    let w = proj.query(&q, Some(h));
    prop_assert!(w.certified);
    prop_assert!(
        w.signed_distance.abs() <= truth + 1e-9,
        "warm {} > brute {}",
        w.signed_distance.abs(),
        truth
    );
    Ok(())
}

/// Surfaces of revolution (partial and full turns) and query points around them,
/// including points near the axis (beyond every centre of curvature of the circles).
#[test]
fn surfaces_of_revolution() {
    case_floor::run(
        file!(),
        "surfaces_of_revolution",
        (
            0u64..1_000_000,
            2usize..=3,
            4usize..=6,
            0.5f64..=std::f64::consts::TAU,
            -45.0f64..45.0,
            -45.0f64..45.0,
            -10.0f64..55.0,
            0.0f64..=1.0,
            0.0f64..=1.0,
        ),
        |(seed, p, n, angle, x, y, z, hu, hv)| {
            let s = revolved(seed, p, n, angle);
            check(&s, Vector3::new(x, y, z), (hu, hv))?;
            Ok(())
        },
    );
}

/// General rational nets (degree 2–3, random positive weights), points anywhere around.
#[test]
fn random_positive_weights() {
    case_floor::run(
        file!(),
        "random_positive_weights",
        (
            0u64..1_000_000,
            2usize..=3,
            4usize..=6,
            -15.0f64..65.0,
            -15.0f64..65.0,
            -25.0f64..25.0,
            0.0f64..=1.0,
            0.0f64..=1.0,
        ),
        |(seed, p, n, x, y, z, hu, hv)| {
            let s = weighted(seed, p, n);
            check(&s, Vector3::new(x, y, z), (hu, hv))?;
            Ok(())
        },
    );
}
