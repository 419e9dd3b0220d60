#![allow(clippy::unwrap_used, clippy::expect_used)]
//! Flank finishing: exact flanking of a developable side, constraint derivatives against
//! finite differences of the whole constraint functions, SLP merit and termination.

use cam_core::CutterShape;
use flank_opt::finishing::{optimise, RunSettings};
use flank_opt::problem::{Family, FlankProblem, Mode, ProblemSettings};
use flank_opt::slp::Model;
use flank_opt::{geometry::guides_through, FlankSide, InitialPath};
use impeller_model::{Impeller, Side};

/// A 30-blade impeller like the narrow fixture; `planar` makes the blades unwrapped
/// (meridional planes) with constant thickness, so each side is a plane.
fn impeller(planar: bool) -> Impeller {
    let (wrap0, wrap1, thick) = if planar {
        (
            "[[0.0, 0.0], [1.0, 0.0]]",
            "[[0.0, 0.0], [1.0, 0.0]]",
            "[[0.0, 2.0], [1.0, 2.0]]",
        )
    } else {
        (
            "[[0.0, 0.0], [0.5, 9.0], [1.0, 20.0]]",
            "[[0.0, 0.0], [0.5, 13.0], [1.0, 20.0]]",
            "[[0.0, 2.0], [0.5, 2.4], [1.0, 2.0]]",
        )
    };
    let text = format!(
        r#"
name = "test"
fillet_radius_mm = 3.0
[hub]
type = "quarter_ellipse"
inlet_zr_mm = [70.0, 47.0]
outlet_zr_mm = [10.0, 160.0]
[shroud]
type = "quarter_ellipse"
inlet_zr_mm = [70.0, 100.0]
outlet_zr_mm = [24.0, 160.0]
[main]
count = 30
kind = "ruled"
thickness_mm = {thick}
leading_edge = "blunt"
trailing_edge = "blunt"
span_extension = 0.05
[[main.wrap]]
span = 0.0
theta_deg = {wrap0}
[[main.wrap]]
span = 1.0
theta_deg = {wrap1}
[stock]
diameter_mm = 324.0
height_mm = 74.0
"#
    );
    impeller_model::from_toml_str(&text, "test.toml").unwrap()
}

fn settings() -> ProblemSettings {
    ProblemSettings {
        overcut_tol: 0.02,
        undercut_tol: 0.02,
        hub_tol: 0.01,
        min_clearance: 0.1,
        flute_length: 60.0,
        stick_out: 70.0,
        youngs: 600e3,
        min_sample_height: 3.0,
    }
}

#[test]
fn a_cylinder_flanks_a_planar_side_exactly() {
    let imp = impeller(true);
    let side = FlankSide::new(&imp, Side::Pressure, 12, 5).unwrap();
    let run = RunSettings {
        problem: settings(),
        locations: 10,
        max_iterations: 6,
        trust_radius: 0.5,
        output_locations: 10,
    };
    let shape = CutterShape::BallEnd { radius: 2.0 };
    let res = optimise(&side, shape, InitialPath::TwoPoint, Mode::Minimax, &run).unwrap();
    let max = flank_opt::problem::deviations_max(&res.deviations);
    assert!(max < 1e-3, "largest deviation {max} mm");
    assert!(res.hub_error_mm < 0.01 + 1e-9, "hub {}", res.hub_error_mm);
    assert!(res.merit_history.windows(2).all(|w| w[1] <= w[0]));
}

#[test]
fn constraint_derivatives_match_finite_differences() {
    let imp = impeller(false);
    let side = FlankSide::new(&imp, Side::Pressure, 8, 4).unwrap();
    let shape = CutterShape::TaperedBallEnd {
        ball_radius: 2.5,
        half_angle: 2f64.to_radians(),
    };
    let (p0, p1) = side
        .initial_locations(&shape, 8, InitialPath::TwoPoint)
        .unwrap();
    let (g0, g1) = guides_through(&p0, &p1).unwrap();
    let mut st = settings();
    st.min_clearance = -50.0; // every adjacent sample within the band: a fixed row set
    for mode in [Mode::Shape, Mode::Minimax] {
        let mut prob =
            FlankProblem::new(&side, g0.clone(), g1.clone(), Family::TaperedBall, mode, st);
        let x = prob.pack(2.5, 2f64.to_radians());
        let e = prob.evaluate(&x, true).unwrap();
        let rows: Vec<_> = e.minimax.iter().chain(&e.constraints).cloned().collect();
        let n_ctrl = prob.n_ctrl();
        // r, θ, and coordinates of an inner control point of each guide.
        let vars = [0, 1, 2 + 3 * 3, 2 + 3 * 4 + 1, 2 + 3 * n_ctrl + 3 * 4 + 2];
        for &k in &vars {
            let h = if k < 2 { 1e-6 } else { 1e-5 };
            let mut xp = x.clone();
            xp[k] += h;
            let mut xm = x.clone();
            xm[k] -= h;
            let ep = prob.evaluate(&xp, false).unwrap();
            let em = prob.evaluate(&xm, false).unwrap();
            let rp: Vec<f64> = ep
                .minimax
                .iter()
                .chain(&ep.constraints)
                .map(|r| r.value)
                .collect();
            let rm: Vec<f64> = em
                .minimax
                .iter()
                .chain(&em.constraints)
                .map(|r| r.value)
                .collect();
            assert_eq!(rp.len(), rows.len());
            for (i, row) in rows.iter().enumerate() {
                let fd = (rp[i] - rm[i]) / (2.0 * h);
                let an: f64 = row.grad.iter().filter(|g| g.0 == k).map(|g| g.1).sum();
                assert!(
                    (fd - an).abs() < 1e-4 * (1.0 + an.abs()),
                    "{mode:?} row {i} var {k}: analytic {an} vs fd {fd}"
                );
            }
            if mode == Mode::Shape {
                let fd = (ep.objective.value - em.objective.value) / (2.0 * h);
                let an: f64 = e
                    .objective
                    .grad
                    .iter()
                    .filter(|g| g.0 == k)
                    .map(|g| g.1)
                    .sum();
                assert!(
                    (fd - an).abs() < 1e-6 * (1.0 + an.abs()),
                    "objective var {k}"
                );
            }
        }
    }
}

#[test]
fn slp_merit_never_rises_and_states_its_reason() {
    let imp = impeller(false);
    let side = FlankSide::new(&imp, Side::Suction, 10, 4).unwrap();
    let run = RunSettings {
        problem: settings(),
        locations: 10,
        max_iterations: 4,
        trust_radius: 0.5,
        output_locations: 10,
    };
    let shape = CutterShape::TaperedBallEnd {
        ball_radius: 2.5,
        half_angle: 2f64.to_radians(),
    };
    for mode in [Mode::Shape, Mode::Minimax] {
        let res = optimise(&side, shape, InitialPath::TwoPoint, mode, &run).unwrap();
        assert!(
            res.merit_history.windows(2).all(|w| w[1] <= w[0]),
            "{mode:?}: {:?}",
            res.merit_history
        );
        assert!(["converged", "iteration_limit", "infeasible"].contains(&res.termination.as_str()));
        assert!(res.iterations <= 4);
    }
}

/// Issue 13: every initial cutter location, from either start, has its ball tangent to the
/// hub body (the hub-tangency rows' measure, [`FlankSide::hub_body_distance`]). At impeller-30-narrow's leading edge the mid-normal start's axis passed more than a
/// ball radius beyond the hub's inlet face; the lowering bisection then stopped on the jump
/// of the hub's signed distance beyond the contour's end and left the ball 1.16 mm above the
/// hub (the two-point start 0 mm), so the minimax from it stalled.
#[test]
fn initial_balls_are_tangent_to_the_hub_from_both_starts() {
    let narrow = impeller_model::load(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/impeller-30-narrow/impeller.toml"
    ))
    .unwrap();
    for (name, imp) in [("impeller-30-narrow", narrow), ("blunt", impeller(false))] {
        for side in [Side::Pressure, Side::Suction] {
            let fs = FlankSide::new(&imp, side, 12, 4).unwrap();
            for r in [2.5, 3.0] {
                let shape = CutterShape::TaperedBallEnd {
                    ball_radius: r,
                    half_angle: 3f64.to_radians(),
                };
                for how in [InitialPath::TwoPoint, InitialPath::MidNormal] {
                    let (p0, _) = fs.initial_locations(&shape, 30, how).unwrap();
                    for (i, c) in p0.iter().enumerate() {
                        let gap = fs.hub_body_distance(c) - r;
                        assert!(
                            gap.abs() < 1e-6,
                            "{name} {side:?} r {r} {how:?} location {i}: hub gap {gap} mm"
                        );
                    }
                }
            }
        }
    }
}

/// The hub body distance is the hub distance on the channel side and continuous beyond the
/// inlet end of the hub contour, where the plain signed distance jumps (its sign flips across
/// the end normal's line while its magnitude is the distance to the end point).
#[test]
fn hub_body_distance_is_continuous_beyond_the_inlet() {
    let imp = impeller(false);
    let fs = FlankSide::new(&imp, Side::Pressure, 4, 2).unwrap();
    // Hub inlet at (z, r) = (70, 47) with an axial end tangent: its end plane is z = 70.
    let at = |z: f64, r: f64| cam_core::Vector3::new(r, 0.0, z);
    let d = 1e-6;
    for dz in [0.5, 2.0, 4.16] {
        let (above, below) = (at(70.0 + dz, 47.0 + d), at(70.0 + dz, 47.0 - d));
        assert!((fs.hub_distance(&above) - dz).abs() < 1e-5);
        assert!(
            (fs.hub_distance(&below) + dz).abs() < 1e-5,
            "the jump this guards"
        );
        assert!((fs.hub_body_distance(&above) - dz).abs() < 1e-5);
        assert!((fs.hub_body_distance(&below) - dz).abs() < 1e-5);
    }
    // Channel side and inside the hub away from the ends: the plain distance.
    for p in [at(40.0, 90.0), at(60.0, 45.0), at(30.0, 60.0)] {
        let (a, b) = (fs.hub_distance(&p), fs.hub_body_distance(&p));
        assert!((a - b).abs() < 1e-12 || (a < 0.0 && b < 0.0), "{a} {b}");
    }
}
