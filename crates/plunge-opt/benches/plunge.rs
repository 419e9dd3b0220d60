//! Criterion benchmarks: the axial-depth solve of one plunge (goal ≤ 2 µs) and planning one
//! whole channel section of `fixtures/impeller-plunge-400` with the Ø30 cutter.
//!
//! `cargo bench -p plunge-opt --bench plunge -- --warm-up-time 1 --measurement-time 3`

#![allow(clippy::expect_used, clippy::unwrap_used)]

use cam_core::{Cutter, CutterShape, HolderSegment, Point3, Tolerances, Vector3};
use cam_plan::{
    ClearanceOptions, DesignClearance, Linker, OperationSpec, PlanContext, Process, SafetySurface,
    Tool,
};
use criterion::{criterion_group, criterion_main, Criterion};
use plunge_opt::axial_depth::{solve_contact, Floor, RevolvedFloor};
use std::hint::black_box;
use std::path::PathBuf;

fn depth(c: &mut Criterion) {
    let hub = impeller_model::MeridionalCurve::quarter_ellipse([125.0, 40.0], [20.0, 200.0])
        .expect("contour");
    let floor = RevolvedFloor::offset(&hub, 0.5);
    let t = hub.param_at_fraction(0.6);
    let fp = floor.eval(t, 0.2);
    let q: Vector3 = (fp.n + fp.su.normalize() * 0.15).normalize();
    let p = Point3::from(fp.p + fp.n * 30.0);
    let cold = solve_contact(&floor, &p, &q, 15.0, None).expect("contact");
    c.bench_function("depth_solve_cold_seed", |b| {
        b.iter(|| solve_contact(&floor, black_box(&p), black_box(&q), 15.0, None))
    });
    // Warm start from the neighbouring plunge, as the optimisation walk and rows do.
    let q2: Vector3 = (fp.n + fp.su.normalize() * 0.16).normalize();
    c.bench_function("depth_solve_warm", |b| {
        b.iter(|| {
            solve_contact(
                &floor,
                black_box(&p),
                black_box(&q2),
                15.0,
                Some((cold.uv, cold.t)),
            )
        })
    });
}

/// A flat-end tool with 140 mm stick-out: radii and lengths `[radius, flute length, shank
/// radius, holder radius, holder length]` (mm), teeth, plunge edge length.
fn flat_tool(number: u32, name: &str, dims: [f64; 5], teeth: u32, edge: Option<f64>) -> Tool {
    let [radius, flute, shank, holder, holder_length] = dims;
    let mut cutter =
        Cutter::new(name, CutterShape::FlatEnd { radius }, flute, shank, 140.0).expect("cutter");
    cutter.holder = vec![HolderSegment {
        bottom_radius: holder,
        top_radius: holder,
        length: holder_length,
    }];
    Tool {
        number,
        cutter,
        teeth,
        tool_length_mm: 210.0, // gauge length: the post's, not used in planning
        plunge_edge_length_mm: edge,
    }
}

fn channel(c: &mut Criterion) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/impeller-plunge-400");
    let impeller = impeller_model::load(root.join("impeller.toml")).expect("fixture");
    // The stock of `job.toml`: the blank turned to the shroud contour (from the
    // uncut blank most plunges of the section are refused by the stock check, and planning
    // measures mostly that).
    let stock = impeller.turned_stock(0.0).expect("turned stock");
    // The Ø30 plunge cutter and its pilot drill of `fixtures/tools/plunge-cutters.toml`.
    let tool = flat_tool(
        31,
        "plunge-d30",
        [15.0, 45.0, 14.0, 25.0, 45.0],
        3,
        Some(8.0),
    );
    let drill = flat_tool(34, "drill-d16", [8.0, 90.0, 8.0, 16.0, 40.0], 2, None);
    let process = Process {
        spindle_rpm: 3000.0,
        feed_per_tooth_mm: 0.1,
        plunge_feed_per_tooth_mm: Some(0.06),
        depth_of_cut_mm: None,
        width_of_cut_mm: None,
        blade_allowance_mm: 1.0,
        hub_allowance_mm: 0.5,
        rapid_mm_per_min: 10_000.0,
    };
    let spec = OperationSpec {
        name: "plunge-d30".into(),
        kind: plunge_opt::KIND.into(),
        tool: "plunge-d30".into(),
        process,
        params: toml::from_str(
            "[pilot]\ntool = \"drill-d16\"\nspindle_rpm = 4000.0\nfeed_per_tooth_mm = 0.1",
        )
        .expect("params"),
    };
    let op = plunge_opt::PlungeRoughing::from_spec(&spec).expect("op");
    let clearance =
        DesignClearance::new(&impeller, &tool, ClearanceOptions::default()).expect("clearance");
    let linker = Linker::new(SafetySurface::around_stock(&stock, 10.0).expect("safety"));
    let tolerances = Tolerances::default();
    let ctx = PlanContext {
        impeller: &impeller,
        stock: &stock,
        tool: &tool,
        tolerances: &tolerances,
        process: &process,
        clearance: &clearance,
        linker: &linker,
        links: &cam_plan::LinkStats::default(),
        reach: None,
        remaining: None,
        progress: None,
    };
    let mut g = c.benchmark_group("plan");
    g.sample_size(10);
    g.bench_function("channel_section_d30", |b| {
        b.iter(|| {
            op.plan_section(black_box(&ctx), Some(&drill))
                .expect("plan")
        })
    });
    g.finish();
}

criterion_group!(benches, depth, channel);
criterion_main!(benches);
