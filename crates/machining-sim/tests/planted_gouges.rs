//! Planted gouges of known depth on the hub and on blade sides of two fixture impellers
//! (`impeller-8+8`, ruled blades; `impeller-5-freeform`, free-form blades), measured at the
//! default 0.1 mm resolution.
//!
//! A ball end (radius r) is placed with its centre C on the outward normal of a design point,
//! `r − δ` from the surface. The planted depth is `r − dist(C, surface)`, where the distance
//! is computed here independently of the simulator's design model: by dense sampling of the
//! NURBS surface around the foot point (two nested 81 × 81 parameter grids). The simulation
//! must read it within 0.01 mm and never under-read it by more (end points are exact
//! ray–sphere intersections, module `machining_sim::endpoints`), and a ball that stops 5 µm
//! short of the surface must read no overcut.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use cam_core::{Cutter, CutterLocation, CutterShape, Move, MoveKind, Point3, ToolPath, Vector3};
use impeller_model::{Impeller, Side};
use machining_sim::{
    simulate, BoxStock, DesignModel, ImpellerDesign, ImpellerSampling, SimOptions, TriDexel,
};

/// The accuracy the end-point measurement must reach at h = 0.1 mm (mm).
const GOAL_MM: f64 = 0.01;
/// Ball radius of the gouging cutter (mm): fits every channel of both fixtures.
const BALL_R: f64 = 1.5;
const H: f64 = 0.1;

fn fixture(name: &str) -> Impeller {
    let path = format!(
        "{}/../../fixtures/{name}/impeller.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    impeller_model::load(&path).unwrap()
}

fn sampling() -> ImpellerSampling {
    ImpellerSampling {
        blade_u: 12,
        blade_v: 6,
        hub_t: 10,
        hub_phi: 90,
        tip_w: 2,
        mesh_u: 32,
        mesh_v: 8,
    }
}

/// Smallest distance from `c` to the parametric surface `f` over the parameter box around
/// `(u, v)` of half widths `(du, dv)`: an 81 × 81 grid, then a second one over the best cell's
/// neighbourhood, repeated three times (the grid spacing shrinks 40× per level).
fn dense_distance(
    f: &dyn Fn(f64, f64) -> nalgebra::Vector3<f64>,
    c: &nalgebra::Vector3<f64>,
    (mut u, mut v): (f64, f64),
    (mut du, mut dv): (f64, f64),
) -> f64 {
    let n = 80;
    let mut best = f64::INFINITY;
    for _ in 0..4 {
        let (u0, v0) = (u, v);
        for i in 0..=n {
            for j in 0..=n {
                let uu = u0 - du + 2.0 * du * i as f64 / n as f64;
                let vv = v0 - dv + 2.0 * dv * j as f64 / n as f64;
                let d = (f(uu, vv) - c).norm();
                if d < best {
                    best = d;
                    u = uu;
                    v = vv;
                }
            }
        }
        du *= 2.0 / n as f64;
        dv *= 2.0 / n as f64;
    }
    best
}

/// One single-position plunge of the ball with centre `c` and axis `axis` into a small box
/// of full material around it; returns (measured overcut, error bound).
fn plant(design: &ImpellerDesign, c: &nalgebra::Vector3<f64>, axis: &Vector3) -> (f64, f64) {
    let cutter = Cutter::new(
        "b3",
        CutterShape::BallEnd { radius: BALL_R },
        2.0,
        BALL_R,
        30.0,
    )
    .unwrap();
    let tip = c - axis * BALL_R;
    let mut path = ToolPath::new("gouge", "b3");
    path.moves.push(Move {
        kind: MoveKind::Feed,
        cl: CutterLocation::new(Point3::from(tip), *axis).unwrap(),
        feed_mm_per_min: None,
    });
    let lo = [c.x - 3.0, c.y - 3.0, c.z - 3.0];
    let hi = [c.x + 3.0, c.y + 3.0, c.z + 3.0];
    let mut stock = TriDexel::from_shape(&BoxStock::new(lo, hi).unwrap(), H).unwrap();
    let opts = SimOptions {
        check_collisions: false,
        ..SimOptions::default()
    };
    let rep = simulate(&mut stock, design, &[(cutter, path)], &opts).unwrap();
    (
        rep.metrics.max_overcut_mm,
        rep.metrics.overcut_error_bound_mm,
    )
}

fn check(label: &str, planted: f64, measured: f64) {
    eprintln!("{label}: planted {planted:.4} mm, measured {measured:.4} mm");
    if planted <= 0.0 {
        assert_eq!(measured, 0.0, "{label}: near miss read as overcut");
        return;
    }
    assert!(
        measured >= planted - GOAL_MM,
        "{label}: planted {planted:.4} mm, measured {measured:.4} mm (under-read)"
    );
    assert!(
        measured <= planted + 1e-3,
        "{label}: planted {planted:.4} mm, measured {measured:.4} mm (over-read)"
    );
}

/// Planted depths (mm); a negative depth is a near miss.
const DEPTHS: [f64; 5] = [-0.005, 0.02, 0.075, 0.2, 0.5];

fn blade_gouges(name: &str, side: Side, frac: (f64, f64)) {
    let imp = fixture(name);
    let design = ImpellerDesign::new(&imp, sampling()).unwrap();
    let blade = imp.main().instance(0);
    let s = blade.side(side);
    let ((u0, u1), (v0, v1)) = s.domain();
    let (u, v) = (u0 + frac.0 * (u1 - u0), v0 + frac.1 * (v1 - v0));
    let p = s.point(u, v);
    let n = blade.outward_normal(side, u, v).unwrap();
    for delta in DEPTHS {
        let c = p + n * (BALL_R - delta);
        let f = |a: f64, b: f64| s.point(a, b);
        let dist = dense_distance(&f, &c, (u, v), (0.05 * (u1 - u0), 0.05 * (v1 - v0)));
        // The simulator's design model agrees with the independent distance (the ball's
        // nearest design point is on this side, not on the hub or another blade).
        let sd = design.signed_distance(&Point3::from(c));
        assert!((sd - dist).abs() < 1e-4, "{name}: sd {sd} vs dense {dist}");
        let planted = if delta < 0.0 { delta } else { BALL_R - dist };
        let (measured, bound) = plant(&design, &c, &n);
        check(&format!("{name} {side:?} δ={delta}"), planted, measured);
        assert!(bound > 0.0 && bound < 0.05, "{bound}");
    }
}

fn hub_gouges(name: &str, t_frac: f64) {
    let imp = fixture(name);
    let design = ImpellerDesign::new(&imp, sampling()).unwrap();
    let hub = imp.hub();
    let (t0, t1) = hub.meridional().domain();
    let t = t0 + t_frac * (t1 - t0);
    // The hub point farthest from every blade among 72 angles.
    let (phi, _) = (0..72)
        .map(|k| {
            let phi = std::f64::consts::TAU * f64::from(k) / 72.0;
            let p = hub.point(t, phi);
            let c = p + hub.normal(t, phi) * BALL_R;
            (phi, design.blade_signed_distance(&Point3::from(c)))
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap();
    let p = hub.point(t, phi);
    let n = hub.normal(t, phi);
    assert!(design.signed_distance(&Point3::from(p + n * 0.1)) > 0.0);
    for delta in DEPTHS {
        let c = p + n * (BALL_R - delta);
        assert!(design.blade_signed_distance(&Point3::from(c)) > BALL_R + 0.2);
        let f = |a: f64, b: f64| hub.point(a, b);
        let dist = dense_distance(&f, &c, (t, phi), (0.05 * (t1 - t0), 0.05));
        let sd = design.signed_distance(&Point3::from(c));
        assert!((sd - dist).abs() < 1e-4, "{name}: sd {sd} vs dense {dist}");
        let planted = if delta < 0.0 { delta } else { BALL_R - dist };
        let (measured, _) = plant(&design, &c, &n);
        check(&format!("{name} hub δ={delta}"), planted, measured);
    }
}

#[test]
fn impeller_8_8_blade_sides() {
    blade_gouges("impeller-8+8", Side::Pressure, (0.5, 0.5));
    blade_gouges("impeller-8+8", Side::Suction, (0.4, 0.6));
}

#[test]
fn impeller_8_8_hub() {
    hub_gouges("impeller-8+8", 0.6);
}

#[test]
fn impeller_5_freeform_blade_sides() {
    blade_gouges("impeller-5-freeform", Side::Pressure, (0.55, 0.45));
    blade_gouges("impeller-5-freeform", Side::Suction, (0.45, 0.55));
}

#[test]
fn impeller_5_freeform_hub() {
    hub_gouges("impeller-5-freeform", 0.5);
}
