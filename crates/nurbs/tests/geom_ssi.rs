//! Surface–surface intersection and curve offset on a surface against closed-form answers.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::Vector3;
use nurbs::surface_intersect::{
    intersect_surfaces, offset_curve_on_surface, BranchEnd, Intersection, ParamBox, SsiOptions,
};
use nurbs::{NurbsCurve, NurbsSurface};
use std::f64::consts::{PI, TAU};

fn line(a: Vector3<f64>, b: Vector3<f64>) -> NurbsCurve<3> {
    NurbsCurve::new(1, vec![0., 0., 1., 1.], vec![a, b], None).unwrap()
}

/// Cylinder of radius `r` about the axis through `c` along `axis`, seam at `seam` (a unit
/// vector ⟂ axis), length 2·half about `c`.
fn cylinder(
    c: Vector3<f64>,
    axis: Vector3<f64>,
    seam: Vector3<f64>,
    r: f64,
    half: f64,
) -> NurbsSurface {
    let p = c + seam * r;
    NurbsSurface::revolution(&line(p - axis * half, p + axis * half), c, axis, TAU).unwrap()
}

fn plane(o: Vector3<f64>, e1: Vector3<f64>, e2: Vector3<f64>) -> NurbsSurface {
    NurbsSurface::new(
        1,
        1,
        vec![0., 0., 1., 1.],
        vec![0., 0., 1., 1.],
        vec![vec![o, o + e2], vec![o + e1, o + e1 + e2]],
        None,
    )
    .unwrap()
}

fn whole(a: &NurbsSurface, b: &NurbsSurface, o: &SsiOptions) -> Intersection {
    intersect_surfaces(a, ParamBox::of(a), b, ParamBox::of(b), o).unwrap()
}

fn dist_to_branches(p: &Vector3<f64>, x: &Intersection) -> f64 {
    let mut best = f64::INFINITY;
    for br in &x.branches {
        for w in br.points.windows(2) {
            let (s, e) = (w[0].point, w[1].point);
            let d = e - s;
            let f = ((p - s).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
            best = best.min((p - (s + d * f)).norm());
        }
    }
    best
}

/// Every point on both surfaces to `point_tol`, and the fitted curves on both implicit
/// surfaces within `fit_tol + chord_tol` at 50 samples per branch.
fn check_on_both(
    x: &Intersection,
    o: &SsiOptions,
    fa: impl Fn(&Vector3<f64>) -> f64,
    fb: impl Fn(&Vector3<f64>) -> f64,
) {
    for br in &x.branches {
        for p in &br.points {
            assert!(p.residual <= o.point_tol, "residual {}", p.residual);
            assert!(fa(&p.point).abs() < 1e-8, "{} off a", p.point);
            assert!(fb(&p.point).abs() < 1e-8, "{} off b", p.point);
        }
        for k in 0..=50 {
            let q = br.curve.point(k as f64 / 50.0);
            let tol = o.fit_tol + o.chord_tol;
            assert!(fa(&q).abs() < tol && fb(&q).abs() < tol, "curve {q}");
        }
    }
}

#[test]
fn perpendicular_cylinders_give_two_loops() {
    let o = SsiOptions {
        max_step: 0.5,
        seed_size: 1.0,
        ..Default::default()
    };
    // A: x² + y² = 25 (axis z, seam at −y); B: y² + z² = 9 (axis x, seam at +y).
    let a = cylinder(Vector3::zeros(), Vector3::z(), -Vector3::y(), 5.0, 10.0);
    let b = cylinder(Vector3::zeros(), Vector3::x(), Vector3::y(), 3.0, 10.0);
    let x = whole(&a, &b, &o);
    check_on_both(&x, &o, |p| p.x.hypot(p.y) - 5.0, |p| p.y.hypot(p.z) - 3.0);
    // Coverage: the closed-form curves x = ±√(25 − 9 sin² s), y = 3 sin s, z = 3 cos s.
    for sign in [1.0, -1.0] {
        for k in 0..200 {
            let s = TAU * k as f64 / 200.0;
            let y = 3.0 * s.sin();
            let p = Vector3::new(sign * (25.0 - y * y).sqrt(), y, 3.0 * s.cos());
            let d = dist_to_branches(&p, &x);
            assert!(d < 2.0 * o.chord_tol, "{p} missed by {d}");
        }
    }
    // Both loops, each split at most at the seams.
    assert!(
        x.branches.len() >= 2 && x.branches.len() <= 6,
        "{}",
        x.branches.len()
    );
}

#[test]
fn plane_and_sphere_give_a_circle() {
    let o = SsiOptions::default();
    // Sphere of radius 5: a half circle in the xz plane revolved about z.
    let half = NurbsCurve::circle_arc(
        Vector3::zeros(),
        Vector3::z(),
        Vector3::x(),
        5.0,
        -PI / 2.0,
        PI / 2.0,
    )
    .unwrap();
    let sphere = NurbsSurface::revolution(&half, Vector3::zeros(), Vector3::z(), TAU).unwrap();
    let pl = plane(
        Vector3::new(-8., -8., 3.),
        Vector3::new(16., 0., 0.),
        Vector3::new(0., 16., 0.),
    );
    let x = whole(&sphere, &pl, &o);
    check_on_both(&x, &o, |p| p.norm() - 5.0, |p| p.z - 3.0);
    // The circle of radius 4 at z = 3, fully covered (one closed loop, or pieces ending at
    // the sphere's seam).
    for k in 0..360 {
        let t = TAU * k as f64 / 360.0;
        let p = Vector3::new(4.0 * t.cos(), 4.0 * t.sin(), 3.0);
        assert!(dist_to_branches(&p, &x) < 2.0 * o.chord_tol);
    }
    let total: usize = x.branches.len();
    assert!((1..=2).contains(&total), "{total} branches");
    for br in &x.branches {
        assert!(br.is_closed() || br.ends.iter().all(|e| *e == BranchEnd::Boundary));
    }
}

#[test]
fn tangent_cylinders_touch_along_a_line() {
    let o = SsiOptions {
        point_tol: 1e-10,
        ..Default::default()
    };
    // A: x² + y² = 4 (seam at −x); B: (x − 5)² + y² = 9 (seam at +x). They touch along
    // x = 2, y = 0.
    let a = cylinder(Vector3::zeros(), Vector3::z(), -Vector3::x(), 2.0, 5.0);
    let b = cylinder(
        Vector3::new(5., 0., 0.),
        Vector3::z(),
        Vector3::x(),
        3.0,
        5.0,
    );
    let x = whole(&a, &b, &o);
    assert_eq!(x.branches.len(), 1, "{:?}", x.branches.len());
    let br = &x.branches[0];
    // Residual 1e-10 with curvatures 1/2 + 1/3 puts the points within √(2·1e-10/0.83) ≈ 2e-5
    // of the line.
    let mut zmin = f64::INFINITY;
    let mut zmax = f64::NEG_INFINITY;
    for p in &br.points {
        assert!(p.tangential);
        assert!(
            (p.point.x - 2.0).abs() < 3e-5 && p.point.y.abs() < 3e-5,
            "{}",
            p.point
        );
        zmin = zmin.min(p.point.z);
        zmax = zmax.max(p.point.z);
    }
    assert!(zmin < -5.0 + 1e-6 && zmax > 5.0 - 1e-6, "{zmin} {zmax}");
}

#[test]
fn cylinder_and_plane_give_two_separate_lines() {
    let o = SsiOptions::default();
    let a = cylinder(Vector3::zeros(), Vector3::z(), -Vector3::x(), 5.0, 10.0);
    // Plane x = 3.
    let pl = plane(
        Vector3::new(3., -8., -12.),
        Vector3::new(0., 16., 0.),
        Vector3::new(0., 0., 24.),
    );
    let x = whole(&a, &pl, &o);
    assert_eq!(x.branches.len(), 2);
    let mut ys: Vec<f64> = Vec::new();
    for br in &x.branches {
        assert_eq!(br.ends, [BranchEnd::Boundary, BranchEnd::Boundary]);
        let y = br.points[0].point.y;
        for p in &br.points {
            assert!((p.point.x - 3.0).abs() < 1e-9 && (p.point.y - y).abs() < 1e-9);
        }
        let zs: Vec<f64> = br.points.iter().map(|p| p.point.z).collect();
        let span = zs.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
            - zs.iter().cloned().fold(f64::INFINITY, f64::min);
        assert!((span - 20.0).abs() < 1e-9, "{span}");
        ys.push(y);
    }
    ys.sort_by(f64::total_cmp);
    assert!(
        (ys[0] + 4.0).abs() < 1e-9 && (ys[1] - 4.0).abs() < 1e-9,
        "{ys:?}"
    );
}

#[test]
fn boxes_restrict_the_result() {
    let o = SsiOptions::default();
    let a = cylinder(Vector3::zeros(), Vector3::z(), -Vector3::x(), 5.0, 10.0);
    let pl = plane(
        Vector3::new(3., -8., -12.),
        Vector3::new(0., 16., 0.),
        Vector3::new(0., 0., 24.),
    );
    // Only y > 0 of the plane (v along 24 mm in z, u along y from −8).
    let bx = ParamBox {
        u: (0.5, 1.0),
        v: (0.0, 1.0),
    };
    let x = intersect_surfaces(&a, ParamBox::of(&a), &pl, bx, &o).unwrap();
    assert_eq!(x.branches.len(), 1);
    assert!(x.branches[0]
        .points
        .iter()
        .all(|p| (p.point.y - 4.0).abs() < 1e-9));
}

#[test]
fn disjoint_surfaces_have_no_intersection_and_bad_boxes_are_errors() {
    let o = SsiOptions::default();
    let a = cylinder(Vector3::zeros(), Vector3::z(), -Vector3::x(), 5.0, 10.0);
    let pl = plane(
        Vector3::new(6., -8., -12.),
        Vector3::new(0., 16., 0.),
        Vector3::new(0., 0., 24.),
    );
    let x = whole(&a, &pl, &o);
    assert!(x.branches.is_empty() && x.touch_points.is_empty());
    let bad = ParamBox {
        u: (0.5, 0.2),
        v: (0.0, 1.0),
    };
    assert!(intersect_surfaces(&a, bad, &pl, ParamBox::of(&pl), &o).is_err());
}

#[test]
fn offset_of_a_parallel_on_a_cylinder() {
    // The circle z = 0 on the cylinder of radius 5, offset by 2 within the surface: the
    // circle z = ±2 (a cylinder's geodesic offset of a parallel is exact).
    let a = cylinder(Vector3::zeros(), Vector3::z(), -Vector3::x(), 5.0, 10.0);
    // u around, v along z ∈ [−10, 10]; z = 0 at v = 0.5.
    let uv: Vec<[f64; 2]> = (0..=40).map(|k| [0.05 + 0.02 * k as f64, 0.5]).collect();
    let off = offset_curve_on_surface(&a, &uv, 2.0, 1e-6).unwrap();
    let z0 = off.points[0].z;
    assert!((z0.abs() - 2.0).abs() < 1e-9, "{z0}");
    for p in &off.points {
        assert!((p.z - z0).abs() < 1e-9 && (p.xy().norm() - 5.0).abs() < 1e-9);
    }
    for k in 0..=20 {
        let q = off.curve.point(k as f64 / 20.0);
        assert!((q.z - z0).abs() < 1e-5 && (q.xy().norm() - 5.0).abs() < 1e-5);
    }
    let back = offset_curve_on_surface(&a, &uv, -2.0, 1e-6).unwrap();
    assert!((back.points[0].z + z0).abs() < 1e-9);
}
