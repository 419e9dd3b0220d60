//! `report.html` as a person sees it: rendered by headless Chromium (Debian `chromium`), the
//! DOM after rendering must hold every plot of the file, each with drawn content, and the 3D
//! view must draw (WebGL on Chromium's software rasteriser); the 3D view's data must agree
//! with the CL file and the verification maps.
//!
//! Without `chromium` on PATH the rendering tests print that they were skipped; under CI
//! (`CI=true`) they fail instead (`cargo xtask ci` installs it).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test helpers

mod common;

use std::path::PathBuf;
use std::process::{Command, Stdio};

fn chromium() -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    ["chromium", "chromium-browser"].iter().find_map(|name| {
        std::env::split_paths(&path)
            .map(|d| d.join(name))
            .find(|p| p.is_file())
    })
}

/// The DOM of `url` after headless Chromium rendered it (`extra`: flags beyond the common
/// ones); fails the test when Chromium fails.
fn dump_dom(
    browser: &std::path::Path,
    profile: &std::path::Path,
    url: &str,
    extra: &[&str],
) -> String {
    let r = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
        ])
        .args(extra)
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg("--dump-dom")
        .arg(url)
        .stdin(Stdio::null())
        .output()
        .unwrap();
    assert!(
        r.status.success(),
        "chromium failed on {url}: {}",
        String::from_utf8_lossy(&r.stderr)
    );
    String::from_utf8_lossy(&r.stdout).into_owned()
}

fn under_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| v == "true" || v == "1")
}

/// The `<svg>…</svg>` elements of an HTML text.
fn svgs(html: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut rest = html;
    while let Some(a) = rest.find("<svg") {
        let Some(b) = rest[a..].find("</svg>") else {
            break;
        };
        out.push(&rest[a..a + b + "</svg>".len()]);
        rest = &rest[a + b + "</svg>".len()..];
    }
    out
}

/// Whether an SVG draws something: a polyline/polygon with points, a path with a `d`, or a
/// circle, rect or line element.
fn draws(svg: &str) -> bool {
    let filled = |tag: &str, attr: &str| {
        svg.match_indices(tag).any(|(i, _)| {
            let el = &svg[i..svg[i..].find('>').map_or(svg.len(), |e| i + e)];
            el.find(attr).is_some_and(|k| {
                let v = &el[k + attr.len()..];
                v.trim_start_matches(['=', '"', '\''])
                    .chars()
                    .next()
                    .is_some_and(|c| c != '"' && c != '\'')
            })
        })
    };
    filled("<polyline", "points")
        || filled("<polygon", "points")
        || filled("<path", " d")
        || svg.contains("<circle")
        || svg.contains("<rect")
        || svg.contains("<line")
}

#[test]
fn report_html_renders_every_plot_in_headless_chromium() {
    let Some(browser) = chromium() else {
        if under_ci() {
            panic!("CI=true but `chromium` is not on PATH (`cargo xtask ci` installs it)");
        }
        eprintln!(
            "SKIPPED: `chromium` is not on PATH, so report.html was not rendered \
             (`cargo xtask ci` installs it; under CI=true this test fails instead)"
        );
        return;
    };
    let dir = std::env::temp_dir().join(format!("impeller-cam-html-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("out");
    let st = Command::new(env!("CARGO_BIN_EXE_impeller-cam"))
        .args(["run", "--out"])
        .arg(&out)
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let file = out.join("report.html");
    let written = std::fs::read_to_string(&file).unwrap();
    let plots = svgs(&written).len();
    assert!(plots >= 1, "report.html holds no plot");
    let profile = dir.join("profile");
    let dom = dump_dom(
        &browser,
        &profile,
        &format!("file://{}", file.display()),
        &["--disable-gpu", "--disable-quic"],
    );
    assert!(dom.contains("<body"), "no rendered document:\n{dom}");
    let rendered = svgs(&dom);
    assert_eq!(rendered.len(), plots, "plots in the rendered DOM");
    for (k, svg) in rendered.iter().enumerate() {
        assert!(draws(svg), "plot {k} is empty:\n{svg}");
    }
    // The setup sheet renders too, with every tool of the program listed (name, stick-out,
    // gauge length), the cycle time and the verdict.
    let setup = out.join("setup.html");
    let dom = dump_dom(
        &browser,
        &profile,
        &format!("file://{}", setup.display()),
        &["--disable-gpu"],
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    for op in report["operations"].as_array().unwrap() {
        let tool = op["tool"].as_str().unwrap();
        assert!(
            dom.contains(&format!("<td>{tool}</td>")),
            "tool {tool} in the setup sheet"
        );
        assert!(dom.contains(&format!("<td>{}</td>", op["name"].as_str().unwrap())));
    }
    assert!(dom.contains("<td>cycle time</td>") && dom.contains("verification PASS"));
    assert!(
        written.contains("<h2 id=\"setup\">Setup sheet</h2>"),
        "a section of report.html"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A small fixture job for the 3D view: blade-root finishing of the impeller-8+8 fixture
/// with 8 stations per side on the turned blank, verified at 0.5 mm (a few seconds).
fn small_view_job(dir: &std::path::Path) -> PathBuf {
    let repo = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let fx = |p: &str| repo.join("fixtures").join(p).display().to_string();
    let job = dir.join("job.toml");
    std::fs::write(
        &job,
        format!(
            "name = \"view3d-small\"\nimpeller = {:?}\nmachine = {:?}\ndialect = \"linuxcnc\"\n\
             tools = {:?}\n[stock]\nstart = \"turned\"\n[verification]\nresolution_mm = 0.5\n\
             [[operations]]\nname = \"blade-root\"\nkind = \"blade_root_finishing\"\n\
             tool = \"T7-ball-d2\"\nstations = 8\n[operations.process]\nspindle_rpm = 6000.0\n\
             feed_per_tooth_mm = 0.1\nblade_allowance_mm = 0.0\nhub_allowance_mm = 0.0\n",
            fx("impeller-8+8/impeller.toml"),
            fx("machines/xyzac-trt.toml"),
            fx("tools/impeller-8+8.toml"),
        ),
    )
    .unwrap();
    job
}

/// Runs the small view job into `dir/out` (with `extra` arguments) and returns that folder.
fn run_small_view_job(dir: &std::path::Path, extra: &[&str]) -> PathBuf {
    let out = dir.join("out");
    let st = Command::new(env!("CARGO_BIN_EXE_impeller-cam"))
        .arg("run")
        .arg(small_view_job(dir))
        .arg("--out")
        .arg(&out)
        .arg("--quiet")
        .args(extra)
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    out
}

/// The 3D view's JSON document in report.html.
fn view_data(html: &str) -> serde_json::Value {
    let open = "<script type=\"application/json\" id=\"view3d-data\">";
    let a = html.find(open).expect("no view3d-data in report.html") + open.len();
    let b = a + html[a..].find("</script>").unwrap();
    serde_json::from_str(&html[a..b]).unwrap()
}

/// RFC 4648 base64 (independent of the writer's encoder).
fn unbase64(s: &str) -> Vec<u8> {
    let val = |c: u8| -> u32 {
        match c {
            b'A'..=b'Z' => u32::from(c - b'A'),
            b'a'..=b'z' => u32::from(c - b'a') + 26,
            b'0'..=b'9' => u32::from(c - b'0') + 52,
            b'+' => 62,
            b'/' => 63,
            _ => panic!("not base64: {c}"),
        }
    };
    let mut out = Vec::new();
    for chunk in s.as_bytes().chunks(4) {
        let pad = chunk.iter().filter(|&&c| c == b'=').count();
        let n = chunk
            .iter()
            .filter(|&&c| c != b'=')
            .fold(0u32, |n, &c| (n << 6) | val(c))
            << (6 * pad);
        let bytes = [(n >> 16) as u8, (n >> 8) as u8, n as u8];
        out.extend_from_slice(&bytes[..3 - pad]);
    }
    out
}

fn u16s(b64: &serde_json::Value) -> Vec<u16> {
    unbase64(b64.as_str().unwrap())
        .chunks(2)
        .map(|c| u16::from_le_bytes([c[0], c[1]]))
        .collect()
}

fn i16s(b64: &serde_json::Value) -> Vec<i16> {
    unbase64(b64.as_str().unwrap())
        .chunks(2)
        .map(|c| i16::from_le_bytes([c[0], c[1]]))
        .collect()
}

/// Positions of the view decoded on its grid (`origin + q·step`).
fn positions(data: &serde_json::Value, b64: &serde_json::Value) -> Vec<[f64; 3]> {
    let o: Vec<f64> = data["origin"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let step = data["step"].as_f64().unwrap();
    u16s(b64)
        .chunks(3)
        .map(|q| [0, 1, 2].map(|k| o[k] + f64::from(q[k]) * step))
        .collect()
}

/// The data written for the 3D view round-trips: every tool tip and axis decoded from the
/// report agrees with `toolpath.cls` within the quantisation step (half a step of the
/// position grid per coordinate, 1/32767 per axis coordinate); every stock vertex's deviation
/// is the signed deviation (−overcut or +residual, 1 µm) of the worst sample of
/// `verification_maps.json` within one lattice spacing of its nearest one (within 2 mm), or
/// "not measured" when there is none.
#[test]
fn view3d_data_round_trips_against_the_cl_file_and_the_verification_maps() {
    let dir = common::scratch("impeller-cam-view3d", "round-trip");
    let out = run_small_view_job(&dir, &["--export-stock", "--export-paths"]);
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    let data = view_data(&html);
    let step = data["step"].as_f64().unwrap();
    assert!(step > 0.0 && step < 0.01, "position step {step} mm");
    // Tool paths against the CL file.
    let cls = std::fs::read_to_string(out.join("toolpath.cls")).unwrap();
    let program = gcode_emit::read_cl(&cls, "toolpath.cls", &Default::default()).unwrap();
    let ops = data["operations"].as_array().unwrap();
    assert_eq!(ops.len(), program.operations.len());
    let mut compared = 0;
    for (op, cl) in ops.iter().zip(&program.operations) {
        assert_eq!(op["name"].as_str().unwrap(), cl.path.name);
        let tips = positions(&data, &op["tips"]);
        let axes = i16s(&op["axes"]);
        assert_eq!(tips.len(), cl.path.moves.len(), "{}", cl.path.name);
        for (i, (tip, m)) in tips.iter().zip(&cl.path.moves).enumerate() {
            let want = [m.cl.tip.x, m.cl.tip.y, m.cl.tip.z];
            let axis = [m.cl.axis.x, m.cl.axis.y, m.cl.axis.z];
            for k in 0..3 {
                // The CL file itself rounds to 1e-6 mm / 1e-7.
                assert!(
                    (tip[k] - want[k]).abs() <= 0.5 * step + 2e-6,
                    "move {i} tip {tip:?} vs {want:?} (step {step})"
                );
                let a = f64::from(axes[3 * i + k]) / 32767.0;
                assert!((a - axis[k]).abs() <= 1.0 / 32767.0 + 2e-7, "move {i} axis");
            }
            compared += 1;
        }
    }
    assert!(compared > 100, "{compared} moves compared");
    // The exports: toolpaths.gltf holds one line segment per move after the first (cutting
    // and link primitives together); stock.stl is a whole binary STL.
    let gltf: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("toolpaths.gltf")).unwrap())
            .unwrap();
    let ends: u64 = gltf["accessors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a["count"].as_u64().unwrap())
        .sum();
    let moves: usize = program
        .operations
        .iter()
        .map(|o| o.path.moves.len() - 1)
        .sum();
    assert_eq!(ends, 2 * moves as u64);
    let stl = std::fs::read(out.join("stock.stl")).unwrap();
    let n = u32::from_le_bytes([stl[80], stl[81], stl[82], stl[83]]) as usize;
    assert!(
        n > 1000 && stl.len() == 84 + 50 * n,
        "{n} triangles, {} bytes",
        stl.len()
    );
    // Stock deviations against the verification maps (about 3000 vertices: brute force).
    let maps: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("verification_maps.json")).unwrap())
            .unwrap();
    let mut samples: Vec<([f64; 3], f64)> = Vec::new();
    for m in maps.as_array().unwrap() {
        let pts = m["points"].as_array().unwrap();
        for (k, p) in pts.iter().enumerate() {
            let p: Vec<f64> = p
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            let o = m["overcut_mm"][k].as_f64();
            let r = m["residual_mm"][k].as_f64();
            let d = match (o, r) {
                (Some(o), _) if o > 0.0 => -o,
                (_, Some(r)) => r,
                (Some(o), None) => -o,
                (None, None) => continue,
            };
            samples.push(([p[0], p[1], p[2]], d));
        }
    }
    assert!(samples.len() > 1000, "{} samples", samples.len());
    let stock = &data["stock"];
    let verts = positions(&data, &stock["positions"]);
    let dev = i16s(&stock["deviation_um"]);
    assert_eq!(verts.len(), dev.len());
    // A decoded vertex is within √3·step/2 of the written one: distances compared with that
    // slack on both sides.
    let slack = 3f64.sqrt() * step;
    let band = stock["spacing_mm"].as_f64().unwrap();
    let tol = stock["machining_tol_mm"].as_f64().unwrap();
    let (mut measured, mut checked) = (0, 0);
    for (v, &d) in verts.iter().zip(&dev).step_by((verts.len() / 3000).max(1)) {
        let dist = |p: &[f64; 3]| (0..3).map(|k| (p[k] - v[k]).powi(2)).sum::<f64>().sqrt();
        let nearest = samples
            .iter()
            .map(|(p, _)| dist(p))
            .fold(f64::INFINITY, f64::min);
        checked += 1;
        if d == i16::MIN {
            assert!(
                nearest > 2.0 - slack,
                "vertex {v:?} unmeasured, sample at {nearest} mm"
            );
            continue;
        }
        measured += 1;
        let got = f64::from(d) / 1000.0;
        // The worst (an overcut beyond machining_tol first, then the larger magnitude) of
        // the samples within one lattice spacing of the nearest: surely in that band below
        // `band - slack`, possibly up to `band + slack`; "beyond" read with the 1 µm
        // quantisation in the written value's favour.
        let badness = |d: f64, tol: f64| if d < -tol { 1.0e6 - d } else { d.abs() };
        let inner = samples
            .iter()
            .filter(|(p, _)| dist(p) <= (nearest + band).min(2.0) - slack)
            .map(|(_, s)| badness(*s, tol + 0.0005))
            .fold(f64::NEG_INFINITY, f64::max);
        let from_band = samples.iter().any(|(p, s)| {
            dist(p) <= nearest + band + slack && (s.clamp(-32.767, 32.767) - got).abs() <= 0.0005
        });
        assert!(
            from_band && badness(got, tol - 0.0005) >= inner - 0.0006,
            "vertex {v:?}: deviation {got} mm is not the worst sample near it (nearest at \
             {nearest} mm)"
        );
    }
    assert!(
        measured * 10 > checked,
        "only {measured} of {checked} stock vertices near the design"
    );
    // Markers carry the move nearest them.
    let markers = data["markers"].as_array().unwrap();
    assert!(markers.iter().any(|m| m["kind"] == "overcut"));
    let total = data["moves"].as_u64().unwrap();
    for m in markers {
        assert!(m["move"].as_u64().is_some_and(|i| i < total), "{m}");
    }
}

/// One headless Chromium run of `page` (a file URL with its hash); returns the `#view3d`
/// element's attributes.
fn view_attributes(browser: &std::path::Path, profile: &std::path::Path, url: &str) -> String {
    let dom = dump_dom(
        browser,
        profile,
        url,
        &[
            // WebGL through the software rasteriser (SwiftShader).
            "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader",
            "--window-size=1000,700",
            // JavaScript runs (imports, first frame) before the DOM is dumped.
            "--virtual-time-budget=30000",
        ],
    );
    let a = dom
        .find("<div id=\"view3d\"")
        .expect("no #view3d in the DOM");
    let b = a + dom[a..].find('>').unwrap();
    dom[a..b].to_string()
}

fn attribute<'a>(element: &'a str, name: &str) -> &'a str {
    let key = format!(" {name}=\"");
    let a = element
        .find(&key)
        .unwrap_or_else(|| panic!("no {name} on {element}"))
        + key.len();
    &element[a..a + element[a..].find('"').unwrap()]
}

/// The 3D view renders in headless Chromium with WebGL on the software rasteriser: no page
/// error or console error, the view says it drew its first frame, and the canvas is not
/// blank (more than 5 % of the sampled pixels unlike the cleared background, at least 16
/// distinct colours) with the tool at the first, a middle and the last move.
#[test]
fn view3d_draws_in_headless_chromium_at_three_playback_positions() {
    let Some(browser) = chromium() else {
        if under_ci() {
            panic!("CI=true but `chromium` is not on PATH (`cargo xtask ci` installs it)");
        }
        eprintln!(
            "SKIPPED: `chromium` is not on PATH, so the 3D view was not rendered \
             (`cargo xtask ci` installs it; under CI=true this test fails instead)"
        );
        return;
    };
    let dir = common::scratch("impeller-cam-view3d", "chromium");
    let out = run_small_view_job(&dir, &[]);
    let file = out.join("report.html");
    let data = view_data(&std::fs::read_to_string(&file).unwrap());
    let total = data["moves"].as_u64().unwrap();
    assert!(total > 10);
    for mv in [0, total / 2, total - 1] {
        let url = format!("file://{}#view3d&move={mv}", file.display());
        let el = view_attributes(&browser, &dir.join("profile"), &url);
        assert_eq!(
            attribute(&el, "data-errors"),
            "",
            "page errors at move {mv}"
        );
        assert_eq!(
            attribute(&el, "data-drawn"),
            "1",
            "first frame at move {mv}: {el}"
        );
        assert_eq!(attribute(&el, "data-move"), mv.to_string());
        let nonblank: f64 = attribute(&el, "data-nonblank").parse().unwrap();
        let colours: usize = attribute(&el, "data-colours").parse().unwrap();
        assert!(
            nonblank > 0.05 && colours >= 16,
            "blank canvas at move {mv}: {nonblank} drawn, {colours} colours"
        );
    }
}

/// Issue 32: the verification section lists every surface group of `report.json` with its
/// residual shares, and the residual distribution is plotted per group.
#[test]
fn verification_lists_and_plots_the_residual_of_every_surface_group() {
    let dir = common::scratch("impeller-cam-view3d", "surface-groups");
    let out = run_small_view_job(&dir, &[]);
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let groups = report["verification"]["surface_groups"]
        .as_object()
        .unwrap();
    assert!(groups.len() >= 3, "{groups:?}");
    assert!(html.contains("<th>surface group</th>"));
    assert!(html.contains("Residual per surface group"));
    for (name, g) in groups {
        let row = format!("<tr><td>{name}</td><td>{}</td>", g["points"]);
        assert!(html.contains(&row), "no row {row}");
        // Each group is a series of the distribution plot (its legend label).
        assert!(html.contains(&name.replace('_', " ")), "no series {name}");
    }
}

/// Issue 37: the post-processing section tabulates the rotary reversals inside cuts of every
/// operation with what explains them, the same figures as report.json.
#[test]
fn post_processing_tabulates_the_reversals_inside_cuts_by_reason() {
    let dir = common::scratch("impeller-cam-view3d", "reversal-table");
    let out = run_small_view_job(&dir, &[]);
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert!(html.contains("<h3>Rotary reversals inside cuts</h3>"));
    let ops = report["post"]["operations"].as_array().unwrap();
    assert!(!ops.is_empty());
    for o in ops {
        let planned = report["operations"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["name"] == o["name"])
            .unwrap();
        let row = format!(
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td>",
            o["name"].as_str().unwrap(),
            o["reverse_motions_cutting_after"],
            o["reverse_motions_links_after"],
            o["reverse_motions_cutting_near_pole"],
            planned["axis_reversals_kept_clearance"],
        );
        assert!(html.contains(&row), "no row {row}");
        assert_eq!(o["reverse_motions_cutting_unaccounted"], 0);
    }
}
