//! `cargo xtask <command>`: the project's two README commands (`demo`,
//! `test`) and the tools behind them. Every command that builds first runs
//! the idempotent bootstrap (`scripts/setup.sh`).

mod bench;
mod demo;
mod estimate;
mod firmware;
mod fuzz;
mod run;
mod studio;

use run::{cargo, root, Result};
use std::process::ExitCode;
use std::time::Instant;

const HELP: &str = "\
usage: cargo xtask <command> [args]

  demo              build everything and run the main job on the simulated machine
  test              host unit tests of every crate, the fuzz targets (40 s each), simtest
  fuzz [TARGET] [--seconds N] [--seed N]
                    build the libFuzzer targets and run each N seconds (default all, 40 s)
  simtest           build the firmware images and run the HIL tests in simavr
  soak              the HIL tests at full size (5000-move streams, 100 wraps of a
                    10 000-connection job, a 1 000 000-connection pattern, fuzzing
                    10 min a target): tens of minutes
  build             release ELF + Intel HEX + size report
  sim [args]        run the firmware in simavr (see `cargo xtask sim --help`)
  studio [--port N] [--machine NAME] [--vcd FILE]
                    the web app (taut studio) against the simulated Mega
  sdimage DIR -o IMG  build a FAT card image from a folder (dd it to a real card)
  estimate DIR      the machine time of a card folder's job: this firmware's (its
                    own job, planner and trapezoids, on the host) and the original's
  bench             measure, write target/bench.json, print a table
  flash             flash a Mega 2560 through ravedude
  setup             install what is missing (apt packages, the pinned nightly)
";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (cmd, rest) = match args.split_first() {
        Some((c, r)) => (c.as_str(), r),
        None => {
            print!("{HELP}");
            return ExitCode::FAILURE;
        }
    };
    let result = match cmd {
        "setup" => run::setup(),
        "build" => run::setup().and_then(|_| firmware::build_release().map(|img| img.print_size())),
        "test" => test(),
        "simtest" => run::setup().and_then(|_| simtest()),
        "soak" => run::setup().and_then(|_| soak()),
        "fuzz" if rest.iter().any(|a| a == "-h" || a == "--help") => {
            println!("{}", fuzz::USAGE);
            Ok(())
        }
        "fuzz" => {
            fuzz::Plan::parse(rest).and_then(|plan| run::setup().and_then(|_| fuzz::run(&plan)))
        }
        "sim" => run::setup().and_then(|_| sim(rest)),
        "studio" => run::setup().and_then(|_| studio::run(rest)),
        "sdimage" => run::setup().and_then(|_| run::bin("taut-sdimage", rest)),
        "demo" => run::setup().and_then(|_| match rest.first().map(String::as_str) {
            None => demo::run(),
            Some("plotter") => demo::plotter(rest.get(1).map_or("flatbed", String::as_str)),
            Some(other) => Err(format!("demo {other}: `demo` or `demo plotter [MACHINE]`").into()),
        }),
        "bench" => run::setup().and_then(|_| bench::run()),
        "estimate" => estimate::run(rest),
        "flash" => run::setup().and_then(|_| firmware::flash()),
        "help" | "--help" | "-h" => {
            print!("{HELP}");
            Ok(())
        }
        other => Err(format!("unknown command `{other}`\n{HELP}").into()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask: {e}");
            ExitCode::FAILURE
        }
    }
}

fn test() -> Result<()> {
    let start = Instant::now();
    run::setup()?;
    // The real senders' downloads overlap the host tests and the fuzzing.
    let clients = run::Background::start(
        "installing the HIL tests' senders (grbl-streamer, CNCjs)",
        &root().join("hil-tests/clients/install.sh"),
        &root().join("target/clients/install.log"),
    )?;
    println!("== host unit tests");
    cargo(&["test", "--workspace", "--exclude", "hil-tests"], &root())?;
    let host = start.elapsed().as_secs();
    fuzz::run(&fuzz::Plan::test())?;
    let fuzz = start.elapsed().as_secs() - host;
    clients.finish()?;
    simtest()?;
    let total = start.elapsed().as_secs();
    println!(
        "== all tests passed in {total} s (host unit tests {host} s, fuzz {fuzz} s, firmware and HIL tests {} s)",
        total - host - fuzz
    );
    Ok(())
}

fn simtest() -> Result<()> {
    let img = firmware::build_release()?;
    firmware::build_examples()?;
    img.print_size();
    println!("== HIL tests (release firmware in simavr)");
    // Each test adds its stack peak (and, with `TAUT_STACK_CHAINS`, its
    // call chain): this run's only.
    let peaks = root().join("target/hil-stack-peaks.txt");
    let _ = std::fs::remove_file(&peaks);
    let _ = std::fs::remove_file(root().join("target/hil-stack-chains.txt"));
    let mut test = run::cargo_cmd(&["test", "-p", "hil-tests"], &root());
    run::status(test.env("TAUT_STACK_CHAINS", "1"))?;
    print_ram(&img, &peaks)
}

/// The run's RAM figure: static data plus the deepest stack any HIL test
/// saw, checked against the budget (each test also checks its own).
fn print_ram(img: &firmware::Image, peaks: &std::path::Path) -> Result<()> {
    let text = std::fs::read_to_string(peaks).unwrap_or_default();
    let deepest = text
        .lines()
        .filter_map(|l| {
            let mut f = l.split_whitespace();
            let test = f.next()?;
            Some((f.next()?.parse::<u64>().ok()?, test))
        })
        .max();
    if let Some((stack, test)) = deepest {
        let total = img.ram_static_bytes + stack;
        println!(
            "== RAM: static {} B + deepest stack {stack} B ({test}) = {total} B of the {} B budget \
             (each test's call chain: target/hil-stack-chains.txt)",
            img.ram_static_bytes,
            firmware::RAM_BUDGET
        );
        if total > firmware::RAM_BUDGET {
            return Err(format!(
                "static RAM + deepest stack {total} B is over the {} B budget",
                firmware::RAM_BUDGET
            )
            .into());
        }
    }
    Ok(())
}

/// The campaigns too long for CI: every HIL test at its full size
/// (`TAUT_SOAK=1`) with the ignored (soak-only) ones, then longer fuzzing.
fn soak() -> Result<()> {
    let img = firmware::build_release()?;
    firmware::build_examples()?;
    img.print_size();
    println!("== HIL tests at full size (TAUT_SOAK=1)");
    let mut c = run::cargo_cmd(
        &["test", "-p", "hil-tests", "--", "--include-ignored"],
        &root(),
    );
    run::status(c.env("TAUT_SOAK", "1"))?;
    fuzz::run(&fuzz::Plan::parse(&[
        "--seconds".to_string(),
        "600".to_string(),
    ])?)
}

/// Run `taut-sim` (the simulator CLI in simavr/) on the release image.
fn sim(args: &[String]) -> Result<()> {
    let img = firmware::build_release()?;
    run::taut_sim(&img.elf, args)
}
