use super::*;

/// A folder of its own per call, with `imp.toml`, `../m.toml` (the LinuxCNC sample machine)
/// and `a.cls` for jobs in `<folder>/y/job.toml`.
fn job_folder(tag: &str) -> PathBuf {
    static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let d = std::env::temp_dir().join(format!("impeller-cam-job-{}-{n}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(d.join("y")).unwrap();
    std::fs::write(d.join("y/imp.toml"), "").unwrap();
    std::fs::write(
        d.join("m.toml"),
        include_str!("../../embedded/machines/xyzac-trt.toml"),
    )
    .unwrap();
    std::fs::write(d.join("y/a.cls"), "GOTO/1,2,3\n").unwrap();
    d
}

#[test]
fn paths_resolve_against_the_job_folder() {
    let d = job_folder("paths");
    let job = Job::from_toml_str(
        "name = \"j\"\nimpeller = \"imp.toml\"\nmachine = \"../m.toml\"\n[[cl_files]]\npath = \"a.cls\"\n",
        &d.join("y/job.toml"),
    )
    .unwrap();
    assert_eq!(job.impeller.unwrap(), d.join("y/imp.toml"));
    assert_eq!(job.machine.unwrap(), d.join("y/../m.toml"));
    assert_eq!(job.cl_files, vec![d.join("y/a.cls")]);
    assert_eq!(job.dialect, "linuxcnc");
}

/// Inputs are checked when the job is read, before anything runs, each error naming the job
/// file, the line and the key: the dialect (`haas` used to be found after planning, leaving
/// `toolpath.cls` behind), missing files, an invalid machine file, a job with nothing to
/// machine (it used to run `0 operation(s)` and exit 0).
#[test]
fn inputs_are_checked_before_anything_runs() {
    let d = job_folder("inputs");
    let job = d.join("y/job.toml");
    let cl = "[[cl_files]]\npath = \"a.cls\"\n";
    let err = |text: &str| Job::from_toml_str(text, &job).unwrap_err().to_string();
    let e = err(&format!("name = \"j\"\ndialect = \"haas\"\n{cl}"));
    let at = format!("{}:2: dialect: unknown dialect `haas`", job.display());
    assert!(e.starts_with(&at), "{e}");
    let e = err(&format!("machine = \"../none.toml\"\n{cl}"));
    assert!(
        e.starts_with(&format!("{}:1: machine: ", job.display())) && e.contains("none.toml"),
        "{e}"
    );
    let e = err(&format!("impeller = \"none.toml\"\n{cl}"));
    assert!(
        e.starts_with(&format!("{}:1: impeller: ", job.display())),
        "{e}"
    );
    let e = err("name = \"j\"\n\n[[cl_files]]\npath = \"b.cls\"\n");
    assert!(
        e.starts_with(&format!("{}:4: cl_files[0].path: ", job.display())) && e.contains("b.cls"),
        "{e}"
    );
    // The machine file's own errors name its line and key.
    let text = include_str!("../../embedded/machines/xyzac-trt.toml")
        .replace("kinematics = \"trivial\"", "kinematics = \"trivkins\"");
    std::fs::write(d.join("bad.toml"), &text).unwrap();
    let e = err(&format!("machine = \"../bad.toml\"\n{cl}"));
    let line = text
        .lines()
        .position(|l| l.contains("kinematics = \"trivkins\""))
        .unwrap()
        + 1;
    assert!(
        e.starts_with(&format!(
            "{}:1: machine: invalid machine file: ",
            job.display()
        )) && e.contains(&format!("bad.toml:{line}"))
            && e.contains("program.kinematics"),
        "{e}"
    );
    let e = err("name = \"j\"\n");
    assert!(
        e.starts_with(&format!("{}:0: operations: no operations", job.display())),
        "{e}"
    );
    std::fs::remove_dir_all(&d).unwrap();
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn errors_name_file_line_and_field() {
    let err = Job::from_toml_str("name = \"j\"\nimpeler = \"x\"\n", Path::new("job.toml"))
        .unwrap_err()
        .to_string();
    assert!(err.starts_with("job.toml:2:"), "{err}");
    assert!(err.contains("impeler"), "{err}");
    let err = Job::from_toml_str("[tolerances]\nchord_tol = -1.0\n", Path::new("job.toml"))
        .unwrap_err()
        .to_string();
    assert!(err.starts_with("job.toml:2: tolerances.chord_tol"), "{err}");
    let err = Job::from_toml_str(
        "[verification]\nresolution_mm = 0.0\n",
        Path::new("job.toml"),
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.starts_with("job.toml:2: verification.resolution_mm"),
        "{err}"
    );
}

#[test]
fn default_job_is_the_fixture_job_with_its_tools() {
    let job = Job::default_job().unwrap();
    assert_eq!(job.name, "impeller-8+8");
    assert_eq!(job.dialect, "linuxcnc");
    assert!(job.tools.len() >= 3, "{:?}", job.tools);
    let t5 = job.tool("T5-taper-ball-r1.5").unwrap();
    assert_eq!(t5.number, 5);
    match t5.cutter.shape {
        CutterShape::TaperedBallEnd {
            ball_radius,
            half_angle,
        } => {
            assert_eq!(ball_radius, 1.5);
            assert!((half_angle - 2f64.to_radians()).abs() < 1e-15);
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(t5.cutter.shank_radius, 3.0);
    assert_eq!(t5.cutter.holder[0].bottom_radius, 10.5);
    let machine = job.machine.clone().unwrap();
    assert!(job.is_embedded(&machine));
    assert!(job.read_text(&machine).unwrap().contains("xyzac-trt"));
    // The process plan: five operations and the rest finishing of what they leave, their
    // tools, from the turned blank; no CL files.
    let ops: Vec<(&str, &str, &str)> = job
        .operations
        .iter()
        .map(|o| (o.name.as_str(), o.kind.as_str(), o.tool.as_str()))
        .collect();
    assert_eq!(
        ops,
        [
            ("rough", "channel_roughing", "T5-taper-ball-r1.5"),
            ("hub-finish", "hub_finishing", "T6-taper-ball-r1"),
            ("blade-semi", "flank_semi_finishing", "T5-taper-ball-r1.5"),
            ("blade-finish", "flank_finishing", "T6-taper-ball-r1"),
            ("blade-root", "blade_root_finishing", "T7-ball-d2"),
            ("rest", "rest_finishing", "T9-ball-d1"),
        ]
    );
    assert_eq!(job.stock.start, crate::job::StockStartKind::Turned);
    assert!(job.cl_files.is_empty());
}

/// A test-only kind whose builder checks its one key, `depth_mm` (never planned here).
#[derive(Debug)]
struct Probe;

impl cam_plan::Operation for Probe {
    fn kind(&self) -> &'static str {
        "probe"
    }
    fn name(&self) -> &str {
        "probe"
    }
    fn tool(&self) -> &str {
        "t"
    }
    fn plan(&self, _: &cam_plan::PlanContext<'_>) -> Result<cam_plan::PlannedOperation, PlanError> {
        Err(PlanError::geometry(
            "probe",
            "-",
            "never planned in these tests",
        ))
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct ProbeParams {
    depth_mm: f64,
}

fn build_probe(spec: &OperationSpec) -> Result<Box<dyn cam_plan::Operation>, PlanError> {
    let p: ProbeParams = cam_plan::params::parse(spec)?;
    if p.depth_mm <= 0.0 {
        return Err(PlanError::param(&spec.name, "depth_mm", "must be > 0"));
    }
    Ok(Box::new(Probe))
}

static PROBE: &Registry = &[("probe", build_probe)];

const TOOL: &str = "[[tools]]\nnumber = 1\nname = \"b3\"\nshape = \"ball_end\"\ndiameter_mm = 3.0\n\
    flute_length_mm = 12.0\nshank_diameter_mm = 6.0\nstick_out_mm = 30.0\ntool_length_mm = 90.0\n\
    teeth = 2\nholder = [\n  { bottom_diameter_mm = 20.0, top_diameter_mm = 20.0, length_mm = 25.0 },\n]\n";

const OP: &str = "[[operations]]\nname = \"a\"\nkind = \"probe\"\ntool = \"b3\"\ndepth_mm = 1.0\n\
    [operations.process]\nspindle_rpm = 10000.0\nfeed_per_tooth_mm = 0.05\n";

/// Parses `text` as `job.toml` with the probe kind and returns the error.
fn err_of(text: &str) -> String {
    Job::from_toml_str_with(text, Path::new("dir/job.toml"), PROBE)
        .unwrap_err()
        .to_string()
}

/// 1-based line of the first line of `text` containing `needle`.
fn line(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

/// Asserts `err` starts with `dir/job.toml:<line of needle>: <key>`.
fn assert_at(err: &str, text: &str, needle: &str, key: &str) {
    let want = format!("dir/job.toml:{}: {key}", line(text, needle));
    assert!(err.starts_with(&want), "want {want:?}, got {err:?}");
}

#[test]
fn a_valid_job_converts_tools_and_process_rows() {
    let text = format!("[tolerances]\nstock_allowance = 0.4\n{TOOL}{OP}");
    let job = Job::from_toml_str_with(&text, Path::new("dir/job.toml"), PROBE).unwrap();
    let t = job.tool("b3").unwrap();
    assert_eq!(t.cutter.shape, CutterShape::BallEnd { radius: 1.5 });
    assert_eq!(t.cutter.shank_radius, 3.0);
    assert_eq!(t.cutter.overall_length, 30.0);
    assert_eq!(t.cutter.holder[0].top_radius, 10.0);
    assert_eq!(t.tool_length_mm, 90.0);
    let p = &job.operations[0].process;
    // stock_allowance is the default allowance of a row that gives none.
    assert_eq!((p.blade_allowance_mm, p.hub_allowance_mm), (0.4, 0.4));
    assert_eq!(
        p.rapid_mm_per_min,
        cam_plan::process::DEFAULT_RAPID_MM_PER_MIN
    );
    assert_eq!(
        job.operations[0].params.get("depth_mm").unwrap().as_float(),
        Some(1.0)
    );
}

#[test]
fn unknown_keys_are_named_with_file_and_line() {
    // Inside a tool.
    let text = format!("{}{OP}", TOOL.replace("teeth = 2", "teeth = 2\nflutes = 2"));
    assert_at(&err_of(&text), &text, "flutes", "tools[0].flutes");
    // Inside a holder frustum (inline table).
    let text = format!(
        "{}{OP}",
        TOOL.replace("length_mm = 25.0", "lenght_mm = 25.0")
    );
    assert_at(
        &err_of(&text),
        &text,
        "lenght_mm",
        "tools[0].holder[0].lenght_mm",
    );
    // Inside the process row.
    let text = format!("{TOOL}{OP}feed_mm_per_min = 800.0\n");
    assert_at(
        &err_of(&text),
        &text,
        "feed_mm_per_min",
        "operations[0].process.feed_mm_per_min",
    );
    // A key of the kind (its builder rejects it).
    let text = format!(
        "{TOOL}{}",
        OP.replace("depth_mm = 1.0", "depth_mm = 1.0\nstep_mm = 2.0")
    );
    assert_at(&err_of(&text), &text, "step_mm", "operations[0].step_mm");
    // In [safety].
    let text = "[safety]\nclearence_mm = 5.0\n";
    assert_at(&err_of(text), text, "clearence_mm", "safety.clearence_mm");
}

#[test]
fn wrong_types_and_values_are_named_with_file_and_line() {
    let text = format!(
        "{}{OP}",
        TOOL.replace("diameter_mm = 3.0", "diameter_mm = \"3\"")
    );
    assert_at(
        &err_of(&text),
        &text,
        "diameter_mm = \"3\"",
        "tools[0].diameter_mm",
    );
    let text = format!(
        "{TOOL}{}",
        OP.replace("spindle_rpm = 10000.0", "spindle_rpm = \"fast\"")
    );
    assert_at(
        &err_of(&text),
        &text,
        "spindle_rpm",
        "operations[0].process.spindle_rpm",
    );
    let text = format!(
        "{TOOL}{}",
        OP.replace("depth_mm = 1.0", "depth_mm = \"deep\"")
    );
    assert_at(&err_of(&text), &text, "depth_mm", "operations[0].depth_mm");
    // Values: a builder's range check, a process row's, a tool's.
    let text = format!("{TOOL}{}", OP.replace("depth_mm = 1.0", "depth_mm = -1.0"));
    assert_at(&err_of(&text), &text, "depth_mm", "operations[0].depth_mm");
    let text = format!(
        "{TOOL}{}",
        OP.replace("feed_per_tooth_mm = 0.05", "feed_per_tooth_mm = 0.0")
    );
    assert_at(
        &err_of(&text),
        &text,
        "feed_per_tooth_mm",
        "operations[0].process.feed_per_tooth_mm",
    );
    let text = format!(
        "{}{OP}",
        TOOL.replace("stick_out_mm = 30.0", "stick_out_mm = -30.0")
    );
    assert_at(
        &err_of(&text),
        &text,
        "stick_out_mm",
        "tools[0].stick_out_mm",
    );
    let text = format!(
        "{}{OP}",
        TOOL.replace("tool_length_mm = 90.0", "tool_length_mm = 20.0")
    );
    assert_at(
        &err_of(&text),
        &text,
        "tool_length_mm",
        "tools[0].tool_length_mm",
    );
    // A dimension the shape does not have, and one it lacks.
    let text = format!(
        "{}{OP}",
        TOOL.replace("teeth = 2", "teeth = 2\nhalf_angle_deg = 2.0")
    );
    assert_at(
        &err_of(&text),
        &text,
        "half_angle_deg",
        "tools[0].half_angle_deg",
    );
    let text = format!(
        "{}{OP}",
        TOOL.replace("shape = \"ball_end\"", "shape = \"bull_nose\"")
    );
    let err = err_of(&text);
    assert!(
        err.contains("tools[0].corner_radius_mm") && err.contains("bull_nose"),
        "{err}"
    );
    // An unknown shape.
    let text = format!("{}{OP}", TOOL.replace("ball_end", "lollipop"));
    assert_at(&err_of(&text), &text, "lollipop", "tools[0].shape");
}

#[test]
fn unknown_tools_and_kinds_and_duplicate_names_are_named() {
    let text = format!("{TOOL}{}", OP.replace("tool = \"b3\"", "tool = \"b4\""));
    let err = err_of(&text);
    assert_at(&err, &text, "tool = \"b4\"", "operations[0].tool");
    assert!(
        err.contains("unknown tool \"b4\"") && err.contains("b3"),
        "{err}"
    );
    let text = format!(
        "{TOOL}{}",
        OP.replace("kind = \"probe\"", "kind = \"plunge_roughing\"")
    );
    let err = err_of(&text);
    assert_at(&err, &text, "kind =", "operations[0].kind");
    assert!(
        err.contains("unknown kind \"plunge_roughing\"") && err.contains("probe"),
        "{err}"
    );
    let text = format!(
        "{TOOL}{OP}{}",
        OP.replace("[[operations]]", "\n[[operations]]")
    );
    let err = err_of(&text);
    let second = text
        .lines()
        .enumerate()
        .filter(|(_, l)| l.contains("name = \"a\""))
        .nth(1)
        .unwrap()
        .0
        + 1;
    assert!(
        err.starts_with(&format!("dir/job.toml:{second}: operations[1].name")),
        "{err}"
    );
    assert!(err.contains("used twice"), "{err}");
    // Missing common keys.
    let text = format!("{TOOL}{}", OP.replace("tool = \"b3\"\n", ""));
    let err = err_of(&text);
    assert!(
        err.contains("operations[0].tool") && err.contains("missing"),
        "{err}"
    );
}

#[test]
fn tool_file_errors_name_the_tool_file() {
    let dir = std::env::temp_dir().join(format!("impeller-cam-jobtools-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("tools.toml"),
        TOOL.replace("teeth = 2", "teeth = 2\nflutes = 2"),
    )
    .unwrap();
    let text = format!("tools = \"tools.toml\"\n{OP}");
    let err = Job::from_toml_str_with(&text, &dir.join("job.toml"), PROBE)
        .unwrap_err()
        .to_string();
    let want = format!("{}:11: tools[0].flutes", dir.join("tools.toml").display());
    assert!(err.starts_with(&want), "want {want:?}, got {err:?}");
    let text = "tools = \"missing.toml\"\n";
    let err = Job::from_toml_str_with(text, &dir.join("job.toml"), PROBE)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("job.toml:1: tools") && err.contains("missing.toml"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `coolant` in a process row: flood, mist, through or off (default off); anything else is
/// named with file, line and key.
#[test]
fn the_process_row_gives_the_coolant() {
    let text = format!("{TOOL}{OP}coolant = \"mist\"\n");
    let job = Job::from_toml_str_with(&text, Path::new("dir/job.toml"), PROBE).unwrap();
    assert_eq!(job.coolant, [gcode_emit::Coolant::Mist]);
    let job =
        Job::from_toml_str_with(&format!("{TOOL}{OP}"), Path::new("dir/job.toml"), PROBE).unwrap();
    assert_eq!(job.coolant, [gcode_emit::Coolant::Off]);
    let text = format!("{TOOL}{OP}coolant = \"water\"\n");
    let err = err_of(&text);
    assert_at(&err, &text, "water", "operations[0].process.coolant");
}

/// `[operation.process]` under each `[[operations]]` (a singular typo) is one top-level table
/// defined twice: the error says so and gives the spelling of the row's table; it used to say
/// only `dir/job.toml:N: duplicate key`.
#[test]
fn a_row_table_under_a_singular_name_is_explained() {
    let op = OP.replace("[operations.process]", "[operation.process]");
    let text = format!("{TOOL}{op}{}", op.replace("name = \"a\"", "name = \"b\""));
    let e = err_of(&text);
    let second = text
        .lines()
        .enumerate()
        .filter(|(_, l)| l.contains("[operation.process]"))
        .nth(1)
        .unwrap()
        .0
        + 1;
    let want = format!(
        "dir/job.toml:{second}: the table `[operation.process]` is defined again (first at line {})",
        line(&text, "[operation.process]")
    );
    assert!(e.starts_with(&want), "{e}");
    assert!(e.contains("written `[operations.process]`"), "{e}");
}
