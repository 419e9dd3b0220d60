//! `cargo xtask regress`: end-to-end regressions on the fixture impellers.
//!
//! A fixture is a folder `fixtures/<name>/` holding `job.toml` (an `impeller-cam run` job)
//! and `bounds.toml`; further jobs of the same fixture are `job-<variant>.toml` with
//! `bounds-<variant>.toml` (reported as `<name>/<variant>`):
//!
//! ```toml
//! [bounds]
//! "impeller.main_blade_count" = { min = 8, max = 8 }
//! "operations.plunge_rough.path_length_mm" = { max = 5000.0 }
//! "operations.plunge_rough.alpha_monotone" = { equals = true }
//! "operations.finish.slp_termination" = { equals = "converged" }
//! "verification.max_overcut_mm" = { max = 0.01 }
//! ```
//!
//! Keys are dotted paths into `report.json`; a segment applied to an array selects the
//! element whose `name` equals it. Numbers and booleans (as 0/1) are bounded by `min`/`max`;
//! `equals` compares a text, boolean or number exactly. A bound whose metric is missing is a
//! breach.
//!
//! A fixture imported from a public design export (`[import] file = ...` in its
//! `impeller.toml`) whose export is not on this machine is skipped with a plain line (a fresh
//! clone has no `shared/data` beside it); under CI (`CI=true`) that is a failure.

use crate::{run_cmd, target_dir, workspace_root, write_atomic};
use serde::Deserialize;
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Arguments of `cargo xtask regress`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Only fixtures whose name contains this string.
    pub filter: Option<String>,
    /// Run the binary `cargo test --workspace` builds (test profile, the dev settings)
    /// instead of a release build: faster to build, slower to run. After the test suite it
    /// is already compiled; `cargo build -p impeller-cam` would compile the dependencies
    /// again, without the features the workspace's dev-dependencies enable.
    #[arg(long)]
    pub debug: bool,
}

#[derive(Debug, Deserialize)]
struct BoundsFile {
    bounds: BTreeMap<String, Bound>,
}

#[derive(Debug, Deserialize, Clone)]
#[serde(deny_unknown_fields)]
struct Bound {
    min: Option<f64>,
    max: Option<f64>,
    equals: Option<Expected>,
}

/// An exact expected value.
#[derive(Debug, Deserialize, Clone, PartialEq)]
#[serde(untagged)]
enum Expected {
    Bool(bool),
    Number(f64),
    Text(String),
}

impl Expected {
    fn matches(&self, v: &Value) -> bool {
        match (self, v) {
            (Expected::Bool(b), Value::Bool(x)) => b == x,
            (Expected::Number(n), Value::Number(x)) => x.as_f64() == Some(*n),
            (Expected::Text(t), Value::String(x)) => t == x,
            _ => false,
        }
    }
}

/// One regression job: its report name, job file and bounds file.
#[derive(Debug, Clone)]
struct FixtureJob {
    name: String,
    job: PathBuf,
    bounds: PathBuf,
}

pub fn run(args: Args) -> Result<bool, String> {
    let root = workspace_root();
    let target = target_dir();
    let fixtures = find_fixtures(&root.join("fixtures"), args.filter.as_deref())?;
    if fixtures.is_empty() {
        return Err("no fixture with job.toml and bounds.toml under fixtures/".into());
    }
    let mut build = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    build.current_dir(&root);
    if args.debug {
        // The binary `cargo test --workspace` builds for the command-line tests: the same
        // dependency features (dev-dependencies included), so right after the test suite
        // nothing is compiled again.
        build.args(["test", "-q", "--workspace", "--no-run"]);
    } else {
        build.args(["build", "-q", "--release", "-p", "impeller-cam"]);
    }
    run_cmd(&mut build)?;
    let exe = target
        .join(if args.debug { "debug" } else { "release" })
        .join("impeller-cam");

    let mut all_ok = true;
    let mut summary = Vec::new();
    println!(
        "{:<28} {:<52} {:>14} {:>12} {:>12}  status",
        "fixture", "metric", "value", "min", "max"
    );
    for fixture in fixtures {
        let name = fixture.name.clone();
        let dir = fixture
            .job
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default();
        if let Some(file) = missing_import(&dir) {
            let ci = std::env::var("CI").is_ok_and(|v| v == "true" || v == "1");
            println!(
                "{name:<28} {:<52} {:>14} {:>12} {:>12}  {}",
                format!("public export {file} not found"),
                "-",
                "-",
                "-",
                if ci { "MISSING DATA" } else { "SKIPPED" }
            );
            all_ok &= !ci;
            summary.push(json!({ "fixture": name, "run_ok": !ci, "skipped": true, "metrics": [] }));
            continue;
        }
        let out = target.join("regress").join(name.replace('/', "-"));
        let status = Command::new(&exe)
            .arg("run")
            .arg(&fixture.job)
            .arg("--out")
            .arg(&out)
            .current_dir(&root)
            .status()
            .map_err(|e| format!("cannot start {}: {e}", exe.display()))?;
        if !status.success() {
            println!(
                "{name:<28} {:<52} {:>14} {:>12} {:>12}  RUN FAILED",
                "-", "-", "-", "-"
            );
            all_ok = false;
            summary.push(json!({ "fixture": name, "run_ok": false, "metrics": [] }));
            continue;
        }
        let report = read_json(&out.join("report.json"))?;
        let bounds_text = std::fs::read_to_string(&fixture.bounds)
            .map_err(|e| format!("{}: {e}", fixture.bounds.display()))?;
        let bounds: BoundsFile =
            toml_lite(&bounds_text).map_err(|e| format!("{}: {e}", fixture.bounds.display()))?;
        let mut metrics = Vec::new();
        for (path, b) in &bounds.bounds {
            let raw = lookup(&report, path);
            let value = raw.and_then(as_number);
            let ok = check(raw, b);
            all_ok &= ok;
            let shown = match (raw, value) {
                (_, Some(v)) => format!("{v:.6}"),
                (Some(Value::String(t)), None) => t.clone(),
                _ => "missing".into(),
            };
            let (min, max) = match &b.equals {
                Some(e) => {
                    let t = match e {
                        Expected::Bool(x) => x.to_string(),
                        Expected::Number(x) => x.to_string(),
                        Expected::Text(x) => x.clone(),
                    };
                    (t.clone(), t)
                }
                None => (
                    b.min.map_or("-".into(), |v| format!("{v}")),
                    b.max.map_or("-".into(), |v| format!("{v}")),
                ),
            };
            println!(
                "{name:<28} {path:<52} {shown:>14} {min:>12} {max:>12}  {}",
                if ok { "ok" } else { "BREACH" }
            );
            metrics.push(json!({
                "metric": path,
                "value": raw,
                "min": b.min,
                "max": b.max,
                "equals": b.equals.as_ref().map(|e| match e {
                    Expected::Bool(x) => json!(x),
                    Expected::Number(x) => json!(x),
                    Expected::Text(x) => json!(x),
                }),
                "ok": ok
            }));
        }
        summary
            .push(json!({ "fixture": name, "run_ok": true, "metrics": metrics, "report": report }));
    }
    let path = target.join("regress").join("summary.json");
    let text = serde_json::to_string_pretty(&json!({ "ok": all_ok, "fixtures": summary }))
        .map_err(|e| e.to_string())?;
    write_atomic(&path, text.as_bytes())?;
    println!("wrote {}", path.display());
    Ok(all_ok)
}

/// Whether the report value `raw` satisfies bound `b` (missing = breach).
fn check(raw: Option<&Value>, b: &Bound) -> bool {
    let Some(raw) = raw else {
        return false;
    };
    if let Some(e) = &b.equals {
        if !e.matches(raw) {
            return false;
        }
    }
    if b.min.is_none() && b.max.is_none() {
        return b.equals.is_some();
    }
    as_number(raw).is_some_and(|v| b.min.is_none_or(|m| v >= m) && b.max.is_none_or(|m| v <= m))
}

fn find_fixtures(dir: &Path, filter: Option<&str>) -> Result<Vec<FixtureJob>, String> {
    let mut out = Vec::new();
    let entries = std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    for e in entries.flatten() {
        let p = e.path();
        let name = e.file_name().to_string_lossy().into_owned();
        if !p.is_dir() {
            continue;
        }
        let mut jobs = Vec::new();
        if p.join("job.toml").is_file() && p.join("bounds.toml").is_file() {
            jobs.push(FixtureJob {
                name: name.clone(),
                job: p.join("job.toml"),
                bounds: p.join("bounds.toml"),
            });
        }
        let files = std::fs::read_dir(&p).map_err(|e| format!("{}: {e}", p.display()))?;
        for f in files.flatten() {
            let file = f.file_name().to_string_lossy().into_owned();
            let Some(variant) = file
                .strip_prefix("job-")
                .and_then(|v| v.strip_suffix(".toml"))
            else {
                continue;
            };
            let bounds = p.join(format!("bounds-{variant}.toml"));
            if bounds.is_file() {
                jobs.push(FixtureJob {
                    name: format!("{name}/{variant}"),
                    job: f.path(),
                    bounds,
                });
            }
        }
        out.extend(
            jobs.into_iter()
                .filter(|j| filter.is_none_or(|f| j.name.contains(f))),
        );
    }
    out.sort_by(|a, b| a.name.cmp(&b.name));
    Ok(out)
}

/// The `[import] file` of a fixture's `impeller.toml` when it cannot be found in any folder
/// above the fixture (how the importer resolves it): an export file or a folder of section
/// tables (the NASA HECC archive).
fn missing_import(dir: &Path) -> Option<String> {
    let text = std::fs::read_to_string(dir.join("impeller.toml")).ok()?;
    let v: toml::Value = toml::from_str(&text).ok()?;
    let file = v.get("import")?.get("file")?.as_str()?.to_string();
    let found = dir.ancestors().any(|a| a.join(&file).exists());
    (!found).then_some(file)
}

fn read_json(p: &Path) -> Result<Value, String> {
    let text = std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))?;
    serde_json::from_str(&text).map_err(|e| format!("{}: {e}", p.display()))
}

/// Dotted-path lookup; on arrays a segment selects the element with that `name`.
fn lookup<'a>(v: &'a Value, path: &str) -> Option<&'a Value> {
    let mut cur = v;
    for seg in path.split('.') {
        cur = match cur {
            Value::Object(m) => m.get(seg)?,
            Value::Array(a) => a
                .iter()
                .find(|e| e.get("name").and_then(Value::as_str) == Some(seg))
                .or_else(|| seg.parse::<usize>().ok().and_then(|i| a.get(i)))?,
            _ => return None,
        };
    }
    Some(cur)
}

fn as_number(v: &Value) -> Option<f64> {
    match v {
        Value::Number(n) => n.as_f64(),
        Value::Bool(b) => Some(f64::from(u8::from(*b))),
        _ => None,
    }
}

/// The bounds file is a tiny TOML subset; parsed through `toml` via serde_json values.
fn toml_lite(text: &str) -> Result<BoundsFile, String> {
    toml::from_str(text).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookup_walks_objects_and_named_array_elements() {
        let v = json!({"operations": [{"name": "rough", "moves": 12}], "post": {"limit_violations": 0}});
        assert_eq!(lookup(&v, "operations.rough.moves"), Some(&json!(12)));
        assert_eq!(lookup(&v, "operations.0.moves"), Some(&json!(12)));
        assert_eq!(lookup(&v, "post.limit_violations"), Some(&json!(0)));
        assert_eq!(lookup(&v, "post.missing"), None);
    }

    #[test]
    fn bounds_check_numbers_booleans_and_texts() {
        let b = |t: &str| {
            toml_lite(&format!("[bounds]\n\"x\" = {t}\n"))
                .unwrap()
                .bounds["x"]
                .clone()
        };
        assert!(check(Some(&json!(3)), &b("{ min = 1, max = 3 }")));
        assert!(!check(Some(&json!(4)), &b("{ max = 3 }")));
        assert!(check(Some(&json!(true)), &b("{ min = 1 }")));
        assert!(check(Some(&json!(true)), &b("{ equals = true }")));
        assert!(!check(Some(&json!(false)), &b("{ equals = true }")));
        assert!(check(
            Some(&json!("converged")),
            &b("{ equals = \"converged\" }")
        ));
        assert!(!check(
            Some(&json!("max_iterations")),
            &b("{ equals = \"converged\" }")
        ));
        assert!(!check(Some(&json!("text")), &b("{ max = 1 }")));
        assert!(!check(None, &b("{ max = 1 }")));
        assert!(toml_lite("[bounds]\n\"x\" = { maxx = 1 }\n").is_err());
    }

    #[test]
    fn bounds_file_parses() {
        let b =
            toml_lite("[bounds]\n\"a.b\" = { min = 1, max = 2.5 }\n\"c\" = { max = 0 }\n").unwrap();
        assert_eq!(b.bounds.len(), 2);
        assert_eq!(b.bounds["a.b"].min, Some(1.0));
        assert_eq!(b.bounds["c"].max, Some(0.0));
    }
}
