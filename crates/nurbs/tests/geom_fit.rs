//! Fitting: interpolation, least squares, smoothing, surface interpolation, skinning.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::{Vector2, Vector3};
use nurbs::fit::{
    self, approximate_curve, approximate_curve_to_tolerance, interpolate_curve,
    interpolate_surface, skin, smooth_curve, Energy, FitError, Parametrisation,
};
use nurbs::NurbsCurve;
use proptest::prelude::*;

fn wiggle(n: usize) -> Vec<Vector3<f64>> {
    (0..n)
        .map(|k| {
            let t = k as f64 / (n - 1) as f64;
            Vector3::new(40.0 * t, 10.0 * (5.0 * t).sin(), 3.0 * (3.0 * t).cos())
        })
        .collect()
}

fn points_strategy() -> impl Strategy<Value = Vec<Vector3<f64>>> {
    prop::collection::vec((0.1f64..5.0, -5.0f64..5.0, -5.0f64..5.0), 6..30).prop_map(|steps| {
        let mut x = 0.0;
        steps
            .into_iter()
            .map(|(dx, y, z)| {
                x += dx;
                Vector3::new(x, y, z)
            })
            .collect()
    })
}

fn param_strategy() -> impl Strategy<Value = Parametrisation> {
    prop_oneof![
        Just(Parametrisation::Uniform),
        Just(Parametrisation::ChordLength),
        Just(Parametrisation::Centripetal)
    ]
}

proptest! {
    /// A9.1: the interpolant passes through every data point at its parameter (1e-10).
    #[test]
    fn interpolation_passes_through_points(pts in points_strategy(), degree in 1usize..=5, par in param_strategy()) {
        let c = interpolate_curve(&pts, degree, par, None).unwrap();
        let params = fit::parameters(&pts, par).unwrap();
        for (u, q) in params.iter().zip(&pts) {
            prop_assert!((c.point(*u) - q).norm() <= 1e-10, "miss {}", (c.point(*u) - q).norm());
        }
    }

    /// §9.2.2: with end derivatives the curve also matches C'(0) and C'(1).
    #[test]
    fn interpolation_with_end_derivatives(pts in points_strategy(), degree in 2usize..=4,
                                          d0 in (-50.0f64..50.0, -50.0f64..50.0, -50.0f64..50.0),
                                          d1 in (-50.0f64..50.0, -50.0f64..50.0, -50.0f64..50.0)) {
        let d0 = Vector3::new(d0.0, d0.1, d0.2);
        let d1 = Vector3::new(d1.0, d1.1, d1.2);
        let c = interpolate_curve(&pts, degree, Parametrisation::ChordLength, Some((d0, d1))).unwrap();
        let params = fit::parameters(&pts, Parametrisation::ChordLength).unwrap();
        for (u, q) in params.iter().zip(&pts) {
            prop_assert!((c.point(*u) - q).norm() <= 1e-10);
        }
        prop_assert!((c.derivs(0.0, 1)[1] - d0).norm() <= 1e-9 * (1.0 + d0.norm()));
        prop_assert!((c.derivs(1.0, 1)[1] - d1).norm() <= 1e-9 * (1.0 + d1.norm()));
    }

    /// A9.4: the surface passes through every grid point.
    #[test]
    fn surface_interpolation_passes_through_grid(nu in 4usize..9, nv in 4usize..9, seed in 0u64..1000,
                                                  pu in 1usize..=3, pv in 1usize..=3) {
        let grid: Vec<Vec<Vector3<f64>>> = (0..nu)
            .map(|k| (0..nv).map(|l| {
                let (x, y) = (k as f64 * 10.0 + (l as f64 * 0.7).sin(), l as f64 * 8.0);
                let z = ((seed as f64 + x * 0.3).sin() + (y * 0.2).cos()) * 4.0;
                Vector3::new(x, y, z)
            }).collect())
            .collect();
        let s = interpolate_surface(&grid, pu, pv, Parametrisation::ChordLength).unwrap();
        // Recover the parameters the way A9.4 does and check every point.
        let u_lines: Vec<Vec<Vector3<f64>>> = (0..nv).map(|l| grid.iter().map(|r| r[l]).collect()).collect();
        let avg = |lines: &Vec<Vec<Vector3<f64>>>| {
            let n = lines[0].len();
            let mut acc = vec![0.0; n];
            for line in lines {
                let p = fit::parameters(line, Parametrisation::ChordLength).unwrap();
                for (a, b) in acc.iter_mut().zip(p) { *a += b / lines.len() as f64; }
            }
            acc
        };
        let up = avg(&u_lines);
        let vp = avg(&grid);
        for k in 0..nu {
            for l in 0..nv {
                prop_assert!((s.point(up[k], vp[l]) - grid[k][l]).norm() <= 1e-10);
            }
        }
    }
}

#[test]
fn least_squares_reproduces_a_spline_in_its_space() {
    // Data sampled at uniform parameters from a cubic B-spline whose knots the
    // approximation reproduces: n_ctrl = 6, 12 points, uniform parameters, eq. 9.69 knots.
    let data: Vec<Vector2<f64>> = (0..12)
        .map(|k| {
            let t = k as f64 / 11.0;
            Vector2::new(t * 30.0, 2.0 * t * t - 3.0 * t * t * t + 1.0)
        })
        .collect();
    // A cubic polynomial in t lies in every cubic spline space on [0, 1].
    let fit = approximate_curve(&data, 3, 6, Parametrisation::Uniform).unwrap();
    assert!(fit.max_error <= 1e-12, "max_error {}", fit.max_error);
    assert_eq!(fit.curve.control_points().len(), 6);
    assert!((fit.curve.point(0.0) - data[0]).norm() == 0.0);
    assert!((fit.curve.point(1.0) - data[11]).norm() == 0.0);
}

#[test]
fn least_squares_error_is_reported_and_ends_fixed() {
    let pts = wiggle(60);
    let fit = approximate_curve(&pts, 3, 10, Parametrisation::ChordLength).unwrap();
    let direct = fit
        .params
        .iter()
        .zip(&pts)
        .map(|(u, q)| (fit.curve.point(*u) - q).norm())
        .fold(0.0, f64::max);
    assert!((direct - fit.max_error).abs() <= 1e-12);
    assert!(
        fit.max_error > 1e-4,
        "10 control points cannot interpolate 60 wiggly points"
    );
    assert_eq!(fit.curve.point(0.0), pts[0]);
    assert_eq!(fit.curve.point(1.0), pts[59]);
    // n_ctrl = number of points: the interpolant.
    let interp = approximate_curve(&pts, 3, 60, Parametrisation::ChordLength).unwrap();
    assert!(interp.max_error <= 1e-10);
}

#[test]
fn approximation_to_tolerance_uses_the_fewest_control_points() {
    let pts = wiggle(80);
    let tol = 1e-3;
    let fit = approximate_curve_to_tolerance(&pts, 3, tol, Parametrisation::ChordLength).unwrap();
    assert!(fit.max_error <= tol);
    let n = fit.curve.control_points().len();
    assert!(n < 80, "should not need the interpolant ({n})");
    let fewer = approximate_curve(&pts, 3, n - 1, Parametrisation::ChordLength).unwrap();
    assert!(
        fewer.max_error > tol,
        "n - 1 = {} control points already pass",
        n - 1
    );
}

/// Bending energy ∫|C''|² by dense midpoint rule.
fn bending(c: &NurbsCurve<3>) -> f64 {
    let n = 2000;
    (0..n)
        .map(|k| c.derivs((k as f64 + 0.5) / n as f64, 2)[2].norm_squared())
        .sum::<f64>()
        / n as f64
}

#[test]
fn smoothing_trades_error_for_bending_energy() {
    // A straight line with alternating noise.
    let pts: Vec<Vector3<f64>> = (0..50)
        .map(|k| Vector3::new(k as f64, if k % 2 == 0 { 0.2 } else { -0.2 }, 0.0))
        .collect();
    let plain = approximate_curve(&pts, 3, 30, Parametrisation::ChordLength).unwrap();
    let zero = smooth_curve(
        &pts,
        3,
        30,
        Parametrisation::ChordLength,
        Energy::SecondDerivative,
        0.0,
    )
    .unwrap();
    assert!((plain.max_error - zero.max_error).abs() <= 1e-9);
    let mut last = bending(&zero.curve);
    for w in [1e-2, 1.0, 1e2] {
        let s = smooth_curve(
            &pts,
            3,
            30,
            Parametrisation::ChordLength,
            Energy::SecondDerivative,
            w,
        )
        .unwrap();
        let e = bending(&s.curve);
        assert!(e < last, "energy must drop with the weight ({e} !< {last})");
        last = e;
        assert_eq!(s.curve.point(0.0), pts[0]);
    }
    let stiff = smooth_curve(
        &pts,
        3,
        30,
        Parametrisation::ChordLength,
        Energy::FirstDerivative,
        1e4,
    )
    .unwrap();
    // A stiff membrane pulls the curve onto the segment between the fixed ends.
    let (a, b) = (pts[0], pts[49]);
    let off = |p: Vector3<f64>| {
        let t = ((p - a).dot(&(b - a)) / (b - a).norm_squared()).clamp(0.0, 1.0);
        (p - (a + (b - a) * t)).norm()
    };
    let dev = |c: &NurbsCurve<3>| {
        (0..=200)
            .map(|k| off(c.point(k as f64 / 200.0)))
            .fold(0.0, f64::max)
    };
    assert!(
        dev(&stiff.curve) < 0.02,
        "membrane deviation {}",
        dev(&stiff.curve)
    );
    assert!(dev(&plain.curve) > 0.1, "the plain fit follows the noise");
}

fn circle(r: f64, z: f64, degree_elevated: bool) -> NurbsCurve<3> {
    let c = NurbsCurve::<3>::circle_arc(
        Vector3::new(0.0, 0.0, z),
        Vector3::x(),
        Vector3::y(),
        r,
        0.0,
        std::f64::consts::PI,
    )
    .unwrap();
    if degree_elevated {
        c.elevate_degree(1).unwrap()
    } else {
        c
    }
}

#[test]
fn skinning_reproduces_its_sections() {
    // Cubic sections with different knot vectors, plus a linear section.
    let a = interpolate_curve(&wiggle(7), 3, Parametrisation::ChordLength, None).unwrap();
    let b_pts: Vec<Vector3<f64>> = wiggle(11)
        .iter()
        .map(|p| p + Vector3::new(0.0, 5.0, 20.0))
        .collect();
    let b = interpolate_curve(&b_pts, 3, Parametrisation::ChordLength, None).unwrap();
    let c = NurbsCurve::<3>::new(
        1,
        vec![0.0, 0.0, 1.0, 1.0],
        vec![Vector3::new(0.0, 0.0, 45.0), Vector3::new(40.0, 0.0, 45.0)],
        None,
    )
    .unwrap();
    let d_pts: Vec<Vector3<f64>> = wiggle(9)
        .iter()
        .map(|p| p + Vector3::new(0.0, -3.0, 60.0))
        .collect();
    let d = interpolate_curve(&d_pts, 2, Parametrisation::ChordLength, None).unwrap();
    let sections = [a, b, c, d];
    let s = skin(&sections, 3, Parametrisation::ChordLength).unwrap();
    // Find each section's v by matching the surface at u = 0 and check the whole curve.
    for sec in &sections {
        let (lo, hi) = sec.domain();
        let target = sec.point(lo);
        let v = (0..=20000)
            .map(|k| k as f64 / 20000.0)
            .min_by(|x, y| {
                (s.point(0.0, *x) - target)
                    .norm()
                    .total_cmp(&(s.point(0.0, *y) - target).norm())
            })
            .unwrap();
        // refine v with the closest point on the v-iso curve: use a fine bisection on the
        // monotone distance near the minimum
        let mut best_v = v;
        let mut step = 1.0 / 20000.0;
        for _ in 0..60 {
            for cand in [best_v - step, best_v + step] {
                if (0.0..=1.0).contains(&cand)
                    && (s.point(0.0, cand) - target).norm() < (s.point(0.0, best_v) - target).norm()
                {
                    best_v = cand;
                }
            }
            step *= 0.5;
        }
        for k in 0..=20 {
            let t = k as f64 / 20.0;
            let p = sec.point(lo + (hi - lo) * t);
            assert!(
                (s.point(t, best_v) - p).norm() <= 1e-9,
                "section mismatch {}",
                (s.point(t, best_v) - p).norm()
            );
        }
    }
}

#[test]
fn skinning_rational_sections_gives_a_surface_of_circles() {
    // Half circles of radii 10, 14, 12 at heights 0, 10, 20 (one elevated to degree 3).
    let sections = [
        circle(10.0, 0.0, false),
        circle(14.0, 10.0, true),
        circle(12.0, 20.0, false),
    ];
    let s = skin(&sections, 2, Parametrisation::ChordLength).unwrap();
    assert!(s.is_rational());
    for k in 0..=10 {
        let u = k as f64 / 10.0;
        for (v, r) in [(0.0, 10.0), (1.0, 12.0)] {
            let p = s.point(u, v);
            assert!(
                (p.xy().norm() - r).abs() <= 1e-10,
                "radius {} vs {r}",
                p.xy().norm()
            );
        }
    }
}

#[test]
fn every_fit_error_is_reported() {
    let pts = wiggle(10);
    assert!(matches!(
        interpolate_curve(&pts[..3], 3, Parametrisation::ChordLength, None),
        Err(FitError::TooFewPoints {
            needed: 4,
            got: 3,
            ..
        })
    ));
    assert!(matches!(
        interpolate_curve(&pts, 0, Parametrisation::ChordLength, None),
        Err(FitError::InvalidDegree { degree: 0 })
    ));
    let mut bad = pts.clone();
    bad[4].y = f64::NAN;
    assert!(matches!(
        interpolate_curve(&bad, 3, Parametrisation::ChordLength, None),
        Err(FitError::NonFinitePoint { index: 4 })
    ));
    let mut dup = pts.clone();
    dup[6] = dup[5];
    assert!(matches!(
        interpolate_curve(&dup, 3, Parametrisation::Centripetal, None),
        Err(FitError::CoincidentPoints { index: 5 })
    ));
    assert!(matches!(
        approximate_curve(&pts, 3, 11, Parametrisation::ChordLength),
        Err(FitError::InvalidControlCount {
            n_ctrl: 11,
            min: 4,
            max: 10
        })
    ));
    assert!(matches!(
        approximate_curve_to_tolerance(&pts, 3, 0.0, Parametrisation::ChordLength),
        Err(FitError::InvalidValue { field: "tol", .. })
    ));
    assert!(matches!(
        smooth_curve(
            &pts,
            3,
            6,
            Parametrisation::ChordLength,
            Energy::FirstDerivative,
            -1.0
        ),
        Err(FitError::InvalidValue {
            field: "weight",
            ..
        })
    ));
    let ragged = vec![pts.clone(), pts[..9].to_vec(), pts.clone(), pts.clone()];
    assert!(matches!(
        interpolate_surface(&ragged, 2, 2, Parametrisation::ChordLength),
        Err(FitError::RaggedGrid {
            row: 1,
            expected: 10,
            got: 9
        })
    ));
    // (SingularSystem is reached by the unit test of the rank-revealing solver in
    // src/fit/solve.rs: the public fits build regular systems by construction.)
    let single = [circle(10.0, 0.0, false)];
    assert!(matches!(
        skin(&single, 1, Parametrisation::ChordLength),
        Err(FitError::TooFewPoints {
            what: "sections",
            needed: 2,
            got: 1
        })
    ));
    // Core errors pass through: chords that overflow give non-finite knots, which the core
    // knot-vector validation rejects.
    let huge = [
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(1e308, 0.0, 0.0),
        Vector3::new(-1e308, 0.0, 0.0),
        Vector3::new(0.0, 1.0, 0.0),
    ];
    let err = interpolate_curve(&huge, 2, Parametrisation::ChordLength, None).unwrap_err();
    assert!(matches!(err, FitError::Nurbs(_)), "{err:?}");
}

/// `interpolate_surface_at`: passes through the grid at the given parameters on any range,
/// equals `interpolate_surface` when given that function's own (normalised) parameters, and
/// reports bad parameters and grids.
#[test]
fn surface_interpolation_at_given_parameters() {
    let u: Vec<f64> = (0..9)
        .map(|i| 3.0 + 2.0 * (i as f64 / 8.0).powf(1.4))
        .collect();
    let v: Vec<f64> = (0..6).map(|j| -1.0 + 0.5 * j as f64).collect();
    let grid: Vec<Vec<Vector3<f64>>> = u
        .iter()
        .map(|&a| {
            v.iter()
                .map(|&b| Vector3::new(10.0 * a, 20.0 * b, (a * b).sin()))
                .collect()
        })
        .collect();
    let s = fit::interpolate_surface_at(&grid, &u, &v, 3, 2).unwrap();
    assert_eq!(s.domain(), ((3.0, 5.0), (-1.0, 1.5)));
    for (i, &a) in u.iter().enumerate() {
        for (j, &b) in v.iter().enumerate() {
            assert!((s.point(a, b) - grid[i][j]).norm() < 1e-12);
        }
    }
    // Same parameters as the chord-length version on [0, 1]: the same surface.
    let auto = interpolate_surface(&grid, 3, 2, Parametrisation::Uniform).unwrap();
    let un: Vec<f64> = (0..9).map(|i| i as f64 / 8.0).collect();
    let vn: Vec<f64> = (0..6).map(|j| j as f64 / 5.0).collect();
    let at = fit::interpolate_surface_at(&grid, &un, &vn, 3, 2).unwrap();
    for (p, q) in auto.control_points().iter().zip(at.control_points()) {
        assert!((p - q).norm() < 1e-12);
    }
    let mut bad = u.clone();
    bad[4] = bad[3];
    assert!(matches!(
        fit::interpolate_surface_at(&grid, &bad, &v, 3, 2),
        Err(FitError::CoincidentPoints { index: 3 })
    ));
    assert!(matches!(
        fit::interpolate_surface_at(&grid[..8], &u, &v, 3, 2),
        Err(FitError::RaggedGrid { row: 8, got: 0, .. })
    ));
    assert!(matches!(
        fit::interpolate_surface_at(&grid, &u, &v, 0, 2),
        Err(FitError::InvalidDegree { degree: 0 })
    ));
}
