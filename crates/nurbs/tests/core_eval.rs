//! Curve and surface evaluation: derivatives against central finite differences,
//! consistency between `point`, `derivs2` and `derivs`, the exact rational quarter circle.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod core_support;

use core_support::{curve2, curve3, surface};
use nalgebra::{Vector2, Vector3};
use nurbs::{NurbsCurve, NurbsSurface, ParametricCurve, ParametricSurface};
use proptest::prelude::*;

/// Central-difference step and tolerance: truncation O(h² |f'''|) + rounding
/// O(ε |f| / h) ≈ 1e-8 relative for the bounded test geometry; we allow 1e-5 relative to the
/// magnitude of the neighbouring derivative orders.
const H: f64 = 1e-5;
const FD_TOL: f64 = 1e-5;

fn same_span(kv: &nurbs::KnotVector, u: f64) -> bool {
    kv.find_span(u - H) == kv.find_span(u + H)
}

fn check_curve_fd<const D: usize>(c: &NurbsCurve<D>, t: f64) -> Result<(), TestCaseError> {
    let (a, b) = c.domain();
    let u = a + H * 2.0 + (b - a - 4.0 * H) * t;
    prop_assume!(same_span(c.knots(), u));
    let n = 4;
    let d = c.derivs(u, n);
    let dm = c.derivs(u - H, n);
    let dp = c.derivs(u + H, n);
    prop_assert!((d[0] - c.point(u)).norm() < 1e-12 * (1.0 + d[0].norm()));
    let d2 = c.derivs2(u);
    for k in 0..3 {
        prop_assert!((d2[k] - d[k]).norm() <= 1e-12 * (1.0 + d[k].norm()));
    }
    for k in 0..n {
        let fd = (dp[k] - dm[k]) / (2.0 * H);
        let scale = 1.0 + d[k].norm() + d[k + 1].norm() + dp[k + 1].norm();
        prop_assert!(
            (fd - d[k + 1]).norm() < FD_TOL * scale,
            "order {} at u={u}: fd {fd:?} vs {:?}",
            k + 1,
            d[k + 1]
        );
    }
    Ok(())
}

proptest! {
    #[test]
    fn curve3_derivatives_match_finite_differences(c in curve3(false), t in 0.0f64..1.0) {
        check_curve_fd(&c, t)?;
    }

    #[test]
    fn rational_curve3_derivatives_match_finite_differences(c in curve3(true), t in 0.0f64..1.0) {
        check_curve_fd(&c, t)?;
    }

    #[test]
    fn rational_curve2_derivatives_match_finite_differences(c in curve2(true), t in 0.0f64..1.0) {
        check_curve_fd(&c, t)?;
    }

    #[test]
    fn surface_derivatives_match_finite_differences(
        s in surface(false), t in 0.0f64..1.0, r in 0.0f64..1.0
    ) {
        check_surface_fd(&s, t, r)?;
    }

    #[test]
    fn rational_surface_derivatives_match_finite_differences(
        s in surface(true), t in 0.0f64..1.0, r in 0.0f64..1.0
    ) {
        check_surface_fd(&s, t, r)?;
    }
}

fn check_surface_fd(s: &NurbsSurface, t: f64, r: f64) -> Result<(), TestCaseError> {
    let ((u0, u1), (v0, v1)) = s.domain();
    let u = u0 + 2.0 * H + (u1 - u0 - 4.0 * H) * t;
    let v = v0 + 2.0 * H + (v1 - v0 - 4.0 * H) * r;
    prop_assume!(same_span(s.knots_u(), u) && same_span(s.knots_v(), v));
    let d = s.derivs2(u, v);
    let full = s.derivs(u, v, 3);
    let scale = 1.0 + d.p.norm();
    prop_assert!((d.p - s.point(u, v)).norm() < 1e-12 * scale);
    for (a, b) in [
        (d.p, full[0][0]),
        (d.su, full[1][0]),
        (d.sv, full[0][1]),
        (d.suu, full[2][0]),
        (d.suv, full[1][1]),
        (d.svv, full[0][2]),
    ] {
        prop_assert!((a - b).norm() < 1e-11 * (1.0 + b.norm()), "{a:?} vs {b:?}");
    }
    let du_m = s.derivs(u - H, v, 3);
    let du_p = s.derivs(u + H, v, 3);
    let dv_m = s.derivs(u, v - H, 3);
    let dv_p = s.derivs(u, v + H, 3);
    for k in 0..3 {
        for l in 0..(3 - k) {
            let fdu = (du_p[k][l] - du_m[k][l]) / (2.0 * H);
            let sc = 1.0 + full[k][l].norm() + full[k + 1][l].norm() + du_p[k + 1][l].norm();
            prop_assert!(
                (fdu - full[k + 1][l]).norm() < FD_TOL * sc,
                "u order ({},{l})",
                k + 1
            );
            let fdv = (dv_p[k][l] - dv_m[k][l]) / (2.0 * H);
            let sc = 1.0 + full[k][l].norm() + full[k][l + 1].norm() + dv_p[k][l + 1].norm();
            prop_assert!(
                (fdv - full[k][l + 1]).norm() < FD_TOL * sc,
                "v order ({k},{})",
                l + 1
            );
        }
    }
    if let Some(n) = d.normal() {
        prop_assert!((n.norm() - 1.0).abs() < 1e-12);
        prop_assert!(n.dot(&d.su).abs() < 1e-9 * (1.0 + d.su.norm()));
        prop_assert!(n.dot(&d.sv).abs() < 1e-9 * (1.0 + d.sv.norm()));
    }
    Ok(())
}

#[test]
fn rational_quarter_circle_has_unit_radius() {
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let c = NurbsCurve::<2>::new(
        2,
        vec![0., 0., 0., 1., 1., 1.],
        vec![
            Vector2::new(1., 0.),
            Vector2::new(1., 1.),
            Vector2::new(0., 1.),
        ],
        Some(vec![1., w, 1.]),
    )
    .unwrap();
    for k in 0..=1000 {
        let u = k as f64 / 1000.0;
        let p = c.point(u);
        assert!((p.norm() - 1.0).abs() <= 1e-14, "u={u} r={}", p.norm());
        // tangent is perpendicular to the radius
        let d = c.derivs(u, 1);
        assert!(d[1].dot(&d[0]).abs() < 1e-13 * d[1].norm());
    }
    assert!((c.point(0.0) - Vector2::new(1.0, 0.0)).norm() < 1e-15);
    assert!((c.point(1.0) - Vector2::new(0.0, 1.0)).norm() < 1e-15);
}

#[test]
fn evaluation_clamps_out_of_domain_parameters() {
    let c = NurbsCurve::<3>::new(
        1,
        vec![0., 0., 1., 1.],
        vec![Vector3::new(0., 0., 0.), Vector3::new(1., 2., 3.)],
        None,
    )
    .unwrap();
    assert_eq!(c.point(-5.0), c.point(0.0));
    assert_eq!(c.point(7.0), Vector3::new(1., 2., 3.));
    assert_eq!(ParametricCurve::point(&c, 0.5), Vector3::new(0.5, 1.0, 1.5));
    assert_eq!(ParametricCurve::domain(&c), (0.0, 1.0));
    assert_eq!(
        ParametricCurve::derivs(&c, 0.5, 1)[1],
        Vector3::new(1., 2., 3.)
    );
}

#[test]
fn bilinear_patch_values_and_normal() {
    let s = NurbsSurface::new(
        1,
        1,
        vec![0., 0., 1., 1.],
        vec![0., 0., 1., 1.],
        vec![
            vec![Vector3::new(0., 0., 0.), Vector3::new(0., 1., 0.)],
            vec![Vector3::new(1., 0., 0.), Vector3::new(1., 1., 1.)],
        ],
        None,
    )
    .unwrap();
    // S(u,v) = (u, v, u v)
    let d = s.derivs2(0.25, 0.5);
    assert!((d.p - Vector3::new(0.25, 0.5, 0.125)).norm() < 1e-15);
    assert!((d.su - Vector3::new(1.0, 0.0, 0.5)).norm() < 1e-15);
    assert!((d.sv - Vector3::new(0.0, 1.0, 0.25)).norm() < 1e-15);
    assert!((d.suv - Vector3::new(0.0, 0.0, 1.0)).norm() < 1e-15);
    assert_eq!(d.suu, Vector3::zeros());
    assert_eq!(d.svv, Vector3::zeros());
    let n = s.normal(0.25, 0.5).unwrap();
    let expected = Vector3::new(-0.5, -0.25, 1.0).normalize();
    assert!((n - expected).norm() < 1e-15);
    assert_eq!(ParametricSurface::normal(&s, 0.25, 0.5), Some(n));
    assert_eq!(ParametricSurface::point(&s, 0.25, 0.5), d.p);
    assert_eq!(ParametricSurface::derivs2(&s, 0.25, 0.5), d);
    assert_eq!(ParametricSurface::domain(&s), ((0.0, 1.0), (0.0, 1.0)));
    assert_eq!(s.control_point(1, 1), Vector3::new(1., 1., 1.));
    assert_eq!(s.weight(1, 1), 1.0);
}

#[test]
fn degenerate_normal_is_none() {
    // all control points in one row coincide: su = 0 along u = 0
    let s = NurbsSurface::new(
        1,
        1,
        vec![0., 0., 1., 1.],
        vec![0., 0., 1., 1.],
        vec![
            vec![Vector3::new(0., 0., 0.), Vector3::new(0., 0., 0.)],
            vec![Vector3::new(1., 0., 0.), Vector3::new(1., 1., 0.)],
        ],
        None,
    )
    .unwrap();
    assert_eq!(s.normal(0.0, 0.5), None);
    assert!(s.normal(0.5, 0.5).is_some());
}

proptest! {
    /// The degree-specialised kernels (degrees 1–3) agree with the general A2.3/A3.6 path
    /// at the domain corners and exactly on knots, where span selection matters.
    #[test]
    fn fast_kernels_agree_with_general_path_on_knots(s in surface(true), iu in 0usize..20, iv in 0usize..20) {
        let ku = s.knots_u().knots();
        let kv = s.knots_v().knots();
        let u = ku[iu % ku.len()];
        let v = kv[iv % kv.len()];
        let d = s.derivs2(u, v);
        let full = s.derivs(u, v, 2);
        for (a, b) in [(d.p, full[0][0]), (d.su, full[1][0]), (d.sv, full[0][1]),
                       (d.suu, full[2][0]), (d.suv, full[1][1]), (d.svv, full[0][2])] {
            prop_assert!((a - b).norm() <= 1e-11 * (1.0 + b.norm()), "{:?} vs {:?}", a, b);
        }
        prop_assert!((s.point(u, v) - full[0][0]).norm() <= 1e-12 * (1.0 + full[0][0].norm()));
    }

    #[test]
    fn fast_curve_point_agrees_with_derivs_on_knots(c in curve3(true), i in 0usize..30) {
        let k = c.knots().knots();
        let u = k[i % k.len()];
        let d = c.derivs(u, 2);
        prop_assert!((c.point(u) - d[0]).norm() <= 1e-12 * (1.0 + d[0].norm()));
        let d2 = c.derivs2(u);
        for k in 0..3 {
            prop_assert!((d2[k] - d[k]).norm() <= 1e-11 * (1.0 + d[k].norm()), "order {}", k);
        }
    }
}
