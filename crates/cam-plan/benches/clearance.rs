//! Cost of the design clearance query on the `impeller-8+8` fixture: building the design
//! mesh (chord 0.01 mm), and one `clearance` / `is_clear` of the T5 tapered ball end (R1.5,
//! 2°, Ø6 shank, shrink-fit holder) at a posture near the hub mid-channel and at one far above
//! the blank; then the fixture's T6 (R1, 3°, 20 mm flutes) at the postures the planners ask
//! about: near the hub inside a channel (axis along the hub normal), beside a blade (ball
//! 0.3 mm off the pressure side, axis along the side's ruling), and far from everything.
//!
//! `cargo bench -p cam-plan --bench clearance -- --warm-up-time 1 --measurement-time 3`
#![allow(clippy::unwrap_used, clippy::expect_used)]

use cam_core::{Cutter, CutterLocation, CutterShape, HolderSegment, Point3, Vector3};
use cam_plan::clearance::DesignMesh;
use cam_plan::{ClearanceOptions, DesignClearance, Tool};
use criterion::{criterion_group, criterion_main, Criterion};
use impeller_model::Side;
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

    // T6 of the fixture's process plan.
    let mut t6 = tool.clone();
    t6.number = 6;
    t6.cutter.shape = CutterShape::TaperedBallEnd {
        ball_radius: 1.0,
        half_angle: 3f64.to_radians(),
    };
    let q6 = DesignClearance::with_mesh(&imp, q.mesh().clone(), &t6, ClearanceOptions::default())
        .expect("query");
    let hub_in_channel = CutterLocation::new(p + n * 0.2, n).expect("cl");
    // Beside main blade 0's pressure side at mid-chord, low on the span.
    let blade = imp.main().blade();
    let side = blade.pressure();
    let ((u0, u1), (v0, v1)) = side.domain();
    let u = 0.5 * (u0 + u1);
    let foot = side.point(u, v0 + 0.15 * (v1 - v0));
    let out = blade
        .outward_normal(Side::Pressure, u, v0 + 0.15 * (v1 - v0))
        .expect("normal");
    let ruling = (side.point(u, v1) - side.point(u, v0)).normalize();
    let centre = foot + out * 1.3;
    let beside_blade = CutterLocation::new(Point3::from(centre - ruling), ruling).expect("cl");
    let far6 = CutterLocation::new(Point3::new(0.0, 0.0, 80.0), Vector3::z()).expect("cl");
    for (name, cl) in [
        ("t6_near_hub", hub_in_channel),
        ("t6_beside_blade", beside_blade),
        ("t6_far_above", far6),
    ] {
        g.bench_function(format!("clearance_{name}"), |b| {
            b.iter(|| q6.clearance(black_box(&cl)))
        });
        g.bench_function(format!("is_clear_{name}"), |b| {
            b.iter(|| q6.is_clear(black_box(&cl), -0.005))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
