//! Constructors and derived geometry: exact circle arcs (A7.1), surfaces of revolution
//! (A8.1), ruled surfaces, principal curvatures, iso-parametric curves, rigid motions.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod core_support;

use std::f64::consts::{FRAC_PI_2, PI};

use core_support::{curve3, surface, surface_scale};
use nalgebra::{Isometry3, Vector2, Vector3};
use nurbs::{NurbsCurve, NurbsError, NurbsSurface};
use proptest::prelude::*;

#[test]
fn quarter_circle_arc_radius_within_1e_14() {
    let c = NurbsCurve::<2>::circle_arc(
        Vector2::zeros(),
        Vector2::x(),
        Vector2::y(),
        1.0,
        0.0,
        FRAC_PI_2,
    )
    .unwrap();
    assert_eq!(c.control_points().len(), 3);
    for k in 0..=1000 {
        let p = c.point(k as f64 / 1000.0);
        assert!((p.norm() - 1.0).abs() <= 1e-14, "{}", p.norm());
    }
    assert!((c.point(1.0) - Vector2::new(0.0, 1.0)).norm() < 1e-15);
}

#[test]
fn full_circle_segments_and_errors() {
    let c = NurbsCurve::<3>::circle_arc(
        Vector3::zeros(),
        Vector3::x(),
        Vector3::y(),
        2.0,
        0.0,
        2.0 * PI,
    )
    .unwrap();
    assert_eq!(c.control_points().len(), 9);
    assert_eq!(
        c.knots().knots(),
        &[0., 0., 0., 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1., 1., 1.]
    );
    assert!((c.point(0.0) - c.point(1.0)).norm() < 1e-14);
    for bad in [
        NurbsCurve::<2>::circle_arc(Vector2::zeros(), Vector2::x(), Vector2::y(), 0.0, 0.0, 1.0),
        NurbsCurve::<2>::circle_arc(Vector2::zeros(), Vector2::x(), Vector2::y(), 1.0, 1.0, 1.0),
        NurbsCurve::<2>::circle_arc(Vector2::zeros(), Vector2::x(), Vector2::y(), 1.0, 0.0, 7.0),
        NurbsCurve::<2>::circle_arc(
            Vector2::zeros(),
            Vector2::x(),
            Vector2::y(),
            1.0,
            0.0,
            f64::NAN,
        ),
        NurbsCurve::<2>::circle_arc(
            Vector2::zeros(),
            Vector2::zeros(),
            Vector2::y(),
            1.0,
            0.0,
            1.0,
        ),
        NurbsCurve::<2>::circle_arc(
            Vector2::zeros(),
            Vector2::x(),
            Vector2::x() * 3.0,
            1.0,
            0.0,
            1.0,
        ),
    ] {
        assert!(
            matches!(bad, Err(NurbsError::InvalidGeometry(_))),
            "{bad:?}"
        );
    }
}

proptest! {
    #[test]
    fn circle_arcs_are_exact(
        start in -7.0f64..7.0, sweep in 0.01f64..=(2.0 * PI), r in 0.1f64..100.0,
        cx in -50.0f64..50.0, cy in -50.0f64..50.0, cz in -50.0f64..50.0, skew in -0.9f64..0.9
    ) {
        let center = Vector3::new(cx, cy, cz);
        let x = Vector3::new(1.0, 2.0, -1.0);
        let y = Vector3::new(0.5, -1.0, 3.0) + x * skew; // non-orthogonal input
        let c = NurbsCurve::<3>::circle_arc(center, x, y, r, start, start + sweep).unwrap();
        let n = x.cross(&y).normalize();
        let tol = 1e-13 * (r + center.norm());
        for k in 0..=64 {
            let p = c.point(k as f64 / 64.0);
            prop_assert!(((p - center).norm() - r).abs() <= tol);
            prop_assert!((p - center).dot(&n).abs() <= tol);
        }
        let xh = x.normalize();
        let yh = n.cross(&xh);
        let expect = |a: f64| center + xh * (r * a.cos()) + yh * (r * a.sin());
        prop_assert!((c.point(0.0) - expect(start)).norm() <= tol);
        prop_assert!((c.point(1.0) - expect(start + sweep)).norm() <= tol);
    }

    #[test]
    fn revolution_radius_matches_profile(
        profile in curve3(true), angle in prop_oneof![Just(2.0 * PI), -6.0f64..-0.1, 0.1f64..6.0],
        ax in -1.0f64..1.0, ay in -1.0f64..1.0, t in 0.0f64..1.0, s in 0.0f64..1.0
    ) {
        let axis_point = Vector3::new(3.0, -2.0, 1.0);
        let axis_dir = Vector3::new(ax, ay, 1.0);
        let sfc = NurbsSurface::revolution(&profile, axis_point, axis_dir, angle).unwrap();
        let tdir = axis_dir.normalize();
        let (v0, v1) = profile.domain();
        prop_assert_eq!(sfc.domain().1, (v0, v1));
        let scale = surface_scale(&sfc);
        let v = v0 + (v1 - v0) * s;
        let c = profile.point(v);
        let rel = c - axis_point;
        let radius = (rel - tdir * rel.dot(&tdir)).norm();
        for k in 0..=16 {
            let u = (k as f64 / 16.0 + t / 16.0).min(1.0);
            let p = sfc.point(u, v) - axis_point;
            let r = (p - tdir * p.dot(&tdir)).norm();
            prop_assert!((r - radius).abs() <= 1e-12 * scale, "r {} vs {}", r, radius);
            prop_assert!((p.dot(&tdir) - rel.dot(&tdir)).abs() <= 1e-12 * scale);
        }
        prop_assert!((sfc.point(0.0, v) - c).norm() <= 1e-12 * scale);
        // the end section is the profile turned by `angle`
        let rot = nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis_dir), angle);
        let turned = axis_point + rot * rel;
        prop_assert!((sfc.point(1.0, v) - turned).norm() <= 1e-12 * scale);
    }

    #[test]
    fn ruled_surface_spans_both_curves(a in curve3(false), b in curve3(true), t in 0.0f64..1.0, s in 0.0f64..1.0) {
        let sfc = NurbsSurface::ruled(&a, &b).unwrap();
        prop_assert_eq!(sfc.degree_u(), a.degree().max(b.degree()));
        prop_assert_eq!(sfc.domain(), ((0.0, 1.0), (0.0, 1.0)));
        let (a0, a1) = a.domain();
        let (b0, b1) = b.domain();
        let scale = surface_scale(&sfc);
        let pa = a.point(a0 + (a1 - a0) * t);
        let pb = b.point(b0 + (b1 - b0) * t);
        prop_assert!((sfc.point(t, 0.0) - pa).norm() <= 1e-12 * scale);
        prop_assert!((sfc.point(t, 1.0) - pb).norm() <= 1e-12 * scale);
        // straight ruling: S(t, s) on the segment pa–pb
        let q = sfc.point(t, s);
        let d = pb - pa;
        if d.norm() > 1e-6 {
            let off = (q - pa).cross(&d).norm() / d.norm();
            prop_assert!(off <= 1e-10 * scale, "off-ruling {}", off);
        }
    }

    #[test]
    fn curvature_matches_fundamental_form_invariants(s in surface(true), t in 0.0f64..1.0, r in 0.0f64..1.0) {
        let ((u0, u1), (v0, v1)) = s.domain();
        let d = s.derivs2(u0 + (u1 - u0) * t, v0 + (v1 - v0) * r);
        let Some(pc) = d.principal_curvatures() else { return Ok(()) };
        let n = pc.normal;
        let (e, f, g) = (d.su.dot(&d.su), d.su.dot(&d.sv), d.sv.dot(&d.sv));
        let (l, m, nn) = (d.suu.dot(&n), d.suv.dot(&n), d.svv.dot(&n));
        let det = e * g - f * f;
        prop_assume!(det > 1e-6 * e * g);
        let k = (l * nn - m * m) / det;
        let h = (e * nn - 2.0 * f * m + g * l) / (2.0 * det);
        let scale = 1.0 + pc.k1.abs() + pc.k2.abs();
        prop_assert!((pc.mean() - h).abs() <= 1e-8 * scale);
        prop_assert!((pc.gaussian() - k).abs() <= 1e-8 * scale * scale);
        prop_assert!(pc.k1 >= pc.k2);
        prop_assert!(pc.dir1.dot(&pc.dir2).abs() < 1e-12);
        prop_assert!(pc.dir1.dot(&n).abs() < 1e-12 && pc.dir2.dot(&n).abs() < 1e-12);
        // Euler: the normal curvature along dir1 is k1. Write dir1 = a su + b sv.
        let a = (pc.dir1.dot(&d.su) * g - pc.dir1.dot(&d.sv) * f) / det;
        let b = (pc.dir1.dot(&d.sv) * e - pc.dir1.dot(&d.su) * f) / det;
        let kn = (l * a * a + 2.0 * m * a * b + nn * b * b) / (e * a * a + 2.0 * f * a * b + g * b * b);
        prop_assert!((kn - pc.k1).abs() <= 1e-7 * scale, "kn {} k1 {}", kn, pc.k1);
    }

    #[test]
    fn iso_curves_lie_on_surface(s in surface(true), t in 0.0f64..1.0, r in 0.0f64..1.0) {
        let ((u0, u1), (v0, v1)) = s.domain();
        let (u, v) = (u0 + (u1 - u0) * t, v0 + (v1 - v0) * r);
        let cu = s.iso_curve_at_u(u).unwrap();
        let cv = s.iso_curve_at_v(v).unwrap();
        prop_assert_eq!(cu.domain(), (v0, v1));
        prop_assert_eq!(cv.domain(), (u0, u1));
        let scale = surface_scale(&s);
        for k in 0..=10 {
            let a = k as f64 / 10.0;
            let vv = v0 + (v1 - v0) * a;
            let uu = u0 + (u1 - u0) * a;
            prop_assert!((cu.point(vv) - s.point(u, vv)).norm() <= 1e-12 * scale);
            prop_assert!((cv.point(uu) - s.point(uu, v)).norm() <= 1e-12 * scale);
        }
    }
}

#[test]
fn cylinder_and_sphere_curvatures() {
    let r = 5.0;
    // cylinder: revolve the line x = r about Z
    let line = NurbsCurve::<3>::new(
        1,
        vec![0., 0., 1., 1.],
        vec![Vector3::new(r, 0., 0.), Vector3::new(r, 0., 10.)],
        None,
    )
    .unwrap();
    let cyl = NurbsSurface::revolution(&line, Vector3::zeros(), Vector3::z(), 2.0 * PI).unwrap();
    for (u, v) in [(0.1, 0.3), (0.55, 0.9), (0.8, 0.0)] {
        let pc = cyl.principal_curvatures(u, v).unwrap();
        let ks = [pc.k1, pc.k2];
        assert!(ks.iter().any(|k| k.abs() < 1e-12), "{ks:?}");
        assert!(
            ks.iter().any(|k| (k.abs() - 1.0 / r).abs() < 1e-12),
            "{ks:?}"
        );
        // the zero-curvature direction is the axis
        let flat_dir = if pc.k1.abs() < 1e-12 {
            pc.dir1
        } else {
            pc.dir2
        };
        assert!((flat_dir.z.abs() - 1.0).abs() < 1e-12);
        assert!((cyl.point(u, v).xy().norm() - r).abs() < 1e-12);
    }
    // sphere: revolve a half circle in the xz plane about Z
    let half = NurbsCurve::<3>::circle_arc(
        Vector3::zeros(),
        Vector3::x(),
        Vector3::z(),
        r,
        -FRAC_PI_2,
        FRAC_PI_2,
    )
    .unwrap();
    let sph = NurbsSurface::revolution(&half, Vector3::zeros(), Vector3::z(), 2.0 * PI).unwrap();
    for (u, v) in [(0.1, 0.3), (0.55, 0.6), (0.9, 0.45)] {
        assert!((sph.point(u, v).norm() - r).abs() < 1e-12);
        let pc = sph.principal_curvatures(u, v).unwrap();
        assert!(
            (pc.k1.abs() - 1.0 / r).abs() < 1e-12 && (pc.k2 - pc.k1).abs() < 1e-12,
            "{pc:?}"
        );
        assert!((pc.gaussian() - 1.0 / (r * r)).abs() < 1e-12);
        // sign convention: positive toward the normal
        let p = sph.point(u, v);
        let outward = pc.normal.dot(&p) > 0.0;
        assert_eq!(pc.mean() < 0.0, outward);
    }
    // the poles are singular: no normal, no curvature
    assert!(sph.principal_curvatures(0.3, 0.0).is_none());
}

#[test]
fn revolution_errors() {
    let line = NurbsCurve::<3>::new(
        1,
        vec![0., 0., 1., 1.],
        vec![Vector3::x(), Vector3::new(1., 0., 1.)],
        None,
    )
    .unwrap();
    for (dir, angle) in [
        (Vector3::zeros(), PI),
        (Vector3::z(), 0.0),
        (Vector3::z(), 7.0),
        (Vector3::new(f64::NAN, 0., 1.), 1.0),
    ] {
        assert!(matches!(
            NurbsSurface::revolution(&line, Vector3::zeros(), dir, angle),
            Err(NurbsError::InvalidGeometry(_))
        ));
    }
}

#[test]
fn rigid_motions_and_blade_copies() {
    let blade = NurbsSurface::ruled(
        &NurbsCurve::<3>::circle_arc(
            Vector3::new(0., 0., 0.),
            Vector3::x(),
            Vector3::y(),
            40.0,
            0.1,
            0.9,
        )
        .unwrap(),
        &NurbsCurve::<3>::new(
            2,
            vec![0., 0., 0., 1., 1., 1.],
            vec![
                Vector3::new(60., 0., 20.),
                Vector3::new(55., 20., 25.),
                Vector3::new(45., 40., 30.),
            ],
            None,
        )
        .unwrap(),
    )
    .unwrap();
    let n = 7;
    for k in 0..n {
        let ang = 2.0 * PI * k as f64 / n as f64;
        let copy = blade.rotated_about_z(ang);
        let rot = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), ang);
        for (u, v) in [(0.0, 0.0), (0.3, 0.7), (1.0, 0.5)] {
            assert!((copy.point(u, v) - rot * blade.point(u, v)).norm() < 1e-12);
        }
    }
    let iso = Isometry3::new(Vector3::new(1., 2., 3.), Vector3::new(0.1, -0.2, 0.3));
    let moved = blade.transformed(&iso);
    assert!(
        (moved.point(0.4, 0.2) - iso.transform_point(&blade.point(0.4, 0.2).into()).coords).norm()
            < 1e-12
    );
    let c = blade.iso_curve_at_v(0.0).unwrap();
    let cm = c.transformed(&iso);
    assert!((cm.point(0.5) - iso.transform_point(&c.point(0.5).into()).coords).norm() < 1e-12);
    let cr = c.rotated_about_z(PI);
    assert!(
        (cr.point(0.5) + Vector3::new(c.point(0.5).x, c.point(0.5).y, -c.point(0.5).z)).norm()
            < 1e-12
    );
}
