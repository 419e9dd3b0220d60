//! The stiffness indicator against closed-form beam solutions and the published comparison.
#![allow(clippy::approx_constant)] // 3.14 mm is a published cutter radius, not π.

use cam_core::{Cutter, CutterShape};
use cutter_stiffness::{cutter_beam, ConicalCutter, RitzOptions, RitzSolution};
use proptest::prelude::*;
use std::f64::consts::PI;

const E_CARBIDE: f64 = 600e3; // N/mm²

fn deg(d: f64) -> f64 {
    d.to_radians()
}

#[test]
fn cylinder_gives_three_ei_over_l_cubed_to_1e9() {
    for &(r, l) in &[(1.0, 20.0), (3.75, 40.0), (6.0, 80.0)] {
        let c = ConicalCutter::new(r, 0.0, l, E_CARBIDE).unwrap();
        let rep = c.report(&RitzOptions::default()).unwrap();
        let k = 3.0 * E_CARBIDE * (PI * r.powi(4) / 4.0) / l.powi(3);
        assert!(
            (rep.stiffness_n_per_mm / k - 1.0).abs() < 1e-9,
            "r={r} l={l}"
        );
        assert!((rep.exact_n_per_mm / k - 1.0).abs() < 1e-12);
    }
}

#[test]
fn default_settings_are_within_0_1_percent_over_the_stated_range() {
    let mut worst: f64 = 0.0;
    for i in 0..=5 {
        for j in 0..=8 {
            for m in 0..=6 {
                let r = 1.0 + i as f64;
                let theta = deg(j as f64);
                let l = 20.0 + 10.0 * m as f64;
                let c = ConicalCutter::new(r, theta, l, E_CARBIDE).unwrap();
                let rep = c.report(&RitzOptions::default()).unwrap();
                let rel = (rep.stiffness_n_per_mm / rep.exact_n_per_mm - 1.0).abs();
                worst = worst.max(rel);
                assert!(rel < 1e-3, "r={r} θ={j}° L={l}: rel {rel}");
            }
        }
    }
    // The adaptive term count actually converges far below the requirement.
    assert!(worst < 1e-8, "worst relative error {worst}");
}

#[test]
fn published_comparison_taper_more_than_doubles_stiffness() {
    // Conical ball end r = 3.14 mm, θ = 3° vs cylindrical r = 3.75 mm, both L = 40 mm:
    // about 2.28 times as stiff.
    let cone = ConicalCutter::new(3.14, deg(3.0), 40.0, E_CARBIDE).unwrap();
    let cyl = ConicalCutter::new(3.75, 0.0, 40.0, E_CARBIDE).unwrap();
    let opts = RitzOptions::default();
    let ratio = cone.report(&opts).unwrap().stiffness_n_per_mm
        / cyl.report(&opts).unwrap().stiffness_n_per_mm;
    assert!((ratio - 2.28).abs() < 0.01, "ratio {ratio}");
}

#[test]
fn ritz_gradient_matches_finite_differences_and_closed_form() {
    let opts = RitzOptions {
        terms: Some(14),
        ..Default::default()
    };
    let base = ConicalCutter::new(3.0, deg(5.0), 45.0, E_CARBIDE).unwrap();
    let rep = base.report(&opts).unwrap();
    let k = |c: ConicalCutter| c.report(&opts).unwrap().stiffness_n_per_mm;
    let h = 1e-5;
    let fd_r = (k(ConicalCutter {
        bottom_radius: 3.0 + h,
        ..base
    }) - k(ConicalCutter {
        bottom_radius: 3.0 - h,
        ..base
    })) / (2.0 * h);
    let hd = 1e-4; // degrees
    let fd_t = (k(ConicalCutter {
        half_angle: base.half_angle + deg(hd),
        ..base
    }) - k(ConicalCutter {
        half_angle: base.half_angle - deg(hd),
        ..base
    })) / (2.0 * hd);
    assert!((rep.d_stiffness_d_radius / fd_r - 1.0).abs() < 1e-6);
    assert!((rep.d_stiffness_d_half_angle_deg / fd_t - 1.0).abs() < 1e-6);
    let (ex_r, ex_t) = base.exact_gradient();
    assert!((rep.d_stiffness_d_radius / ex_r - 1.0).abs() < 1e-6);
    assert!((rep.d_stiffness_d_half_angle_deg / (ex_t * PI / 180.0) - 1.0).abs() < 1e-6);
}

#[test]
fn catalogue_tapered_ball_end_has_shank_and_flute_sections() {
    let cutter = Cutter::new(
        "tbe",
        CutterShape::TaperedBallEnd {
            ball_radius: 3.0,
            half_angle: deg(3.0),
        },
        35.0,
        5.0,
        60.0,
    )
    .unwrap();
    let beam = cutter_beam(&cutter, E_CARBIDE).unwrap();
    assert_eq!(beam.sections.len(), 2);
    assert!((beam.length() - 57.0).abs() < 1e-12); // stick-out minus ball radius
    let ritz = RitzSolution::solve(&beam, &RitzOptions::default()).unwrap();
    let exact = beam.exact_stiffness();
    assert!((ritz.stiffness / exact - 1.0).abs() < 1e-9);
    // A straight shank of the flute's bottom radius throughout is less stiff.
    let cyl = Cutter::new("cyl", CutterShape::BallEnd { radius: 3.0 }, 35.0, 3.0, 60.0).unwrap();
    assert!(cutter_beam(&cyl, E_CARBIDE).unwrap().exact_stiffness() < exact);
}

#[test]
fn invalid_inputs_are_typed_errors() {
    assert!(ConicalCutter::new(0.0, 0.0, 10.0, 1.0).is_err());
    assert!(ConicalCutter::new(1.0, deg(95.0), 10.0, 1.0).is_err());
    assert!(ConicalCutter::new(1.0, 0.0, f64::NAN, 1.0).is_err());
    assert!(ConicalCutter::new(1.0, 0.0, 10.0, 0.0).is_err());
    let short = Cutter::new("s", CutterShape::BallEnd { radius: 3.0 }, 2.0, 3.0, 10.0).unwrap();
    assert!(matches!(
        cutter_beam(&short, E_CARBIDE),
        Err(cutter_stiffness::StiffnessError::UnsupportedCutter(_))
    ));
}

proptest! {
    #[test]
    fn ritz_is_an_upper_bound_close_to_exact(r in 0.5f64..8.0, t in 0.0f64..10.0, l in 10.0f64..120.0) {
        let c = ConicalCutter::new(r, deg(t), l, E_CARBIDE).unwrap();
        let rep = c.report(&RitzOptions::default()).unwrap();
        prop_assert!(rep.stiffness_n_per_mm >= rep.exact_n_per_mm * (1.0 - 1e-12));
        prop_assert!((rep.stiffness_n_per_mm / rep.exact_n_per_mm - 1.0).abs() < 1e-6);
        prop_assert!((c.exact_stiffness() / rep.exact_n_per_mm - 1.0).abs() < 1e-12);
    }
}
