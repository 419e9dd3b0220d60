//! `cargo xtask ci`: what CI runs, runnable on any machine.
//!
//! 1. Installs the real consumers the tests use when they are missing (Debian packages,
//!    through `apt-get`; as root, else with `sudo -n`): LinuxCNC's standalone interpreter
//!    `rs274` (package `linuxcnc-uspace`) and headless `chromium` (package `chromium`). A
//!    failed installation is reported and the run continues: those tests then say they were
//!    skipped, or fail under `CI=true`.
//! 2. `cargo fmt --all -- --check`, `cargo clippy --workspace --all-targets -- -D warnings`.
//! 3. `cargo test --workspace` (`PROPTEST_CASES` defaults to 64, `CARGO_TERM_COLOR=never`).
//! 4. `cargo xtask regress --debug` (the fixture regressions with the binary just built).
//! 5. One closing line with the totals of every test binary: `tests: N passed, N failed`.
//!
//! Stops at the first failing step (after printing the test totals when the tests ran).

use crate::workspace_root;
use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Stdio};

/// Arguments of `cargo xtask ci`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Do not try to install missing packages.
    #[arg(long)]
    pub no_install: bool,
    /// Only the set-up and the static checks (install, fmt, clippy): `.ci/run` then runs the
    /// README's test command and the regressions itself.
    #[arg(long)]
    pub checks_only: bool,
}

/// Debian packages providing the external programs the tests use: (program, package).
const PACKAGES: [(&str, &str); 2] = [("rs274", "linuxcnc-uspace"), ("chromium", "chromium")];

/// Default number of proptest cases per property in CI.
const PROPTEST_CASES_DEFAULT: &str = "64";

fn on_path(program: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|p| std::env::split_paths(&p).any(|d| d.join(program).is_file()))
}

fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
}

/// `apt-get` as root, or through `sudo -n` (never prompting).
fn apt(args: &[&str]) -> bool {
    let mut cmd = if is_root() {
        Command::new("apt-get")
    } else {
        let mut c = Command::new("sudo");
        c.args(["-n", "apt-get"]);
        c
    };
    cmd.args(args)
        .env("DEBIAN_FRONTEND", "noninteractive")
        .status()
        .is_ok_and(|s| s.success())
}

fn install_missing() {
    let missing: Vec<(&str, &str)> = PACKAGES
        .iter()
        .copied()
        .filter(|(prog, _)| !on_path(prog))
        .collect();
    if missing.is_empty() {
        return;
    }
    let names: Vec<&str> = missing.iter().map(|(_, pkg)| *pkg).collect();
    println!("ci: installing {}", names.join(", "));
    let mut args = vec!["install", "-y", "-qq", "--no-install-recommends"];
    args.extend(&names);
    if !(apt(&["update", "-qq"]) && apt(&args)) {
        println!(
            "ci: warning: could not install {}; the tests that need them will say they were \
             skipped (or fail under CI=true)",
            names.join(", ")
        );
    }
}

fn cargo() -> Command {
    let mut c = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    c.current_dir(workspace_root());
    c
}

/// Totals of every `test result:` line: (passed, failed).
pub(crate) fn totals(log: &str) -> (u64, u64) {
    let (mut passed, mut failed) = (0, 0);
    for line in log.lines().filter(|l| l.starts_with("test result:")) {
        let words: Vec<&str> = line.split_whitespace().collect();
        for w in words.windows(2) {
            let n = w[0].parse::<u64>().ok();
            match (n, w[1].trim_end_matches([';', ','])) {
                (Some(n), "passed") => passed += n,
                (Some(n), "failed") => failed += n,
                _ => {}
            }
        }
    }
    (passed, failed)
}

pub fn run(args: Args) -> Result<bool, String> {
    if !args.no_install {
        install_missing();
    }
    std::env::set_var("CARGO_TERM_COLOR", "never");
    if std::env::var_os("PROPTEST_CASES").is_none() {
        std::env::set_var("PROPTEST_CASES", PROPTEST_CASES_DEFAULT);
    }
    crate::run_cmd(cargo().args(["fmt", "--all", "--", "--check"]))?;
    crate::run_cmd(cargo().args([
        "clippy",
        "--workspace",
        "--all-targets",
        "--",
        "-D",
        "warnings",
    ]))?;
    if args.checks_only {
        return Ok(true);
    }
    // The tests: stream both outputs through, keep them for the totals.
    let mut child = cargo()
        .args(["test", "--workspace"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start cargo test: {e}"))?;
    let stderr = child.stderr.take();
    let err_thread = std::thread::spawn(move || {
        let mut kept = String::new();
        if let Some(s) = stderr {
            for line in BufReader::new(s).lines().map_while(Result::ok) {
                eprintln!("{line}");
                kept.push_str(&line);
                kept.push('\n');
            }
        }
        kept
    });
    let mut log = String::new();
    if let Some(out) = child.stdout.take() {
        let mut so = std::io::stdout();
        for line in BufReader::new(out).lines().map_while(Result::ok) {
            let _ = writeln!(so, "{line}");
            log.push_str(&line);
            log.push('\n');
        }
    }
    let status = child
        .wait()
        .map_err(|e| format!("cargo test did not finish: {e}"))?;
    let kept_err = err_thread.join().unwrap_or_default();
    log.push_str(&kept_err);
    let (passed, failed) = totals(&log);
    let tests_ok = status.success();
    if tests_ok {
        let regress_ok = crate::regress::run(crate::regress::Args {
            filter: None,
            debug: true,
        })?;
        println!("tests: {passed} passed, {failed} failed");
        Ok(regress_ok)
    } else {
        println!("tests: {passed} passed, {failed} failed");
        Ok(false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn totals_sum_every_test_binary() {
        let log = "running 3 tests\ntest result: ok. 3 passed; 0 failed; 1 ignored; 0 measured; 0 filtered out; finished in 0.1s\n\
                   test result: FAILED. 5 passed; 2 failed; 0 ignored; 0 measured; 0 filtered out\n\
                   not a result: 7 passed\n";
        assert_eq!(totals(log), (8, 2));
    }
}
