//! Blade-root finishing on the fixtures: ball centres at ball-radius distance from hub and
//! blade side, accessible, no overcut; at blunt trailing edges the path stops where the ball
//! stops fitting; stations no tool axis reaches are skipped and reported, not fatal.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod support;

use cam_core::MoveKind;
use cam_plan::{DesignClearance, OperationSpec, PlannedOperation};
use channel_paths::blade_root::{plan_side, LeftOut, SidePlan};
use impeller_model::{query::blade_side_distance, Blade, BladeEdge, BladeSet, Impeller, Side};
use nalgebra::Vector3;
use nurbs::closest::SurfaceProjector;
use nurbs::NurbsSurface;

fn spec(params: &str) -> OperationSpec {
    OperationSpec {
        name: "root".into(),
        kind: channel_paths::BLADE_ROOT_FINISHING.into(),
        tool: "ball-r1".into(),
        process: support::process(),
        params: toml::from_str(params).unwrap(),
    }
}

fn metric(p: &PlannedOperation, name: &str) -> f64 {
    p.metrics.get(name).unwrap().as_f64().unwrap()
}

/// The smallest distance (mm) from a point to the boundary of `blade`: both side patches and
/// the faces of its blunt edges (global closest points, computed here apart from the
/// planner). A ball of radius `r` centred there stays out of the blade exactly when this is at
/// least `r` (see `channel_paths::ball_fit`).
fn boundary_distance(blade: &Blade) -> impl Fn(&Vector3<f64>) -> f64 + '_ {
    let faces: Vec<SurfaceProjector> = [BladeEdge::Leading, BladeEdge::Trailing]
        .iter()
        .filter_map(|&e| blade.edge_face(e).unwrap())
        .map(|f| SurfaceProjector::new(&f))
        .collect();
    move |c| {
        [Side::Pressure, Side::Suction]
            .iter()
            .map(|&s| blade.projector(s))
            .chain(&faces)
            .map(|p| p.closest_point(c).distance)
            .fold(f64::INFINITY, f64::min)
    }
}

/// Plans one side of main blade 0 with the context's tool.
fn side(c: &support::Ctx, cl: &DesignClearance<'_>, side: Side, stations: usize) -> SidePlan {
    let ctx = plan_ctx!(c, cl);
    let order = c.imp.blades_in_order();
    let n = order.len();
    plan_side(
        &ctx,
        "root",
        "main blade 0",
        &order[0],
        side,
        &order[1 % n],
        &order[n - 1],
        stations,
        1.5f64.to_radians(),
    )
    .unwrap()
}

#[test]
fn centres_are_at_ball_radius_from_hub_and_blade_and_accessible() {
    // Ball radius = the 1 mm fillet (paper 003 T7): the centre is on both offset surfaces.
    let c = support::Ctx::new("impeller-8+8", 1.0);
    let cl = c.clearance();
    let order = c.imp.blades_in_order();
    for s in [Side::Pressure, Side::Suction] {
        let plan = side(&c, &cl, s, 8);
        // Every station keeps a position; refined where the chord strays from the root curve.
        assert_eq!(plan.kept, 8);
        assert!(plan.left_out.is_empty(), "{:?}", plan.left_out);
        let count: usize = plan.runs.iter().map(Vec::len).sum();
        assert!(count > 8, "{count} positions");
        // Between two positions the ball centre runs on their chord: its midpoint stays within
        // machining_tol of both offset surfaces (the distances are 1-Lipschitz, so a chord
        // within tol of the root curve keeps them within tol of the ball radius).
        // (Midpoints within a ball radius of the hub's inlet plane are left out: beyond the
        // end of the hub contour its signed distance is not the offset surface's.)
        let tol = c.tol.machining_tol;
        let hub = c.imp.hub().meridional();
        let z_inlet = hub
            .point_at_fraction(0.0)
            .x
            .max(hub.point_at_fraction(1.0).x);
        let mut checked = 0;
        for run in &plan.runs {
            for w in run.windows(2) {
                let mid = 0.5 * (w[0].centre + w[1].centre);
                if mid.z > z_inlet - 1.0 {
                    continue;
                }
                checked += 1;
                let dh = c.imp.hub().signed_distance(&mid);
                let (_, db) = blade_side_distance(&order[0], s, &mid, None);
                assert!(
                    (dh - 1.0).abs() <= tol + 1e-9,
                    "chord midpoint hub distance {dh}"
                );
                assert!(
                    (db - 1.0).abs() <= tol + 1e-9,
                    "chord midpoint blade distance {db}"
                );
            }
        }
        assert!(checked >= 6, "{checked} chords checked");
        for p in plan.runs.iter().flatten() {
            assert!((p.axis.norm() - 1.0).abs() < 1e-12);
            assert!(p.clearance >= -c.tol.machining_tol, "{}", p.clearance);
            assert!(p.overcut < 1e-6, "{}", p.overcut);
            if p.centre.z > z_inlet - 1.0 {
                continue;
            }
            let dh = c.imp.hub().signed_distance(&p.centre);
            let (_, db) = blade_side_distance(&order[0], s, &p.centre, None);
            assert!((dh - 1.0).abs() < 1e-6, "hub distance {dh}");
            assert!((db - 1.0).abs() < 1e-6, "blade distance {db}");
        }
    }
}

#[test]
fn full_plan_on_impeller_8_8_has_no_overcut() {
    let c = support::Ctx::new("impeller-8+8", 1.0);
    let cl = c.clearance();
    let ctx = plan_ctx!(c, cl);
    let op = channel_paths::build_blade_root_finishing(&spec("stations = 3")).unwrap();
    let planned = op.plan(&ctx).unwrap();
    // 8 main + 8 splitter blades, two sides each.
    assert_eq!(planned.paths.len(), 32);
    let over = metric(&planned, "max_overcut_mm");
    let under = metric(&planned, "max_undercut_mm");
    assert!(over < 1e-6, "{over}");
    assert!(
        under < 1e-6,
        "ball = fillet leaves the fillet exactly: {under}"
    );
    let clear = metric(&planned, "min_blade_clearance_mm");
    assert!(clear >= -c.tol.machining_tol, "{clear}");
    // Every station of the four reference sides (main 0 and splitter 0, each with its own
    // leading edge) keeps a position.
    assert_eq!(metric(&planned, "stations_kept"), 12.0);
    assert_eq!(metric(&planned, "skipped_stations"), 0.0);
    assert_eq!(metric(&planned, "unfit_stations"), 0.0);
}

#[test]
fn unknown_keys_and_bad_values_are_errors() {
    assert!(channel_paths::build_blade_root_finishing(&spec("statons = 3")).is_err());
    assert!(channel_paths::build_blade_root_finishing(&spec("step_deg = 0.0")).is_err());
}

/// impeller-5-freeform: blunt 2 mm trailing edges ending where the hub contour ends
/// (r = 60 mm), fillet 2 mm, ball r2. At the trailing edge itself no ball touches both the
/// hub and the pressure side (the hub's offset surface ends before the side's): the planner
/// used to refuse the whole operation there ("the hub and blade offset surfaces do not
/// intersect here", station 5/6, u = 1). Now the pressure side's path stops at the edge's
/// start, the station is reported, and no ball centre comes within the ball radius of the
/// blade (sides and trailing-edge face) or the hub by more than the machining tolerance.
#[test]
fn blunt_trailing_edge_stops_the_path_at_the_edge_start() {
    let c = support::Ctx::new("impeller-5-freeform", 2.0);
    let cl = c.clearance();
    let ctx = plan_ctx!(c, cl);
    let blade = c.imp.main().blade();
    assert!(
        blade.edge_face(BladeEdge::Trailing).unwrap().is_some(),
        "blunt"
    );
    let op = channel_paths::build_blade_root_finishing(&spec("stations = 6")).unwrap();
    let planned = op.plan(&ctx).unwrap();
    assert_eq!(planned.paths.len(), 10, "5 blades, two sides");
    assert!(metric(&planned, "unfit_stations") >= 1.0);
    assert!(
        planned
            .notes
            .iter()
            .any(|n| n.contains("pressure side") && n.contains("left out")),
        "{:?}",
        planned.notes
    );
    // Every ball the reference blade's two paths place (feed and plunge end points; the
    // copies #0 are not turned).
    let tol = c.tol.machining_tol;
    let r = 2.0;
    let distance = boundary_distance(blade);
    let mut balls = 0;
    for path in planned.paths.iter().filter(|p| p.name.ends_with(" #0")) {
        for m in &path.moves {
            if !matches!(m.kind, MoveKind::Feed | MoveKind::Link | MoveKind::Plunge) {
                continue;
            }
            balls += 1;
            let centre = m.cl.tip.coords + m.cl.axis.into_inner() * r;
            let d = distance(&centre);
            assert!(
                d >= r - tol,
                "{}: ball centre {d} mm from the blade",
                path.name
            );
            let dh = cl.hub_signed_distance(&cam_plan::Point3::from(centre));
            assert!(dh >= r - tol, "{}: {dh} mm from the hub", path.name);
        }
    }
    assert!(balls > 12, "{balls}");
    // The pressure side stops short of u = 1, where no ball touches hub and side.
    let pressure = side(&c, &cl, Side::Pressure, 6);
    let last = pressure.runs.last().unwrap().last().unwrap();
    let ((_, u1), _) = blade.side(Side::Pressure).domain();
    assert!(last.u < u1 && last.u > u1 - 0.01, "stops at {}", last.u);
    assert!(matches!(
        pressure.left_out.last().unwrap().reason,
        LeftOut::NoSpine
    ));
}

/// A hand-built blade whose blunt trailing edge hooks over its pressure side: the 8 + 8
/// main blade with the suction side's last row of control points moved 0.5 mm downstream
/// and 1.6 mm across to the pressure side's outside (the blade is 0.8 mm thick), so the edge
/// face and the suction lip overhang the pressure side's root. The pressure side's offset
/// runs into that overhang: the planner used to place ball centres there, inside the ball
/// radius of the face and the lip. Now the path stops where the ball still fits, the stations
/// beyond are reported, and every placed ball keeps the ball radius from the whole blade.
#[test]
fn hooked_blunt_edge_never_gets_a_ball_inside_it() {
    let base = support::fixture("impeller-8+8");
    let b = base.main().blade();
    let s = b.suction();
    let (n_u, n_v) = (s.n_u(), s.n_v());
    let ((_, u1), (v0, v1)) = b.pressure().domain();
    let out = b
        .outward_normal(Side::Pressure, u1, 0.5 * (v0 + v1))
        .unwrap();
    let mut ctrl = s.control_points().to_vec();
    for j in 0..n_v {
        let last = (n_u - 1) * n_v + j;
        let along = (ctrl[last] - ctrl[last - n_v]).normalize();
        ctrl[last] += along * 0.5 + out * 1.6;
    }
    let hooked = NurbsSurface::from_flat(
        s.knots_u().clone(),
        s.knots_v().clone(),
        ctrl,
        s.weights().map(|w| w.to_vec()),
    )
    .unwrap();
    let blade = Blade::from_sides(b.kind(), b.pressure().clone(), hooked, None).unwrap();
    let imp = Impeller::from_parts(
        "hooked trailing edge",
        base.hub().clone(),
        base.shroud().clone(),
        BladeSet::new(base.main().count(), blade).unwrap(),
        None,
        base.fillet_radius_mm(),
        base.stock().clone(),
    )
    .unwrap();
    let mut c = support::Ctx::new("impeller-8+8", 1.0);
    c.imp = imp;
    let cl = c.clearance();
    let r = 1.0;
    let tol = c.tol.machining_tol;
    let blade = c.imp.main().blade().clone();
    let plan = side(&c, &cl, Side::Pressure, 24);
    let distance = boundary_distance(&blade);
    assert!(
        plan.left_out
            .iter()
            .any(|l| matches!(l.reason, LeftOut::BallMeetsBlade { .. })),
        "{:?}",
        plan.left_out
    );
    for p in plan.runs.iter().flatten() {
        let d = distance(&p.centre);
        assert!(
            d >= r - tol,
            "u = {}: ball centre {d} mm from the blade",
            p.u
        );
    }
    // The run ends between the last uniform station where the ball fits and the first where
    // it does not (the bisection moves it toward the edge).
    let last = plan.runs.last().unwrap().last().unwrap();
    let first_out = plan
        .left_out
        .iter()
        .find(|l| l.u > last.u)
        .expect("a station beyond the end");
    let gap = u1 / 23.0;
    assert!(
        last.u < first_out.u && last.u > first_out.u - gap - 1e-12,
        "{} {}",
        last.u,
        first_out.u
    );
}

/// impeller-30-narrow (30 blades, 3 mm fillet) with the test tool (ball r1, Ø20 holder 25 mm
/// above the tip): over the middle of the root no tool axis up to C_max clears the holder.
/// The planner used to refuse the whole operation at the first such station; now each is
/// skipped, the path is split there with a retract and an approach, and a note names the
/// blade, side, station, ball centre and the largest ball radius that would fit there.
#[test]
fn inaccessible_stations_are_skipped_and_reported_not_fatal() {
    let c = support::Ctx::new("impeller-30-narrow", 1.0);
    let cl = c.clearance();
    let ctx = plan_ctx!(c, cl);
    let op = channel_paths::build_blade_root_finishing(&spec("stations = 5")).unwrap();
    let planned = op.plan(&ctx).unwrap();
    let skipped = metric(&planned, "skipped_stations");
    assert!(skipped >= 1.0, "{skipped}");
    assert!(metric(&planned, "stations_kept") >= 1.0);
    let notes: Vec<&String> = planned
        .notes
        .iter()
        .filter(|n| n.contains("skipped"))
        .collect();
    assert_eq!(notes.len() as f64, skipped, "{notes:?}");
    for n in &notes {
        assert!(
            n.contains("main blade 0")
                && n.contains("station ")
                && n.contains("ball centre (")
                && n.contains("largest ball radius"),
            "{n}"
        );
    }
    // A side with a skipped station inside it is split: retract and approach mid-path.
    assert!(metric(&planned, "path_splits") >= 1.0);
    let split = planned.paths.iter().any(|p| {
        let k = p.moves.len();
        p.moves[1..k - 1]
            .iter()
            .any(|m| m.kind == MoveKind::Retract)
    });
    assert!(split, "no retract inside a path");
    assert!(metric(&planned, "max_overcut_mm") < 1e-6);
    assert!(metric(&planned, "min_blade_clearance_mm") >= -c.tol.machining_tol);
}
