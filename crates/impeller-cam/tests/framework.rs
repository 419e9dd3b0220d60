//! The operations framework end to end with a test-only operation (never registered in the
//! binary, never in a fixture job): a ring of arcs above the blade tips, one arc per main
//! channel made by rotational copy, planned through the registry passed to
//! `impeller_cam::run_job_with`, linked over the safety surface, written to the CL file and
//! the program, verified, and reported with its kind's metrics and plots; a step it plans with
//! a further tool of the job is posted as its own operation before it. Also: job-file errors
//! of the kind's own keys name the file, line and key.
#![allow(clippy::unwrap_used, clippy::panic)] // test code

mod common;

use common::repo;

use cam_core::{CutterLocation, Move, Point3, ToolPath, Vector3};
use cam_plan::{
    order, params, pattern, Builder, Metrics, Operation, OperationSpec, PlanContext, PlanError,
    PlannedOperation, PlannedStep, Plot, PlotKind, PlotSeries, StepTool, Tool,
};
use impeller_cam::{run_job_with, Job};
use serde::Deserialize;

/// The kind's own keys.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct RingParams {
    /// Ring radius (mm).
    radius_mm: f64,
    /// Depth below the blank's top (mm).
    depth_mm: f64,
    /// Chords per channel.
    #[serde(default = "default_chords")]
    chords: usize,
    /// A further tool of the job: a step with it runs the same ring 2 mm further in, before
    /// the operation.
    #[serde(default)]
    pre_tool: Option<String>,
}

fn default_chords() -> usize {
    8
}

#[derive(Debug)]
struct Ring {
    name: String,
    tool: String,
    params: RingParams,
}

impl Operation for Ring {
    fn kind(&self) -> &'static str {
        "test_ring"
    }
    fn name(&self) -> &str {
        &self.name
    }
    fn tool(&self) -> &str {
        &self.tool
    }
    fn plan(&self, ctx: &PlanContext<'_>) -> Result<PlannedOperation, PlanError> {
        self.ring(ctx, self.params.radius_mm, &self.tool)
    }
    fn step_tools(&self) -> Vec<StepTool> {
        self.params
            .pre_tool
            .iter()
            .map(|t| StepTool {
                key: "pre_tool".into(),
                tool: t.clone(),
            })
            .collect()
    }
    fn plan_with_steps(
        &self,
        ctx: &PlanContext<'_>,
        tools: &[&Tool],
    ) -> Result<(PlannedOperation, Vec<PlannedStep>), PlanError> {
        let main = self.plan(ctx)?;
        let steps = tools
            .iter()
            .map(|t| {
                Ok(PlannedStep {
                    name: format!("{}-pre", self.name),
                    kind: "test_pre".into(),
                    tool: t.name().into(),
                    process: cam_plan::Process {
                        spindle_rpm: 8000.0,
                        ..*ctx.process
                    },
                    before: true,
                    planned: self.ring(ctx, self.params.radius_mm - 2.0, t.name())?,
                })
            })
            .collect::<Result<_, PlanError>>()?;
        Ok((main, steps))
    }
}

impl Ring {
    /// The ring of arcs at `radius` with `tool`.
    fn ring(
        &self,
        ctx: &PlanContext<'_>,
        radius: f64,
        tool: &str,
    ) -> Result<PlannedOperation, PlanError> {
        let p = &self.params;
        let set = ctx.impeller.main();
        let pitch = set.pitch_rad();
        let z = ctx.stock.z_range().1 - p.depth_mm;
        let tilt = 10f64.to_radians();
        // Channel 0's arc: one pitch of the ring, axis tilted 10° outward.
        let mut arc = ToolPath::new(format!("{} arc", self.name), tool);
        for k in 0..=p.chords {
            let phi = pitch * k as f64 / p.chords as f64;
            let (s, c) = phi.sin_cos();
            let cl = CutterLocation::new(
                Point3::new(radius * c, radius * s, z),
                Vector3::new(tilt.sin() * c, tilt.sin() * s, tilt.cos()),
            )
            .map_err(|e| PlanError::cam(&self.name, e))?;
            arc.moves.push(Move::feed(cl));
        }
        let order = order::angular_sequence(set.count(), 0);
        let paths = pattern::copy_to(&arc, pitch, &order);
        let mut metrics = Metrics::new();
        let mean_radius = paths
            .iter()
            .flat_map(|q| q.moves.iter())
            .map(|m| m.cl.tip.x.hypot(m.cl.tip.y))
            .sum::<f64>()
            / (paths.len() * (p.chords + 1)) as f64;
        let min_clearance = paths
            .iter()
            .flat_map(|q| q.moves.iter())
            .map(|m| ctx.clearance.clearance(&m.cl).distance_mm)
            .fold(f64::INFINITY, f64::min);
        metrics
            .count("arcs", paths.len())
            .number("ring_radius_mm", mean_radius)
            .number("min_design_clearance_mm", min_clearance)
            .flag("clear_of_design", min_clearance > 0.0)
            .text("ring_termination", "complete");
        let plot = Plot {
            title: "arc radius per channel".into(),
            kind: PlotKind::Lines {
                x_label: "channel".into(),
                y_label: "radius (mm)".into(),
                series: vec![PlotSeries {
                    label: "first tip".into(),
                    points: paths
                        .iter()
                        .enumerate()
                        .map(|(i, q)| [i as f64, q.moves[0].cl.tip.x.hypot(q.moves[0].cl.tip.y)])
                        .collect(),
                }],
                equal_aspect: false,
            },
        };
        Ok(PlannedOperation {
            paths,
            metrics,
            plots: vec![plot],
            notes: vec![],
        })
    }
}

fn build_ring(spec: &OperationSpec) -> Result<Box<dyn Operation>, PlanError> {
    let params: RingParams = params::parse(spec)?;
    if !(params.radius_mm.is_finite() && params.radius_mm > 0.0) {
        return Err(PlanError::param(&spec.name, "radius_mm", "must be > 0"));
    }
    if params.chords == 0 {
        return Err(PlanError::param(&spec.name, "chords", "must be at least 1"));
    }
    Ok(Box::new(Ring {
        name: spec.name.clone(),
        tool: spec.tool.clone(),
        params,
    }))
}

static TEST_REGISTRY: &[(&str, Builder)] = &[("test_ring", build_ring)];

fn scratch(name: &str) -> common::Scratch {
    common::scratch("impeller-cam-fw", name)
}

fn job_text(ops: &str) -> String {
    format!(
        "name = \"ring-op\"\nimpeller = {:?}\nmachine = {:?}\ndialect = \"linuxcnc\"\n\
         tools = {:?}\n\n[verification]\nresolution_mm = 0.5\n\n\
         [[tools]]\nnumber = 3\nname = \"flat-d6\"\nshape = \"flat_end\"\ndiameter_mm = 6.0\n\
         flute_length_mm = 20.0\nshank_diameter_mm = 6.0\nstick_out_mm = 40.0\n\
         tool_length_mm = 100.0\nteeth = 2\n\n{ops}",
        repo()
            .join("fixtures/impeller-8+8/impeller.toml")
            .display()
            .to_string(),
        repo()
            .join("fixtures/machines/xyzac-trt.toml")
            .display()
            .to_string(),
        "unused"
    )
    .replace("tools = \"unused\"\n", "")
}

const RING_OP: &str = "[[operations]]\nname = \"ring\"\nkind = \"test_ring\"\ntool = \"flat-d6\"\n\
    radius_mm = 30.0\ndepth_mm = 0.5\n\n[operations.process]\nspindle_rpm = 10000.0\n\
    feed_per_tooth_mm = 0.04\n";

#[test]
fn a_registered_operation_is_planned_linked_posted_verified_and_reported() {
    let dir = scratch("e2e");
    let job_path = dir.join("job.toml");
    std::fs::write(
        &job_path,
        job_text(&format!("{RING_OP}coolant = \"flood\"\n")),
    )
    .unwrap();
    let job = Job::from_file_with(&job_path, TEST_REGISTRY).unwrap();
    assert_eq!(job.operations.len(), 1);
    // stock_allowance (default 0.5) fills the allowances the row does not give.
    assert_eq!(job.operations[0].process.blade_allowance_mm, 0.5);
    let out = dir.join("out");
    let report = run_job_with(&job, &out, TEST_REGISTRY).unwrap();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let op = &json["operations"][0];
    assert_eq!(op["name"], "ring");
    assert_eq!(op["kind"], "test_ring");
    assert_eq!(op["tool"], "flat-d6");
    assert!(op["plan_ms"].as_f64().unwrap() > 0.0, "{op}");
    // The kind's metrics, flattened into the operation object (xtask reads
    // operations.ring.<metric>): counts, numbers, booleans and texts.
    assert_eq!(op["arcs"], 8);
    assert!(
        (op["ring_radius_mm"].as_f64().unwrap() - 30.0).abs() < 1e-9,
        "{op}"
    );
    assert_eq!(op["clear_of_design"], true);
    assert_eq!(op["ring_termination"], "complete");
    // Moves: approach (safety point, 2 mm above, plunge), 8 arcs of 9 points whose first
    // points are reached by the links, links between arcs, final retract.
    let moves = op["moves"].as_u64().unwrap() as usize;
    assert_eq!(moves, report.operations[0].moves);
    let cls = std::fs::read_to_string(out.join("toolpath.cls")).unwrap();
    assert_eq!(cls.matches("GOTO/").count(), moves);
    assert!(cls.contains("LOADTL/3"), "tool number from the job");
    // Feed rate: 10000 rpm · 0.04 mm · 2 teeth = 800 mm/min; cutting time from that rate.
    assert!(cls.contains("FEDRAT/MMPM,800"), "{cls}");
    let cut_len = 8.0 * 8.0 * 2.0 * 30.0 * (std::f64::consts::PI / 8.0 / 8.0).sin();
    let t = op["cutting_time_s"].as_f64().unwrap();
    assert!(
        t > 60.0 * cut_len / 800.0,
        "{t} s for {cut_len} mm at 800 mm/min"
    );
    // The program is written and verification found no overcut and no collision.
    assert!(out.join("program.ngc").is_file());
    // The process row's coolant is switched on with the operation (it was always M9).
    let program = std::fs::read_to_string(out.join("program.ngc")).unwrap();
    assert!(program.contains(" M8"), "flood coolant");
    let v = &json["verification"];
    assert!(v["max_overcut_mm"].as_f64().unwrap() <= 0.5, "{v}");
    assert_eq!(v["collisions"], 0, "{v}");
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains("ring: top view") && html.contains("ring: meridional view"));
    assert!(html.contains("arc radius per channel"));
}

fn parse_err(text: &str) -> String {
    let dir = scratch("err");
    let path = dir.join("job.toml");
    std::fs::write(&path, text).unwrap();
    Job::from_file_with(&path, TEST_REGISTRY)
        .unwrap_err()
        .to_string()
}

/// The line of the first line of `text` that starts with `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines()
        .position(|l| l.trim_start().starts_with(needle))
        .unwrap()
        + 1
}

#[test]
fn a_step_with_a_further_tool_is_posted_as_its_own_operation_before_it() {
    let pre_tool = "[[tools]]\nnumber = 4\nname = \"flat-d4\"\nshape = \"flat_end\"\n\
        diameter_mm = 4.0\nflute_length_mm = 20.0\nshank_diameter_mm = 4.0\n\
        stick_out_mm = 40.0\ntool_length_mm = 100.0\nteeth = 2\n\n";
    let op = RING_OP.replace(
        "depth_mm = 0.5\n",
        "depth_mm = 0.5\npre_tool = \"flat-d4\"\n",
    );
    let dir = scratch("steps");
    let job_path = dir.join("job.toml");
    std::fs::write(&job_path, job_text(&format!("{pre_tool}{op}"))).unwrap();
    let job = Job::from_file_with(&job_path, TEST_REGISTRY).unwrap();
    let out = dir.join("out");
    let report = run_job_with(&job, &out, TEST_REGISTRY).unwrap();
    // The step first, with its own tool, kind, feeds and metrics; then the operation.
    let names: Vec<&str> = report.operations.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["ring-pre", "ring"]);
    let pre = &report.operations[0];
    assert_eq!(
        (pre.kind.as_str(), pre.tool.as_str()),
        ("test_pre", "flat-d4")
    );
    assert!(pre.moves > 0);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert!((json["operations"][0]["ring_radius_mm"].as_f64().unwrap() - 28.0).abs() < 1e-9);
    // Two tool changes in that order; 8000 rpm · 0.04 mm · 2 teeth = 640 mm/min for the step.
    let program = std::fs::read_to_string(out.join("program.ngc")).unwrap();
    let t4 = program.find("T4 M6").unwrap();
    let t3 = program.find("T3 M6").unwrap();
    assert!(t4 < t3, "the step's tool change comes first");
    assert!(program[t4..t3].contains("S8000"));
    let cls = std::fs::read_to_string(out.join("toolpath.cls")).unwrap();
    assert!(
        cls.contains("LOADTL/4") && cls.contains("FEDRAT/MMPM,640"),
        "{cls}"
    );
    assert_eq!(json["verification"]["collisions"], 0);
    // A further tool that is not a job tool is named with the file, line and key.
    let text =
        job_text(&RING_OP.replace("depth_mm = 0.5\n", "depth_mm = 0.5\npre_tool = \"nope\"\n"));
    let err = parse_err(&text);
    let line = line_of(&text, "pre_tool");
    assert!(
        err.contains(&format!("job.toml:{line}: operations[0].pre_tool")) && err.contains("nope"),
        "{err}"
    );
}

#[test]
fn kind_key_errors_name_file_line_and_key() {
    // An unknown kind key (the kind's parser rejects it).
    let text = job_text(&RING_OP.replace("depth_mm", "dept_mm"));
    let err = parse_err(&text);
    let line = line_of(&text, "dept_mm");
    assert!(
        err.contains(&format!("job.toml:{line}: operations[0].dept_mm")),
        "{err}"
    );
    // A value the kind's builder rejects, named by the builder's key.
    let text = job_text(&RING_OP.replace("radius_mm = 30.0", "radius_mm = -1.0"));
    let err = parse_err(&text);
    let line = line_of(&text, "radius_mm");
    assert!(
        err.contains(&format!("job.toml:{line}: operations[0].radius_mm")),
        "{err}"
    );
    // A wrong type of a kind key.
    let text = job_text(&RING_OP.replace("depth_mm = 0.5", "depth_mm = \"deep\""));
    let err = parse_err(&text);
    assert!(
        err.contains("job.toml:") && err.contains("depth_mm"),
        "{err}"
    );
    // A missing kind key.
    let text = job_text(&RING_OP.replace("depth_mm = 0.5\n", ""));
    let err = parse_err(&text);
    assert!(err.contains("depth_mm") && err.contains("ring"), "{err}");
}

#[test]
fn a_turned_start_stock_follows_the_shroud_and_bad_keys_are_named() {
    // `[stock] start = "turned"`: the blank faced at the design's top (43 mm) and turned to
    // the shroud contour (outer radius 38.5 mm at the outlet, 22 mm at the inlet) instead of
    // the file's Ø79 × 44 cylinder.
    let stock = "[stock]\nstart = \"turned\"\n\n";
    let dir = scratch("turned");
    let path = dir.join("job.toml");
    std::fs::write(&path, job_text(&format!("{stock}{RING_OP}"))).unwrap();
    let job = Job::from_file_with(&path, TEST_REGISTRY).unwrap();
    let imp = impeller_cam::pipeline::model(&job).unwrap();
    let s = imp.stock();
    assert!((s.z_range().1 - 43.0).abs() < 1e-9, "{:?}", s.z_range());
    assert!((s.max_radius() - 38.5).abs() < 0.01, "{}", s.max_radius());
    assert!((s.radius_at(42.9).unwrap() - 22.0).abs() < 0.05);
    // The shroud contour lies inside the turned stock.
    let shroud = imp.shroud().meridional();
    for k in 0..=64 {
        let p = shroud.point_at_fraction(k as f64 / 64.0);
        assert!(s.radius_at(p.x).unwrap() >= p.y - 1e-9, "at z {}", p.x);
    }
    // The default starts from the file's blank.
    std::fs::write(&path, job_text(RING_OP)).unwrap();
    let job = Job::from_file_with(&path, TEST_REGISTRY).unwrap();
    let imp = impeller_cam::pipeline::model(&job).unwrap();
    assert!((imp.stock().max_radius() - 39.5).abs() < 1e-9);
    // A negative allowance is named with file, line and key; an unknown start kind too.
    let text = job_text("[stock]\nstart = \"turned\"\nturning_allowance_mm = -1.0\n\n");
    let err = parse_err(&text);
    let line = line_of(&text, "turning_allowance_mm");
    assert!(
        err.contains(&format!("job.toml:{line}: stock.turning_allowance_mm")),
        "{err}"
    );
    let err = parse_err(&job_text("[stock]\nstart = \"lathe\"\n\n"));
    assert!(err.contains("job.toml:") && err.contains("lathe"), "{err}");
}
