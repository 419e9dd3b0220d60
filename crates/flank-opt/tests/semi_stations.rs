#![allow(clippy::unwrap_used, clippy::expect_used)]
//! The written semi-finishing pass follows its two-point tangency solution: between two
//! written locations the solution halfway lies within the job's chord tolerance of the
//! straight move. On the NUMECA AutoGrid export of a 12 + 12 impeller (rounded leading
//! edges, Ø401) the side's normal turns around the nose between two of the 30 even rulings,
//! and the straight move between them cut 0.75 mm into the nose (the verification reported
//! a 2.97 mm overcut at 1 mm resolution and withheld the program).

#[path = "../../impeller-model/tests/import_common/mod.rs"]
mod import_common;

use cam_core::CutterShape;
use flank_opt::semi::{chord_deviation, pass_stations, tangency_station};
use impeller_model::Side;

const CHORD_MM: f64 = 0.01;

#[test]
fn written_moves_follow_the_tangency_solution_around_a_rounded_leading_edge() {
    if import_common::skip_without_shared_data() {
        return;
    }
    let imp = impeller_model::load(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/impeller-autoblade-12+12/impeller.toml"
    ))
    .unwrap();
    let blade = imp.main().blade();
    // The job's R6 tapered ball (2°) with 0.2 mm of blade allowance, on a mid-span strip.
    let shape = CutterShape::TaperedBallEnd {
        ball_radius: 6.0,
        half_angle: 2f64.to_radians(),
    };
    let r = 6.0;
    for side in [Side::Pressure, Side::Suction] {
        let strip = (0.4, 0.6);
        let st = pass_stations(blade, side, strip, &shape, 0.2, 30, CHORD_MM).unwrap();
        assert!(
            st.len() > 30,
            "{side:?}: no refinement ({} stations)",
            st.len()
        );
        let mut worst_even = 0.0f64;
        for w in st.windows(2) {
            let mid =
                tangency_station(blade, side, strip, &shape, 0.2, 0.5 * (w[0].u + w[1].u)).unwrap();
            let e = chord_deviation(&w[0], &mid, &w[1], r);
            assert!(
                e <= CHORD_MM,
                "{side:?}: {e} mm between u = {} and {}",
                w[0].u,
                w[1].u
            );
        }
        // The even rulings alone: around the nose the straight move leaves the solution by
        // millimetres (what the refinement is for).
        let ((u0, u1), _) = blade.side(side).domain();
        let even: Vec<_> = (0..30)
            .map(|i| {
                let u = u0 + (u1 - u0) * i as f64 / 29.0;
                tangency_station(blade, side, strip, &shape, 0.2, u).unwrap()
            })
            .collect();
        for w in even.windows(2) {
            let mid =
                tangency_station(blade, side, strip, &shape, 0.2, 0.5 * (w[0].u + w[1].u)).unwrap();
            worst_even = worst_even.max(chord_deviation(&w[0], &mid, &w[1], r));
        }
        eprintln!(
            "{side:?}: {} stations, even rulings deviate up to {worst_even:.3} mm",
            st.len()
        );
        assert!(
            worst_even > 1.0,
            "{side:?}: even rulings deviate {worst_even} mm"
        );
    }
}
