//! The axial depth of one plunge: how far a flat plunge cutter goes down its axis before its
//! bottom circle touches the hub (paper 000 §4, eqs. 2–9), for axes tilted more and more
//! against the hub normal.
//!
//! `cargo run -p plunge-opt --example axial_depth`
//!
//! Hub: the quarter-ellipse meridional contour of the `impeller-plunge-400` fixture's size
//! (inlet (z, r) = (125, 40) mm, outlet (20, 200) mm) revolved about +Z, offset by a 0.5 mm
//! hub allowance. A Ø30 mm cutter stands on an axis through a point 30 mm above the floor at
//! 60 % of the meridional length; the axis leans from the floor normal toward the outlet by
//! α (an axis exactly along the normal is a degenerate case of the solve: every rim point
//! is equally low on a locally symmetric floor, so the table starts at 2°). For each α the Newton solve gives the axial position `t` of the bottom centre
//! `P + t·q` (negative: below `P`), the contact point and the iterations; the check columns confirm that the contact
//! point lies on the bottom circle (distance to the centre = radius, in the bottom plane) and
//! that the floor there is tangent to the circle.

use cam_core::{Point3, Vector3};
use plunge_opt::axial_depth::{solve_contact, Floor, RevolvedFloor};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let hub = impeller_model::MeridionalCurve::quarter_ellipse([125.0, 40.0], [20.0, 200.0])?;
    let floor = RevolvedFloor::offset(&hub, 0.5);
    let radius = 15.0;
    let fp = floor.eval(hub.param_at_fraction(0.6), 0.2);
    let p = Point3::from(fp.p + fp.n * 30.0);
    let along = fp.su.normalize();
    println!(
        "{:>6} {:>10} {:>28} {:>5} {:>12} {:>12} {:>15}",
        "α/deg", "t/mm", "contact point (mm)", "iter", "|QC|−r", "(Q−C)·q", "n·(q×(Q−C))/r"
    );
    let mut seed = None;
    for deg in [2.0, 5.0, 8.5, 12.0, 16.0, 20.0, 25.0, 30.0] {
        let a = f64::to_radians(deg);
        let q: Vector3 = (fp.n * a.cos() + along * a.sin()).normalize();
        let c = match solve_contact(&floor, &p, &q, radius, seed) {
            Ok(c) => c,
            Err(e) => {
                println!("{deg:>6.1} no contact: {e}");
                continue;
            }
        };
        seed = Some((c.uv, c.t));
        let centre = p.coords + q * c.t;
        let d = c.point - centre;
        println!(
            "{deg:>6.1} {:>10.4} {:>28} {:>5} {:>12.2e} {:>12.2e} {:>15.2e}",
            c.t,
            format!("({:.3}, {:.3}, {:.3})", c.point.x, c.point.y, c.point.z),
            c.iterations,
            d.norm() - radius,
            d.dot(&q),
            c.normal.dot(&q.cross(&d)) / radius,
        );
    }
    Ok(())
}
