//! `cargo xtask <command>`: the project's two README commands (`demo`,
//! `test`) and the tools behind them. Every command that builds first runs
//! the idempotent bootstrap (`scripts/setup.sh`).

mod bench;
mod firmware;
mod run;

use run::{cargo, root, Result};
use std::process::ExitCode;

const HELP: &str = "\
usage: cargo xtask <command> [args]

  demo              build everything and run the main job on the simulated machine
  test              host unit tests of every crate + simtest
  simtest           build the firmware images and run the HIL tests in simavr
  build             release ELF + Intel HEX + size report
  sim [args]        run the firmware in simavr (see `cargo xtask sim --help`)
  sdimage DIR -o IMG  build a FAT card image from a folder (dd it to a real card)
  bench             measure, write target/bench.json, print a table
  flash             flash a Mega 2560 through ravedude
  setup             install what is missing (apt packages, rust-src)
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
        "sim" => run::setup().and_then(|_| sim(rest)),
        "sdimage" => run::setup().and_then(|_| run::bin("taut-sdimage", rest)),
        "demo" => run::setup().and_then(|_| demo()),
        "bench" => run::setup().and_then(|_| bench::run()),
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
    run::setup()?;
    println!("== host unit tests");
    cargo(&["test", "--workspace", "--exclude", "hil-tests"], &root())?;
    simtest()
}

fn simtest() -> Result<()> {
    let img = firmware::build_release()?;
    firmware::build_examples()?;
    img.print_size();
    println!("== HIL tests (release firmware in simavr)");
    cargo(&["test", "-p", "hil-tests"], &root())
}

/// Run `taut-sim` (the simulator CLI in simavr/) on the release image.
fn sim(args: &[String]) -> Result<()> {
    let img = firmware::build_release()?;
    run::taut_sim(&img.elf, args)
}

fn demo() -> Result<()> {
    let img = firmware::build_release()?;
    img.print_size();
    let out = root().join("target/demo");
    std::fs::create_dir_all(&out)?;
    let report = out.join("report.json");
    let vcd = out.join("trace.vcd");
    let job = root().join("examples/demo.gcode");
    println!(
        "== the simulated machine runs {} (drilling a hexagon's 6 holes)",
        job.display()
    );
    let wall = std::time::Instant::now();
    run::taut_sim(
        &img.elf,
        &[
            "--send".into(),
            job.display().to_string(),
            "--vcd".into(),
            vcd.display().to_string(),
            "--report".into(),
            report.display().to_string(),
            "--echo".into(),
        ],
    )?;
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report)?)?;
    println!(
        "\nmachine time {:.1} s, wall time {:.1} s",
        r["sim_seconds"].as_f64().unwrap_or(0.0),
        wall.elapsed().as_secs_f64()
    );
    for pin in r["pins"].as_array().into_iter().flatten() {
        if let Some(steps) = pin["net_steps"].as_i64() {
            println!(
                "  {:<12} {:>6} pulses, net {:>6} steps",
                pin["name"].as_str().unwrap_or(""),
                pin["rising"],
                steps
            );
        }
    }
    println!(
        "\nThe full string-art job (card, buttons, winding, picture) arrives with issues 5 and 6."
    );
    println!("written: {}\n         {}", report.display(), vcd.display());
    Ok(())
}
