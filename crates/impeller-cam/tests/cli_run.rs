//! `impeller-cam run` end to end: default job, a job with CL data from another CAM system
//! (posted, accepted by LinuxCNC's rs274, verified by simulation), a C-axis swing removed by
//! checked reverse-motion smoothing, and user errors.
#![allow(clippy::unwrap_used, clippy::panic)] // test helpers

mod common;

use common::repo;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

fn cli() -> Command {
    Command::new(env!("CARGO_BIN_EXE_impeller-cam"))
}

fn scratch(name: &str) -> common::Scratch {
    common::scratch("impeller-cam-run", name)
}

fn report(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap()
}

#[test]
fn default_job_is_the_impeller_8_8_fixture_job() {
    let out = scratch("default");
    let st = cli().args(["run", "--out"]).arg(&out).output().unwrap();
    assert!(
        st.status.success(),
        "{:?}: {}",
        st.status,
        String::from_utf8_lossy(&st.stderr)
    );
    let r = report(&out);
    assert_eq!(r["job"], "impeller-8+8");
    assert_eq!(r["impeller"]["main_blade_count"], 8);
    assert_eq!(r["impeller"]["splitter_blade_count"], 8);
    let d = r["impeller"]["blade_tip_diameter_mm"].as_f64().unwrap();
    assert!((d - 77.0).abs() < 0.5, "{d}");
    // The fixture job's process plan (paper 003, Table 1), planned, posted and verified.
    let ops = r["operations"].as_array().unwrap();
    let kinds: Vec<(&str, &str)> = ops
        .iter()
        .map(|o| (o["name"].as_str().unwrap(), o["kind"].as_str().unwrap()))
        .collect();
    assert_eq!(
        kinds,
        [
            ("rough", "channel_roughing"),
            ("hub-finish", "hub_finishing"),
            ("blade-semi", "flank_semi_finishing"),
            ("blade-finish", "flank_finishing"),
            ("blade-root", "blade_root_finishing"),
            ("rest", "rest_finishing"),
        ]
    );
    for o in ops {
        assert!(o["moves"].as_u64().unwrap() > 100, "{o}");
        assert!(o["plan_ms"].as_f64().unwrap() > 0.0, "{o}");
        assert_eq!(o["uncertified_links"], 0.0, "{o}");
    }
    // Without a terminal (stderr is a pipe here) each operation's start and end are stage
    // lines: a long planning run shows which operations are under way.
    let stderr = String::from_utf8_lossy(&st.stderr);
    for (name, kind) in &kinds {
        assert!(
            stderr.contains(&format!("[impeller-cam] planning {name} ({kind}) …")),
            "{stderr}"
        );
        assert!(
            stderr.contains(&format!("[impeller-cam] planned {name} ({kind}): ")),
            "{stderr}"
        );
    }
    // The turned blank: the shroud's outlet radius, not the file's Ø79 cylinder.
    let sr = r["impeller"]["stock_radius_mm"].as_f64().unwrap();
    assert!((sr - 38.5).abs() < 0.02, "{sr}");
    assert_eq!(r["post"]["written"], true);
    assert!(out.join("program.ngc").is_file());
    // Verified from the written program, one operation per header, without defects.
    assert_eq!(r["verification"]["source"], "program");
    assert_eq!(r["verification"]["collisions"], 0);
    assert!(r["verification"]["defects"].as_array().unwrap().is_empty());
    assert_eq!(r["verdict"]["status"], "pass");
    // The deepest dexel overcut readings re-measured on the exact swept envelopes: each
    // within the simulation's error bound of its dexel reading (limit − machining_tol).
    let v = &r["verification"];
    let bound = v["overcut_limit_mm"].as_f64().unwrap() - 0.01;
    let cc = &v["details"]["overcut_crosscheck"];
    assert_eq!(cc["samples"], 20, "{cc}");
    for p in cc["points"].as_array().unwrap() {
        let (d, e) = (
            p["dexel_overcut_mm"].as_f64().unwrap(),
            p["envelope_overcut_mm"].as_f64().unwrap(),
        );
        assert!((d - e).abs() <= bound, "{p}");
    }
    let last = stderr.lines().last().unwrap_or_default();
    assert!(
        last.contains("program.ngc, verification PASS (overcut") && last.contains("<= limit"),
        "{last}"
    );
    for k in ["model_ms", "plan_ms", "post_ms", "verify_ms", "total_ms"] {
        assert!(r["timings_ms"][k].as_f64().is_some(), "{k}");
    }
    // The cycle time, re-computed from the written program text and the machine file's own
    // limits by an independent replay (`replay_ngc_s`), agrees with the report within 1 %.
    let program = std::fs::read_to_string(out.join("program.ngc")).unwrap();
    let machine: toml::Value = toml::from_str(
        &std::fs::read_to_string(repo().join("fixtures/machines/xyzac-trt.toml")).unwrap(),
    )
    .unwrap();
    let replayed = replay_ngc_s(&program, &machine);
    let reported = r["post"]["cycle_time"]["total_s"].as_f64().unwrap();
    eprintln!("cycle time: report {reported:.3} s, replay of program.ngc {replayed:.3} s");
    assert!(
        (replayed - reported).abs() <= 0.01 * replayed,
        "cycle time: report {reported} s, replay of program.ngc {replayed} s"
    );
    // LinuxCNC's own interpreter accepts the whole program in a trivkins configuration.
    rs274_accepts(
        &out,
        &out.join("program.ngc"),
        "T5 P5 Z115 D3 ;T5\nT6 P6 Z115 D2 ;T6\nT7 P7 Z110 D2 ;T7\nT9 P9 Z110 D1 ;T9\n",
        50_000,
    );
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains("<svg") && html.contains("Meridional view"));
    for name in ["rough", "hub-finish", "blade-finish", "blade-root"] {
        assert!(
            html.contains(&format!("{name}: top view"))
                && html.contains(&format!("{name}: meridional view")),
            "{name}"
        );
    }
}

/// The running time (s) of a LinuxCNC joint-output program on a machine file, written
/// independently of the library's cycle-time code from the program text alone: every motion
/// block moves the five joints X Y Z A C linearly in one parameter `s`; its cruise rate is
/// `u = min(1/T, min_i v_i/|D_i|)` (T = 60/F s under G93, the XYZ length over F under G94,
/// none for G0), its acceleration `α = k·min_i a_i/|D_i|` with `k = ½` when the machine blends
/// (two blends overlap) and 1 at exact stop; from rest to rest it takes `1/u + u/α`
/// (trapezoid, `u²/α ≤ 1`) or `2/√α` (triangle). Blended blocks start when the block before
/// begins to decelerate, not before the one before it has ended; M-code blocks stop the
/// motion, and `M6` with a new tool adds the machine's `tool_change_s`. `G53` moves are taken
/// in the workpiece frame (the machine files here put G54 at the machine's origin).
fn replay_ngc_s(program: &str, machine: &toml::Value) -> f64 {
    let axes = ["X", "Y", "Z", "A", "C"];
    let limit = |a: &str, k: &str| machine["axes"][a][k].as_float().unwrap();
    let speed: Vec<f64> = axes.iter().map(|a| limit(a, "max_speed") / 60.0).collect();
    let accel: Vec<f64> = axes.iter().map(|a| limit(a, "max_acceleration")).collect();
    let blend = machine["blending"].as_str() == Some("parabolic");
    let change_s = machine["tool_change_s"].as_float().unwrap_or(0.0);
    let (mut at, mut rapid, mut inverse_time, mut feed) = ([0.0f64; 5], true, false, 0.0);
    // End of the program so far, earliest start of the next block, end of the one before.
    let (mut end, mut next, mut before): (f64, f64, f64) = (0.0, 0.0, 0.0);
    let (mut tool, mut loaded) = (None::<i64>, None::<i64>);
    for line in program.lines() {
        let code = line.split('(').next().unwrap_or_default();
        let (mut to, mut moved, mut stop, mut m6) = (at, false, false, false);
        for word in code.split_whitespace() {
            let (letter, value) = word.split_at(1);
            let Ok(v) = value.parse::<f64>() else {
                continue;
            };
            match letter {
                "G" if v == 0.0 => rapid = true,
                "G" if v == 1.0 => rapid = false,
                "G" if v == 93.0 => inverse_time = true,
                "G" if v == 94.0 => inverse_time = false,
                "F" => feed = v,
                "T" => tool = Some(v as i64),
                "M" => {
                    stop = true;
                    m6 |= v == 6.0;
                }
                _ => {
                    if let Some(i) = axes.iter().position(|a| *a == letter) {
                        to[i] = v;
                        moved = true;
                    }
                }
            }
        }
        if stop {
            before = end;
            next = end;
            if m6 && tool != loaded {
                end += change_s;
                before = end;
                next = end;
                loaded = tool;
            }
        }
        if !moved {
            continue;
        }
        let d: Vec<f64> = (0..5).map(|i| (to[i] - at[i]).abs()).collect();
        at = to;
        if d.iter().all(|x| *x < 1e-9) {
            continue;
        }
        let mut u = f64::INFINITY;
        if !rapid {
            let xyz = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            let t = if inverse_time {
                60.0 / feed
            } else {
                60.0 * if xyz > 0.0 { xyz } else { d[3].hypot(d[4]) } / feed
            };
            u = 1.0 / t;
        }
        let mut alpha = f64::INFINITY;
        for i in 0..5 {
            if d[i] >= 1e-9 {
                u = u.min(speed[i] / d[i]);
                alpha = alpha.min(accel[i] / d[i]);
            }
        }
        if blend {
            alpha *= 0.5;
        }
        let (duration, decel) = if u * u / alpha <= 1.0 {
            (1.0 / u + u / alpha, u / alpha)
        } else {
            (2.0 / alpha.sqrt(), 1.0 / alpha.sqrt())
        };
        let start = if blend { next.max(before) } else { end };
        before = end;
        end = end.max(start + duration);
        next = start + duration - decel;
    }
    end
}

#[test]
fn the_program_replay_reproduces_closed_form_times() {
    let machine: toml::Value = toml::from_str(
        &std::fs::read_to_string(repo().join("fixtures/machines/xyzac-trt.toml")).unwrap(),
    )
    .unwrap();
    // One 100 mm rapid on X (20 mm/s, 300 mm/s² halved by the blend): 100/20 + 20/150 s.
    let t = replay_ngc_s("G0 X100\n", &machine);
    assert!((t - (5.0 + 20.0 / 150.0)).abs() < 1e-12, "{t}");
    // Ten 1 mm feeds at 60 mm/min under G93 (F = 60 per minute: 1 s each) on Y, blended:
    // cruise 1 mm/s, one ramp up and one down at 150 mm/s²: 10 + 1/150 s. A tool change
    // between two of them stops the motion and adds 5 s; the same tool again adds nothing.
    let mut p = String::from("G93 G1\n");
    for k in 1..=10 {
        p.push_str(&format!("Y{k} F60\n"));
    }
    let t = replay_ngc_s(&p, &machine);
    assert!((t - (10.0 + 1.0 / 150.0)).abs() < 1e-9, "{t}");
    let p2 = p.replace("Y5 F60\n", "Y5 F60\nT3 M6\nT3 M6\n");
    let t2 = replay_ngc_s(&p2, &machine);
    assert!((t2 - (10.0 + 2.0 / 150.0 + 5.0)).abs() < 1e-9, "{t2}");
    // A 90° turn of A alone at 30°/s, from rest to rest: 3 s + 30/150 s.
    let t = replay_ngc_s("G0 A90\n", &machine);
    assert!((t - (3.0 + 0.2)).abs() < 1e-12, "{t}");
}

/// A five-axis ring cut in the stock above the impeller's shroud contour (r = 30 mm, top
/// 0.5 mm of the 44 mm blank, axis tilted 10° outward): it removes stock but must not touch
/// the design.
fn ring_cl() -> String {
    swing_ring_cl(0.0, 43.5, true)
}

/// [`ring_cl`] at height `z` whose tool-axis azimuth is the tip's azimuth φ plus a local
/// swing `−A·u·exp(−u²)`, `u = (φ − 90°)/5°` (A in degrees): for `A > 5°` the azimuth, and
/// with it the C axis, runs backwards around φ = 90° (two reverse motions). With `plunge`
/// the pass starts with a rapid to z = 60 and plunges, otherwise with a rapid to its first
/// point.
fn swing_ring_cl(amplitude_deg: f64, z: f64, plunge: bool) -> String {
    let mut s = String::from(
        "PARTNO RING TEST\nUNITS/MM\nMULTAX/ON\nLOADTL/1\nCUTTER/6.0,3.0,0.0,3.0,0.0,0.0,40.0\n\
         SPINDL/RPM,10000,CLW\nRAPID\n",
    );
    if plunge {
        s.push_str("GOTO/30.0,0.0,60.0,0.1736482,0.0,0.9848078\n");
    }
    let tilt = 10f64.to_radians();
    for k in 0..=72 {
        if k == usize::from(!plunge) {
            s.push_str("FEDRAT/MMPM,800\n");
        }
        let phi_deg = k as f64 * 2.5;
        let phi = phi_deg.to_radians();
        let u = (phi_deg - 90.0) / 5.0;
        let az = (phi_deg - amplitude_deg * u * (-u * u).exp()).to_radians();
        s.push_str(&format!(
            "GOTO/{:.6},{:.6},{:.6},{:.7},{:.7},{:.7}\n",
            30.0 * phi.cos(),
            30.0 * phi.sin(),
            z,
            tilt.sin() * az.cos(),
            tilt.sin() * az.sin(),
            tilt.cos()
        ));
    }
    s.push_str("FINI\n");
    s
}

#[test]
fn job_with_cl_data_is_posted_accepted_by_rs274_and_verified() {
    let (r, _) = run_ring_job("cljob", &ring_cl(), 73);
    let op = &r["operations"][0];
    assert_eq!(op["moves"], 74);
    // 72 chords of a 2.5° step on r = 30 mm plus the 16.5 mm plunge from the rapid point.
    let chord = 2.0 * 30.0 * (1.25f64.to_radians()).sin();
    let expected = 72.0 * chord + 16.5;
    let len = op["path_length_mm"].as_f64().unwrap();
    assert!((len - expected).abs() < 1e-3, "{len} vs {expected}");
    assert_eq!(r["post"]["reverse_motions_before"], 0);
    assert_eq!(r["post"]["reverse_motions_after"], 0);
}

#[test]
fn c_axis_swing_is_removed_checked_posted_and_verified() {
    // The ring job's realistic shape: a rapid to z = 60, a 16.5 mm plunge into the top
    // 0.5 mm of the 44 mm blank, then the swinging ring. The cutting run spans the plunge
    // (constant posture) and the sweep; the smoothing refits with more control values than
    // the paper's four (whose fit exceeds the 10° limit, so the run was kept with its two
    // reversals) and every smoothed posture still passes the design gouge check.
    let (r, out) = run_ring_job_with(
        "swing",
        &swing_ring_cl(10.0, 43.5, true),
        73,
        "[post]\nsmooth_imported_cl = true\n",
    );
    assert_eq!(
        r["operations"][0]["moves"], 74,
        "rapid, plunge and 72 ring chords"
    );
    let post = &r["post"];
    let before = post["reverse_motions_before"].as_u64().unwrap();
    assert!(before >= 2, "{post}");
    assert_eq!(post["reverse_motions_after"], 0, "{post}");
    let op = &post["operations"][0];
    assert_eq!(op["reverse_motion_removal"], true, "{op}");
    assert_eq!(op["smoothed_runs"], 1, "{op}");
    assert_eq!(op["kept_runs"], 0, "{op}");
    // The swing is ±4.3° about the ring's steady turn; the smoothing changes C by about that.
    let change = op["max_angle_change_deg"].as_f64().unwrap();
    assert!(change > 1.0 && change <= 10.0, "{op}");
    // The ball (CUTTER r = 3) turns about its centre: the contact stays on the ball.
    assert!(op["max_contact_shift_mm"].as_f64().unwrap() <= 1e-9, "{op}");
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains(&format!("reverse motions {before} → 0")));
    // Both displacement plots (rotary axes, all axes) carry the curves before removal
    // (dashed, legend "C before removal") beside those after.
    assert!(
        html.matches("C before removal</text>").count() >= 2,
        "before/after plots"
    );
}

#[test]
fn imported_cl_is_smoothed_only_when_the_job_opts_in() {
    // The same swinging ring without `[post] smooth_imported_cl`: counted, not removed, and
    // the report says how to opt in. The smoothing turns the tool about a point the other
    // CAM system may not have put the contact on.
    let (r, out) = run_ring_job("swing-default", &swing_ring_cl(10.0, 43.5, true), 73);
    let post = &r["post"];
    let before = post["reverse_motions_before"].as_u64().unwrap();
    assert!(before >= 2, "{post}");
    assert_eq!(
        post["reverse_motions_after"].as_u64().unwrap(),
        before,
        "{post}"
    );
    assert_eq!(post["operations"][0]["reverse_motion_removal"], false);
    let notes = r["notes"].to_string();
    assert!(notes.contains("smooth_imported_cl = true"), "{notes}");
    assert!(out.join("program.ngc").exists());
}

/// Runs a job with `cl` as its CL file on the fixture impeller and machine (LinuxCNC) and
/// checks what every such job must satisfy: exit 0, no limit violation, linearisation within
/// 0.005 mm, at least `min_feeds` feed moves in rs274's output, no overcut beyond the 0.5 mm dexel resolution, no collision, every move in the
/// CL file written back, and rs274 accepting the program. Returns the report and the output
/// folder.
fn run_ring_job(name: &str, cl: &str, min_feeds: usize) -> (serde_json::Value, PathBuf) {
    run_ring_job_with(name, cl, min_feeds, "")
}

/// [`run_ring_job`] with `extra` appended to the job file.
fn run_ring_job_with(
    name: &str,
    cl: &str,
    min_feeds: usize,
    extra: &str,
) -> (serde_json::Value, PathBuf) {
    let job = ring_job_with(name, cl, extra);
    let dir = job.parent().unwrap().to_path_buf();
    let out = dir.join("out");
    let st = cli()
        .arg("run")
        .arg(&job)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{:?}: {}",
        st.status,
        String::from_utf8_lossy(&st.stderr)
    );
    let r = report(&out);
    assert_eq!(r["post"]["limit_violations"], 0);
    assert!(r["post"]["max_linearisation_error_mm"].as_f64().unwrap() <= 0.005 + 1e-9);
    let v = &r["verification"];
    // The ring stays outside the design: no overcut beyond the dexel resolution.
    assert!(v["max_overcut_mm"].as_f64().unwrap() <= 0.5, "{v}");
    assert_eq!(v["collisions"], 0, "{v}");
    // The cycle time from the machine's limits: per operation (cutting, air, tool change)
    // and for the program, whose total is the operations' sum (the final retract is the
    // last operation's); cutting at the machine is never faster than at programmed feed.
    let t = &r["post"]["cycle_time"];
    let total = t["total_s"].as_f64().unwrap();
    let mut sum = 0.0;
    for (o, row) in t["operations"]
        .as_array()
        .unwrap()
        .iter()
        .zip(r["operations"].as_array().unwrap())
    {
        let f = |k: &str| o[k].as_f64().unwrap();
        assert!(
            (f("cutting_s") + f("link_s") + f("rapid_s") + f("tool_change_s") - f("total_s")).abs()
                < 1e-9,
            "{o}"
        );
        assert_eq!(row["total_time_s"].as_f64().unwrap(), f("total_s"));
        assert!(
            f("cutting_s") >= row["cutting_time_s"].as_f64().unwrap() * (1.0 - 1e-9),
            "{o} {row}"
        );
        let change = f("tool_change_s");
        assert!(
            change == 0.0 || change == t["tool_change_each_s"].as_f64().unwrap(),
            "{o}"
        );
        sum += f("total_s");
    }
    assert!(
        total > 0.0 && (total - sum).abs() < 1e-6 * total,
        "{total} vs {sum}"
    );
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains("<h2>Cycle time: "), "cycle time table");
    // The CL file written back contains every move.
    let cls = std::fs::read_to_string(out.join("toolpath.cls")).unwrap();
    assert_eq!(cls.matches("GOTO/").count(), cl.matches("GOTO/").count());
    // LinuxCNC's own interpreter accepts the program.
    let program = out.join("program.ngc");
    assert!(program.is_file());
    rs274_accepts(&dir, &program, "T1 P1 Z0 D6 ;ring\n", min_feeds);
    (r, out)
}

/// Runs LinuxCNC's `rs274` on `program` (in `dir`, with `tool_table`) and asserts that it
/// accepts every line and makes at least `min_feeds` feed moves; skipped with a line when
/// `rs274` is not installed (a failure under `CI=true`).
fn rs274_accepts(dir: &Path, program: &Path, tool_table: &str, min_feeds: usize) {
    match which("rs274") {
        Some(rs) => {
            let tbl = dir.join("tool.tbl");
            std::fs::write(&tbl, tool_table).unwrap();
            // A stock trivkins configuration (xyzac-trt's machine file says kinematics =
            // "trivial"): no remapped kinematics switch, so an M429 would be rejected
            // ("M-code greater than 199").
            let ini = dir.join("machine.ini");
            std::fs::write(
                &ini,
                "[TRAJ]\nCOORDINATES = XYZAC\nLINEAR_UNITS = mm\nANGULAR_UNITS = deg\n",
            )
            .unwrap();
            let res = Command::new(rs)
                .arg("-t")
                .arg(&tbl)
                .arg("-i")
                .arg(&ini)
                .arg("-g")
                .arg(program)
                .current_dir(dir)
                .env("HOME", dir)
                .stdin(Stdio::null())
                .output()
                .unwrap();
            let stderr = String::from_utf8_lossy(&res.stderr);
            assert!(res.status.success(), "{stderr}");
            let noise: Vec<&str> = stderr
                .lines()
                .filter(|l| !l.trim().is_empty() && l.trim() != "executing")
                .collect();
            assert!(noise.is_empty(), "rs274: {noise:?}");
            let feeds = String::from_utf8_lossy(&res.stdout)
                .matches("STRAIGHT_FEED")
                .count();
            assert!(feeds >= min_feeds, "{feeds} feed moves");
        }
        None if std::env::var("CI").is_ok_and(|v| v == "true" || v == "1") => {
            panic!("CI=true but rs274 is not on PATH (`cargo xtask ci` installs linuxcnc-uspace)")
        }
        None => eprintln!(
            "SKIPPED: the rs274 check of program.ngc (`rs274` not on PATH; `cargo xtask ci` \
             installs it)"
        ),
    }
}

fn which(name: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join(name))
        .find(|p| p.is_file())
}

#[test]
fn bad_job_files_exit_1_with_file_and_line() {
    let dir = scratch("bad");
    std::fs::write(dir.join("job.toml"), "name = \"x\"\ndialekt = \"fanuc\"\n").unwrap();
    let st = cli()
        .arg("run")
        .arg(dir.join("job.toml"))
        .arg("--out")
        .arg(dir.join("out"))
        .output()
        .unwrap();
    assert_eq!(st.status.code(), Some(1));
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(
        err.contains("job.toml:2:") && err.contains("dialekt"),
        "{err}"
    );
    assert!(!err.contains("panicked"));
    let st = cli()
        .args(["run", "/nonexistent/job.toml", "--out"])
        .arg(dir.join("out"))
        .output()
        .unwrap();
    assert_eq!(st.status.code(), Some(1));
}

#[test]
fn finishing_job_of_the_fixture_is_planned_posted_and_accepted_by_rs274() {
    // fixtures/impeller-8+8/job-finishing.toml: channel roughing (T5) so that the program
    // can be verified, then blade semi-finishing (T5), flank finishing (T6) and blade-root
    // finishing (T7) of every blade side of both rows, planned by the registered flank-opt
    // and channel-paths operations, and verified.
    let dir = scratch("finishing");
    let out = dir.join("out");
    let st = cli()
        .arg("run")
        .arg(repo().join("fixtures/impeller-8+8/job-finishing.toml"))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{:?}: {}",
        st.status,
        String::from_utf8_lossy(&st.stderr)
    );
    let r = report(&out);
    let ops = r["operations"].as_array().unwrap();
    let kinds: Vec<&str> = ops.iter().map(|o| o["kind"].as_str().unwrap()).collect();
    assert_eq!(
        kinds,
        [
            "channel_roughing",
            "flank_semi_finishing",
            "flank_finishing",
            "blade_root_finishing"
        ]
    );
    for o in ops {
        assert!(o["moves"].as_u64().unwrap() > 100, "{o}");
        assert!(o["plan_ms"].as_f64().unwrap() > 0.0, "{o}");
    }
    // the finishing pass meets the job's machining tolerance (0.01 mm) on the blade sides
    assert!(
        ops[2]["max_deviation_mm"].as_f64().unwrap() <= 0.01,
        "{}",
        ops[2]
    );
    // Both rows are finished: the splitter sides are planned, not copies of the main row.
    assert_eq!(ops[2]["rows"], "main, splitter", "{}", ops[2]);
    assert_eq!(r["post"]["limit_violations"], 0);
    // Verified: no collision and the overcut within the limit in force.
    let v = &r["verification"];
    assert_eq!(v["collisions"], 0, "{v}");
    assert!(
        v["max_overcut_mm"].as_f64().unwrap() <= v["overcut_limit_mm"].as_f64().unwrap_or(0.1),
        "{v}"
    );
    let post_err = |name: &str| {
        r["post"]["operations"]
            .as_array()
            .unwrap()
            .iter()
            .find(|o| o["name"] == name)
            .unwrap()["max_linearisation_error_mm"]
            .as_f64()
            .unwrap()
    };
    // The finishing pass is linearised within linearisation_tol, tip and flute top.
    assert!(post_err("blade-finish") <= 0.005 + 1e-9);
    // The semi-finishing sweep passes 1.9° from the table's axis at the radial trailing edge:
    // the post keeps the branch and turns C around the pole, so the flute top follows it too
    // (it read 1.03 mm when the nearest posture flipped the branch through the pole).
    assert!(post_err("blade-semi") <= 0.005 + 1e-9);
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains("blade-finish: top view"));
    rs274_accepts(
        &dir,
        &out.join("program.ngc"),
        "T5 P5 Z115 D3 ;T5\nT6 P6 Z115 D2 ;T6\nT7 P7 Z110 D2 ;T7\n",
        1000,
    );
}

/// Writes a ring job (CL file `cl`, verified at 0.5 mm) into a fresh folder and returns the
/// job file.
fn ring_job(name: &str, cl: &str) -> PathBuf {
    ring_job_with(name, cl, "")
}

/// [`ring_job`] with `extra` appended to the job file (e.g. a `[post]` table).
fn ring_job_with(name: &str, cl: &str, extra: &str) -> PathBuf {
    let dir = scratch(name).keep();
    std::fs::write(dir.join("ring.cls"), cl).unwrap();
    let imp = repo().join("fixtures/impeller-8+8/impeller.toml");
    let machine = repo().join("fixtures/machines/xyzac-trt.toml");
    let job = dir.join("job.toml");
    std::fs::write(
        &job,
        format!(
            "name = \"ring\"\nimpeller = {:?}\nmachine = {:?}\ndialect = \"linuxcnc\"\n\
             [verification]\nresolution_mm = 0.5\n[[cl_files]]\npath = \"ring.cls\"\n{extra}",
            imp.display().to_string(),
            machine.display().to_string()
        ),
    )
    .unwrap();
    job
}

#[test]
fn gouging_program_is_withheld_with_exit_3_unless_defects_are_allowed() {
    // The ring at z = 12 mm on r = 30 mm runs between hub (z = 6.6 mm there) and shroud
    // contour (z = 15.6 mm): through every blade it passes. Verification must find the
    // overcut, `run` exit 3 with the report written and no program; with --allow-defects
    // exit 0 and the program written.
    let job = ring_job("gouge", &swing_ring_cl(0.0, 12.0, true));
    let out = job.parent().unwrap().join("out");
    let st = cli()
        .arg("run")
        .arg(&job)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(
        st.status.code(),
        Some(3),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let stderr = String::from_utf8_lossy(&st.stderr);
    assert!(stderr.contains("DEFECT: overcut"), "{stderr}");
    // The last line says the program was withheld and why, with the limit in force (it
    // used to say `program (none: nothing to machine)`).
    let last = stderr.lines().last().unwrap_or_default();
    assert!(
        last.contains("program withheld (verification failed: overcut")
            && last.contains("verification FAIL (overcut")
            && last.contains("> limit")
            && !last.contains("nothing to machine"),
        "{last}"
    );
    let r = report(&out);
    let v = &r["verification"];
    assert!(
        v["max_overcut_mm"].as_f64().unwrap() > v["overcut_limit_mm"].as_f64().unwrap(),
        "{v}"
    );
    assert!(!v["defects"].as_array().unwrap().is_empty(), "{v}");
    assert_eq!(r["verdict"]["status"], "fail");
    assert_eq!(r["verdict"]["program"], "withheld");
    assert_eq!(r["verdict"]["overcut_limit_mm"], v["overcut_limit_mm"]);
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains("Verdict: FAIL") && html.contains("withheld (verification failed"));
    assert_eq!(r["post"]["written"], false);
    assert!(!out.join("program.ngc").exists());
    assert!(out.join("report.html").is_file());

    let out2 = job.parent().unwrap().join("out2");
    let st = cli()
        .arg("run")
        .arg(&job)
        .arg("--out")
        .arg(&out2)
        .arg("--allow-defects")
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{:?}: {}",
        st.status,
        String::from_utf8_lossy(&st.stderr)
    );
    assert!(out2.join("program.ngc").is_file());
    let r = report(&out2);
    assert_eq!(r["post"]["written"], true);
    let notes = r["notes"].to_string();
    assert!(notes.contains("--allow-defects"), "{notes}");
}

#[test]
fn flank_finishing_refuses_a_path_outside_its_tolerance() {
    // The fixture's finishing pass reaches about 0.003 mm; asked for 0.0001 mm it must fail
    // with the measured figures instead of emitting the pass.
    let dir = scratch("flank-tol");
    let fx = repo().join("fixtures");
    let job = dir.join("job.toml");
    std::fs::write(
        &job,
        format!(
            "name = \"tight\"\nimpeller = {:?}\nmachine = {:?}\ntools = {:?}\n\
             [verification]\nenabled = false\n\
             [[operations]]\nname = \"finish\"\nkind = \"flank_finishing\"\n\
             tool = \"T6-taper-ball-r1\"\noptimise_shape = false\ncompare_cylindrical = false\n\
             sides = \"pressure\"\novercut_tol_mm = 0.0001\n\
             [operations.process]\nspindle_rpm = 6000.0\nfeed_per_tooth_mm = 0.1\n",
            fx.join("impeller-8+8/impeller.toml").display().to_string(),
            fx.join("machines/xyzac-trt.toml").display().to_string(),
            fx.join("tools/impeller-8+8.toml").display().to_string(),
        ),
    )
    .unwrap();
    let st = cli()
        .arg("run")
        .arg(&job)
        .arg("--out")
        .arg(dir.join("out"))
        .output()
        .unwrap();
    assert_eq!(st.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&st.stderr);
    assert!(
        stderr.contains("misses its tolerances") && stderr.contains("overcut"),
        "{stderr}"
    );
    assert!(!dir.join("out/program.ngc").exists());
}

#[test]
fn progress_goes_to_stderr_as_lines_off_a_terminal_and_not_at_all_with_quiet() {
    // Off a terminal (as here) the stage lines are printed and no progress bar is drawn (no
    // cursor control); with --quiet neither, while the summary line stays.
    // A short job (the ring CL data); the stage lines do not depend on the operations.
    let job = ring_job_with("progress-job", &ring_cl(), "");
    let out = scratch("progress");
    let run = |quiet: bool| {
        let mut c = cli();
        c.arg("run").arg(&job).arg("--out").arg(&out);
        if quiet {
            c.arg("--quiet");
        }
        let o = c.output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let loud = run(false);
    assert!(
        loud.contains("[impeller-cam] planning operations"),
        "{loud}"
    );
    assert!(
        !loud.contains('\u{1b}'),
        "escape codes off a terminal: {loud}"
    );
    let quiet = run(true);
    assert!(!quiet.contains("planning operations"), "{quiet}");
    assert!(!quiet.contains('\u{1b}'), "{quiet}");
    assert!(quiet.contains(": 1 operation(s)"), "{quiet}");
}

/// `impeller-cam run JOB --out OUT`.
fn run_into(job: &Path, out: &Path) -> std::process::Output {
    cli()
        .arg("run")
        .arg(job)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap()
}

/// An unknown dialect is refused when the job is read (it used to be found after planning,
/// without file or line, leaving `toolpath.cls` behind): exit 1, nothing written.
#[test]
fn an_unknown_dialect_is_refused_before_anything_runs() {
    let job = ring_job("haas", &ring_cl());
    let text = std::fs::read_to_string(&job).unwrap();
    std::fs::write(&job, text.replace("\"linuxcnc\"", "\"haas\"")).unwrap();
    let out = job.parent().unwrap().join("out");
    let st = run_into(&job, &out);
    assert_eq!(st.status.code(), Some(1));
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(
        err.contains("job.toml:4: dialect: unknown dialect `haas`"),
        "{err}"
    );
    assert!(!out.exists(), "nothing written");
}

/// A run owns its output folder: a Sinumerik run into a folder a LinuxCNC run used leaves
/// no `program.ngc` beside its `program.mpf` (it used to keep the old program); a folder with
/// other files is refused unless `--force`, and then they stay.
#[test]
fn a_run_removes_the_earlier_runs_program_of_another_dialect() {
    let job = ring_job("stale", &ring_cl());
    let text = std::fs::read_to_string(&job).unwrap();
    std::fs::write(&job, text.replace("\"linuxcnc\"", "\"sinumerik\"")).unwrap();
    let out = job.parent().unwrap().join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("program.ngc"), "G0 X0\n").unwrap();
    std::fs::write(out.join("mine.txt"), "keep").unwrap();
    // A folder holding a file a run does not write is refused before anything runs ...
    let st = run_into(&job, &out);
    assert_eq!(st.status.code(), Some(1));
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(
        err.contains("holds 1 entry a run does not write (`mine.txt`)") && err.contains("--force"),
        "{err}"
    );
    assert!(
        out.join("program.ngc").is_file(),
        "nothing removed when refused"
    );
    // ... and with --force the run writes beside it.
    let st = cli()
        .arg("run")
        .arg(&job)
        .arg("--out")
        .arg(&out)
        .arg("--force")
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{:?}: {}",
        st.status,
        String::from_utf8_lossy(&st.stderr)
    );
    assert!(out.join("program.mpf").is_file());
    assert!(!out.join("program.ngc").exists());
    assert!(out.join("mine.txt").is_file());
}

/// A machine whose A axis cannot reach the ring's 10° tilt: the run posts nothing, names
/// the operation, how many blocks and moves leave the travel and the range A needs, writes
/// the report with the violations and fails with exit 3 (it used to stop in the post at the
/// first block with no count, no range and no report, then with exit 1 and no report).
#[test]
fn travel_the_machine_cannot_hold_is_reported_with_count_and_range() {
    let job = ring_job("travel", &ring_cl());
    let dir = job.parent().unwrap();
    let machine = std::fs::read_to_string(repo().join("fixtures/machines/xyzac-trt.toml")).unwrap();
    let (a, c) = (
        machine.find("[axes.A]").unwrap(),
        machine.find("[axes.C]").unwrap(),
    );
    let narrow = format!(
        "{}{}{}",
        &machine[..a],
        machine[a..c]
            .replace("min = -100.0", "min = -5.0")
            .replace("max = 50.0", "max = 5.0"),
        &machine[c..]
    );
    std::fs::write(dir.join("narrow.toml"), narrow).unwrap();
    let text = std::fs::read_to_string(&job).unwrap();
    let fixture = format!(
        "{:?}",
        repo()
            .join("fixtures/machines/xyzac-trt.toml")
            .display()
            .to_string()
    );
    assert!(text.contains(&fixture));
    std::fs::write(&job, text.replace(&fixture, "\"narrow.toml\"")).unwrap();
    let out = dir.join("out");
    for allow in [false, true] {
        let mut cmd = cli();
        cmd.arg("run")
            .arg(&job)
            .arg("--out")
            .arg(&out)
            .arg("--force");
        if allow {
            cmd.arg("--allow-defects");
        }
        let st = cmd.output().unwrap();
        // Exit 3 even with --allow-defects: there is no program to keep.
        assert_eq!(st.status.code(), Some(3), "allow {allow}");
        let err = String::from_utf8_lossy(&st.stderr);
        assert!(
            err.contains("cannot hold the planned tool paths within its travel")
                && err.contains(" blocks (moves 0–")
                && err.contains("A needs -10.000 to -10.000 (travel -5 to 5)"),
            "{err}"
        );
        assert!(
            err.contains("DEFECT: machine ") && err.contains("program withheld (the machine"),
            "{err}"
        );
        assert!(
            !err.contains("verifying by stock simulation"),
            "nothing verified: {err}"
        );
        assert!(!out.join("program.ngc").exists(), "no program posted");
        assert!(out.join("toolpath.cls").is_file() && out.join("report.html").is_file());
        let r: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap())
                .unwrap();
        let t = &r["post"]["travel"][0];
        assert_eq!(t["operation"], "op1", "{t}");
        assert!(t["blocks"].as_u64().unwrap() > 0);
        assert_eq!(t["axes"][0]["axis"], "A");
        assert!((t["axes"][0]["min_needed"].as_f64().unwrap() + 10.0).abs() < 1e-3);
        assert_eq!(t["axes"][0]["travel"], serde_json::json!([-5.0, 5.0]));
        assert_eq!(r["verdict"]["status"], "fail");
        assert_eq!(r["verdict"]["program"], "withheld");
        assert!(r["verification"].is_null());
    }
}
