//! The feed direction by lean and the W walk (paper 000 §3):
//! - a hand-built row whose axes lean back against the outlet → inlet feed interferes fed
//!   that way and is clean fed the other way, and the planner feeds it the clean way (its
//!   entry, into virgin stock, gets a pilot hole);
//! - the walk takes the smallest discrete move that satisfies its criterion (one step less
//!   does not), first in the feed direction, then against it, and stops at an inadmissible
//!   candidate.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use cam_core::{CutterLocation, Point3, UnitVector3, Vector3};
use impeller_model::Stock;
use plunge_opt::axial_depth::Contact;
use plunge_opt::axis_optimisation::{fit_w_curve, moved, walk, Verdict, WalkGoal};
use plunge_opt::conventional_axes::{Posture, PostureBuilder};
use plunge_opt::entries::{EntryKind, EntryMode};
use plunge_opt::feed::{segments_by_lean, Feed};
use plunge_opt::feed_plan::{plan_feed, stroke, FeedInput};
use plunge_opt::interference::{core_travel, Material, INTERFERENCE_TRAVEL_TOL_MM};
use std::path::PathBuf;

fn fixture() -> impeller_model::Impeller {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/impeller-plunge-400");
    impeller_model::load(root.join("impeller.toml")).unwrap()
}

/// Cutter radius, centre disk radius and plunge step of the hand-built row (edge 6 mm).
const R: f64 = 10.0;
const CORE: f64 = 4.0;
const STEP: f64 = 5.0;

/// A plunge into the flat floor z = 5 of a Ø400 × 20 blank at `x`, its axis leaning by
/// `lean_deg` toward +x; the bottom disk touches the floor at its lowest rim point, and the
/// stroke starts 2 mm above the blank.
fn plunge(x: f64, lean_deg: f64) -> Posture {
    let l = lean_deg.to_radians();
    let axis = UnitVector3::new_normalize(Vector3::new(l.sin(), 0.0, l.cos()));
    let tip = Point3::new(x, 0.0, 5.0 + R * l.sin().abs());
    let start = tip + axis.into_inner() * ((22.0 - tip.z) / l.cos());
    Posture {
        m: 0.5,
        s: 0.5,
        centre: Vector3::new(x, 0.0, 5.0),
        w: Vector3::new(x, 0.0, 5.0) + axis.into_inner() * 60.0,
        cl: CutterLocation { tip, axis },
        start: CutterLocation { tip: start, axis },
        contact: Contact {
            t: 0.0,
            uv: (0.0, 0.0),
            point: Vector3::new(x, 0.0, 5.0),
            normal: Vector3::z(),
            iterations: 0,
        },
        alpha: l.abs(),
    }
}

#[test]
fn a_row_leaning_back_is_fed_the_way_it_leans() {
    let stock = Stock::cylinder(400.0, 20.0).unwrap();
    let material = Material::stock(&stock);
    // Stations in order outlet → inlet run toward −x; every axis leans 10° toward +x, i.e.
    // back against the outlet → inlet feed.
    let row: Vec<Posture> = (0..8)
        .map(|i| plunge(150.0 - STEP * i as f64, 10.0))
        .collect();
    let strokes =
        |order: &[usize]| -> Vec<_> { order.iter().map(|&i| stroke(&row[i], R, CORE)).collect() };
    // Fed outlet → inlet each plunge's centre cuts the wedge the previous one left ahead of
    // it (0.87 mm); the first drills through the blank.
    let forward: Vec<usize> = (0..row.len()).collect();
    let t = core_travel(&strokes(&forward), &material);
    // (Parallel bottom planes STEP apart along x: STEP·sin 10° apart along the axis.)
    let wedge = STEP * 10f64.to_radians().sin();
    for (i, v) in t.iter().enumerate().skip(1) {
        assert!((v - wedge).abs() < 1e-6, "plunge {i}: {v} vs {wedge}");
    }
    // Fed inlet → outlet, the way the axes lean, every plunge after the first is clean.
    let backward: Vec<usize> = (0..row.len()).rev().collect();
    let t = core_travel(&strokes(&backward), &material);
    assert!(t[0] > 10.0, "the entry drills: {}", t[0]);
    for (i, v) in t.iter().enumerate().skip(1) {
        assert!(*v <= INTERFERENCE_TRAVEL_TOL_MM, "plunge {i}: {v}");
    }
    // The planner picks that direction, and drills a pilot for the entry.
    let segs = segments_by_lean(0, &row);
    assert_eq!(segs.len(), 1);
    assert_eq!(segs[0].feed, Feed::TowardOutlet);
    let impeller = fixture();
    let builder = PostureBuilder::new(&impeller, &stock, R, 0.0, 0.5, 2.0, "test");
    let rows = vec![row.clone()];
    let plan = |mode: EntryMode, pilot_radius: Option<f64>| {
        plan_feed(&FeedInput {
            rows: &rows,
            radius: R,
            core: CORE,
            mode,
            pilot_radius,
            material,
            optimise: false,
            w_step: 1e-5,
            builder: &builder,
            admissible: &|_| true,
            operation: "test",
        })
        .unwrap()
    };
    let plan_pilot = plan(EntryMode::Pilot, Some(CORE + 0.5));
    assert_eq!(plan_pilot.segments.len(), 1);
    assert_eq!(plan_pilot.segments[0].segment.feed, Feed::TowardOutlet);
    assert_eq!(plan_pilot.segments[0].segment.stations[0], row.len() - 1);
    assert_eq!(plan_pilot.segments[0].entry, EntryKind::Pilot);
    assert_eq!(plan_pilot.pilots.len(), 1);
    assert!(plan_pilot
        .travel
        .iter()
        .all(|v| *v <= INTERFERENCE_TRAVEL_TOL_MM));
    // Without a drill (entry = "lead_in") the entry cannot be handled: the segment is fed
    // from its other end only if that end does not drill either; here both do.
    let plan_lead_in = plan(EntryMode::LeadIn, None);
    assert_eq!(plan_lead_in.segments[0].entry, EntryKind::Unhandled);
    assert!(plan_lead_in.travel[0] > 10.0);
    assert!(plan_lead_in.travel[1..]
        .iter()
        .all(|v| *v <= INTERFERENCE_TRAVEL_TOL_MM));
}

/// Six conventional plunges from m = 0.95 toward the inlet on the fixture's meridian φ = 0,
/// their shroud points 10 % of the meridian toward the inlet.
fn fixture_row<'a>(
    imp: &'a impeller_model::Impeller,
    builder: &PostureBuilder<'a>,
) -> Vec<Posture> {
    let (hub, shroud) = (imp.hub(), imp.shroud());
    (0..6)
        .map(|i| {
            let m = 0.95 - 0.003 * i as f64;
            let th = hub.meridional().param_at_fraction(m);
            let ts = shroud.meridional().param_at_fraction(m - 0.1);
            let centre: Vector3 = hub.point(th, 0.0);
            let w: Vector3 = shroud.point(ts, 0.0);
            builder.through(m, 0.5, centre, w, None).unwrap()
        })
        .collect()
}

/// A walk that may move W 50 mm and must reach a travel of 0 (the criteria below are 0 when
/// met), and one that may move it 0.01 mm only.
const FAR: WalkGoal = WalkGoal {
    reach_mm: 50.0,
    tol: 0.0,
};
const NEAR: WalkGoal = WalkGoal {
    reach_mm: 0.01,
    tol: 0.0,
};

#[test]
fn the_walk_takes_the_smallest_move_in_the_feed_direction_first() {
    let imp = fixture();
    let stock = imp.stock().clone();
    let builder = PostureBuilder::new(&imp, &stock, 15.0, 0.0, 0.5, 2.0, "test");
    let row = fixture_row(&imp, &builder);
    let curve = fit_w_curve(&row, 1e-5, "test").unwrap().unwrap();
    let i = 3;
    let p = row[i];
    // A criterion met only once the axis has turned by 0.4° from its conventional one: the
    // walk toward the inlet (this plunge's feed) must find the first discrete point past it.
    let turned = |q: &Posture| p.cl.axis.angle(&q.cl.axis);
    let need = 0.4f64.to_radians();
    let judge = |q: &Posture| Verdict::Travel((need - turned(q)).max(0.0));
    let w = walk(&builder, &curve, &p, i, Feed::TowardInlet, FAR, &judge).unwrap();
    assert!(w.toward_feed);
    assert!(turned(&w.posture) >= need);
    let (back, _) = moved(&builder, &curve, &p, i, Feed::TowardInlet, w.steps - 1).unwrap();
    assert!(
        turned(&back) < need,
        "one step less must not satisfy the criterion"
    );
    // Fed the other way the same criterion is met toward the outlet first.
    let v = walk(&builder, &curve, &p, i, Feed::TowardOutlet, FAR, &judge).unwrap();
    assert!(v.toward_feed);
    // A criterion met only toward the inlet is found against an outlet-ward feed: the
    // second direction.
    let toward_inlet = |q: &Posture| {
        let (c, _) = moved(&builder, &curve, &p, i, Feed::TowardInlet, 1).unwrap();
        // Closer to the first inlet-ward candidate than to the plunge itself.
        if q.w.metric_distance(&c.w) < q.w.metric_distance(&p.w) && turned(q) >= need {
            Verdict::Travel(0.0)
        } else {
            Verdict::Travel(1.0)
        }
    };
    let u = walk(
        &builder,
        &curve,
        &p,
        i,
        Feed::TowardOutlet,
        FAR,
        &toward_inlet,
    )
    .unwrap();
    assert!(!u.toward_feed);
    assert!(u.param > curve.params[i]);
    // An inadmissible candidate stops the walk; so does the reach.
    assert!(walk(&builder, &curve, &p, i, Feed::TowardInlet, FAR, &|_| {
        Verdict::Inadmissible
    })
    .is_none());
    assert!(walk(&builder, &curve, &p, i, Feed::TowardInlet, NEAR, &judge).is_none());
}
