//! Cost of the design clearance query on the `impeller-8+8` fixture: building the design
//! mesh (chord 0.01 mm), and one `clearance` / `is_clear` of the T5 tapered ball end (R1.5,
//! 2°, Ø6 shank, shrink-fit holder) at a posture near the hub mid-channel and at one far above
//! the blank.
//!
//! `cargo bench -p cam-plan --bench clearance -- --warm-up-time 1 --measurement-time 3`
#![allow(clippy::unwrap_used, clippy::expect_used)]

use cam_core::{Cutter, CutterLocation, CutterShape, HolderSegment, Point3, Vector3};
use cam_plan::clearance::DesignMesh;
use cam_plan::{ClearanceOptions, DesignClearance, Tool};
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use std::sync::Arc;

fn bench(c: &mut Criterion) {
    let imp = impeller_model::fixtures::default_impeller().expect("fixture");
    let mut g = c.benchmark_group("clearance");
    g.sample_size(10);
    g.bench_function("design_mesh_chord_0.01", |b| {
        b.iter(|| DesignMesh::new(black_box(&imp), 0.01).expect("mesh"))
    });
    let mut cutter = Cutter::new(
        "T5",
        CutterShape::TaperedBallEnd {
            ball_radius: 1.5,
            half_angle: 2f64.to_radians(),
        },
        20.0,
        3.0,
        35.0,
    )
    .expect("cutter");
    cutter.holder = vec![
        HolderSegment {
            bottom_radius: 10.5,
            top_radius: 13.5,
            length: 38.0,
        },
        HolderSegment {
            bottom_radius: 13.5,
            top_radius: 13.5,
            length: 42.0,
        },
    ];
    let tool = Tool {
        number: 5,
        cutter,
        teeth: 3,
        tool_length_mm: 115.0,
        plunge_edge_length_mm: None,
    };
    let mesh = Arc::new(DesignMesh::new(&imp, 0.01).expect("mesh"));
    let q =
        DesignClearance::with_mesh(&imp, mesh, &tool, ClearanceOptions::default()).expect("query");
    // Near the hub mid-way between two blades, axis along the hub normal tilted outward.
    let (t0, t1) = imp.hub().meridional().domain();
    let t = 0.5 * (t0 + t1);
    let phi = 0.5 * imp.main().pitch_rad() * 0.5;
    let p = Point3::from(imp.hub().point(t, phi));
    let n = imp.hub().normal(t, phi);
    let near = CutterLocation::new(p + n * 0.3, n).expect("cl");
    let far = CutterLocation::new(Point3::new(0.0, 0.0, 80.0), Vector3::z()).expect("cl");
    g.sample_size(30);
    g.bench_function("clearance_near_hub", |b| {
        b.iter(|| q.clearance(black_box(&near)))
    });
    g.bench_function("is_clear_near_hub", |b| {
        b.iter(|| q.is_clear(black_box(&near), 0.0))
    });
    g.bench_function("clearance_far_above", |b| {
        b.iter(|| q.clearance(black_box(&far)))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
