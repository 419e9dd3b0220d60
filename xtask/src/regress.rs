//! `cargo xtask regress`: end-to-end regressions on the fixture impellers.
//!
//! A fixture is a folder `fixtures/<name>/` holding `job.toml` (an `impeller-cam run` job)
//! and `bounds.toml`:
//!
//! ```toml
//! [bounds]
//! "impeller.main_blade_count" = { min = 8, max = 8 }
//! "operations.plunge_rough.path_length_mm" = { max = 5000.0 }
//! "verification.max_overcut_mm" = { max = 0.01 }
//! ```
//!
//! Keys are dotted paths into `report.json`; a segment applied to an array selects the
//! element whose `name` equals it. A bound whose metric is missing is a breach.
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
    /// Use the dev profile instead of release (faster build, slower run).
    #[arg(long)]
    pub debug: bool,
}

#[derive(Debug, Deserialize)]
struct BoundsFile {
    bounds: BTreeMap<String, Bound>,
}

#[derive(Debug, Deserialize, Clone, Copy)]
struct Bound {
    min: Option<f64>,
    max: Option<f64>,
}

pub fn run(args: Args) -> Result<bool, String> {
    let root = workspace_root();
    let target = target_dir();
    let fixtures = find_fixtures(&root.join("fixtures"), args.filter.as_deref())?;
    if fixtures.is_empty() {
        return Err("no fixture with job.toml and bounds.toml under fixtures/".into());
    }
    let mut build = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    build
        .current_dir(&root)
        .args(["build", "-q", "-p", "impeller-cam"]);
    if !args.debug {
        build.arg("--release");
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
    for dir in fixtures {
        let name = dir
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
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
        let out = target.join("regress").join(&name);
        let status = Command::new(&exe)
            .arg("run")
            .arg(dir.join("job.toml"))
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
        let bounds_text = std::fs::read_to_string(dir.join("bounds.toml"))
            .map_err(|e| format!("{}: {e}", dir.join("bounds.toml").display()))?;
        let bounds: BoundsFile = toml_lite(&bounds_text)
            .map_err(|e| format!("{}: {e}", dir.join("bounds.toml").display()))?;
        let mut metrics = Vec::new();
        for (path, b) in &bounds.bounds {
            let value = lookup(&report, path).and_then(as_number);
            let ok =
                value.is_some_and(|v| b.min.is_none_or(|m| v >= m) && b.max.is_none_or(|m| v <= m));
            all_ok &= ok;
            println!(
                "{name:<28} {path:<52} {:>14} {:>12} {:>12}  {}",
                value.map_or("missing".into(), |v| format!("{v:.6}")),
                b.min.map_or("-".into(), |v| format!("{v}")),
                b.max.map_or("-".into(), |v| format!("{v}")),
                if ok { "ok" } else { "BREACH" }
            );
            metrics.push(
                json!({ "metric": path, "value": value, "min": b.min, "max": b.max, "ok": ok }),
            );
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

fn find_fixtures(dir: &Path, filter: Option<&str>) -> Result<Vec<PathBuf>, String> {
    let mut out = Vec::new();
    let entries = std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    for e in entries.flatten() {
        let p = e.path();
        let name = e.file_name().to_string_lossy().into_owned();
        if p.join("job.toml").is_file()
            && p.join("bounds.toml").is_file()
            && filter.is_none_or(|f| name.contains(f))
        {
            out.push(p);
        }
    }
    out.sort();
    Ok(out)
}

/// The `[import] file` of a fixture's `impeller.toml` when it cannot be found in any folder
/// above the fixture (how the importer resolves it).
fn missing_import(dir: &Path) -> Option<String> {
    let text = std::fs::read_to_string(dir.join("impeller.toml")).ok()?;
    let v: toml::Value = toml::from_str(&text).ok()?;
    let file = v.get("import")?.get("file")?.as_str()?.to_string();
    let found = dir.ancestors().any(|a| a.join(&file).is_file());
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
    fn bounds_file_parses() {
        let b =
            toml_lite("[bounds]\n\"a.b\" = { min = 1, max = 2.5 }\n\"c\" = { max = 0 }\n").unwrap();
        assert_eq!(b.bounds.len(), 2);
        assert_eq!(b.bounds["a.b"].min, Some(1.0));
        assert_eq!(b.bounds["c"].max, Some(0.0));
    }
}
