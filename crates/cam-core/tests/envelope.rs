#![allow(clippy::unwrap_used, clippy::expect_used)]
//! Signed distance to the swept envelope: closed-form cases, brute force, derivatives.

use cam_core::{
    CamError, CutterShape, EnvelopeOptions, EnvelopeParam, GuideCurve, Point3, SphereFamily,
    SweptEnvelope, Vector3,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Clamped uniform cubic B-spline with the given control points on [0, 1].
fn cubic(pts: &[Vector3]) -> GuideCurve {
    let n = pts.len();
    let mut knots = vec![0.0; 4];
    for i in 1..(n - 3) {
        knots.push(i as f64 / (n - 3) as f64);
    }
    knots.extend([1.0; 4]);
    GuideCurve::new(3, knots, pts.to_vec(), None).unwrap()
}

/// Exact full circle of radius `r` in the plane z = `z` (rational quadratic, 9 points).
fn circle(r: f64, z: f64) -> GuideCurve {
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let c = [
        (1.0, 0.0),
        (1.0, 1.0),
        (0.0, 1.0),
        (-1.0, 1.0),
        (-1.0, 0.0),
        (-1.0, -1.0),
        (0.0, -1.0),
        (1.0, -1.0),
        (1.0, 0.0),
    ];
    GuideCurve::new(
        2,
        vec![
            0.0, 0.0, 0.0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1.0, 1.0, 1.0,
        ],
        c.iter()
            .map(|&(x, y)| Vector3::new(r * x, r * y, z))
            .collect(),
        Some(vec![1.0, w, 1.0, w, 1.0, w, 1.0, w, 1.0]),
    )
    .unwrap()
}

fn envelope(shape: CutterShape, l: f64, g0: GuideCurve, g1: GuideCurve, hg: f64) -> SweptEnvelope {
    let fam = SphereFamily::from_shape(&shape, l).unwrap();
    SweptEnvelope::new(fam, g0, g1, hg, EnvelopeOptions::default()).unwrap()
}

/// A curved flank-like path: tip meandering, axis tilting (guide height `hg`).
fn flank_guides(hg: f64) -> (GuideCurve, GuideCurve) {
    let mut p0 = Vec::new();
    let mut p1 = Vec::new();
    for i in 0..8 {
        let u = i as f64 / 7.0;
        let tip = Vector3::new(60.0 * u, 8.0 * (3.0 * u).sin(), 2.0 * u * u);
        let axis = Vector3::new(0.3 * (u - 0.5), 0.2 + 0.3 * u, 1.0).normalize();
        p0.push(tip + axis * hg);
        p1.push(tip + axis * (hg + 20.0));
    }
    (cubic(&p0), cubic(&p1))
}

#[test]
fn flat_end_along_a_line_is_a_slab() {
    let r = 4.0;
    let line =
        |z: f64| cubic(&[0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0].map(|u| Vector3::new(100.0 * u, 0.0, z)));
    let env = envelope(
        CutterShape::FlatEnd { radius: r },
        20.0,
        line(0.0),
        line(10.0),
        0.0,
    );
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    for _ in 0..200 {
        let x = rng.random_range(20.0..80.0);
        let y: f64 = rng.random_range(-9.0..9.0);
        let z: f64 = rng.random_range(-5.0..15.0);
        let p = Point3::new(x, y, z);
        let d = env.signed_distance(&p, None).unwrap().distance;
        let dy = y.abs() - r;
        let exact = if z >= 0.0 && dy > 0.0 {
            dy
        } else if z < 0.0 && dy <= 0.0 {
            -z
        } else if z < 0.0 {
            (dy * dy + z * z).sqrt()
        } else {
            // Inside the slab |y| <= r, 0 <= z: negative, bounded by the true depth.
            let depth = (-dy).min(z);
            assert!(
                d < 0.0 && d >= -depth - 1e-9,
                "inside {p}: {d} vs depth {depth}"
            );
            continue;
        };
        assert!((d - exact).abs() < 1e-9, "{p}: {d} vs {exact}");
    }
    // Beyond the path's ends the nearest member belongs to the first / last cutter location.
    for (p, exact) in [
        (Point3::new(-5.0, 0.0, 5.0), 1.0),
        (Point3::new(-3.0, 4.0, 2.0), 1.0),
        (
            Point3::new(106.0, 0.0, -2.0),
            (4.0f64 + 2.0f64.powi(2)).sqrt(),
        ),
    ] {
        let d = env.signed_distance(&p, None).unwrap();
        assert!(
            (d.distance - exact).abs() < 1e-9,
            "{p}: {} vs {exact}",
            d.distance
        );
        assert!(d.param.s == 0.0 || d.param.s == 1.0);
    }
}

#[test]
fn ball_along_a_circle_is_a_torus() {
    let (rb, rc) = (3.0, 50.0);
    let env = envelope(
        CutterShape::BallEnd { radius: rb },
        20.0,
        circle(rc, 0.0),
        circle(rc, 10.0),
        0.0,
    );
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    for _ in 0..200 {
        let phi = rng.random_range(0.0..std::f64::consts::TAU);
        let rho = rng.random_range(40.0..60.0);
        let z = rng.random_range(-6.0..rb); // below the ball centres: the torus is nearest
        let p = Point3::new(rho * phi.cos(), rho * phi.sin(), z);
        let exact = ((rho - rc).powi(2) + (z - rb).powi(2)).sqrt() - rb;
        let d = env.signed_distance(&p, None).unwrap().distance;
        assert!((d - exact).abs() < 1e-9, "{p}: {d} vs {exact}");
    }
}

/// Brute force: dense (s, t) grid of members, then three zoomed grids around the best.
fn brute_force(env: &SweptEnvelope, p: &Point3) -> f64 {
    let fam = env.family();
    let (t0, t1) = fam.param_range();
    let f = |s: f64, t: f64| {
        let cl = env.cutter_location(s).unwrap();
        let v = p - cl.tip;
        let z = v.dot(&cl.axis);
        let w = (v.norm_squared() - z * z).max(0.0).sqrt();
        fam.member(t).signed_distance(w, z)
    };
    let (ns, nt) = (400, 120);
    let mut best = (f64::INFINITY, 0.0, 0.0);
    for i in 0..=ns {
        let s = i as f64 / ns as f64;
        let cl = env.cutter_location(s).unwrap();
        let v = p - cl.tip;
        let z = v.dot(&cl.axis);
        let w = (v.norm_squared() - z * z).max(0.0).sqrt();
        for j in 0..=nt {
            let t = t0 + (t1 - t0) * j as f64 / nt as f64;
            let d = fam.member(t).signed_distance(w, z);
            if d < best.0 {
                best = (d, s, t);
            }
        }
    }
    let (mut hs, mut ht) = (1.0 / ns as f64, (t1 - t0) / nt as f64);
    for _ in 0..6 {
        let (_, sc, tc) = best;
        for i in -10..=10 {
            for j in -10..=10 {
                let s = (sc + hs * i as f64 / 10.0).clamp(0.0, 1.0);
                let t = (tc + ht * j as f64 / 10.0).clamp(t0, t1);
                let d = f(s, t);
                if d < best.0 {
                    best = (d, s, t);
                }
            }
        }
        hs /= 5.0;
        ht /= 5.0;
    }
    best.0
}

#[test]
fn agrees_with_brute_force_sampling() {
    let shapes = [
        CutterShape::TaperedBallEnd {
            ball_radius: 3.0,
            half_angle: 3f64.to_radians(),
        },
        CutterShape::BullNose {
            radius: 4.0,
            corner_radius: 1.0,
        },
        CutterShape::TaperedFlatEnd {
            tip_radius: 3.0,
            half_angle: 4f64.to_radians(),
        },
    ];
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for shape in shapes {
        let (g0, g1) = flank_guides(1.0);
        let env = envelope(shape, 25.0, g0, g1, 1.0);
        for _ in 0..6 {
            // Points around a random cutter location, some inside, some outside.
            let s = rng.random_range(0.0..1.0);
            let cl = env.cutter_location(s).unwrap();
            let off = Vector3::new(
                rng.random_range(-9.0..9.0),
                rng.random_range(-9.0..9.0),
                rng.random_range(-4.0..15.0),
            );
            let p = cl.tip + off;
            let d = env.signed_distance(&p, None).unwrap().distance;
            let b = brute_force(&env, &p);
            assert!(
                d <= b + 1e-9,
                "{shape:?} {p}: Newton {d} worse than brute {b}"
            );
            assert!((d - b).abs() < 1e-6, "{shape:?} {p}: {d} vs brute {b}");
        }
    }
}

#[test]
fn warm_start_along_a_line_matches_cold() {
    let (g0, g1) = flank_guides(3.0);
    let shape = CutterShape::TaperedBallEnd {
        ball_radius: 3.0,
        half_angle: 3f64.to_radians(),
    };
    let env = envelope(shape, 25.0, g0, g1, 3.0);
    let mut hint: Option<EnvelopeParam> = None;
    for i in 0..100 {
        let s = i as f64 / 99.0;
        let cl = env.cutter_location(s).unwrap();
        // A point 0.2 mm off the side of the cutter, 8 mm up.
        let side = cl.axis.cross(&Vector3::z()).normalize();
        let p = cl.axis_point(8.0) + side * (shape.radius_at(8.0) + 0.2);
        let cold = env.signed_distance(&p, None).unwrap();
        let warm = env.signed_distance(&p, hint).unwrap();
        hint = Some(warm.param);
        assert!((cold.distance - warm.distance).abs() < 1e-9, "{i}");
        assert!(cold.distance <= 0.2 + 1e-12);
    }
}

/// Central differences of the distance against the closed-form gradient.
fn check_derivatives(shape_of: &dyn Fn(f64, f64) -> CutterShape, q: (f64, f64), nq: usize) {
    let hg = 2.0;
    let (g0, g1) = flank_guides(hg);
    let l = 25.0;
    let build = |g0: &GuideCurve, g1: &GuideCurve, q: (f64, f64)| {
        envelope(shape_of(q.0, q.1), l, g0.clone(), g1.clone(), hg)
    };
    let env = build(&g0, &g1, q);
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let h = 1e-5;
    let close = |an: f64, fd: f64, scale: f64, what: &str| {
        assert!(
            (an - fd).abs() <= 1e-6 * an.abs().max(scale),
            "{what}: analytic {an} vs fd {fd}"
        );
    };
    let (mut inside, mut outside) = (0, 0);
    for _ in 0..8 {
        let s = rng.random_range(0.05..0.95);
        let cl = env.cutter_location(s).unwrap();
        let off = Vector3::new(
            rng.random_range(-7.0..7.0),
            rng.random_range(-7.0..7.0),
            rng.random_range(-3.0..14.0),
        );
        let p = cl.tip + off;
        let (d, g) = env.signed_distance_with_gradient(&p, None).unwrap();
        if d.distance > 0.0 {
            outside += 1;
        } else {
            inside += 1;
        }
        let dist =
            |e: &SweptEnvelope, p: &Point3| e.signed_distance(p, Some(d.param)).unwrap().distance;
        let scale = 1.0;
        // Point.
        for k in 0..3 {
            let mut dp = Vector3::zeros();
            dp[k] = h;
            let fd = (dist(&env, &(p + dp)) - dist(&env, &(p - dp))) / (2.0 * h);
            close(g.point[k], fd, scale, "point");
        }
        if d.distance > 0.0 {
            assert!((g.point.norm() - 1.0).abs() < 1e-9, "outside: unit normal");
        }
        // Control points of both guides (support and one point outside it).
        for which in 0..2 {
            let guide = if which == 0 { &g0 } else { &g1 };
            let cg = if which == 0 { &g.guide0 } else { &g.guide1 };
            for i in 0..guide.control_points().len() {
                for k in 0..3 {
                    let bumped = |sign: f64| {
                        let mut gg = guide.clone();
                        gg.control_points_mut()[i][k] += sign * h;
                        if which == 0 {
                            build(&gg, &g1, q)
                        } else {
                            build(&g0, &gg, q)
                        }
                    };
                    let fd = (dist(&bumped(1.0), &p) - dist(&bumped(-1.0), &p)) / (2.0 * h);
                    close(
                        cg.get(i)[k],
                        fd,
                        scale,
                        &format!("guide{which} ctrl {i}.{k}"),
                    );
                }
            }
        }
        // Shape parameters.
        for k in 0..nq {
            let (dq0, dq1) = if k == 0 { (h, 0.0) } else { (0.0, h) };
            let ep = build(&g0, &g1, (q.0 + dq0, q.1 + dq1));
            let em = build(&g0, &g1, (q.0 - dq0, q.1 - dq1));
            let fd = (dist(&ep, &p) - dist(&em, &p)) / (2.0 * h);
            close(g.shape[k], fd, scale, &format!("shape {k}"));
        }
    }
    assert!(
        inside >= 1 && outside >= 3,
        "{inside} inside, {outside} outside"
    );
}

#[test]
fn tapered_ball_derivatives_match_central_differences() {
    check_derivatives(
        &|r, th| CutterShape::TaperedBallEnd {
            ball_radius: r,
            half_angle: th,
        },
        (3.0, 3f64.to_radians()),
        2,
    );
}

#[test]
fn bull_nose_derivatives_match_central_differences() {
    check_derivatives(
        &|r, rc| CutterShape::BullNose {
            radius: r,
            corner_radius: rc,
        },
        (4.0, 1.2),
        2,
    );
}

#[test]
fn tapered_flat_derivatives_match_central_differences() {
    check_derivatives(
        &|r, th| CutterShape::TaperedFlatEnd {
            tip_radius: r,
            half_angle: th,
        },
        (3.0, 4f64.to_radians()),
        2,
    );
}

#[test]
fn builds_from_a_cutter_and_nurbs_guides() {
    let cutter = cam_core::Cutter::new(
        "tb",
        CutterShape::TaperedBallEnd {
            ball_radius: 3.0,
            half_angle: 0.05,
        },
        25.0,
        5.0,
        60.0,
    )
    .unwrap();
    let (g0, g1) = flank_guides(0.0);
    let env = SweptEnvelope::for_cutter(
        &cutter,
        &g0.to_curve().unwrap(),
        &g1.to_curve().unwrap(),
        0.0,
        EnvelopeOptions::default(),
    )
    .unwrap();
    let reference = envelope(cutter.shape, 25.0, g0, g1, 0.0);
    let p = Point3::new(30.0, 4.0, 6.0);
    assert_eq!(
        env.signed_distance(&p, None).unwrap(),
        reference.signed_distance(&p, None).unwrap()
    );
}

#[test]
fn invalid_inputs_are_typed_errors() {
    let (g0, g1) = flank_guides(0.0);
    let fam = SphereFamily::from_shape(&CutterShape::BallEnd { radius: 3.0 }, 20.0).unwrap();
    // Different parameter domains.
    let mut knots = g1.knots().to_vec();
    knots.iter_mut().for_each(|k| *k *= 2.0);
    let g2 = GuideCurve::new(3, knots, g1.control_points().to_vec(), None).unwrap();
    assert!(matches!(
        SweptEnvelope::new(fam.clone(), g0.clone(), g2, 0.0, EnvelopeOptions::default()),
        Err(CamError::InvalidGuide { .. })
    ));
    // Coincident guides: no axis.
    assert!(matches!(
        SweptEnvelope::new(
            fam.clone(),
            g0.clone(),
            g0.clone(),
            0.0,
            EnvelopeOptions::default()
        ),
        Err(CamError::DegenerateAxis { .. })
    ));
    let bad = EnvelopeOptions {
        step_tol: 0.0,
        ..EnvelopeOptions::default()
    };
    assert!(matches!(
        SweptEnvelope::new(fam.clone(), g0.clone(), g1.clone(), 0.0, bad),
        Err(CamError::NonPositive { .. })
    ));
    let env = SweptEnvelope::new(fam, g0, g1, 0.0, EnvelopeOptions::default()).unwrap();
    assert!(matches!(
        env.signed_distance(&Point3::new(f64::NAN, 0.0, 0.0), None),
        Err(CamError::NonFinitePoint(..))
    ));
}

mod properties {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// The result is a global minimum (no member is nearer) and the distance is
        /// 1-Lipschitz in the point.
        #[test]
        fn global_minimum_and_lipschitz(
            x in -5.0f64..65.0, y in -12.0f64..12.0, z in -5.0f64..20.0,
            s in 0.0f64..1.0, t in 0.0f64..1.0,
            dx in -0.5f64..0.5, dy in -0.5f64..0.5, dz in -0.5f64..0.5,
        ) {
            let (g0, g1) = flank_guides(0.0);
            let shape = CutterShape::TaperedBallEnd { ball_radius: 3.0, half_angle: 0.05 };
            let env = envelope(shape, 25.0, g0, g1, 0.0);
            let p = Point3::new(x, y, z);
            let d = env.signed_distance(&p, None).unwrap().distance;
            let cl = env.cutter_location(s).unwrap();
            let v = p - cl.tip;
            let zz = v.dot(&cl.axis);
            let w = (v.norm_squared() - zz * zz).max(0.0).sqrt();
            prop_assert!(d <= env.family().member(t).signed_distance(w, zz) + 1e-9);
            let q = p + Vector3::new(dx, dy, dz);
            let dq = env.signed_distance(&q, None).unwrap().distance;
            prop_assert!((d - dq).abs() <= (q - p).norm() + 1e-9);
        }
    }
}

mod certified {
    use super::*;
    use proptest::prelude::*;
    use rand::Rng;

    /// A random wavy path: 6 random control points per guide (tip meandering with large
    /// swings so the distance has several local minima along the path), random tilt.
    fn random_guides(seed: u64, hg: f64) -> (GuideCurve, GuideCurve) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut p0 = Vec::new();
        let mut p1 = Vec::new();
        for i in 0..6 {
            let u = i as f64 / 5.0;
            let tip = Vector3::new(
                40.0 * u + rng.random_range(-6.0..6.0),
                rng.random_range(-12.0..12.0),
                rng.random_range(-4.0..4.0),
            );
            let axis = Vector3::new(
                rng.random_range(-0.5..0.5),
                rng.random_range(-0.5..0.5),
                1.0,
            )
            .normalize();
            p0.push(tip + axis * hg);
            p1.push(tip + axis * (hg + 20.0));
        }
        (cubic(&p0), cubic(&p1))
    }

    proptest! {
        /// Hinted (with an arbitrary, possibly far hint) and cold answers are never larger
        /// than the dense brute-force minimum by more than 1e-9 mm, and are certified.
        #[test]
        fn never_above_the_brute_force_minimum(
            seed in 0u64..1_000_000,
            r in 1.0f64..4.0, theta_deg in 0.0f64..8.0,
            s in 0.0f64..1.0, hint_s in 0.0f64..1.0,
            dx in -10.0f64..10.0, dy in -10.0f64..10.0, dz in -4.0f64..18.0,
        ) {
            let hg = r;
            let (g0, g1) = random_guides(seed, hg);
            let shape = CutterShape::TaperedBallEnd {
                ball_radius: r,
                half_angle: theta_deg.to_radians(),
            };
            let env = envelope(shape, 25.0, g0, g1, hg);
            let p = env.cutter_location(s).unwrap().tip + Vector3::new(dx, dy, dz);
            let brute = brute_force(&env, &p);
            let cold = env.signed_distance(&p, None).unwrap();
            let hint = EnvelopeParam { s: hint_s, t: 0.0 };
            let warm = env.signed_distance(&p, Some(hint)).unwrap();
            for (name, d) in [("cold", cold), ("hinted", warm)] {
                prop_assert!(d.certified, "{name}: not certified");
                prop_assert!(
                    d.distance <= brute + 1e-9,
                    "{name}: {} above brute force {brute}", d.distance
                );
            }
        }
    }

    /// A hint in the wrong basin: the uncertified Newton answer would be a local minimum far
    /// above the true one; the certified answer finds the true one.
    #[test]
    fn a_wrong_basin_hint_is_corrected() {
        // A hairpin path: out along y = 0, back along y = 20; the point sits between the
        // legs, nearer the return leg, so Newton from the start stops on the outgoing leg.
        let ctrl = [
            (0.0, 0.0),
            (20.0, 0.0),
            (40.0, 0.0),
            (50.0, 10.0),
            (40.0, 20.0),
            (20.0, 20.0),
            (0.0, 20.0),
        ];
        let p0: Vec<Vector3> = ctrl.iter().map(|&(x, y)| Vector3::new(x, y, 3.0)).collect();
        let p1: Vec<Vector3> = ctrl
            .iter()
            .map(|&(x, y)| Vector3::new(x, y, 23.0))
            .collect();
        let shape = CutterShape::TaperedBallEnd {
            ball_radius: 3.0,
            half_angle: 0.05,
        };
        let env = envelope(shape, 25.0, cubic(&p0), cubic(&p1), 3.0);
        let p = Point3::new(15.0, 14.0, 5.0);
        let brute = brute_force(&env, &p);
        let warm = env
            .signed_distance(&p, Some(EnvelopeParam { s: 0.0, t: 0.0 }))
            .unwrap();
        assert!(warm.certified);
        assert!(
            warm.distance <= brute + 1e-9,
            "{} vs {brute}",
            warm.distance
        );
        // Without certification runs the hinted Newton answer is the wrong basin's.
        let fam = SphereFamily::from_shape(&shape, 25.0).unwrap();
        let opts = EnvelopeOptions {
            max_certify_runs: 0,
            ..EnvelopeOptions::default()
        };
        let bare = SweptEnvelope::new(fam, cubic(&p0), cubic(&p1), 3.0, opts).unwrap();
        let local = bare
            .signed_distance(&p, Some(EnvelopeParam { s: 0.0, t: 0.0 }))
            .unwrap();
        assert!(!local.certified);
        assert!(
            local.distance > brute + 1.0,
            "{} vs {brute}",
            local.distance
        );
    }

    /// A query from the centre of a ring-shaped path sees every interval at nearly the same
    /// distance, so certification runs Newton in interval after interval: with the largest run
    /// budget (64) it must neither overrun its record of searched intervals (it panicked
    /// above 42 runs) nor answer farther than a dense brute force.
    #[test]
    fn certification_with_the_largest_run_budget_on_a_ring() {
        let ring = |z: f64| {
            let pts: Vec<Vector3> = (0..=60)
                .map(|i| {
                    let a = std::f64::consts::TAU * i as f64 / 60.0;
                    Vector3::new(30.0 * a.cos(), 30.0 * a.sin(), z)
                })
                .collect();
            cubic(&pts)
        };
        let shape = CutterShape::BallEnd { radius: 2.0 };
        let fam = SphereFamily::from_shape(&shape, 20.0).unwrap();
        let opts = EnvelopeOptions {
            max_certify_runs: 64,
            ..EnvelopeOptions::default()
        };
        let env = SweptEnvelope::new(fam, ring(0.0), ring(20.0), 0.0, opts).unwrap();
        for p in [
            Point3::new(0.0, 0.0, 2.0),
            Point3::new(0.5, -0.3, 8.0),
            Point3::new(-1.0, 0.2, -3.0),
        ] {
            let d = env.signed_distance(&p, None).unwrap();
            let brute = brute_force(&env, &p);
            assert!(d.distance <= brute + 1e-9, "{} vs {brute}", d.distance);
        }
    }

    /// A written pass: 2000 short linear moves (degree-1 guides) along a gently curved path
    /// with a slowly tilting axis. Beside the flank the distance rises by less than the cone
    /// bound's `L·h/2` over dozens of seed intervals on each side of the minimiser; the
    /// first-order certificate needed a Newton run for each and ran out of its 16 runs
    /// (uncertified: issue 13's dense measurement of written flank passes). The second-order
    /// bound of sphere families excludes them: certified, and not above the brute force by
    /// more than `KINK_SLACK_MM`.
    #[test]
    fn dense_linear_moves_beside_the_flank_are_certified() {
        // The guides turn at every knot (C0): `g` can have a second local minimum a few 1e-8
        // mm deeper on the other side of a knot inside a seed interval Newton already
        // searched, which the certificate does not cover (module docs: "what is not
        // proven"); measured 2.4e-8 mm at the third point. Far below any machining use.
        const KINK_SLACK_MM: f64 = 1e-7;
        let n = 2001;
        let (mut p0, mut p1) = (Vec::new(), Vec::new());
        for i in 0..n {
            let u = i as f64 / (n - 1) as f64;
            let ang = 0.3 * u; // 60 mm of a 200 mm radius arc
            let tip = Vector3::new(200.0 * ang.sin(), 200.0 * (1.0 - ang.cos()), 0.5 * u);
            let axis = Vector3::new(0.1 * u, -0.05 + 0.1 * u, 1.0).normalize();
            p0.push(tip);
            p1.push(tip + axis * 25.0);
        }
        let mut knots = vec![0.0];
        knots.extend((0..n).map(|i| i as f64 / (n - 1) as f64));
        knots.push(1.0);
        let g0 = GuideCurve::new(1, knots.clone(), p0, None).unwrap();
        let g1 = GuideCurve::new(1, knots, p1, None).unwrap();
        let (r, theta) = (3.0, 3f64.to_radians());
        let shape = CutterShape::TaperedBallEnd {
            ball_radius: r,
            half_angle: theta,
        };
        let env = envelope(shape, 25.0, g0, g1, 0.0);
        let mut checked = 0;
        for (s, z, delta) in [
            (0.37, 10.0, 0.0),
            (0.37, 10.0, 0.01),
            (0.61, 4.0, -0.01),
            (0.83, 18.0, 0.002),
        ] {
            let cl = env.cutter_location(s).unwrap();
            let dir = (env.cutter_location(s + 1e-4).unwrap().tip - cl.tip).normalize();
            let axis = cl.axis.into_inner();
            let side = axis.cross(&dir).normalize();
            // The flank's radius at height z (member centre below z by ρ·sin θ).
            let rho = r + (z - r) * theta.sin() / (1.0 + theta.sin());
            let p = cl.tip + axis * z + side * (rho / theta.cos() + delta);
            let brute = brute_force(&env, &p);
            for hint in [None, Some(EnvelopeParam { s, t: 0.0 })] {
                let d = env.signed_distance(&p, hint).unwrap();
                assert!(d.certified, "{p} hint {hint:?}: not certified");
                assert!(
                    d.distance <= brute + KINK_SLACK_MM,
                    "{p}: {} above brute force {brute}",
                    d.distance
                );
                checked += 1;
            }
        }
        assert_eq!(checked, 8);
    }

    /// Rational guides carry no hodograph bound: the answer says it is not certified.
    #[test]
    fn rational_guides_are_reported_uncertified() {
        let shape = CutterShape::BallEnd { radius: 2.0 };
        let env = envelope(shape, 20.0, circle(30.0, 2.0), circle(30.0, 22.0), 2.0);
        let d = env
            .signed_distance(&Point3::new(35.0, 0.0, 5.0), None)
            .unwrap();
        assert!(!d.certified);
    }
}
