#![allow(clippy::unwrap_used, clippy::expect_used)]
//! One SLP iteration (model evaluation with derivatives, one clarabel LP, the trial
//! evaluation) of the shape-and-path problem on the fixture impeller-30-narrow: 30 cutter
//! locations (182 variables), 24 × 8 accuracy samples, hub and clearance rows.
//! Run: `cargo bench -p flank-opt --bench slp -- --warm-up-time 1 --measurement-time 3`.

use cam_core::CutterShape;
use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use flank_opt::geometry::guides_through;
use flank_opt::problem::{Family, FlankProblem, Mode, ProblemSettings};
use flank_opt::slp::{solve, SlpOptions};
use flank_opt::{FlankSide, InitialPath};
use impeller_model::Side;

fn bench(c: &mut Criterion) {
    let imp = impeller_model::load(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/impeller-30-narrow/impeller.toml"
    ))
    .unwrap();
    let side = FlankSide::new(&imp, Side::Pressure, 24, 8).unwrap();
    let shape = CutterShape::TaperedBallEnd {
        ball_radius: 3.0,
        half_angle: 3f64.to_radians(),
    };
    let (p0, p1) = side
        .initial_locations(&shape, 30, InitialPath::TwoPoint)
        .unwrap();
    let (g0, g1) = guides_through(&p0, &p1).unwrap();
    let settings = ProblemSettings {
        overcut_tol: 0.02,
        undercut_tol: 0.02,
        hub_tol: 0.01,
        min_clearance: 0.1,
        flute_length: 60.0,
        stick_out: 70.0,
        youngs: 600e3,
        min_sample_height: 3.0,
    };
    let n = 2 + 6 * 30;
    let mut scale = vec![1.0; n];
    scale[1] = 0.02;
    let opts = SlpOptions {
        max_iterations: 1,
        radius: 0.5,
        min_radius: 1e-4,
        tol: 1e-9,
        penalty: 100.0,
        feas_tol: 1e-3,
        scale,
        lower: vec![f64::NEG_INFINITY; n],
        upper: vec![f64::INFINITY; n],
    };
    c.bench_function("flank_opt/slp_iteration_30_locations", |b| {
        b.iter_batched(
            || {
                let prob = FlankProblem::new(
                    &side,
                    g0.clone(),
                    g1.clone(),
                    Family::TaperedBall,
                    Mode::Shape,
                    settings,
                );
                let x = prob.pack(3.0, 3f64.to_radians());
                (prob, x)
            },
            |(mut prob, x)| solve(&mut prob, x, &opts).unwrap().iterations,
            BatchSize::SmallInput,
        )
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
