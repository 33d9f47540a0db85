//! `cargo xtask fuzz`: the libFuzzer targets in `fuzz/` (over the logic
//! crate's parsers), built the way cargo-fuzz builds them and run for a
//! bounded time. No cargo-fuzz needed: its build is one `cargo build` with
//! the sanitizer-coverage flags below, and its run is the target binary with
//! libFuzzer's options.

use crate::run::{cargo_cmd, root, status, Result};
use std::fs::{self, File};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::time::Instant;

/// Every target in fuzz/Cargo.toml.
pub const TARGETS: [&str; 4] = ["gcode", "fat", "param", "poradi"];

/// Seconds per target in `cargo xtask test`: a seeded sample, the longer
/// campaigns are `cargo xtask soak`'s and `cargo xtask fuzz --seconds N`'s.
/// Measured from the committed seeds (docs/fuzzing.md): `gcode`, `param`
/// and `poradi` reach the edge coverage of a 2-minute run within 20 s;
/// `fat` keeps finding a little after. Four targets, two at a time on two
/// cores, take 40 s plus the build (about 70 s from nothing).
pub const TEST_SECONDS: u64 = 20;

/// libFuzzer's seed in `cargo xtask test`, so that a CI run mutates the same
/// way every time (how far it gets still depends on the machine's speed).
pub const TEST_SEED: u64 = 1;

/// An input that runs longer than this is a hang, reported like a crash.
const INPUT_TIMEOUT_S: u64 = 10;

/// Instrumentation as cargo-fuzz passes it (`cargo fuzz build` defaults,
/// release, without AddressSanitizer: taut-logic and the targets are
/// `forbid(unsafe_code)`, so ASan would find nothing that bounds checks do not,
/// at half the executions per second), plus `-Cdebug-assertions` (cargo-fuzz's
/// `-a`): overflow checks on, as in the host tests.
const RUSTFLAGS: &[&str] = &[
    "-Cpasses=sancov-module",
    "-Cllvm-args=-sanitizer-coverage-level=4",
    "-Cllvm-args=-sanitizer-coverage-inline-8bit-counters",
    "-Cllvm-args=-sanitizer-coverage-pc-table",
    "-Cllvm-args=-sanitizer-coverage-trace-compares",
    "--cfg",
    "fuzzing",
    "-Cllvm-args=-simplifycfg-branch-fold-threshold=0",
    "-Cdebug-assertions",
    "-Ccodegen-units=1",
];

pub const USAGE: &str = "usage: cargo xtask fuzz [TARGET] [--seconds N] [--seed N]
  TARGET      gcode, fat, param or poradi (default: all four)
  --seconds N each target runs N seconds (default 20)
  --seed N    libFuzzer's random seed (default: a new one each run)
The corpus grows in target/fuzz/corpus/TARGET (started from fuzz/seeds/TARGET);
a crashing input is saved in target/fuzz/artifacts/TARGET/.";

pub struct Plan {
    pub targets: Vec<&'static str>,
    pub seconds: u64,
    pub seed: Option<u64>,
}

impl Plan {
    /// What `cargo xtask test` runs.
    pub fn test() -> Plan {
        Plan {
            targets: TARGETS.to_vec(),
            seconds: TEST_SECONDS,
            seed: Some(TEST_SEED),
        }
    }

    pub fn parse(args: &[String]) -> Result<Plan> {
        let mut plan = Plan {
            targets: TARGETS.to_vec(),
            seconds: TEST_SECONDS,
            seed: None,
        };
        let mut it = args.iter();
        let number = |flag: &str, v: Option<&String>| -> Result<u64> {
            v.and_then(|v| v.parse().ok())
                .ok_or_else(|| format!("{flag} needs a number\n{USAGE}").into())
        };
        while let Some(a) = it.next() {
            match a.as_str() {
                "--seconds" => plan.seconds = number(a, it.next())?.max(1),
                "--seed" => plan.seed = Some(number(a, it.next())?),
                t => match TARGETS.iter().find(|&&n| n == t) {
                    Some(n) => plan.targets = vec![n],
                    None => return Err(format!("unknown fuzz target `{t}`\n{USAGE}").into()),
                },
            }
        }
        Ok(plan)
    }
}

fn fuzz_dir() -> PathBuf {
    root().join("fuzz")
}

/// The fuzz build's own target dir (not the host workspace's artifacts).
fn out_dir() -> PathBuf {
    root().join("target/fuzz")
}

/// Build every target; returns the folder of the binaries.
pub fn build() -> Result<PathBuf> {
    // The pinned nightly: fuzz/rust-toolchain.toml, picked by running in fuzz/.
    let out = Command::new("rustc")
        .arg("-vV")
        .current_dir(fuzz_dir())
        .env_remove("RUSTUP_TOOLCHAIN")
        .output()?;
    let info = String::from_utf8_lossy(&out.stdout);
    let host = info
        .lines()
        .find_map(|l| l.strip_prefix("host: "))
        .ok_or("no host triple in `rustc -vV`")?
        .to_string();
    let mut flags = RUSTFLAGS.join(" ");
    if host.contains("-linux-") {
        flags.push_str(" -Cllvm-args=-sanitizer-coverage-stack-depth");
    }
    println!("== building the fuzz targets (libFuzzer, {host})");
    let dir = out_dir();
    let mut c = cargo_cmd(
        &[
            "build",
            "--release",
            "--bins",
            "--target",
            &host,
            "--config",
            "profile.release.debug=\"line-tables-only\"",
            "--target-dir",
        ],
        &fuzz_dir(),
    );
    c.arg(&dir)
        .env("RUSTFLAGS", flags)
        .env_remove("CARGO_ENCODED_RUSTFLAGS");
    status(&mut c)?;
    Ok(dir.join(host).join("release"))
}

struct Outcome {
    target: &'static str,
    passed: bool,
    report: String,
}

/// Build, then run the plan's targets, as many at a time as there are cores.
/// Fails if any target finds a crash, a hang or runs out of memory.
pub fn run(plan: &Plan) -> Result<()> {
    let bins = build()?;
    let jobs = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(plan.targets.len());
    println!(
        "== fuzzing: {} for {} s each, {jobs} at a time, seed {}",
        plan.targets.join(", "),
        plan.seconds,
        plan.seed.map_or("random".into(), |s| s.to_string()),
    );
    let queue = Mutex::new(plan.targets.iter().copied());
    let outcomes = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..jobs {
            s.spawn(|| loop {
                let Some(target) = queue.lock().unwrap().next() else {
                    break;
                };
                let o = run_one(&bins, target, plan);
                println!("{}", o.report);
                outcomes.lock().unwrap().push(o);
            });
        }
    });
    let outcomes = outcomes.into_inner().unwrap();
    let failed: Vec<_> = outcomes
        .iter()
        .filter(|o| !o.passed)
        .map(|o| o.target)
        .collect();
    println!(
        "fuzz: {} passed, {} failed",
        outcomes.len() - failed.len(),
        failed.len()
    );
    if failed.is_empty() {
        Ok(())
    } else {
        Err(format!("fuzz target(s) failed: {}", failed.join(", ")).into())
    }
}

fn run_one(bins: &Path, target: &'static str, plan: &Plan) -> Outcome {
    match try_run_one(bins, target, plan) {
        Ok(o) => o,
        Err(e) => Outcome {
            target,
            passed: false,
            report: format!("fuzz {target}: FAILED to run: {e}"),
        },
    }
}

fn try_run_one(bins: &Path, target: &'static str, plan: &Plan) -> Result<Outcome> {
    let dir = out_dir();
    let corpus = dir.join("corpus").join(target);
    let artifacts = dir.join("artifacts").join(target);
    let logs = dir.join("logs");
    for d in [&corpus, &artifacts, &logs] {
        fs::create_dir_all(d)?;
    }
    let log_path = logs.join(format!("{target}.log"));
    let log = File::create(&log_path)?;
    let bin = bins.join(target);
    let mut c = Command::new(&bin);
    // New inputs go to the first folder; the committed seeds are read only.
    c.arg(&corpus);
    let seeds = fuzz_dir().join("seeds").join(target);
    if seeds.is_dir() {
        c.arg(&seeds);
    }
    c.arg(format!("-max_total_time={}", plan.seconds))
        .arg(format!("-timeout={INPUT_TIMEOUT_S}"))
        .arg(format!("-artifact_prefix={}/", artifacts.display()))
        .arg("-print_final_stats=1")
        .stdin(Stdio::null())
        .stdout(log.try_clone()?)
        .stderr(log);
    if let Some(seed) = plan.seed {
        c.arg(format!("-seed={seed}"));
    }
    let start = Instant::now();
    let st = c
        .status()
        .map_err(|e| format!("cannot run {}: {e}", bin.display()))?;
    let secs = start.elapsed().as_secs();
    let text = fs::read_to_string(&log_path).unwrap_or_default();
    let rel = |p: &Path| p.strip_prefix(root()).unwrap_or(p).display().to_string();
    if st.success() {
        return Ok(Outcome {
            target,
            passed: true,
            report: format!("fuzz {target}: ok, {} in {secs} s", stats(&text)),
        });
    }
    // A crash, a hang or out of memory: libFuzzer saved the input.
    let input = text
        .lines()
        .rev()
        .find_map(|l| l.split_once("Test unit written to ").map(|(_, p)| p.trim()));
    let mut report = format!("fuzz {target}: FAILED ({st}) after {secs} s\n");
    for l in what_failed(&text) {
        report += &format!("  | {l}\n");
    }
    match input {
        Some(p) => {
            report += &format!("  input: {p}\n");
            report += &format!("  reproduce: {} {p}\n", rel(&bin));
        }
        None => report += "  (no input saved)\n",
    }
    report += &format!("  log: {}\n", rel(&log_path));
    Ok(Outcome {
        target,
        passed: false,
        report: report.trim_end().to_string(),
    })
}

/// The lines of a failed run's log that say what happened: the panic
/// message (without its backtrace) and libFuzzer's error and summary.
fn what_failed(log: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut in_panic = false;
    for l in log.lines() {
        if l.contains(" panicked at ") {
            in_panic = true;
        } else if l.starts_with("stack backtrace:")
            || l.starts_with("note: ")
            || l.starts_with("==")
        {
            in_panic = false;
        }
        if (in_panic && out.len() < 12)
            || (l.starts_with("==") && l.contains("ERROR"))
            || l.starts_with("SUMMARY:")
        {
            out.push(l);
        }
    }
    out
}

/// "N runs, cov C, corpus K" from libFuzzer's last status line.
fn stats(log: &str) -> String {
    let field = |line: &str, key: &str| -> Option<String> {
        let mut words = line.split_whitespace();
        words.find(|&w| w == key)?;
        words.next().map(str::to_string)
    };
    let runs = log
        .lines()
        .rev()
        .filter_map(|l| l.strip_prefix("Done "))
        .find_map(|l| l.split_whitespace().next());
    // `#123 DONE cov: …` (not the `###### Recommended dictionary` lines).
    let last = log
        .lines()
        .rev()
        .find(|l| {
            l.strip_prefix('#')
                .is_some_and(|r| r.starts_with(|c: char| c.is_ascii_digit()))
        })
        .unwrap_or("");
    let mut parts = vec![];
    if let Some(r) = runs {
        parts.push(format!("{r} runs"));
    }
    if let Some(c) = field(last, "cov:") {
        parts.push(format!("cov {c}"));
    }
    if let Some(c) = field(last, "corp:") {
        parts.push(format!("corpus {}", c.split('/').next().unwrap_or(&c)));
    }
    if let Some(e) = field(last, "exec/s:") {
        parts.push(format!("{e} exec/s"));
    }
    parts.join(", ")
}
