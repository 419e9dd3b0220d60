//! Knot insertion, refinement, splitting, degree elevation, Bézier decomposition, clamping,
//! reversal and reparametrisation: The NURBS Book example 5.1 and shape-preservation
//! properties (1e-12 relative to the control-net size).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod core_support;

use core_support::{
    curve2, curve3, curve_distance, curve_scale, surface, surface_distance, surface_scale,
};
use nalgebra::{Vector2, Vector3};
use nurbs::{Direction, NurbsCurve, NurbsError, NurbsSurface, MAX_DEGREE};
use proptest::prelude::*;

const REL: f64 = 1e-12;

#[test]
fn nurbs_book_ex5_1_single_insertion() {
    // p = 3, U = {0,0,0,0,1,2,3,4,5,5,5,5}, insert u = 5/2 once (k = 5)
    let pts: Vec<Vector2<f64>> = (0..8)
        .map(|i| Vector2::new(i as f64, (i * i) as f64))
        .collect();
    let c = NurbsCurve::<2>::new(
        3,
        vec![0., 0., 0., 0., 1., 2., 3., 4., 5., 5., 5., 5.],
        pts.clone(),
        None,
    )
    .unwrap();
    let q = c.insert_knot(2.5, 1).unwrap();
    assert_eq!(
        q.knots().knots(),
        &[0., 0., 0., 0., 1., 2., 2.5, 3., 4., 5., 5., 5., 5.]
    );
    let qp = q.control_points();
    assert_eq!(qp.len(), 9);
    let expect = [
        pts[0],
        pts[1],
        pts[2],
        pts[3] * (5.0 / 6.0) + pts[2] * (1.0 / 6.0),
        pts[4] * 0.5 + pts[3] * 0.5,
        pts[5] * (1.0 / 6.0) + pts[4] * (5.0 / 6.0),
        pts[5],
        pts[6],
        pts[7],
    ];
    for (a, b) in qp.iter().zip(expect) {
        assert!((a - b).norm() < 1e-14, "{a:?} vs {b:?}");
    }
}

#[test]
fn insertion_errors() {
    let c = NurbsCurve::<2>::new(
        2,
        vec![0., 0., 0., 0.5, 0.5, 1., 1., 1.],
        (0..5).map(|i| Vector2::new(i as f64, 0.0)).collect(),
        None,
    )
    .unwrap();
    assert_eq!(
        c.insert_knot(0.5, 1).unwrap_err(),
        NurbsError::InsertionExceedsMultiplicity {
            value: 0.5,
            times: 1,
            multiplicity: 2,
            degree: 2
        }
    );
    assert!(matches!(
        c.insert_knot(1.0, 1),
        Err(NurbsError::ParameterOutOfDomain { value: 1.0, .. })
    ));
    assert!(matches!(
        c.refine_knots(&[0.2, f64::NAN]),
        Err(NurbsError::ParameterOutOfDomain { .. })
    ));
    assert!(matches!(
        c.split(0.0),
        Err(NurbsError::ParameterOutOfDomain { .. })
    ));
    assert!(matches!(
        c.reparametrize(1.0, 1.0),
        Err(NurbsError::EmptyDomain { .. })
    ));
    assert!(matches!(
        c.elevate_degree(MAX_DEGREE),
        Err(NurbsError::DegreeOutOfRange { .. })
    ));
    // splitting at a knot of full multiplicity needs no insertion
    let (l, r) = c.split(0.5).unwrap();
    assert_eq!(l.domain(), (0.0, 0.5));
    assert_eq!(r.domain(), (0.5, 1.0));
}

#[test]
fn unclamped_curve_is_clamped_exactly() {
    // uniform (unclamped) cubic
    let knots: Vec<f64> = (0..11).map(|i| i as f64).collect();
    let pts: Vec<Vector3<f64>> = (0..7)
        .map(|i| Vector3::new(i as f64, (i as f64).sin(), 0.3 * i as f64))
        .collect();
    let c =
        NurbsCurve::<3>::new(3, knots, pts, Some(vec![1.0, 2.0, 0.5, 1.0, 1.5, 0.7, 1.0])).unwrap();
    assert!(!c.knots().is_clamped());
    let cc = c.clamped().unwrap();
    assert!(cc.knots().is_clamped());
    assert_eq!(cc.domain(), c.domain());
    assert!(curve_distance(&c, &cc, 200) < REL * curve_scale(&c));
    let e = c.elevate_degree(1).unwrap();
    assert!(curve_distance(&c, &e, 200) < REL * curve_scale(&c));
    let segs = c.bezier_segments().unwrap();
    assert_eq!(segs.len(), 4);
    for s in &segs {
        assert!(curve_distance(s, &c, 50) < REL * curve_scale(&c));
    }
}

fn interior(c: &NurbsCurve<3>, t: f64) -> f64 {
    let (a, b) = c.domain();
    a + (b - a) * (0.01 + 0.98 * t)
}

proptest! {
    #[test]
    fn knot_insertion_preserves_shape(c in curve3(true), t in 0.0f64..1.0, times in 1usize..=5) {
        let u = interior(&c, t);
        let times = times.min(c.degree() - c.knots().multiplicity(u));
        prop_assume!(times > 0);
        let q = c.insert_knot(u, times).unwrap();
        prop_assert_eq!(q.knots().multiplicity(u), c.knots().multiplicity(u) + times);
        prop_assert!(curve_distance(&c, &q, 100) <= REL * curve_scale(&c));
    }

    #[test]
    fn knot_refinement_preserves_shape(c in curve3(true), ts in prop::collection::vec(0.0f64..1.0, 1..8)) {
        let x: Vec<f64> = ts.iter().map(|&t| interior(&c, t)).collect();
        let q = c.refine_knots(&x).unwrap();
        prop_assert_eq!(q.control_points().len(), c.control_points().len() + x.len());
        prop_assert!(curve_distance(&c, &q, 100) <= REL * curve_scale(&c));
        // refinement equals repeated insertion
        let mut r = c.clone();
        for &u in &x { r = r.insert_knot(u, 1).unwrap(); }
        prop_assert!(curve_distance(&r, &q, 50) <= REL * curve_scale(&c));
    }

    #[test]
    fn degree_elevation_preserves_shape(c in curve3(true), t in 1usize..=3) {
        let e = c.elevate_degree(t).unwrap();
        prop_assert_eq!(e.degree(), c.degree() + t);
        prop_assert_eq!(e.domain(), c.domain());
        let breaks = c.knots().interior_breaks();
        let expected = c.control_points().len() + t * (breaks.len() + 1);
        prop_assert_eq!(e.control_points().len(), expected);
        prop_assert!(curve_distance(&c, &e, 100) <= REL * curve_scale(&c));
    }

    #[test]
    fn split_pieces_reproduce_curve(c in curve2(true), t in 0.0f64..1.0) {
        let (a, b) = c.domain();
        let u = a + (b - a) * (0.01 + 0.98 * t);
        let (l, r) = c.split(u).unwrap();
        prop_assert_eq!(l.domain(), (a, u));
        prop_assert_eq!(r.domain(), (u, b));
        let scale = curve_scale(&c);
        for k in 0..=50 {
            let s = k as f64 / 50.0;
            let ul = a + (u - a) * s;
            let ur = u + (b - u) * s;
            prop_assert!((l.point(ul) - c.point(ul)).norm() <= REL * scale);
            prop_assert!((r.point(ur) - c.point(ur)).norm() <= REL * scale);
        }
    }

    #[test]
    fn bezier_segments_reproduce_curve(c in curve3(true)) {
        let segs = c.bezier_segments().unwrap();
        prop_assert_eq!(segs.len(), c.knots().interior_breaks().len() + 1);
        let mut prev_end = c.domain().0;
        for s in &segs {
            prop_assert_eq!(s.control_points().len(), c.degree() + 1);
            prop_assert_eq!(s.domain().0, prev_end);
            prev_end = s.domain().1;
            prop_assert!(curve_distance(s, &c, 20) <= REL * curve_scale(&c));
        }
        prop_assert_eq!(prev_end, c.domain().1);
    }

    #[test]
    fn reverse_and_reparametrize(c in curve3(true), lo in -5.0f64..5.0, len in 0.1f64..10.0) {
        let (a, b) = c.domain();
        let r = c.reverse().unwrap();
        prop_assert_eq!(r.domain(), (a, b));
        let q = c.reparametrize(lo, lo + len).unwrap();
        prop_assert_eq!(q.domain(), (lo, lo + len));
        let scale = curve_scale(&c);
        for k in 0..=40 {
            let s = k as f64 / 40.0;
            let u = a + (b - a) * s;
            prop_assert!((r.point(a + b - u) - c.point(u)).norm() <= 1e-10 * scale);
            prop_assert!((q.point(lo + len * s) - c.point(u)).norm() <= 1e-10 * scale);
        }
    }

    #[test]
    fn surface_knot_operations_preserve_shape(
        s in surface(true), t in 0.0f64..1.0, r in 0.0f64..1.0, e in 1usize..=2
    ) {
        let ((u0, u1), (v0, v1)) = s.domain();
        let u = u0 + (u1 - u0) * (0.01 + 0.98 * t);
        let v = v0 + (v1 - v0) * (0.01 + 0.98 * r);
        let scale = surface_scale(&s);
        if s.knots_u().multiplicity(u) < s.degree_u() {
            let q = s.insert_knot(Direction::U, u, 1).unwrap();
            prop_assert!(surface_distance(&s, &q, 12) <= REL * scale);
        }
        let q = s.refine_knots(Direction::V, &[v, v0 + 0.5 * (v - v0)]).unwrap();
        prop_assert!(surface_distance(&s, &q, 12) <= REL * scale);
        let q = s.elevate_degree(Direction::U, e).unwrap().elevate_degree(Direction::V, 1).unwrap();
        prop_assert_eq!((q.degree_u(), q.degree_v()), (s.degree_u() + e, s.degree_v() + 1));
        prop_assert!(surface_distance(&s, &q, 12) <= REL * scale);
        let (lo, hi) = s.split(Direction::V, v).unwrap();
        prop_assert!((lo.point(u, v0) - s.point(u, v0)).norm() <= REL * scale);
        prop_assert!((hi.point(u, v1) - s.point(u, v1)).norm() <= REL * scale);
        prop_assert!((lo.point(u, v) - hi.point(u, v)).norm() <= REL * scale);
        let sw = s.swap_uv().unwrap();
        prop_assert!((sw.point(v, u) - s.point(u, v)).norm() <= REL * scale);
        let rv = s.reverse(Direction::U).unwrap();
        prop_assert!((rv.point(u0 + u1 - u, v) - s.point(u, v)).norm() <= 1e-10 * scale);
        let rp = s.reparametrize(Direction::V, 0.0, 1.0).unwrap();
        prop_assert!((rp.point(u, (v - v0) / (v1 - v0)) - s.point(u, v)).norm() <= 1e-10 * scale);
    }

    #[test]
    fn bezier_patches_reproduce_surface(s in surface(true), t in 0.0f64..1.0, r in 0.0f64..1.0) {
        let patches = s.bezier_patches().unwrap();
        let nu = s.knots_u().interior_breaks().len() + 1;
        let nv = s.knots_v().interior_breaks().len() + 1;
        prop_assert_eq!(patches.len(), nu * nv);
        let scale = surface_scale(&s);
        for p in &patches {
            prop_assert_eq!(p.surface.n_u(), s.degree_u() + 1);
            prop_assert_eq!(p.surface.n_v(), s.degree_v() + 1);
            let u = p.u_range.0 + (p.u_range.1 - p.u_range.0) * t;
            let v = p.v_range.0 + (p.v_range.1 - p.v_range.0) * r;
            prop_assert!((p.surface.point(u, v) - s.point(u, v)).norm() <= REL * scale);
        }
    }
}

#[test]
fn surface_operation_errors() {
    let s = NurbsSurface::new(
        1,
        1,
        vec![0., 0., 1., 1.],
        vec![0., 0., 1., 1.],
        vec![
            vec![Vector3::zeros(), Vector3::y()],
            vec![Vector3::x(), Vector3::new(1., 1., 1.)],
        ],
        None,
    )
    .unwrap();
    assert!(matches!(
        s.insert_knot(Direction::U, 0.5, 2),
        Err(NurbsError::InsertionExceedsMultiplicity { .. })
    ));
    assert!(matches!(
        s.split(Direction::V, 1.0),
        Err(NurbsError::ParameterOutOfDomain { .. })
    ));
    assert!(matches!(
        s.elevate_degree(Direction::V, MAX_DEGREE),
        Err(NurbsError::DegreeOutOfRange { .. })
    ));
    assert!(matches!(
        s.reparametrize(Direction::U, 2.0, f64::NAN),
        Err(NurbsError::EmptyDomain { .. })
    ));
    let patches = s.bezier_patches().unwrap();
    assert_eq!(patches.len(), 1);
    assert_eq!(patches[0].surface, s);
}
