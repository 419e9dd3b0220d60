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
