//! Signed distance to the envelope a tapered ball end sweeps, and ball-end scallop heights.
//!
//! `cargo run -p cam-core --example swept_envelope`
//!
//! A 3 mm ball with a 3° taper moves 50 mm along +x while its axis tilts from vertical to
//! 20° (the tip guide on z = 0, the axis guide 10 mm above it). The example prints the signed
//! distance (negative inside the swept volume) and its gradient for points across the path,
//! then the scallop height left by a 6 mm ball on flat, convex and concave surfaces.

use cam_core::{
    ball_scallop, CutterShape, EnvelopeOptions, GuideCurve, Point3, SphereFamily, SweptEnvelope,
    Vector3,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let shape = CutterShape::TaperedBallEnd {
        ball_radius: 3.0,
        half_angle: 3f64.to_radians(),
    };
    let family = SphereFamily::from_shape(&shape, 25.0)?;
    let tilt = 20f64.to_radians();
    let tip = GuideCurve::new(
        1,
        vec![0.0, 0.0, 1.0, 1.0],
        vec![Vector3::new(0.0, 0.0, 0.0), Vector3::new(50.0, 0.0, 0.0)],
        None,
    )?;
    let axis = GuideCurve::new(
        1,
        vec![0.0, 0.0, 1.0, 1.0],
        vec![
            Vector3::new(0.0, 0.0, 10.0),
            Vector3::new(50.0, 10.0 * tilt.sin(), 10.0 * tilt.cos()),
        ],
        None,
    )?;
    let env = SweptEnvelope::new(family, tip, axis, 0.0, EnvelopeOptions::default())?;
    println!("signed distance to the swept envelope (mm; < 0 inside)");
    println!(
        "{:>28} {:>10} {:>28}",
        "point", "distance", "gradient wrt the point"
    );
    let mut hint = None;
    for p in [
        Point3::new(25.0, 0.0, -1.0),
        Point3::new(25.0, 0.0, 1.0),
        Point3::new(25.0, 5.0, 4.0),
        Point3::new(25.0, -5.0, 4.0),
        Point3::new(60.0, 0.0, 2.0),
    ] {
        let (d, g) = env.signed_distance_with_gradient(&p, hint)?;
        hint = Some(d.param);
        println!(
            "{:>28} {:>10.4} {:>28}",
            format!("({:.1}, {:.1}, {:.1})", p.x, p.y, p.z),
            d.distance,
            format!("({:.3}, {:.3}, {:.3})", g.point.x, g.point.y, g.point.z)
        );
    }
    println!();
    println!("scallop of a 6 mm ball (radius 3 mm) at 1 mm step-over (µm)");
    for (label, curvature) in [
        ("flat", 0.0),
        ("convex, R = 20 mm", 1.0 / 20.0),
        ("concave, R = 20 mm", -1.0 / 20.0),
    ] {
        let h = ball_scallop(3.0, curvature, 1.0)?;
        println!("  {label:<20} {:8.2}", h * 1e3);
    }
    Ok(())
}
