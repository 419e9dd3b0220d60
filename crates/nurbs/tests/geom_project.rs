//! Projection of a point along a direction.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::Vector3;
use nurbs::closest::SurfaceProjector;
use nurbs::project::{ProjectError, RayMode};
use nurbs::{KnotVector, NurbsCurve, NurbsSurface};

fn wavy() -> NurbsSurface {
    let ctrl: Vec<Vec<Vector3<f64>>> = (0..8)
        .map(|i| {
            (0..8)
                .map(|j| {
                    Vector3::new(
                        10.0 * i as f64,
                        10.0 * j as f64,
                        4.0 * ((i as f64) * 0.9).sin() * ((j as f64) * 0.6).cos(),
                    )
                })
                .collect()
        })
        .collect();
    let k = KnotVector::clamped_uniform(3, 8).unwrap().knots().to_vec();
    NurbsSurface::new(3, 3, k.clone(), k, ctrl, None).unwrap()
}

#[test]
fn vertical_projection_onto_a_height_field() {
    let s = wavy();
    let p = SurfaceProjector::new(&s);
    for (u, v) in [(0.2, 0.3), (0.77, 0.5), (0.5, 0.95), (0.0, 0.4)] {
        let foot = s.point(u, v);
        let q = foot + Vector3::new(0.0, 0.0, 12.0);
        let hit = p
            .project_along(&q, &Vector3::new(0.0, 0.0, -3.0), RayMode::Forward)
            .unwrap()
            .unwrap();
        assert!(
            (hit.point - foot).norm() <= 1e-9,
            "{:?} vs {foot:?}",
            hit.point
        );
        assert!((hit.t - 12.0).abs() <= 1e-9);
        assert!((s.point(hit.u, hit.v) - hit.point).norm() <= 1e-12);
        // Pointing away: no forward hit, but the line hits behind.
        assert!(p
            .project_along(&q, &Vector3::z(), RayMode::Forward)
            .unwrap()
            .is_none());
        let back = p
            .project_along(&q, &Vector3::z(), RayMode::Line)
            .unwrap()
            .unwrap();
        assert!((back.t + 12.0).abs() <= 1e-9);
    }
    // Outside the footprint: miss.
    let q = Vector3::new(-5.0, 30.0, 10.0);
    assert!(p
        .project_along(&q, &-Vector3::z(), RayMode::Line)
        .unwrap()
        .is_none());
}

#[test]
fn line_through_a_cylinder_hits_twice() {
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
    let q = Vector3::new(5.0, -3.0, 12.0);
    let d = Vector3::new(1.0, 0.5, 0.1);
    let hits = p.intersect_line(&q, &d, RayMode::Line).unwrap();
    assert_eq!(hits.len(), 2, "{hits:?}");
    for h in &hits {
        assert!((h.point.xy().norm() - 20.0).abs() <= 1e-9);
        let on_line = q + d.normalize() * h.t;
        assert!((on_line - h.point).norm() <= 1e-9);
    }
    assert!(hits[0].t < 0.0 && hits[1].t > 0.0);
    let nearest = p.project_along(&q, &d, RayMode::Line).unwrap().unwrap();
    assert_eq!(
        nearest.t,
        if hits[0].t.abs() < hits[1].t.abs() {
            hits[0].t
        } else {
            hits[1].t
        }
    );
}

#[test]
fn invalid_projection_input_is_reported() {
    let p = SurfaceProjector::new(&wavy());
    assert!(matches!(
        p.project_along(&Vector3::zeros(), &Vector3::zeros(), RayMode::Line),
        Err(ProjectError::InvalidInput(_))
    ));
    assert!(matches!(
        p.intersect_line(
            &Vector3::new(f64::NAN, 0.0, 0.0),
            &Vector3::z(),
            RayMode::Forward
        ),
        Err(ProjectError::InvalidInput(_))
    ));
}

proptest::proptest! {
    /// A line through a known surface point is reported hitting it.
    #[test]
    fn line_through_a_surface_point_finds_it(u in 0.0f64..=1.0, v in 0.0f64..=1.0,
                                              dx in -1.0f64..1.0, dy in -1.0f64..1.0, t0 in 1.0f64..20.0) {
        let s = wavy();
        let p = SurfaceProjector::new(&s);
        let foot = s.point(u, v);
        let n = s.normal(u, v).unwrap();
        let d = (n + Vector3::new(dx, dy, 0.0)).normalize();
        proptest::prop_assume!(d.dot(&n).abs() > 0.3);
        let q = foot - d * t0;
        let hits = p.intersect_line(&q, &d, RayMode::Line).unwrap();
        let found = hits.iter().any(|h| (h.point - foot).norm() <= 1e-8 && (h.t - t0).abs() <= 1e-8);
        proptest::prop_assert!(found, "no hit at the generating point; hits {:?}", hits);
        for h in &hits {
            proptest::prop_assert!(((q + d * h.t) - h.point).norm() <= 1e-8);
        }
    }
}
