//! Global closest points on surfaces and curves.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::sync::OnceLock;

use nalgebra::{Vector2, Vector3};
use nurbs::closest::{
    closest_point_on_curve, closest_point_on_surface, local_closest_point, CurveProjector,
    SurfacePoint, SurfaceProjector,
};
use nurbs::{KnotVector, NurbsCurve, NurbsSurface};
use proptest::prelude::*;

/// The benchmark reference surface of issue 2.
fn reference() -> &'static (NurbsSurface, SurfaceProjector) {
    static S: OnceLock<(NurbsSurface, SurfaceProjector)> = OnceLock::new();
    S.get_or_init(|| {
        let ctrl: Vec<Vec<Vector3<f64>>> = (0..12)
            .map(|i| {
                (0..12)
                    .map(|j| {
                        let x = 100.0 * i as f64 / 11.0;
                        let y = 100.0 * j as f64 / 11.0;
                        Vector3::new(
                            x,
                            y,
                            8.0 * (x / 17.0).sin() * (y / 23.0).cos() + 0.002 * x * y,
                        )
                    })
                    .collect()
            })
            .collect();
        let k = KnotVector::clamped_uniform(3, 12).unwrap().knots().to_vec();
        let s = NurbsSurface::new(3, 3, k.clone(), k, ctrl, None).unwrap();
        let p = SurfaceProjector::new(&s);
        (s, p)
    })
}

/// Best distance over an n × n grid of the surface (an upper bound of the true minimum).
fn dense_min(s: &NurbsSurface, q: &Vector3<f64>, n: usize) -> f64 {
    let ((u0, u1), (v0, v1)) = s.domain();
    let mut best = f64::INFINITY;
    for i in 0..n {
        for j in 0..n {
            let u = u0 + (u1 - u0) * i as f64 / (n - 1) as f64;
            let v = v0 + (v1 - v0) * j as f64 / (n - 1) as f64;
            best = best.min((s.point(u, v) - q).norm());
        }
    }
    best
}

/// First-order optimality: interior answers have `S − q` normal to the surface (1e-9,
/// relative); boundary answers have the free variable's condition and the held variable's
/// gradient pointing out of the domain.
fn check_optimality(
    s: &NurbsSurface,
    q: &Vector3<f64>,
    a: &SurfacePoint,
) -> Result<(), TestCaseError> {
    let ((u0, u1), (v0, v1)) = s.domain();
    prop_assert!(
        a.u >= u0 && a.u <= u1 && a.v >= v0 && a.v <= v1,
        "parameters outside the domain"
    );
    let d = s.derivs2(a.u, a.v);
    prop_assert!((d.p - a.point).norm() <= 1e-9);
    prop_assert!(((d.p - q).norm() - a.distance).abs() <= 1e-9);
    let r = d.p - q;
    if r.norm() < 1e-6 {
        return Ok(());
    }
    let cu = r.dot(&d.su) / (r.norm() * d.su.norm());
    let cv = r.dot(&d.sv) / (r.norm() * d.sv.norm());
    let ok = |x: f64, c: f64, lo: f64, hi: f64| {
        c.abs() <= 1e-9 || (x <= lo && c > 0.0) || (x >= hi && c < 0.0)
    };
    prop_assert!(
        ok(a.u, cu, u0, u1),
        "u condition: cos = {cu:e} at u = {}",
        a.u
    );
    prop_assert!(
        ok(a.v, cv, v0, v1),
        "v condition: cos = {cv:e} at v = {}",
        a.v
    );
    if !a.on_boundary {
        prop_assert!(cu.abs() <= 1e-9 && cv.abs() <= 1e-9);
    }
    Ok(())
}

fn bumpy_surface(seed: u64, p: usize, rational: bool) -> NurbsSurface {
    let n = 7;
    let h = |i: usize, j: usize| {
        let x = (seed as f64 * 0.37 + i as f64 * 1.3 + j as f64 * 0.7).sin();
        let y = (seed as f64 * 0.11 + j as f64 * 1.9 - i as f64 * 0.5).cos();
        6.0 * x * y
    };
    let ctrl: Vec<Vec<Vector3<f64>>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| Vector3::new(10.0 * i as f64, 10.0 * j as f64, h(i, j)))
                .collect()
        })
        .collect();
    let weights = rational.then(|| {
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| 1.0 + 0.5 * ((i * 3 + j * 5 + seed as usize) % 4) as f64)
                    .collect()
            })
            .collect()
    });
    let k = KnotVector::clamped_uniform(p, n).unwrap().knots().to_vec();
    NurbsSurface::new(p, p, k.clone(), k, ctrl, weights).unwrap()
}

proptest! {
    /// Reference surface, benchmark-like queries: optimality conditions and never farther
    /// than the best of a dense sample.
    #[test]
    fn reference_surface_queries_are_optimal(u in 0.0f64..=1.0, v in 0.0f64..=1.0, d in -5.0f64..5.0) {
        let (s, p) = reference();
        let q = s.point(u, v) + Vector3::new(0.0, 0.0, d);
        let a = p.closest_point(&q);
        check_optimality(s, &q, &a)?;
        prop_assert!(a.distance <= dense_min(s, &q, 81) + 1e-12);
        // The hint changes nothing but speed.
        let w = p.closest_point_with_hint(&q, Some((1.0 - u, v * 0.5)));
        prop_assert!((w.distance - a.distance).abs() <= 1e-9);
    }

    /// Random bumpy (rational and non-rational, degree 2–3) surfaces and query points
    /// anywhere around them, including far away and beyond the boundary.
    #[test]
    fn bumpy_surfaces_global_minimum(seed in 0u64..10_000, p in 2usize..=3, rational in any::<bool>(),
                                     x in -20.0f64..80.0, y in -20.0f64..80.0, z in -30.0f64..30.0) {
        let s = bumpy_surface(seed, p, rational);
        let q = Vector3::new(x, y, z);
        let a = closest_point_on_surface(&s, &q);
        check_optimality(&s, &q, &a)?;
        prop_assert!(a.distance <= dense_min(&s, &q, 61) + 1e-12,
            "distance {} > dense {}", a.distance, dense_min(&s, &q, 61));
    }

    /// The local solver from a start near the global answer (within 0.02 of the domain) meets
    /// the same first-order conditions and finds the global distance within 1e-9 mm; from any
    /// start it never ends farther than where it started.
    #[test]
    fn local_solver_from_a_near_start_finds_the_global_answer(u in 0.0f64..=1.0, v in 0.0f64..=1.0,
            d in -5.0f64..5.0, du in -0.02f64..0.02, dv in -0.02f64..0.02, su in 0.0f64..=1.0, sv in 0.0f64..=1.0) {
        let (s, p) = reference();
        let q = s.point(u, v) + Vector3::new(0.0, 0.0, d);
        let g = p.closest_point(&q);
        let l = local_closest_point(s, &q, (g.u + du, g.v + dv));
        check_optimality(s, &q, &l)?;
        prop_assert!((l.distance - g.distance).abs() <= 1e-9, "local {} global {}", l.distance, g.distance);
        let far = local_closest_point(s, &q, (su, sv));
        prop_assert!(far.distance <= (s.point(su, sv) - q).norm() + 1e-12);
        prop_assert!(far.distance + 1e-12 >= g.distance);
    }

    /// Curves: optimality and dense-sample bound.
    #[test]
    fn curve_closest_point_is_global(seed in 0u64..10_000, x in -60.0f64..110.0, y in -80.0f64..80.0) {
        let pts: Vec<Vector2<f64>> = (0..9)
            .map(|k| Vector2::new(6.0 * k as f64, 15.0 * ((seed as f64) * 0.3 + k as f64 * 1.7).sin()))
            .collect();
        let kv = KnotVector::clamped_uniform(3, 9).unwrap().knots().to_vec();
        let c = NurbsCurve::<2>::new(3, kv, pts, None).unwrap();
        let q = Vector2::new(x, y);
        let a = closest_point_on_curve(&c, &q);
        let dense = (0..=4000).map(|k| (c.point(k as f64 / 4000.0) - q).norm()).fold(f64::INFINITY, f64::min);
        prop_assert!(a.distance <= dense + 1e-12);
        let d = c.derivs(a.u, 1);
        let r = d[0] - q;
        let cos = r.dot(&d[1]) / (r.norm() * d[1].norm());
        prop_assert!(cos.abs() <= 1e-9 || (a.u <= 0.0 && cos > 0.0) || (a.u >= 1.0 && cos < 0.0));
    }
}

#[test]
fn closest_point_on_a_plane() {
    // Bicubic patch with a planar, non-uniform control net in z = 2.
    let ctrl: Vec<Vec<Vector3<f64>>> = (0..5)
        .map(|i| {
            (0..4)
                .map(|j| Vector3::new((i * i) as f64 * 3.0, j as f64 * 7.0 + i as f64, 2.0))
                .collect()
        })
        .collect();
    let s = NurbsSurface::new(
        3,
        3,
        KnotVector::clamped_uniform(3, 5).unwrap().knots().to_vec(),
        KnotVector::clamped_uniform(3, 4).unwrap().knots().to_vec(),
        ctrl,
        None,
    )
    .unwrap();
    let p = SurfaceProjector::new(&s);
    for (u, v, h) in [(0.3, 0.4, 5.0), (0.9, 0.1, -3.0), (0.5, 0.5, 0.25)] {
        let foot = s.point(u, v);
        let a = p.closest_point(&(foot + Vector3::new(0.0, 0.0, h)));
        assert!(
            (a.distance - h.abs()).abs() <= 1e-12,
            "{} vs {h}",
            a.distance
        );
        assert!((a.point - foot).norm() <= 1e-10);
        assert!(!a.on_boundary);
    }
    // Beyond the corner (0, 0): the corner is the answer, flagged as a boundary answer.
    let corner = s.point(0.0, 0.0);
    let a = p.closest_point(&(corner + Vector3::new(-3.0, -4.0, 1.0)));
    assert!(a.on_boundary && a.u == 0.0 && a.v == 0.0);
    assert!((a.distance - 26f64.sqrt()).abs() <= 1e-12);
}

#[test]
fn closest_point_on_a_cylinder_of_revolution() {
    // Cylinder radius 20 about z, height 0..30: revolve a vertical line.
    let line = NurbsCurve::<3>::new(
        1,
        vec![0.0, 0.0, 1.0, 1.0],
        vec![Vector3::new(20.0, 0.0, 0.0), Vector3::new(20.0, 0.0, 30.0)],
        None,
    )
    .unwrap();
    let s = NurbsSurface::revolution(&line, Vector3::zeros(), Vector3::z(), std::f64::consts::TAU)
        .unwrap();
    let p = SurfaceProjector::new(&s);
    for (r, phi, z) in [
        (35.0, 0.3, 10.0),
        (5.0, 2.0, 25.0),
        (20.5, 4.0, 1.0),
        (12.0, 5.9, 29.0),
    ] {
        let q = Vector3::new(r * f64::cos(phi), r * f64::sin(phi), z);
        let a = p.closest_point(&q);
        assert!(
            (a.distance - (r - 20.0f64).abs()).abs() <= 1e-10,
            "r {r}: {}",
            a.distance
        );
        let expect = Vector3::new(20.0 * phi.cos(), 20.0 * phi.sin(), z);
        assert!((a.point - expect).norm() <= 1e-9);
    }
    // Above the top rim: the rim circle is the answer.
    let q = Vector3::new(30.0, 0.0, 40.0);
    let a = p.closest_point(&q);
    assert!((a.distance - (100.0f64 + 100.0).sqrt()).abs() <= 1e-10);
    assert!(a.on_boundary);
}

#[test]
fn closest_point_on_a_circle_arc() {
    let arc = NurbsCurve::<3>::circle_arc(
        Vector3::new(1.0, 2.0, 3.0),
        Vector3::x(),
        Vector3::y(),
        10.0,
        0.0,
        2.0,
    )
    .unwrap();
    let proj = CurveProjector::new(&arc);
    for (r, phi) in [(4.0, 0.5), (25.0, 1.9), (10.0, 1.0), (0.5, 0.01)] {
        let q = Vector3::new(1.0 + r * f64::cos(phi), 2.0 + r * f64::sin(phi), 3.0);
        let a = proj.closest_point(&q);
        assert!((a.distance - (r - 10.0f64).abs()).abs() <= 1e-10);
        let expect = Vector3::new(1.0 + 10.0 * phi.cos(), 2.0 + 10.0 * phi.sin(), 3.0);
        assert!((a.point - expect).norm() <= 1e-9);
    }
    // Outside the angular range: the nearer end point.
    let q = Vector3::new(
        1.0 + 12.0 * f64::cos(-0.4),
        2.0 + 12.0 * f64::sin(-0.4),
        3.0,
    );
    let a = proj.closest_point(&q);
    assert!(a.on_boundary && a.u == 0.0);
    let hinted = proj.closest_point_with_hint(&q, Some(0.9));
    assert_eq!(hinted.u, 0.0);
}

#[test]
fn crease_surface_global_minimum() {
    // A C0 crease: knot of full multiplicity in u; a ridge whose top line is the answer for
    // points above it (a minimum where the surface has no tangent plane).
    let ctrl: Vec<Vec<Vector3<f64>>> = (0..7)
        .map(|i| {
            (0..4)
                .map(|j| {
                    Vector3::new(
                        10.0 * i as f64,
                        10.0 * j as f64,
                        -(i as f64 - 3.0).abs() * 5.0,
                    )
                })
                .collect()
        })
        .collect();
    let ku = vec![0.0, 0.0, 0.0, 0.0, 0.5, 0.5, 0.5, 1.0, 1.0, 1.0, 1.0];
    let kv = KnotVector::clamped_uniform(3, 4).unwrap().knots().to_vec();
    let s = NurbsSurface::new(3, 3, ku, kv, ctrl, None).unwrap();
    let p = SurfaceProjector::new(&s);
    let q = Vector3::new(30.0, 15.0, 8.0);
    let a = p.closest_point(&q);
    assert!(a.distance <= dense_min(&s, &q, 201) + 1e-12);
    assert!(
        (a.u - 0.5).abs() <= 1e-12,
        "minimum on the crease, got u = {}",
        a.u
    );
    assert!((a.distance - 8.0).abs() <= 1e-9);
}

#[test]
fn closest_point_on_a_sphere_with_poles() {
    // Half circle in the xz-plane revolved about z: a sphere of radius 15 with poles.
    let profile = NurbsCurve::<3>::circle_arc(
        Vector3::zeros(),
        Vector3::x(),
        Vector3::z(),
        15.0,
        -std::f64::consts::FRAC_PI_2,
        std::f64::consts::FRAC_PI_2,
    )
    .unwrap();
    let s = NurbsSurface::revolution(
        &profile,
        Vector3::zeros(),
        Vector3::z(),
        std::f64::consts::TAU,
    )
    .unwrap();
    let p = SurfaceProjector::new(&s);
    for q in [
        Vector3::new(3.0, 4.0, 30.0),
        Vector3::new(0.0, 0.0, 40.0),
        Vector3::new(0.0, 0.0, -2.0),
        Vector3::new(-20.0, 5.0, 1.0),
        Vector3::new(1.0, -2.0, 3.0),
    ] {
        let a = p.closest_point(&q);
        assert!(
            (a.distance - (q.norm() - 15.0).abs()).abs() <= 1e-9,
            "{q:?}: {}",
            a.distance
        );
        assert!(a.distance <= dense_min(&s, &q, 101) + 1e-12);
    }
}

#[test]
fn non_finite_queries_do_not_panic() {
    let (_, p) = reference();
    let a = p.closest_point(&Vector3::new(f64::NAN, 1.0, 2.0));
    assert!(a.distance.is_nan());
    let b = p.closest_point_with_hint(&Vector3::new(1.0, 2.0, 3.0), Some((f64::NAN, 0.5)));
    assert!(b.distance.is_finite());
    let arc =
        NurbsCurve::<2>::circle_arc(Vector2::zeros(), Vector2::x(), Vector2::y(), 1.0, 0.0, 1.0)
            .unwrap();
    let c = CurveProjector::new(&arc).closest_point(&Vector2::new(f64::INFINITY, 0.0));
    assert!(c.distance.is_nan());
}
