//! Hub and shroud signed distance of every fixture impeller against a dense brute force on
//! the meridional contour (4000 samples, then a golden-section polish around the best):
//! random query points around the contour, any polar angle. The answer is never farther
//! than the brute force by more than 1e-9 mm (the brute force is an upper bound of the true
//! minimum), the returned point is on the surface at the returned distance, and the answer
//! is certified. Cases: max(`PROPTEST_CASES` or 256, 256), so
//! at least 256 even under `cargo xtask ci` (which sets 64 when unset).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use impeller_model::{load, Impeller, MeridionalCurve, RevolvedSurface};
use nalgebra::{Vector2, Vector3};
use nurbs::closest::PointQuery;
use proptest::prelude::*;

mod case_floor;
use std::sync::OnceLock;

const FIXTURES: [&str; 5] = [
    "impeller-8+8",
    "impeller-5-freeform",
    "impeller-11+11-freeform",
    "impeller-30-narrow",
    "impeller-plunge-400",
];

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

/// Dense sample, then golden-section polish around the best sample: an upper bound of the
/// true minimum distance, within round-off of it for samples finer than the contour's
/// features. Returns (distance, parameter).
fn brute(m: &MeridionalCurve, q: &Vector2<f64>) -> (f64, f64) {
    let (a, b) = m.domain();
    let n = 4000;
    let f = |u: f64| (m.point(u) - q).norm();
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
    let um = 0.5 * (lo + hi);
    if f(um) < bd {
        (f(um), um)
    } else {
        (bd, bu)
    }
}

fn surface(k: usize, shroud: bool) -> &'static RevolvedSurface {
    let imp = &fixtures()[k];
    if shroud {
        imp.shroud()
    } else {
        imp.hub()
    }
}

/// Random points in the box of the contour widened by 40 % (and down to the axis).
#[test]
fn hub_and_shroud_distance_is_the_global_minimum() {
    case_floor::run(
        file!(),
        "hub_and_shroud_distance_is_the_global_minimum",
        (
            0usize..FIXTURES.len(),
            any::<bool>(),
            0.0f64..=1.0,
            0.0f64..=1.0,
            -4.0f64..4.0,
        ),
        |(k, shroud, a, b, phi)| {
            let s = surface(k, shroud);
            let m = s.meridional();
            let (mut lo, mut hi) = (
                Vector2::repeat(f64::INFINITY),
                Vector2::repeat(f64::NEG_INFINITY),
            );
            for i in 0..=64 {
                let (t0, t1) = m.domain();
                let p = m.point(t0 + (t1 - t0) * i as f64 / 64.0);
                lo = lo.inf(&p);
                hi = hi.sup(&p);
            }
            let pad = (hi - lo) * 0.4;
            let z = lo.x - pad.x + a * (hi.x - lo.x + 2.0 * pad.x);
            let r = ((lo.y - pad.y).max(0.0)) + b * (hi.y + pad.y - (lo.y - pad.y).max(0.0));
            let p = Vector3::new(r * phi.cos(), r * phi.sin(), z);
            let d = s.signed_distance(&p);
            let (truth, _) = brute(m, &MeridionalCurve::zr_of(&p));
            prop_assert!(
                d.abs() <= truth + 1e-9,
                "{} > brute {} (excess {:.3e})",
                d.abs(),
                truth,
                d.abs() - truth
            );
            prop_assert!(
                d.abs() >= truth - 1e-6,
                "{} far below brute {}",
                d.abs(),
                truth
            );
            let a = s.query(&p, None);
            prop_assert!(a.certified);
            prop_assert!((a.signed_distance - d).abs() <= 1e-12);
            prop_assert!(((a.point - p).norm() - d.abs()).abs() <= 1e-9);
            let (t, _, _) = s.closest(&p);
            prop_assert!((s.point(t, phi) - a.point).norm() <= 1e-9);
            Ok(())
        },
    );
}

/// Points offset along the channel-side normal by less than the contour's radius of
/// curvature: the signed distance is the offset (sign convention of the existing API).
#[test]
fn offsets_along_the_normal() {
    case_floor::run(
        file!(),
        "offsets_along_the_normal",
        (
            0usize..FIXTURES.len(),
            any::<bool>(),
            0.05f64..0.95,
            -0.5f64..0.5,
            -4.0f64..4.0,
        ),
        |(k, shroud, f, h, phi)| {
            let s = surface(k, shroud);
            let (t0, t1) = s.meridional().domain();
            let t = t0 + f * (t1 - t0);
            let p = s.point(t, phi) + s.normal(t, phi) * h;
            let d = s.signed_distance(&p);
            prop_assert!((d - h).abs() <= 1e-9, "{d} vs offset {h}");
            Ok(())
        },
    );
}
