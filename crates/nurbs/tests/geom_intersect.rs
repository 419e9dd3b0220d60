#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
//! Curve–curve intersection against hand-built cases with known answers.

use nalgebra::{Vector2, Vector3};
use nurbs::intersect::{closest_approach, intersect_curves, CurveIntersection, IntersectOptions};
use nurbs::{Curve2, Curve3, NurbsCurve};
use std::f64::consts::PI;

fn line2(a: (f64, f64), b: (f64, f64)) -> Curve2 {
    NurbsCurve::new(
        1,
        vec![0., 0., 1., 1.],
        vec![Vector2::new(a.0, a.1), Vector2::new(b.0, b.1)],
        None,
    )
    .unwrap()
}

fn circle2(cx: f64, cy: f64, r: f64) -> Curve2 {
    NurbsCurve::circle_arc(
        Vector2::new(cx, cy),
        Vector2::x(),
        Vector2::y(),
        r,
        0.0,
        2.0 * PI,
    )
    .unwrap()
}

fn points<const D: usize>(x: &[CurveIntersection<D>]) -> Vec<nalgebra::SVector<f64, D>> {
    x.iter()
        .filter_map(|i| match i {
            CurveIntersection::Point(p) => Some(p.point),
            _ => None,
        })
        .collect()
}

const OPTS: IntersectOptions = IntersectOptions {
    tol: 1e-9,
    min_overlap_length: None,
};

#[test]
fn line_crosses_circle_twice() {
    // y = 0.5 across the unit circle: x = ±√0.75.
    let r = intersect_curves(
        &line2((-2.0, 0.5), (2.0, 0.5)),
        &circle2(0.0, 0.0, 1.0),
        &OPTS,
    )
    .unwrap();
    let p = points(&r);
    assert_eq!(r.len(), 2, "{r:?}");
    let x = 0.75f64.sqrt();
    assert!((p[0] - Vector2::new(-x, 0.5)).norm() < 1e-12, "{p:?}");
    assert!((p[1] - Vector2::new(x, 0.5)).norm() < 1e-12, "{p:?}");
    // Parameters map back to the points on both curves.
    for i in &r {
        let CurveIntersection::Point(q) = i else {
            panic!()
        };
        assert!(q.distance < 1e-12);
    }
}

#[test]
fn tangent_line_and_circles_report_one_point() {
    // y = 1 touches the unit circle at (0, 1).
    let r = intersect_curves(
        &line2((-2.0, 1.0), (2.0, 1.0)),
        &circle2(0.0, 0.0, 1.0),
        &OPTS,
    )
    .unwrap();
    assert_eq!(r.len(), 1, "{r:?}");
    let p = points(&r)[0];
    // Linear convergence at the tangency: √tol-level position accuracy.
    assert!((p - Vector2::new(0.0, 1.0)).norm() < 1e-4, "{p:?}");
    // Two circles touching externally at (1, 0), and internally at (2, 0).
    let r = intersect_curves(&circle2(0.0, 0.0, 1.0), &circle2(2.0, 0.0, 1.0), &OPTS).unwrap();
    assert_eq!(r.len(), 1, "{r:?}");
    assert!((points(&r)[0] - Vector2::new(1.0, 0.0)).norm() < 1e-4);
    let r = intersect_curves(&circle2(0.0, 0.0, 2.0), &circle2(1.0, 0.0, 1.0), &OPTS).unwrap();
    assert_eq!(r.len(), 1, "{r:?}");
    assert!((points(&r)[0] - Vector2::new(2.0, 0.0)).norm() < 1e-4);
    // Just missing: nothing.
    let r = intersect_curves(
        &line2((-2.0, 1.001), (2.0, 1.001)),
        &circle2(0.0, 0.0, 1.0),
        &OPTS,
    )
    .unwrap();
    assert!(r.is_empty(), "{r:?}");
}

#[test]
fn sine_like_spline_crosses_a_line_at_every_root() {
    // Interpolating cubic through a sampled sine: it crosses y = 0 near x = kπ; the exact
    // crossings are where the spline itself is zero, found by bisection here (brute force).
    let pts: Vec<Vector2<f64>> = (0..=40)
        .map(|i| {
            let x = 0.2 + i as f64 * (3.0 * PI) / 40.0;
            Vector2::new(x, x.sin())
        })
        .collect();
    let c = nurbs::fit::interpolate_curve(&pts, 3, nurbs::fit::Parametrisation::Centripetal, None)
        .unwrap();
    let l = line2((0.0, 0.0), (10.0, 0.0));
    let r = intersect_curves(&c, &l, &OPTS).unwrap();
    // Brute force: sign changes of y on a fine grid, refined by bisection.
    let (t0, t1) = c.domain();
    let n = 20000;
    let mut want = Vec::new();
    for i in 0..n {
        let (a, b) = (
            t0 + (t1 - t0) * i as f64 / n as f64,
            t0 + (t1 - t0) * (i + 1) as f64 / n as f64,
        );
        if c.point(a).y.signum() != c.point(b).y.signum() {
            let (mut lo, mut hi) = (a, b);
            for _ in 0..100 {
                let m = 0.5 * (lo + hi);
                if c.point(m).y.signum() == c.point(lo).y.signum() {
                    lo = m;
                } else {
                    hi = m;
                }
            }
            want.push(c.point(lo));
        }
    }
    assert_eq!(want.len(), 3);
    let got = points(&r);
    assert_eq!(got.len(), 3, "{r:?}");
    for (g, w) in got.iter().zip(&want) {
        assert!((g - w).norm() < 1e-9, "{g:?} vs {w:?}");
    }
}

#[test]
fn overlapping_pieces_are_ranges() {
    // Collinear segments overlapping on x ∈ [1, 2].
    let a = line2((0.0, 0.0), (2.0, 0.0));
    let b = line2((1.0, 0.0), (3.0, 0.0));
    let r = intersect_curves(&a, &b, &OPTS).unwrap();
    assert_eq!(r.len(), 1, "{r:?}");
    let CurveIntersection::Overlap { u, v } = r[0] else {
        panic!("{r:?}")
    };
    assert!(
        (u.0 - 0.5).abs() < 1e-9 && (u.1 - 1.0).abs() < 1e-9,
        "{u:?}"
    );
    assert!(
        (v.0 - 0.0).abs() < 1e-9 && (v.1 - 0.5).abs() < 1e-9,
        "{v:?}"
    );
    // Two arcs of the same circle overlapping over 60°, opposite directions.
    let a = NurbsCurve::circle_arc(Vector2::zeros(), Vector2::x(), Vector2::y(), 2.0, 0.0, 2.0)
        .unwrap();
    let b = NurbsCurve::circle_arc(
        Vector2::zeros(),
        Vector2::x(),
        -Vector2::y(),
        2.0,
        -2.5,
        -1.0,
    )
    .unwrap();
    // b runs from angle 2.5 down to 1.0: overlap with a on angles [1.0, 2.0].
    let r = intersect_curves(&a, &b, &OPTS).unwrap();
    assert_eq!(r.len(), 1, "{r:?}");
    let CurveIntersection::Overlap { u, v } = r[0] else {
        panic!("{r:?}")
    };
    let ang = |p: Vector2<f64>| p.y.atan2(p.x);
    assert!(
        (ang(a.point(u.0)) - 1.0).abs() < 1e-7,
        "{}",
        ang(a.point(u.0))
    );
    assert!((ang(a.point(u.1)) - 2.0).abs() < 1e-7);
    assert!((a.point(u.0) - b.point(v.0)).norm() < 1e-8);
    assert!((a.point(u.1) - b.point(v.1)).norm() < 1e-8);
    assert!(v.0 > v.1, "opposite directions: {v:?}");
}

#[test]
fn space_curves_closest_approach_and_near_intersection() {
    // Skew lines: x axis and the line through (0, 0, 1) along y: distance 1 at (0,0,·).
    let a: Curve3 = NurbsCurve::new(
        1,
        vec![0., 0., 1., 1.],
        vec![Vector3::new(-1.0, 0.0, 0.0), Vector3::new(3.0, 0.0, 0.0)],
        None,
    )
    .unwrap();
    let b: Curve3 = NurbsCurve::new(
        1,
        vec![0., 0., 1., 1.],
        vec![Vector3::new(0.0, -2.0, 1.0), Vector3::new(0.0, 2.0, 1.0)],
        None,
    )
    .unwrap();
    let c = closest_approach(&a, &b, 1e-12).unwrap();
    assert!((c.distance - 1.0).abs() < 1e-12);
    assert!((c.u - 0.25).abs() < 1e-9 && (c.v - 0.5).abs() < 1e-9);
    assert!(intersect_curves(&a, &b, &OPTS).unwrap().is_empty());
    // A helix meets a vertical line through one of its points at every turn.
    let pts: Vec<Vector3<f64>> = (0..=80)
        .map(|i| {
            let t = i as f64 / 80.0 * 4.0 * PI;
            Vector3::new(t.cos(), t.sin(), 0.3 * t)
        })
        .collect();
    let helix =
        nurbs::fit::interpolate_curve(&pts, 3, nurbs::fit::Parametrisation::Centripetal, None)
            .unwrap();
    // Points of the interpolant at angle 0 lie at x = 1 exactly (interpolated nodes).
    let line: Curve3 = NurbsCurve::new(
        1,
        vec![0., 0., 1., 1.],
        vec![Vector3::new(1.0, 0.0, -1.0), Vector3::new(1.0, 0.0, 5.0)],
        None,
    )
    .unwrap();
    let r = intersect_curves(
        &helix,
        &line,
        &IntersectOptions {
            tol: 1e-7,
            min_overlap_length: None,
        },
    )
    .unwrap();
    let z: Vec<f64> = points(&r).iter().map(|p| p.z).collect();
    assert_eq!(z.len(), 3, "{r:?}");
    for (g, w) in z.iter().zip([0.0, 0.6 * PI, 1.2 * PI]) {
        assert!((g - w).abs() < 1e-6, "{z:?}");
    }
}

#[test]
fn invalid_tolerance_is_an_error() {
    let l = line2((0.0, 0.0), (1.0, 1.0));
    let bad = IntersectOptions {
        tol: 0.0,
        min_overlap_length: None,
    };
    assert!(intersect_curves(&l, &l, &bad).is_err());
    assert!(closest_approach(&l, &l, -1.0).is_err());
}
