//! Rest finishing on the impeller-8+8 fixture with hand-made remaining-material grids: a hub
//! patch in mid-channel is cut with the ball on the hub and nothing left above the
//! threshold; at the end of a blade-root fillet (the main blades' leading-edge root at the
//! hub's inlet rim, where the fillet stops) no ball enters the fillet.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod support;

use cam_plan::{Operation, OperationSpec, PlanContext, Point3, RemainingMaterial, RestGrid};
use channel_paths::build_rest_finishing;
use impeller_model::fillet::{ImpellerFillets, DEFAULT_FILLET_TOL_MM};
use nalgebra::Vector3;
use support::Ctx;

fn op() -> Box<dyn Operation> {
    let spec = OperationSpec {
        name: "rest".into(),
        kind: channel_paths::REST_FINISHING.into(),
        tool: "ball".into(),
        process: support::process(),
        params: toml::toml! { threshold_mm = 0.1 },
    };
    build_rest_finishing(&spec).unwrap()
}

fn grid(surface: &str, points: Vec<[f64; 3]>, nu: usize, nv: usize) -> RemainingMaterial {
    RemainingMaterial {
        after: vec!["earlier".into()],
        resolution_mm: 0.1,
        grids: vec![RestGrid {
            surface: surface.into(),
            nu,
            nv,
            residual_mm: vec![Some(0.3); nu * nv],
            points,
        }],
    }
}

fn centres(planned: &cam_plan::PlannedOperation, r: f64) -> Vec<Vector3<f64>> {
    planned
        .paths
        .iter()
        .flat_map(|p| p.moves.iter())
        .filter(|m| m.kind.at_cutting_feed())
        .map(|m| m.cl.tip.coords + m.cl.axis.into_inner() * r)
        .collect()
}

#[test]
fn a_hub_patch_in_mid_channel_is_cut_to_the_threshold_with_the_ball_on_the_hub() {
    let r = 0.5;
    let c = Ctx::new("impeller-8+8", r);
    let cl = c.clearance();
    let hub = c.imp.hub();
    // The polar angle of the hub point farthest from every blade at t = 0.8, where the
    // channel is wide enough for the ball to keep clear of the fillets by their reach (the
    // conservative fillet certificate, see the module docs).
    let t = 0.8;
    let phi = (0..720)
        .map(|k| k as f64 * std::f64::consts::TAU / 720.0)
        .max_by(|a, b| {
            let d = |phi: f64| cl.blade_signed_distance(&Point3::from(hub.point(t, phi))).0;
            d(*a).total_cmp(&d(*b))
        })
        .unwrap();
    let (nu, nv) = (5, 4);
    let mut points = Vec::new();
    for j in 0..nv {
        for i in 0..nu {
            let p = hub.point(t + 0.004 * j as f64, phi + 0.004 * i as f64);
            points.push([p.x, p.y, p.z]);
        }
    }
    let rm = grid("hub", points, nu, nv);
    let mut ctx: PlanContext<'_> = plan_ctx!(c, cl);
    ctx.remaining = Some(&rm);
    let recorder = cam_plan::ProgressLog::default();
    ctx.progress = Some(&recorder);
    let planned = op().plan(&ctx).unwrap();
    // Progress in samples, pass by pass, up to all of them.
    let reports = recorder.reports();
    assert!(reports.len() > 2, "{reports:?}");
    assert!(reports.iter().all(|r| r.2 == nu * nv), "{reports:?}");
    assert!(reports.windows(2).all(|w| w[0].1 <= w[1].1), "{reports:?}");
    assert_eq!(reports.last().map(|r| r.1), Some(nu * nv), "{reports:?}");
    let m = &planned.metrics;
    let get = |k: &str| m.get(k).and_then(|v| v.as_f64()).unwrap();
    assert_eq!(get("regions"), 1.0);
    assert_eq!(get("target_points"), (nu * nv) as f64);
    assert_eq!(get("unreachable_points"), 0.0, "{m:?}");
    assert_eq!(get("corner_points"), 0.0, "{m:?}");
    assert!(get("residual_after_max_mm") <= 0.1, "{m:?}");
    let cs = centres(&planned, r);
    assert!(cs.len() > 20, "{} stations", cs.len());
    for c0 in &cs {
        // On a face away from the blades the ball touches the hub: its centre is r above it
        // (1e-6 mm: the settling tolerance plus the hub distance's own accuracy).
        let d = hub.signed_distance(c0);
        assert!((d - r).abs() < 1e-6, "hub distance {d} of {c0:?}");
    }
}

#[test]
fn no_ball_enters_the_fillet_where_it_ends_at_the_inlet_rim() {
    let r = 0.5;
    let c = Ctx::new("impeller-8+8", r);
    let cl = c.clearance();
    let fillets = ImpellerFillets::new(&c.imp, DEFAULT_FILLET_TOL_MM)
        .unwrap()
        .unwrap();
    // A patch on the suction side of a main blade at its root on the hub's inlet rim (the
    // verifier's map sample main2_suction (3, 1)), where the fillet ends: without the
    // fillet certificate a Ø1 ball here cut 0.15 mm into the fillet's end.
    let centre = Vector3::new(-0.4008, 9.3719, 42.6912);
    let (nu, nv) = (4, 4);
    let mut points = Vec::new();
    for j in 0..nv {
        for i in 0..nu {
            let p = centre + Vector3::new(0.15 * (i as f64 - 1.5), 0.0, 0.1 * (j as f64 - 1.5));
            points.push([p.x, p.y, p.z]);
        }
    }
    let rm = grid("main2_suction", points, nu, nv);
    let mut ctx: PlanContext<'_> = plan_ctx!(c, cl);
    ctx.remaining = Some(&rm);
    let planned = op().plan(&ctx).unwrap();
    // Every ball station (planned, and the motions are certified on the same margin): no
    // point of the ball lies in fillet material or in the sharp design (2 000 directions).
    let n = 2000;
    for c0 in centres(&planned, r) {
        for k in 0..n {
            // Fibonacci sphere.
            let z = 1.0 - 2.0 * (k as f64 + 0.5) / n as f64;
            let a = k as f64 * std::f64::consts::PI * (3.0 - 5f64.sqrt());
            let w = Vector3::new(
                (1.0 - z * z).sqrt() * a.cos(),
                (1.0 - z * z).sqrt() * a.sin(),
                z,
            );
            let x = c0 + w * r;
            let f = fillets.closest(&x).map_or(f64::INFINITY, |(d, _)| d);
            // Half the machining tolerance, the floor of every posture and motion.
            assert!(
                f > -5e-3,
                "ball at {c0:?} is {:.4} mm into the fillet at {x:?}",
                -f
            );
            let sharp = cl.design_signed_distance(&Point3::from(x)).0;
            assert!(
                sharp > -5e-3,
                "ball at {c0:?} is {:.4} mm into the design",
                -sharp
            );
        }
    }
    let count = |k: &str| planned.metrics.get(k).and_then(|v| v.as_f64()).unwrap();
    // Balls are placed (the check above is not vacuous): on the margin they settle clear of
    // the fillet's end instead of in the sharp corner beyond it.
    assert!(count("stations") > 0.0, "{:?}", planned.metrics);
}

/// Hub samples 0.15–0.25 mm from a main blade's side, mid-blade: under the 1 mm fillet, so
/// material the earlier operations leave there is fillet material no Ø1 ball can reach (the
/// ball tangent to the hub there sits 0.25–0.35 mm inside the blade). Every one stays above
/// the threshold and every one is proven out of reach (`corner_points`), with its area.
#[test]
fn hub_samples_in_the_root_corner_are_proven_out_of_the_balls_reach() {
    let r = 0.5;
    let c = Ctx::new("impeller-8+8", r);
    let cl = c.clearance();
    let hub = c.imp.hub();
    let blade_d = |t: f64, phi: f64| cl.blade_signed_distance(&Point3::from(hub.point(t, phi))).0;
    // At each t: from the hub point farthest from the blades toward the nearer blade,
    // bisected to the requested distance from its side.
    let phi_at = |t: f64, d: f64| {
        let far = (0..720)
            .map(|k| k as f64 * std::f64::consts::TAU / 720.0)
            .max_by(|a, b| blade_d(t, *a).total_cmp(&blade_d(t, *b)))
            .unwrap();
        let mut near = far;
        while blade_d(t, near) > 0.0 {
            near += 0.002;
        }
        let (mut a, mut b) = (far, near);
        for _ in 0..60 {
            let m = 0.5 * (a + b);
            if blade_d(t, m) > d {
                a = m;
            } else {
                b = m;
            }
        }
        0.5 * (a + b)
    };
    let (nu, nv) = (3, 3);
    let mut points = Vec::new();
    for j in 0..nv {
        let t = 0.5 + 0.01 * j as f64;
        for i in 0..nu {
            let d = 0.25 - 0.05 * i as f64;
            let p = hub.point(t, phi_at(t, d));
            points.push([p.x, p.y, p.z]);
        }
    }
    let rm = grid("hub", points, nu, nv);
    let mut ctx: PlanContext<'_> = plan_ctx!(c, cl);
    ctx.remaining = Some(&rm);
    let planned = op().plan(&ctx).unwrap();
    let m = &planned.metrics;
    let get = |k: &str| m.get(k).and_then(|v| v.as_f64()).unwrap();
    assert_eq!(get("target_points"), (nu * nv) as f64, "{m:?}");
    assert_eq!(get("unreachable_points"), (nu * nv) as f64, "{m:?}");
    assert_eq!(get("corner_points"), (nu * nv) as f64, "{m:?}");
    assert!(
        (get("corner_area_mm2") - get("unreachable_area_mm2")).abs() < 1e-12
            && get("corner_area_mm2") > 0.0,
        "{m:?}"
    );
    assert!(
        planned.notes.iter().any(|n| n.contains("9 of them")),
        "{:?}",
        planned.notes
    );
}
