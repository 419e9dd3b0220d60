//! Hub finishing on impeller-8+8 (coarse settings to keep the debug-profile test short):
//! every ball centre on the hub's offset surface (1e-6 mm) and at least `max(r, 2R_f − r)`
//! from the blades, no overcut, every channel machined, the residual measured.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod support;

use cam_core::MoveKind;
use cam_plan::OperationSpec;

fn spec(params: &str) -> OperationSpec {
    OperationSpec {
        name: "hub".into(),
        kind: channel_paths::HUB_FINISHING.into(),
        tool: "ball-r1".into(),
        process: support::process(),
        params: toml::from_str(params).unwrap(),
    }
}

fn metric(p: &cam_plan::PlannedOperation, name: &str) -> f64 {
    p.metrics.get(name).unwrap().as_f64().unwrap()
}

#[test]
fn impeller_8_8_hub_balls_sit_on_the_offset_hub_clear_of_the_blades() {
    let mut c = support::Ctx::new("impeller-8+8", 1.0);
    c.tool = support::tapered_t6();
    c.process.width_of_cut_mm = None;
    let cl = c.clearance();
    let ctx = plan_ctx!(c, cl);
    let op = channel_paths::build_hub_finishing(&spec("scallop_mm = 0.5\nstations = 4")).unwrap();
    let planned = op.plan(&ctx).unwrap();
    for (k, v) in planned.metrics.0.iter() {
        eprintln!("{k} = {v:?}");
    }
    for n in &planned.notes {
        eprintln!("{n}");
    }
    assert_eq!(planned.paths.len(), 8);
    let feeds = planned
        .paths
        .iter()
        .map(|p| p.moves.iter().filter(|m| m.kind == MoveKind::Feed).count())
        .sum::<usize>();
    assert!(feeds > 8 * 20, "{feeds} feed moves");
    let r = 1.0;
    let rf = c.imp.fillet_radius_mm();
    for path in &planned.paths {
        for m in path.moves.iter().filter(|m| m.kind == MoveKind::Feed) {
            let centre = m.cl.tip.coords + m.cl.axis.into_inner() * r;
            let dh = c.imp.hub().signed_distance(&centre);
            assert!((dh - r).abs() < 1e-6, "hub distance {dh}");
            let db = cl.blade_signed_distance(&nalgebra::Point3::from(centre)).0;
            assert!(db >= r.max(2.0 * rf - r) - 1e-9, "blade distance {db}");
        }
    }
    // Exact ball placement: no penetration of hub or blades (1e-6 mm).
    assert!(metric(&planned, "max_overcut_mm") < 1e-6);
    // The tool above the ball keeps the certified clearance (−tol/2).
    assert!(metric(&planned, "min_blade_clearance_mm") >= -0.5 * c.tol.machining_tol - 1e-9);
    // Upstream of the splitter one lane, beside it two.
    assert_eq!(metric(&planned, "lanes"), 3.0);
    // The residual is measured (finite, at most the ball radius where points are uncut).
    let h = metric(&planned, "max_scallop_mm");
    assert!(h.is_finite() && h > 0.0 && h <= r + 1e-12, "{h}");
}

#[test]
fn impeller_8_8_hub_is_finished_within_its_scallop_target() {
    // Every sampled hub point between the blades (the residual grid of every lane, measured
    // along the hub normal with exact ray–ball entries against the emitted ball centres) lies
    // within the scallop target of some path, and no point is left uncut.
    let mut c = support::Ctx::new("impeller-8+8", 1.0);
    c.tool = support::tapered_t6();
    // As in the default job: the blade sides keep 0.3 mm for blade finishing, 1 mm width
    // of cut (paper 003, Table 1).
    c.process.blade_allowance_mm = 0.3;
    c.process.width_of_cut_mm = Some(1.0);
    let cl = c.clearance();
    let ctx = plan_ctx!(c, cl);
    let target = 0.1;
    let op =
        channel_paths::build_hub_finishing(&spec(&format!("scallop_mm = {target}\nstations = 12")))
            .unwrap();
    let planned = op.plan(&ctx).unwrap();
    assert_eq!(metric(&planned, "skipped_locations"), 0.0);
    let h = metric(&planned, "max_scallop_mm");
    assert!(
        h <= target,
        "measured scallop {h} mm above the target {target} mm"
    );
    assert!(metric(&planned, "max_overcut_mm") < 1e-6);
}

/// Tool axes no more than `max_tilt` from the impeller axis: a machine whose tilt axis
/// reaches only that far.
#[derive(Debug)]
struct TiltCone {
    max_tilt: f64,
}

impl cam_plan::AxisReach for TiltCone {
    fn reaches(&self, axis: &nalgebra::Vector3<f64>) -> bool {
        axis.z.clamp(-1.0, 1.0).acos() <= self.max_tilt
    }
}

/// A machine that cannot tilt the tool as far as the hub finishing's first choices: the axis
/// search passes over the axes it cannot take, so every posture planned can be posted (the
/// search used to ignore the machine, and the run stopped after planning with the blocks
/// outside the travel). The cone is set below the largest tilt planned without it.
#[test]
fn hub_axes_stay_within_the_machines_reach() {
    let mut c = support::Ctx::new("impeller-8+8", 1.0);
    c.tool = support::tapered_t6();
    c.process.width_of_cut_mm = None;
    let cl = c.clearance();
    let op = channel_paths::build_hub_finishing(&spec("scallop_mm = 0.5\nstations = 4")).unwrap();
    let tilts = |p: &cam_plan::PlannedOperation| -> Vec<f64> {
        p.paths
            .iter()
            .flat_map(|path| path.moves.iter())
            .filter(|m| m.kind == MoveKind::Feed)
            .map(|m| m.cl.axis.z.clamp(-1.0, 1.0).acos())
            .collect()
    };
    let free = tilts(&op.plan(&plan_ctx!(c, cl)).unwrap());
    let mut sorted = free.clone();
    sorted.sort_by(f64::total_cmp);
    let cone = TiltCone {
        max_tilt: sorted[sorted.len() * 3 / 4],
    };
    assert!(free.iter().any(|t| *t > cone.max_tilt + 1e-3));
    let links = cam_plan::LinkStats::default();
    let ctx = cam_plan::PlanContext {
        impeller: &c.imp,
        stock: c.imp.stock(),
        tool: &c.tool,
        tolerances: &c.tol,
        process: &c.process,
        clearance: &cl,
        linker: &c.linker,
        links: &links,
        reach: Some(&cone),
    };
    let held = op.plan(&ctx).unwrap();
    let t = tilts(&held);
    assert!(
        t.len() > free.len() / 2,
        "{} of {} feed moves",
        t.len(),
        free.len()
    );
    let worst = t.iter().copied().fold(0.0, f64::max);
    assert!(
        worst <= cone.max_tilt + 1e-9,
        "{}° > {}°",
        worst.to_degrees(),
        cone.max_tilt.to_degrees()
    );
}
