//! `cargo xtask bench`: criterion benchmarks → Bencher Metric Format.

use crate::{run_cmd, target_dir, workspace_root, write_atomic};
use serde_json::{json, Map, Value};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Arguments of `cargo xtask bench`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Only run benchmarks whose id contains this string (criterion filter).
    pub filter: Option<String>,
    /// Short measurement (criterion `--quick`): for a smoke run, not for figures.
    #[arg(long)]
    pub quick: bool,
    /// Do not run the benchmarks; only collect existing criterion results.
    #[arg(long)]
    pub collect_only: bool,
}

pub fn run(args: Args) -> Result<bool, String> {
    let root = workspace_root();
    let target = target_dir();
    let mut export_ok = true;
    if !args.collect_only {
        // One `cargo bench` per criterion target: `--benches` alone would also hand
        // criterion's flags to the libtest harness of every library.
        for (package, bench) in bench_targets(&root)? {
            let mut cmd = Command::new(env_cargo());
            cmd.current_dir(&root)
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
    }
    let results = collect(&target.join("criterion"))?;
    if results.is_empty() {
        return Err("no criterion results found under target/criterion".into());
    }
    let mut bmf = Map::new();
    println!("{:<48} {:>14}", "benchmark", "median");
    for (name, ns) in &results {
        println!("{name:<48} {:>14}", human_ns(*ns));
        bmf.insert(name.clone(), json!({ "latency": { "value": ns } }));
    }
    let out = target.join("bench").join("bmf.json");
    let text = serde_json::to_string_pretty(&Value::Object(bmf)).map_err(|e| e.to_string())?;
    write_atomic(&out, text.as_bytes())?;
    println!("wrote {}", out.display());
    Ok(export_ok)
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

/// Every `<dir>/**/new/{benchmark,estimates}.json` pair → (full id, median ns).
fn collect(dir: &Path) -> Result<Vec<(String, f64)>, String> {
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
                    if let Some(r) = read_result(&p)? {
                        out.push(r);
                    }
                } else {
                    stack.push(p);
                }
            }
        }
    }
    out.sort_by(|a, b| a.0.cmp(&b.0));
    Ok(out)
}

fn read_json(p: &Path) -> Result<Value, String> {
    let text = std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))?;
    serde_json::from_str(&text).map_err(|e| format!("{}: {e}", p.display()))
}

fn read_result(new_dir: &Path) -> Result<Option<(String, f64)>, String> {
    let bench = new_dir.join("benchmark.json");
    let est = new_dir.join("estimates.json");
    if !bench.is_file() || !est.is_file() {
        return Ok(None);
    }
    let b = read_json(&bench)?;
    let e = read_json(&est)?;
    let Some(id) = b.get("full_id").and_then(Value::as_str) else {
        return Ok(None);
    };
    let Some(median) = e
        .get("median")
        .and_then(|m| m.get("point_estimate"))
        .and_then(Value::as_f64)
    else {
        return Ok(None);
    };
    // Per-element figure when the benchmark declared a throughput of N elements.
    let per = b
        .get("throughput")
        .and_then(|t| t.get("Elements"))
        .and_then(Value::as_f64)
        .filter(|n| *n > 0.0)
        .unwrap_or(1.0);
    Ok(Some((id.to_string(), median / per)))
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
