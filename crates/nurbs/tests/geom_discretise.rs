//! Arc length and curve discretisation.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::f64::consts::PI;

use nalgebra::{Vector2, Vector3};
use nurbs::discretise::{
    arc_length, arc_length_between, discretise_by_arc_length, discretise_by_chord,
    discretise_by_parameter, ArcLengthTable, DiscretiseError,
};
use nurbs::{KnotVector, NurbsCurve};
use proptest::prelude::*;

fn arc(r: f64, theta: f64) -> NurbsCurve<2> {
    NurbsCurve::<2>::circle_arc(
        Vector2::new(3.0, -1.0),
        Vector2::x(),
        Vector2::y(),
        r,
        0.2,
        0.2 + theta,
    )
    .unwrap()
}

proptest! {
    /// The length of an exact rational circle arc is r·θ (1e-10).
    #[test]
    fn circle_arc_length(r in 0.5f64..200.0, theta in 0.05f64..(2.0 * PI)) {
        let c = arc(r, theta);
        let l = arc_length(&c, 1e-13).unwrap();
        prop_assert!((l - r * theta).abs() <= 1e-10, "{l} vs {}", r * theta);
    }
}

#[test]
fn partial_length_and_inverse() {
    let c = arc(10.0, PI);
    let half = arc_length_between(&c, 0.0, 0.5, 1e-13).unwrap();
    // The rational parametrisation is symmetric: half the parameter range is half the arc.
    assert!((half - 5.0 * PI).abs() <= 1e-10);
    let table = ArcLengthTable::new(&c, 1e-13).unwrap();
    for s in [0.0, 1.0, 7.5, 20.0, 10.0 * PI] {
        let u = table.param_at_length(s);
        assert!((table.length_at(u) - s).abs() <= 1e-9, "s = {s}");
    }
}

#[test]
fn equal_arc_length_points_on_a_circle() {
    let c = arc(25.0, 1.5 * PI);
    let pts = discretise_by_arc_length(&c, 2.0).unwrap();
    let total = 25.0 * 1.5 * PI;
    let n = (total / 2.0).ceil() as usize;
    assert_eq!(pts.len(), n + 1);
    // Equal arcs on a circle subtend equal chords 2r·sin(Δs / 2r).
    let ds = total / n as f64;
    let chord = 2.0 * 25.0 * (ds / 50.0).sin();
    for w in pts.windows(2) {
        assert!(((w[1].point - w[0].point).norm() - chord).abs() <= 1e-9);
    }
    assert_eq!(pts[0].u, 0.0);
    assert_eq!(pts[n].u, 1.0);
}

#[test]
fn parameter_steps_are_uniform() {
    let c = arc(5.0, 1.0);
    let pts = discretise_by_parameter(&c, 0.3).unwrap();
    assert_eq!(pts.len(), 5); // ceil(1 / 0.3) = 4 steps
    for (k, s) in pts.iter().enumerate() {
        assert!((s.u - k as f64 * 0.25).abs() <= 1e-15);
        assert!((s.point - c.point(s.u)).norm() == 0.0);
    }
}

fn wavy() -> NurbsCurve<3> {
    let ctrl: Vec<Vector3<f64>> = (0..12)
        .map(|k| {
            Vector3::new(
                k as f64 * 8.0,
                20.0 * (k as f64).sin(),
                5.0 * (0.7 * k as f64).cos(),
            )
        })
        .collect();
    NurbsCurve::<3>::new(
        3,
        KnotVector::clamped_uniform(3, 12).unwrap().knots().to_vec(),
        ctrl,
        None,
    )
    .unwrap()
}

fn segment_distance(p: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    let ab = b - a;
    let t = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
    (p - (a + ab * t)).norm()
}

#[test]
fn chord_tolerance_polyline_stays_within_tolerance() {
    let c = wavy();
    for tol in [0.5, 0.05, 0.005] {
        let pts = discretise_by_chord(&c, tol).unwrap();
        // Dense check: every curve point between two samples lies within tol of their chord.
        let mut worst: f64 = 0.0;
        for w in pts.windows(2) {
            for k in 1..50 {
                let u = w[0].u + (w[1].u - w[0].u) * k as f64 / 50.0;
                worst = worst.max(segment_distance(&c.point(u), &w[0].point, &w[1].point));
            }
        }
        assert!(worst <= tol, "tol {tol}: deviation {worst}");
        // Knots are kept.
        for &k in c.knots().knots() {
            assert!(pts.iter().any(|s| s.u == k));
        }
    }
}

#[test]
fn every_discretise_error_is_reported() {
    let c = arc(1.0, 1.0);
    assert!(matches!(
        discretise_by_arc_length(&c, 0.0),
        Err(DiscretiseError::InvalidValue { field: "step", .. })
    ));
    assert!(matches!(
        discretise_by_chord(&c, f64::NAN),
        Err(DiscretiseError::InvalidValue {
            field: "chord_tol",
            ..
        })
    ));
    assert!(matches!(
        arc_length(&c, -1.0),
        Err(DiscretiseError::InvalidValue { field: "tol", .. })
    ));
    assert!(matches!(
        arc_length_between(&c, 0.5, 0.2, 1e-9),
        Err(DiscretiseError::InvalidInterval { .. })
    ));
    assert!(matches!(
        discretise_by_parameter(&c, 1e-9),
        Err(DiscretiseError::TooManyPoints {
            limit: nurbs::discretise::MAX_POINTS,
            ..
        })
    ));
}
