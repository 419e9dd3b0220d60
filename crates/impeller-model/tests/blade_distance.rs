//! Blade-side signed distance (global, through the cached `nurbs` surface projector) of
//! fixture impellers against a dense brute force followed by a local polish: cold and warm
//! (hint = a random parameter pair, or the answer of a nearby query) answers are never
//! farther than the brute force by more than 1e-9 mm (the brute force is an upper bound of
//! the true minimum). Cases: max(`PROPTEST_CASES` or 256, 256), so
//! at least 256 even under `cargo xtask ci` (which sets 64 when unset).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use impeller_model::query::blade_side_distance;
use impeller_model::{load, Impeller, Side};
use nalgebra::Vector3;
use nurbs::NurbsSurface;
use proptest::prelude::*;
use std::sync::OnceLock;

mod case_floor;

const FIXTURES: [&str; 2] = ["impeller-8+8", "impeller-5-freeform"];

fn fixtures() -> &'static Vec<Impeller> {
    static F: OnceLock<Vec<Impeller>> = OnceLock::new();
    F.get_or_init(|| {
        let root = format!("{}/../../fixtures", env!("CARGO_MANIFEST_DIR"));
        FIXTURES
            .iter()
            .map(|n| load(format!("{root}/{n}/impeller.toml")).unwrap())
            .collect()
    })
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

/// Best of a dense 481 × 41 grid (u along the flow, v hub → shroud), then the polish from
/// the four best grid points.
fn brute(s: &NurbsSurface, q: &Vector3<f64>) -> f64 {
    let (nu, nv) = (481, 41);
    let ((u0, u1), (v0, v1)) = s.domain();
    let mut grid: Vec<(f64, f64, f64)> = Vec::with_capacity(nu * nv);
    for i in 0..nu {
        for j in 0..nv {
            let u = u0 + (u1 - u0) * i as f64 / (nu - 1) as f64;
            let v = v0 + (v1 - v0) * j as f64 / (nv - 1) as f64;
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

/// Points within 3 mm of either side of a main blade (both sides of the side surface,
/// through the blade and beyond its edges), cold and warm.
#[test]
fn blade_side_distance_is_the_global_minimum() {
    case_floor::run(
        file!(),
        "blade_side_distance_is_the_global_minimum",
        (
            0usize..FIXTURES.len(),
            any::<bool>(),
            -0.05f64..1.05,
            -0.05f64..1.05,
            -3.0f64..3.0,
            0.0f64..=1.0,
            0.0f64..=1.0,
        ),
        |(k, suction, u, v, h, hu, hv)| {
            let blade = fixtures()[k].main().blade();
            let side = if suction {
                Side::Suction
            } else {
                Side::Pressure
            };
            let s = blade.side(side);
            let ((u0, u1), (v0, v1)) = s.domain();
            let (uc, vc) = (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0));
            let (pu, pv) = (u0 + uc * (u1 - u0), v0 + vc * (v1 - v0));
            let n = blade.outward_normal(side, pu, pv).unwrap_or(Vector3::z());
            // Beyond the domain in u or v: push the point out along the surface too.
            let d = s.derivs2(pu, pv);
            let q = d.p + n * h + d.su * ((u - uc) * (u1 - u0)) + d.sv * ((v - vc) * (v1 - v0));
            let truth = brute(s, &q);
            let (cold, sd) = blade_side_distance(blade, side, &q, None);
            prop_assert!(
                cold.distance <= truth + 1e-9,
                "cold {} > brute {} (excess {:.3e})",
                cold.distance,
                truth,
                cold.distance - truth
            );
            prop_assert!((sd.abs() - cold.distance).abs() <= 1e-12);
            prop_assert!(((s.point(cold.u, cold.v) - q).norm() - cold.distance).abs() <= 1e-9);
            let hint = (u0 + hu * (u1 - u0), v0 + hv * (v1 - v0));
            let (warm, _) = blade_side_distance(blade, side, &q, Some(hint));
            prop_assert!(
                warm.distance <= truth + 1e-9,
                "warm {} > brute {}",
                warm.distance,
                truth
            );
            // A nearby query warm-started from this answer.
            let q2 = q + n * 0.05;
            let (next, _) = blade_side_distance(blade, side, &q2, Some((cold.u, cold.v)));
            let (next_cold, _) = blade_side_distance(blade, side, &q2, None);
            prop_assert!((next.distance - next_cold.distance).abs() <= 1e-9);
            Ok(())
        },
    );
}
