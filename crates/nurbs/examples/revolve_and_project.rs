//! Exact conics, knot insertion, a surface of revolution, its curvature and closest points.
//!
//! `cargo run -p nurbs --example revolve_and_project`
//!
//! A rational quadratic quarter circle is checked to lie on the unit circle and to survive
//! knot insertion unchanged; a segment revolved about +Z gives an exact cylinder of radius 5,
//! whose principal curvatures are 0 and 1/5; then points are projected onto the cylinder and
//! onto a bilinear patch (closest point, distance, whether the answer lies on the boundary).

use nalgebra::{Vector2, Vector3};
use nurbs::closest::SurfaceProjector;
use nurbs::{NurbsCurve, NurbsSurface};
use std::f64::consts::{FRAC_1_SQRT_2, PI};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // Rational quarter circle of radius 1: one Bézier segment of degree 2.
    let arc = NurbsCurve::<2>::new(
        2,
        vec![0., 0., 0., 1., 1., 1.],
        vec![
            Vector2::new(1., 0.),
            Vector2::new(1., 1.),
            Vector2::new(0., 1.),
        ],
        Some(vec![1., FRAC_1_SQRT_2, 1.]),
    )?;
    let refined = arc.insert_knot(0.5, 1)?;
    let mut radius_err: f64 = 0.0;
    let mut insert_err: f64 = 0.0;
    for i in 0..=100 {
        let t = f64::from(i) / 100.0;
        radius_err = radius_err.max((arc.point(t).norm() - 1.0).abs());
        insert_err = insert_err.max((refined.point(t) - arc.point(t)).norm());
    }
    println!("quarter circle: largest |radius − 1| over 101 points = {radius_err:.2e}");
    println!("knot insertion at 0.5: largest point change = {insert_err:.2e}");

    // A cylinder of radius 5 and height 10: revolve a segment about +Z.
    let line = NurbsCurve::<3>::new(
        1,
        vec![0., 0., 1., 1.],
        vec![Vector3::new(5., 0., 0.), Vector3::new(5., 0., 10.)],
        None,
    )?;
    let cylinder = NurbsSurface::revolution(&line, Vector3::zeros(), Vector3::z(), 2.0 * PI)?;
    let k = cylinder
        .principal_curvatures(0.3, 0.5)
        .ok_or("degenerate point")?;
    println!(
        "cylinder: principal curvatures {:.6} and {:.6} (1/mm; expected 0 and ±0.2)",
        k.k1, k.k2
    );

    let projector = SurfaceProjector::new(&cylinder);
    println!("closest points on the cylinder:");
    for q in [
        Vector3::new(8.0, 1.0, 4.0),
        Vector3::new(1.0, -2.0, 7.5),
        Vector3::new(3.0, 3.0, 12.0),
    ] {
        let a = projector.closest_point(&q);
        println!(
            "  ({:5.1}, {:5.1}, {:5.1}) -> ({:7.3}, {:7.3}, {:7.3})  u = {:.4}  v = {:.4}  \
             distance = {:.6}{}",
            q.x,
            q.y,
            q.z,
            a.point.x,
            a.point.y,
            a.point.z,
            a.u,
            a.v,
            a.distance,
            if a.on_boundary {
                "  (on the boundary)"
            } else {
                ""
            }
        );
    }
    Ok(())
}
