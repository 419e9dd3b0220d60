#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
//! Channel roughing on the default impeller (impeller-8+8, splitters: paper 003's three
//! areas), planned through the `Operation` trait with a hand-built context.

use cam_core::{Cutter, CutterShape, HolderSegment, Tolerances};
use cam_plan::{
    ClearanceOptions, DesignClearance, Linker, OperationSpec, PartSet, PlanContext, Process,
    SafetySurface, Tool,
};
use channel_paths::{build_channel_roughing, CHANNEL_ROUGHING};

fn tool(shape: CutterShape) -> Tool {
    // Short tool and holder: the test runs in the dev profile, where each clearance query
    // costs its number of axis samples.
    let mut cutter = Cutter::new("rough", shape, 40.0, 2.0, 45.0).unwrap();
    cutter.holder = vec![HolderSegment {
        bottom_radius: 6.0,
        top_radius: 6.0,
        length: 4.0,
    }];
    Tool {
        number: 1,
        cutter,
        teeth: 2,
        tool_length_mm: 100.0,
        plunge_edge_length_mm: None,
    }
}

fn process() -> Process {
    Process {
        spindle_rpm: 12000.0,
        feed_per_tooth_mm: 0.04,
        plunge_feed_per_tooth_mm: None,
        depth_of_cut_mm: Some(40.0),
        width_of_cut_mm: None,
        blade_allowance_mm: 0.3,
        hub_allowance_mm: 0.3,
        rapid_mm_per_min: 10000.0,
    }
}

fn spec(params: &str) -> OperationSpec {
    OperationSpec {
        name: "rough".into(),
        kind: CHANNEL_ROUGHING.into(),
        tool: "rough".into(),
        process: process(),
        params: toml::from_str(params).unwrap(),
    }
}

/// Plans channel roughing with `params` in a context around the impeller's own stock (safety
/// surface 10 mm over it), reporting progress to `progress`.
fn plan_rough(
    imp: &impeller_model::Impeller,
    tool: &Tool,
    tol: &Tolerances,
    process: &Process,
    clearance: &DesignClearance<'_>,
    params: &str,
    progress: Option<&dyn cam_plan::PlanProgress>,
) -> cam_plan::PlannedOperation {
    try_plan_rough(imp, tool, tol, process, clearance, params, progress).unwrap()
}

/// [`plan_rough`], the operation's refusal kept.
fn try_plan_rough(
    imp: &impeller_model::Impeller,
    tool: &Tool,
    tol: &Tolerances,
    process: &Process,
    clearance: &DesignClearance<'_>,
    params: &str,
    progress: Option<&dyn cam_plan::PlanProgress>,
) -> Result<cam_plan::PlannedOperation, cam_plan::PlanError> {
    let stock = imp.stock();
    let linker = Linker::new(SafetySurface::around_stock(stock, 10.0).unwrap());
    let ctx = PlanContext {
        impeller: imp,
        stock,
        tool,
        tolerances: tol,
        process,
        clearance,
        linker: &linker,
        links: &cam_plan::LinkStats::default(),
        reach: None,
        remaining: None,
        progress,
    };
    build_channel_roughing(&spec(params)).unwrap().plan(&ctx)
}

/// The refusal of channel roughing with `tool` and `process` on the default impeller.
fn rough_refusal(tool: &Tool, process: &Process) -> String {
    let imp = impeller_model::fixtures::default_impeller().unwrap();
    let tol = Tolerances::default();
    let clearance = DesignClearance::new(&imp, tool, ClearanceOptions::default()).unwrap();
    match try_plan_rough(
        &imp,
        tool,
        &tol,
        process,
        &clearance,
        "scallop_mm = 0.5",
        None,
    ) {
        Ok(plan) => panic!(
            "planned {} moves",
            plan.paths.iter().map(|p| p.moves.len()).sum::<usize>()
        ),
        Err(e) => e.to_string(),
    }
}

/// A depth of cut deeper than the flutes is refused, naming the field and the tool: the
/// shank would rub on every level's wall (and a tapered ball's blade offset, the cone's
/// radius at that depth, grew until nothing fitted: 200 mm on impeller-8+8's Ø3 tapered ball
/// planned no move, and the finishing tools then met the whole blank).
#[test]
fn a_depth_of_cut_beyond_the_flutes_is_refused() {
    let tool = tool(CutterShape::BallEnd { radius: 1.0 });
    let mut proc_ = process();
    proc_.depth_of_cut_mm = Some(40.5);
    let e = rough_refusal(&tool, &proc_);
    assert!(
        e.contains("depth_of_cut_mm") && e.contains("deeper than the flutes"),
        "{e}"
    );
}

/// A cutter that fits nowhere between the blades (a Ø16 ball in channels 4–13 mm wide) is
/// refused: nothing would be roughed.
#[test]
fn a_cutter_that_fits_nowhere_is_refused() {
    let tool = tool(CutterShape::BallEnd { radius: 8.0 });
    let e = rough_refusal(&tool, &process());
    assert!(
        e.contains("fits nowhere") && e.contains("nothing is roughed"),
        "{e}"
    );
}

/// A ball end, one level on the hub offset (about 2 s in the dev profile): the scallop
/// measured over the machinable region within the target, clear of the blades.
#[test]
fn rough_default_impeller_within_scallop_and_clear_of_blades() {
    let imp = impeller_model::fixtures::default_impeller().unwrap();
    let tool = tool(CutterShape::BallEnd { radius: 1.0 });
    let tol = Tolerances::default();
    let proc_ = process();
    let clearance = DesignClearance::new(
        &imp,
        &tool,
        ClearanceOptions {
            sample_tol_mm: 0.2,
            ..ClearanceOptions::default()
        },
    )
    .unwrap();
    let recorder = cam_plan::ProgressLog::default();
    let plan = plan_rough(
        &imp,
        &tool,
        &tol,
        &proc_,
        &clearance,
        "scallop_mm = 0.3",
        Some(&recorder),
    );
    let m = &plan.metrics;
    let get = |k: &str| m.get(k).and_then(|v| v.as_f64()).unwrap();
    eprintln!("{m:?}");
    assert_eq!(plan.paths.len(), 8);
    assert!(get("levels") >= 1.0);
    // Progress: the start, then every level once, up to all of them.
    let reports = recorder.reports();
    let n = get("levels") as usize;
    assert_eq!(reports.len(), n + 1, "{reports:?}");
    let mut done: Vec<usize> = reports.iter().map(|r| r.1).collect();
    done.sort_unstable();
    assert_eq!(done, (0..=n).collect::<Vec<_>>(), "{reports:?}");
    assert!(reports.iter().all(|r| r.0 == "levels" && r.2 == n));
    // Measured scallop within the target (plus the sampling of discrete cutter positions).
    assert!(
        get("max_scallop_mm") <= 0.3 + 0.01,
        "{}",
        get("max_scallop_mm")
    );
    // No gouge: every location clears the true blades by at least the allowance's margin.
    assert!(
        get("min_blade_clearance_mm") >= 0.0,
        "{}",
        get("min_blade_clearance_mm")
    );
    assert!(get("saving_ratio") > 0.0);
}

/// Issue 11: on impeller-8+8 with a tapered ball end (the fixture's T5: r 1.5, 2°, 20 mm of
/// flutes) the planner used to skip locations with no clear axis (the flutes above the level
/// against the nearest blade) and then measured a whole level of scallop there. Now the
/// levels are trimmed to where the cutter fits: two levels of 7 mm (the second on the hub
/// offset), 0.5 mm scallop target.
///
/// Properties, with their tolerances:
/// - no location is skipped, and the reasons add up to the total;
/// - every cutting posture of channel 0 is clear of hub and blades by the design clearance
///   query (`≥ 0`), and the cutter alone keeps the blade allowance from the blades within
///   half the machining tolerance (`≥ 0.3 − 0.005 mm`, the roughing contract);
/// - the scallop measured over the machinable region is within the target plus 0.01 mm
///   (discrete cutter positions);
/// - the unmachinable area is reported, positive and a small part of the level area.
///
/// About 6 s in the dev profile (short holder, two levels, coarse ball sampling).
#[test]
fn rough_tapered_ball_trimmed_to_where_the_cutter_fits() {
    let imp = impeller_model::fixtures::default_impeller().unwrap();
    let tool = tool(CutterShape::TaperedBallEnd {
        ball_radius: 1.5,
        half_angle: 2f64.to_radians(),
    });
    let mut cutter_only = tool.clone();
    cutter_only.cutter.overall_length = cutter_only.cutter.flute_length;
    cutter_only.cutter.holder.clear();
    let tol = Tolerances::default();
    let mut proc_ = process();
    proc_.depth_of_cut_mm = Some(7.0);
    // Coarse sampling of the swept balls (0.2 mm; the mesh chord stays 0.05 mm) keeps the
    // dev-profile queries cheap; the check below samples the cutter as the operation does.
    let options = ClearanceOptions {
        sample_tol_mm: 0.2,
        ..ClearanceOptions::default()
    };
    let clearance = DesignClearance::new(&imp, &tool, options).unwrap();
    let cutter_blades = DesignClearance::with_mesh(
        &imp,
        clearance.mesh().clone(),
        &cutter_only,
        ClearanceOptions {
            parts: PartSet::BLADES,
            ..options
        },
    )
    .unwrap();
    let plan = plan_rough(
        &imp,
        &tool,
        &tol,
        &proc_,
        &clearance,
        "scallop_mm = 0.5",
        None,
    );
    let m = &plan.metrics;
    let get = |k: &str| m.get(k).and_then(|v| v.as_f64()).unwrap();
    eprintln!("{m:?}");
    assert_eq!(get("levels"), 2.0);
    assert_eq!(get("skipped_locations"), 0.0);
    assert_eq!(
        get("skipped_cutter_blocked") + get("skipped_shank_or_holder"),
        get("skipped_locations")
    );
    let allowance_min = proc_.blade_allowance_mm - 0.5 * tol.machining_tol;
    let mut feeds = 0;
    for mv in &plan.paths[0].moves {
        if !mv.kind.at_cutting_feed() {
            continue;
        }
        feeds += 1;
        let c = clearance.clearance(&mv.cl).distance_mm;
        assert!(c >= 0.0, "posture {:?} penetrates by {c} mm", mv.cl);
        let b = cutter_blades.clearance(&mv.cl).distance_mm;
        assert!(
            b >= allowance_min,
            "cutter at {:?} only {b} mm from the blades",
            mv.cl
        );
    }
    assert!(feeds > 100, "{feeds} cutting moves");
    assert!(get("min_blade_clearance_mm") >= allowance_min);
    assert!(
        get("max_scallop_mm") <= 0.5 + 0.01,
        "{}",
        get("max_scallop_mm")
    );
    let (area, out) = (get("level_area_mm2"), get("unmachinable_area_mm2"));
    assert!(out > 0.0 && out < 0.2 * area, "{out} of {area} mm²");
    // Issue 37: the located runs' axes smoothed about the ball centres (the postures above,
    // all clear, are the smoothed ones): fewer direction changes, each one left reported
    // with its reason, no ball centre moved.
    let (before, after) = (get("axis_reversals_before"), get("axis_reversals_after"));
    assert!(after < before, "{before} -> {after}");
    let kept = cam_plan::SmoothingSummary::kept_in(&plan.metrics).unwrap();
    assert_eq!(kept as f64, after);
    // The written paths, cut into cutting runs wherever a move is not a cut (a link at feed
    // between two located runs, a plunge, retract or rapid), change the direction of their
    // axis angles exactly as often as the planner reports: every link it joins runs with is
    // marked as one (cam_core::MoveKind::Link), so the post counts a reversal across it as
    // at a link, and what it counts inside cuts is the planner's kept reversals.
    let mut written = 0;
    for path in &plan.paths {
        let mut run: Vec<cam_core::CutterLocation> = Vec::new();
        let mut flush = |run: &mut Vec<cam_core::CutterLocation>| {
            let angles = cam_plan::axis_smoothing::spherical_angles(run);
            for pick in [|a: &(f64, f64)| a.0, |a: &(f64, f64)| a.1] {
                let x: Vec<f64> = angles.iter().map(pick).collect();
                written += cam_plan::axis_smoothing::reversal_indices(&x).len();
            }
            run.clear();
        };
        for m in &path.moves {
            match m.kind {
                cam_core::MoveKind::Feed => run.push(m.cl),
                cam_core::MoveKind::Link | cam_core::MoveKind::Plunge => {
                    flush(&mut run);
                    run.push(m.cl);
                }
                cam_core::MoveKind::Rapid | cam_core::MoveKind::Retract => flush(&mut run),
            }
        }
        flush(&mut run);
    }
    assert!(get("in_lane_links") > 0.0);
    assert_eq!(written as f64, after);
    assert!(get("axis_smoothing_runs_smoothed") >= 1.0);
    assert!(get("axis_smoothing_max_centre_shift_mm") <= 1e-6);
    assert!(get("saving_ratio") > 0.0);
}

#[test]
fn unknown_keys_and_bad_values_are_errors() {
    assert!(build_channel_roughing(&spec("scallop_mm = 0.05\nfoo = 1")).is_err());
    assert!(build_channel_roughing(&spec("scallop_mm = -1.0")).is_err());
    assert!(build_channel_roughing(&spec("scallop_mm = 0.1\nlinking = \"spiral\"")).is_err());
    assert!(build_channel_roughing(&spec("scallop_mm = 0.1\nlinking = \"one_way\"")).is_ok());
}
