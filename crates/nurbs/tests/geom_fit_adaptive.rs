//! Error-driven compatible fitting: dense regions get knots, corners become C⁰ knots,
//! sections with unequal point counts share one knot vector, and every point is within the
//! tolerance (checked independently by evaluating the returned curves).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::Vector2;
use nurbs::fit::{approximate_compatible, approximate_curve_to_tolerance, Parametrisation};
use nurbs::fit::{CompatibleFit, DEFAULT_KINK_ANGLE};

/// An aerofoil-like side: a leading-edge quarter circle of radius `r` sampled with `n_le`
/// points, then a gently curved flank of length 60 with `n_flank` points.
fn dense_le_side(r: f64, n_le: usize, n_flank: usize, bow: f64) -> Vec<Vector2<f64>> {
    let mut pts: Vec<Vector2<f64>> = (0..n_le)
        .map(|k| {
            let a = std::f64::consts::FRAC_PI_2 * (1.0 - k as f64 / (n_le - 1) as f64);
            Vector2::new(r - r * a.sin(), r * a.cos())
        })
        .collect();
    for k in 1..=n_flank {
        let t = k as f64 / n_flank as f64;
        pts.push(Vector2::new(
            r + 60.0 * t,
            r + bow * (std::f64::consts::PI * t).sin(),
        ));
    }
    pts
}

/// Largest distance of the data from the returned curves at the returned parameters.
fn check(fit: &CompatibleFit<2>, data: &[Vec<Vector2<f64>>]) -> f64 {
    let mut worst: f64 = 0.0;
    for (k, pts) in data.iter().enumerate() {
        let c = fit.curve(k).unwrap();
        for (u, q) in fit.params[k].iter().zip(pts) {
            worst = worst.max((c.point(*u) - q).norm());
        }
        assert!((c.point(0.0) - pts[0]).norm() < 1e-12, "start interpolated");
        assert!(
            (c.point(1.0) - pts[pts.len() - 1]).norm() < 1e-12,
            "end interpolated"
        );
    }
    worst
}

#[test]
fn dense_leading_edge_meets_tolerance_with_local_knots() {
    let tol = 1e-3;
    let data = vec![dense_le_side(0.3, 40, 60, 2.0)];
    let fit = approximate_compatible(&data, 3, tol, DEFAULT_KINK_ANGLE).unwrap();
    let worst = check(&fit, &data);
    assert!(worst <= tol, "{worst}");
    assert!((fit.max_error() - worst).abs() < 1e-12);
    // Error-driven knots are no more than the quantile count search needs (the same data,
    // the same tolerance), usually fewer.
    let q = approximate_curve_to_tolerance(&data[0], 3, tol, Parametrisation::ChordLength).unwrap();
    assert!(
        fit.knots.n_ctrl() <= q.curve.control_points().len(),
        "{} > {}",
        fit.knots.n_ctrl(),
        q.curve.control_points().len()
    );
}

#[test]
fn a_corner_is_a_c0_knot_and_the_fit_holds() {
    // Two arcs meeting at a 90° corner at (10, 0).
    let mut pts: Vec<Vector2<f64>> = (0..30)
        .map(|k| {
            let t = k as f64 / 29.0;
            Vector2::new(10.0 * t, 0.5 * (std::f64::consts::PI * t).sin())
        })
        .collect();
    for k in 1..30 {
        let t = k as f64 / 29.0;
        pts.push(Vector2::new(
            10.0 + 0.5 * (std::f64::consts::PI * t).sin(),
            -10.0 * t,
        ));
    }
    let data = vec![pts];
    let tol = 1e-4;
    let fit = approximate_compatible(&data, 3, tol, DEFAULT_KINK_ANGLE).unwrap();
    assert_eq!(fit.kinks.len(), 1, "{:?}", fit.kinks);
    let k = fit.kinks[0];
    let mult = fit.knots.knots().iter().filter(|&&x| x == k).count();
    assert_eq!(mult, 3, "full multiplicity at the corner");
    assert!(check(&fit, &data) <= tol);
    // The corner point is met.
    let c = fit.curve(0).unwrap();
    assert!((c.point(k) - Vector2::new(10.0, 0.0)).norm() <= tol);
}

#[test]
fn unequal_sections_share_one_knot_vector_within_tolerance() {
    let data = vec![
        dense_le_side(0.3, 40, 60, 2.0),
        dense_le_side(0.25, 23, 71, 3.0),
        dense_le_side(0.2, 57, 44, 4.0),
    ];
    let tol = 2e-3;
    let fit = approximate_compatible(&data, 3, tol, DEFAULT_KINK_ANGLE).unwrap();
    assert!(fit.ctrl.iter().all(|c| c.len() == fit.knots.n_ctrl()));
    assert!(check(&fit, &data) <= tol);
}

#[test]
fn few_points_are_followed_and_bad_arguments_rejected() {
    // A zig-zag of five points: refinement reaches (near) interpolation.
    let data = vec![vec![
        Vector2::new(0.0, 0.0),
        Vector2::new(1.0, 1.0),
        Vector2::new(2.0, -1.0),
        Vector2::new(3.0, 1.0),
        Vector2::new(4.0, 0.0),
    ]];
    let fit = approximate_compatible(&data, 3, 1e-9, 0.9 * std::f64::consts::PI).unwrap();
    // Five points, degree 3: the interpolant is reachable and found.
    assert!(fit.max_error() <= 1e-9, "{}", fit.max_error());
    assert!(approximate_compatible(&data, 3, -1.0, DEFAULT_KINK_ANGLE).is_err());
    assert!(approximate_compatible::<2>(&[], 3, 1.0, DEFAULT_KINK_ANGLE).is_err());
}
