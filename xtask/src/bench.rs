//! `cargo xtask bench`: criterion benchmarks → Bencher Metric Format (BMF).
//!
//! Every criterion benchmark target of the workspace (`crates/<crate>/benches/<bench>.rs`) is
//! run with `cargo bench -p <crate> --bench <bench>`; criterion writes one folder per
//! benchmark under its home (`$CRITERION_HOME`, else `<target dir>/criterion`) with
//! `new/benchmark.json` (id, declared throughput) and `new/estimates.json` (bootstrap
//! estimates in nanoseconds per iteration). The export holds **only the benchmarks that ran
//! in this invocation**: before running, the `new/` folders already present are fingerprinted
//! (modification time and contents of `estimates.json`), and afterwards only folders that
//! are new or whose estimates changed are read. Folders left by earlier runs (other filters,
//! renamed or deleted benchmarks) are never exported.
//!
//! BMF written to `<target dir>/bench/bmf.json`, one entry per benchmark id:
//!
//! ```json
//! { "group/function/param": {
//!     "latency":    { "value": 1234.5, "lower_value": 1220.0, "upper_value": 1250.0 },
//!     "throughput": { "value": 8.1e8,  "lower_value": 8.0e8,  "upper_value": 8.2e8 } } }
//! ```
//!
//! - `latency`: nanoseconds per iteration of the benchmarked routine — criterion's median
//!   estimate, with the bounds of its confidence interval (95 % by default).
//! - throughput, only for benchmarks that declared one with `Throughput::*`: the count per
//!   iteration divided by the latency, per second (the bounds swap: the upper latency bound
//!   gives the lower throughput). Measures: `throughput` for `Throughput::Elements`
//!   (elements/s), `throughput-bytes` for `Bytes`/`BytesDecimal` (bytes/s),
//!   `throughput-bits` for `Bits` (bits/s). The latency is never divided by the count.

use crate::{run_cmd, target_dir, workspace_root, write_atomic};
use serde_json::{json, Map, Value};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::SystemTime;

/// Arguments of `cargo xtask bench`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Only run benchmarks whose id contains this string (criterion filter).
    pub filter: Option<String>,
    /// Short measurement (criterion `--quick`): for a smoke run, not for figures.
    #[arg(long)]
    pub quick: bool,
    /// Only the benchmark targets of this crate (repeatable; default: every crate).
    #[arg(short, long = "package", value_name = "CRATE")]
    pub packages: Vec<String>,
}

pub fn run(args: Args) -> Result<bool, String> {
    let root = workspace_root();
    let target = target_dir();
    let home = criterion_home(&target);
    let before = snapshot(&home)?;
    let mut export_ok = true;
    // One `cargo bench` per criterion target: `--benches` alone would also hand criterion's
    // flags to the libtest harness of every library.
    let mut targets = bench_targets(&root)?;
    if !args.packages.is_empty() {
        for p in &args.packages {
            if !targets.iter().any(|(package, _)| package == p) {
                return Err(format!(
                    "crate `{p}` has no criterion benchmark (crates/{p}/benches/)"
                ));
            }
        }
        targets.retain(|(package, _)| args.packages.contains(package));
    }
    for (package, bench) in targets {
        let mut cmd = Command::new(env_cargo());
        cmd.current_dir(&root)
            .env("CRITERION_HOME", &home)
            .args(["bench", "-p", &package, "--bench", &bench, "--"]);
        if args.quick {
            cmd.arg("--quick");
        }
        if let Some(f) = &args.filter {
            cmd.arg(f);
        }
        run_cmd(&mut cmd)?;
    }
    // The closest-point query set, so other libraries can run exactly the same points.
    let csv = target.join("bench").join("closest_point_queries.csv");
    std::fs::create_dir_all(target.join("bench"))
        .map_err(|e| format!("{}: {e}", target.join("bench").display()))?;
    let mut ex = Command::new(env_cargo());
    ex.current_dir(&root).args([
        "run",
        "--release",
        "-q",
        "-p",
        "nurbs",
        "--example",
        "closest_point_queries",
        "--",
    ]);
    ex.arg(&csv);
    if let Err(e) = run_cmd(&mut ex) {
        eprintln!("xtask bench: closest-point query export failed: {e}");
        export_ok = false;
    }
    let results = collect_fresh(&home, &before)?;
    if results.is_empty() {
        return Err(format!(
            "no benchmark ran in this invocation (no new criterion results under {}); \
             does the filter match a benchmark id?",
            home.display()
        ));
    }
    println!("{:<56} {:>12} {:>24}", "benchmark", "median", "throughput");
    for r in &results {
        let tp = r
            .throughput
            .map(|t| format!("{:.4e} {}", t.per_second(r.median_ns), t.unit()))
            .unwrap_or_default();
        println!("{:<56} {:>12} {:>24}", r.id, human_ns(r.median_ns), tp);
    }
    let out = target.join("bench").join("bmf.json");
    let text = serde_json::to_string_pretty(&to_bmf(&results)).map_err(|e| e.to_string())?;
    write_atomic(&out, text.as_bytes())?;
    println!("wrote {} ({} benchmarks)", out.display(), results.len());
    Ok(export_ok)
}

/// Where criterion writes its results: `$CRITERION_HOME`, else `<target>/criterion` (the
/// same rule as criterion's, which also receives `CRITERION_HOME` from us).
fn criterion_home(target: &Path) -> PathBuf {
    std::env::var_os("CRITERION_HOME")
        .map(PathBuf::from)
        .unwrap_or_else(|| target.join("criterion"))
}

/// (package, bench) for every `crates/<package>/benches/<bench>.rs`.
fn bench_targets(root: &Path) -> Result<Vec<(String, String)>, String> {
    let crates = root.join("crates");
    let mut out = Vec::new();
    let entries = std::fs::read_dir(&crates).map_err(|e| format!("{}: {e}", crates.display()))?;
    for e in entries.flatten() {
        let package = e.file_name().to_string_lossy().into_owned();
        let Ok(benches) = std::fs::read_dir(e.path().join("benches")) else {
            continue;
        };
        for b in benches.flatten() {
            let p = b.path();
            if p.extension().is_some_and(|x| x == "rs") {
                if let Some(stem) = p.file_stem() {
                    out.push((package.clone(), stem.to_string_lossy().into_owned()));
                }
            }
        }
    }
    out.sort();
    Ok(out)
}

fn env_cargo() -> String {
    std::env::var("CARGO").unwrap_or_else(|_| "cargo".into())
}

/// What a criterion `new/estimates.json` looked like before the run.
#[derive(Debug, Clone, PartialEq)]
struct Fingerprint {
    modified: Option<SystemTime>,
    contents: Vec<u8>,
}

/// Fingerprints of every `new/` folder's `estimates.json` under `dir`.
type Snapshot = BTreeMap<PathBuf, Fingerprint>;

fn fingerprint(new_dir: &Path) -> Option<Fingerprint> {
    let est = new_dir.join("estimates.json");
    let contents = std::fs::read(&est).ok()?;
    let modified = std::fs::metadata(&est).and_then(|m| m.modified()).ok();
    Some(Fingerprint { modified, contents })
}

/// Every folder named `new` below `dir` (criterion's latest result of one benchmark).
fn new_dirs(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack: Vec<PathBuf> = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                if p.file_name().is_some_and(|n| n == "new") {
                    out.push(p);
                } else {
                    stack.push(p);
                }
            }
        }
    }
    out.sort();
    out
}

/// Fingerprints of the results present before a run (an absent folder is an empty snapshot).
fn snapshot(dir: &Path) -> Result<Snapshot, String> {
    Ok(new_dirs(dir)
        .into_iter()
        .filter_map(|d| fingerprint(&d).map(|f| (d, f)))
        .collect())
}

/// Throughput a benchmark declared per iteration (criterion's `Throughput`).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Throughput {
    Elements(f64),
    Bytes(f64),
    Bits(f64),
}

impl Throughput {
    /// From `benchmark.json`'s `"throughput"` (`{"Elements": n}`, `{"Bytes": n}`, ...).
    fn from_json(v: &Value) -> Option<Self> {
        let count = |key: &str| v.get(key).and_then(Value::as_f64).filter(|n| *n > 0.0);
        if let Some(n) = count("Elements") {
            Some(Self::Elements(n))
        } else if let Some(n) = count("Bytes").or_else(|| count("BytesDecimal")) {
            Some(Self::Bytes(n))
        } else {
            count("Bits").map(Self::Bits)
        }
    }

    fn count(self) -> f64 {
        match self {
            Self::Elements(n) | Self::Bytes(n) | Self::Bits(n) => n,
        }
    }

    /// BMF measure name.
    fn measure(self) -> &'static str {
        match self {
            Self::Elements(_) => "throughput",
            Self::Bytes(_) => "throughput-bytes",
            Self::Bits(_) => "throughput-bits",
        }
    }

    fn unit(self) -> &'static str {
        match self {
            Self::Elements(_) => "elem/s",
            Self::Bytes(_) => "B/s",
            Self::Bits(_) => "bit/s",
        }
    }

    /// Per second at `ns` nanoseconds per iteration.
    fn per_second(self, ns: f64) -> f64 {
        self.count() / (ns * 1e-9)
    }
}

/// One benchmark's result: median and confidence bounds in ns per iteration.
#[derive(Debug, Clone, PartialEq)]
struct BenchResult {
    id: String,
    median_ns: f64,
    lower_ns: f64,
    upper_ns: f64,
    throughput: Option<Throughput>,
}

/// The results under `dir` that are new or changed since `before`, sorted by id.
fn collect_fresh(dir: &Path, before: &Snapshot) -> Result<Vec<BenchResult>, String> {
    let mut out = Vec::new();
    for d in new_dirs(dir) {
        let Some(now) = fingerprint(&d) else {
            continue;
        };
        if before.get(&d) == Some(&now) {
            continue; // left by an earlier run: not measured now
        }
        if let Some(r) = read_result(&d)? {
            out.push(r);
        }
    }
    out.sort_by(|a, b| a.id.cmp(&b.id));
    Ok(out)
}

fn read_json(p: &Path) -> Result<Value, String> {
    let text = std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))?;
    serde_json::from_str(&text).map_err(|e| format!("{}: {e}", p.display()))
}

fn read_result(new_dir: &Path) -> Result<Option<BenchResult>, String> {
    let bench = new_dir.join("benchmark.json");
    let est = new_dir.join("estimates.json");
    if !bench.is_file() || !est.is_file() {
        return Ok(None);
    }
    let b = read_json(&bench)?;
    let e = read_json(&est)?;
    let id = b
        .get("full_id")
        .and_then(Value::as_str)
        .ok_or_else(|| format!("{}: no `full_id`", bench.display()))?;
    let median = e
        .get("median")
        .ok_or_else(|| format!("{}: no `median`", est.display()))?;
    let num = |v: Option<&Value>, what: &str| {
        v.and_then(Value::as_f64)
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("{}: no finite median `{what}`", est.display()))
    };
    let median_ns = num(median.get("point_estimate"), "point_estimate")?;
    let ci = median.get("confidence_interval");
    let lower_ns = num(ci.and_then(|c| c.get("lower_bound")), "lower_bound")?;
    let upper_ns = num(ci.and_then(|c| c.get("upper_bound")), "upper_bound")?;
    let throughput = b.get("throughput").and_then(Throughput::from_json);
    Ok(Some(BenchResult {
        id: id.to_string(),
        median_ns,
        lower_ns,
        upper_ns,
        throughput,
    }))
}

/// The BMF document of `results`.
fn to_bmf(results: &[BenchResult]) -> Value {
    let mut bmf = Map::new();
    for r in results {
        let mut measures = Map::new();
        measures.insert(
            "latency".into(),
            json!({ "value": r.median_ns, "lower_value": r.lower_ns, "upper_value": r.upper_ns }),
        );
        if let Some(t) = r.throughput {
            measures.insert(
                t.measure().into(),
                json!({
                    "value": t.per_second(r.median_ns),
                    "lower_value": t.per_second(r.upper_ns),
                    "upper_value": t.per_second(r.lower_ns),
                }),
            );
        }
        bmf.insert(r.id.clone(), Value::Object(measures));
    }
    Value::Object(bmf)
}

fn human_ns(ns: f64) -> String {
    if ns < 1e3 {
        format!("{ns:.1} ns")
    } else if ns < 1e6 {
        format!("{:.2} µs", ns / 1e3)
    } else if ns < 1e9 {
        format!("{:.2} ms", ns / 1e6)
    } else {
        format!("{:.2} s", ns / 1e9)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]

    use super::*;

    /// A temporary folder removed on drop.
    struct TempDir(PathBuf);

    impl TempDir {
        fn new(tag: &str) -> Self {
            let p = std::env::temp_dir().join(format!(
                "xtask-bmf-{tag}-{}-{:?}",
                std::process::id(),
                std::thread::current().id()
            ));
            let _ = std::fs::remove_dir_all(&p);
            std::fs::create_dir_all(&p).unwrap();
            Self(p)
        }
    }

    impl Drop for TempDir {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    /// Writes a criterion result folder `<home>/<dir>/new/` like criterion 0.7 does.
    fn write_result(
        home: &Path,
        dir: &str,
        full_id: &str,
        throughput: Value,
        (lo, med, hi): (f64, f64, f64),
    ) {
        let new = home.join(dir).join("new");
        std::fs::create_dir_all(&new).unwrap();
        let bench = json!({
            "group_id": full_id.split('/').next().unwrap(),
            "function_id": null,
            "value_str": null,
            "throughput": throughput,
            "full_id": full_id,
            "directory_name": dir,
            "title": full_id,
        });
        let ci = |p: f64| {
            json!({
                "confidence_interval": {
                    "confidence_level": 0.95, "lower_bound": p * 0.9, "upper_bound": p * 1.1
                },
                "point_estimate": p,
                "standard_error": p * 0.05,
            })
        };
        let est = json!({
            // Mean and slope deliberately differ from the median: the export must use the
            // median.
            "mean": ci(med * 2.0),
            "median": {
                "confidence_interval": {
                    "confidence_level": 0.95, "lower_bound": lo, "upper_bound": hi
                },
                "point_estimate": med,
                "standard_error": 1.0,
            },
            "median_abs_dev": ci(1.0),
            "slope": ci(med * 3.0),
            "std_dev": ci(2.0),
        });
        std::fs::write(new.join("benchmark.json"), bench.to_string()).unwrap();
        std::fs::write(new.join("estimates.json"), est.to_string()).unwrap();
        // A baseline copy, as criterion keeps it: never read.
        let base = home.join(dir).join("base");
        std::fs::create_dir_all(&base).unwrap();
        std::fs::write(base.join("estimates.json"), est.to_string()).unwrap();
    }

    #[test]
    fn bmf_holds_latency_bounds_separate_throughput_and_only_fresh_results() {
        let tmp = TempDir::new("fresh");
        let home = tmp.0.join("criterion");
        // Left by an earlier run, unchanged by this one.
        write_result(
            &home,
            "stale/old",
            "stale/old",
            Value::Null,
            (9.0, 10.0, 11.0),
        );
        // Measured before, measured again now (its estimates change).
        write_result(
            &home,
            "eval/point",
            "eval/point",
            Value::Null,
            (1.0, 2.0, 3.0),
        );
        let before = snapshot(&home).unwrap();
        assert_eq!(before.len(), 2);

        write_result(
            &home,
            "eval/point",
            "eval/point",
            Value::Null,
            (40.0, 50.0, 65.0),
        );
        // New in this run, with 1000 elements per iteration.
        write_result(
            &home,
            "closest/batch_1000",
            "closest/batch 1000",
            json!({ "Elements": 1000 }),
            (1.8e6, 2.0e6, 2.5e6),
        );
        // New, bytes per iteration.
        write_result(
            &home,
            "io/read_cl",
            "io/read_cl",
            json!({ "Bytes": 4096 }),
            (900.0, 1000.0, 1100.0),
        );
        // Incomplete folder (criterion interrupted): skipped.
        std::fs::create_dir_all(home.join("broken").join("new")).unwrap();

        let results = collect_fresh(&home, &before).unwrap();
        let ids: Vec<&str> = results.iter().map(|r| r.id.as_str()).collect();
        assert_eq!(ids, ["closest/batch 1000", "eval/point", "io/read_cl"]);

        let bmf = to_bmf(&results);
        let obj = bmf.as_object().unwrap();
        assert_eq!(obj.len(), 3);
        assert!(!obj.contains_key("stale/old"));

        // Latency: median and its confidence bounds, ns per iteration, no throughput.
        let p = &bmf["eval/point"];
        assert_eq!(p["latency"]["value"], json!(50.0));
        assert_eq!(p["latency"]["lower_value"], json!(40.0));
        assert_eq!(p["latency"]["upper_value"], json!(65.0));
        assert_eq!(p.as_object().unwrap().len(), 1);

        // Elements: latency is per iteration (not divided by 1000); throughput separate.
        let c = &bmf["closest/batch 1000"];
        assert_eq!(c["latency"]["value"], json!(2.0e6));
        let tp = &c["throughput"];
        let close = |v: &Value, x: f64| (v.as_f64().unwrap() / x - 1.0).abs() < 1e-12;
        assert!(close(&tp["value"], 1000.0 / 2.0e-3), "{tp}");
        assert!(close(&tp["lower_value"], 1000.0 / 2.5e-3), "{tp}");
        assert!(close(&tp["upper_value"], 1000.0 / 1.8e-3), "{tp}");

        // Bytes: its own measure.
        let io = &bmf["io/read_cl"];
        assert!(close(&io["throughput-bytes"]["value"], 4096.0 / 1e-6));
        assert!(io.get("throughput").is_none());

        // Nothing ran: nothing fresh.
        let again = snapshot(&home).unwrap();
        assert!(collect_fresh(&home, &again).unwrap().is_empty());
    }

    #[test]
    fn missing_criterion_home_is_an_empty_snapshot() {
        let tmp = TempDir::new("missing");
        let home = tmp.0.join("does-not-exist");
        assert!(snapshot(&home).unwrap().is_empty());
        assert!(collect_fresh(&home, &Snapshot::new()).unwrap().is_empty());
    }

    #[test]
    fn malformed_estimates_are_an_error_naming_the_file() {
        let tmp = TempDir::new("malformed");
        let new = tmp.0.join("g").join("new");
        std::fs::create_dir_all(&new).unwrap();
        std::fs::write(new.join("benchmark.json"), r#"{"full_id":"g"}"#).unwrap();
        std::fs::write(new.join("estimates.json"), r#"{"mean":{}}"#).unwrap();
        let e = collect_fresh(&tmp.0, &Snapshot::new()).unwrap_err();
        assert!(e.contains("estimates.json"), "{e}");
    }
}
