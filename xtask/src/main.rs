//! `cargo xtask <command>`: the project's two README commands (`demo`,
//! `test`) and the tools behind them. Every command that builds first runs
//! the idempotent bootstrap (`scripts/setup.sh`).

mod bench;
mod bench_page;
mod cycles;
mod demo;
mod estimate;
mod firmware;
mod flashmap;
mod fuzz;
mod run;
mod stackargs;
mod studio;

use run::{root, Result};
use std::process::ExitCode;
use std::time::Instant;

const HELP: &str = "\
usage: cargo xtask <command> [args]

  demo              build everything and run the string-art machine's whole job
                    on the simulated Mega (target/demo/: trace, report, picture)
  demo plotter [MACHINE]
                    a plotter (flatbed, drum, whiteboard, scara; default flatbed)
                    draws examples/plotter/star.gcode streamed over its serial port
  test              the firmware images and lints, the fuzz targets (20 s each),
                    then the host unit tests of every crate and the HIL tests
  fuzz [TARGET] [--seconds N] [--seed N]
                    build the libFuzzer targets and run each N seconds (default all,
                    20 s); `cargo xtask fuzz --help` lists the targets
  cycles            the import cycles between each crate's modules (test runs it)
  simtest           build the firmware images and run the HIL tests in simavr
  soak              the HIL tests at full size (5000-move streams, 100 wraps of a
                    10 000-connection job, a 1 000 000-connection pattern, fuzzing
                    10 min a target): tens of minutes
  build             release ELF + Intel HEX, the size and the flash map checked
                    (fails past 224 KiB, without the watchdog entry at 0x20000,
                    or with a function pointer out of a 16-bit pointer's reach)
  sim [OPTIONS]     run the release image in simavr; `cargo xtask sim --help`
                    lists the options (docs/simulator.md)
  sim --bootloader HEX --pty PATH [OPTIONS]
                    a Mega holding only that bootloader, its serial port on PATH:
                    flash it with avrdude -c wiring or ravedude (docs/hardware.md)
  studio [--port N] [--machine NAME] [--vcd FILE]
                    the web app (taut studio) against the simulated Mega
  sdimage DIR -o IMG
                    build a FAT card image from a folder (dd it to a real card)
  estimate DIR      the machine time of a card folder's job: this firmware's (its
                    own job, planner and trapezoids, on the host) and the original's
  bench [--page]    measure, write target/bench.json and docs/benchmarks.md
                    (--page: only the page again, from target/bench.json)
  flash             build, then flash a Mega 2560 through ravedude (`cargo run
                    --release` in firmware/; RAVEDUDE_PORT=PATH picks the port)
  setup             install what is missing (apt packages, the pinned nightly,
                    avrdude, the stock bootloader, ravedude)
  help              this text
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
        "cycles" => cycles::check(),
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
        "bench" => run::setup().and_then(|_| bench::run(rest)),
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
    // The real senders' downloads overlap the firmware build and the fuzzing.
    let clients = run::Background::start(
        "installing the HIL tests' senders (grbl-streamer, CNCjs)",
        &root().join("hil-tests/clients/install.sh"),
        &root().join("target/clients/install.log"),
    )?;
    cycles::check()?;
    let img = firmware_images()?;
    let firmware = start.elapsed().as_secs();
    fuzz::run(&fuzz::Plan::test())?;
    let fuzz = start.elapsed().as_secs() - firmware;
    clients.finish()?;
    // The host unit tests and the HIL tests in one cargo run: every crate
    // is built once, with the features of the whole workspace (two runs
    // selecting different packages built the shared ones twice).
    println!("== host unit tests, then the HIL tests (release firmware in simavr)");
    hil_tests(&["test", "--workspace"], &img)?;
    let total = start.elapsed().as_secs();
    println!(
        "== all tests passed in {total} s (firmware lints and images {firmware} s, fuzz {fuzz} s, \
         host and HIL tests {} s)",
        total - firmware - fuzz
    );
    Ok(())
}

fn simtest() -> Result<()> {
    let img = firmware_images()?;
    println!("== HIL tests (release firmware in simavr)");
    hil_tests(&["test", "-p", "hil-tests"], &img)
}

/// The firmware's lints, its release image and the example images.
fn firmware_images() -> Result<firmware::Image> {
    firmware::lint()?;
    let img = firmware::build_release()?;
    firmware::build_examples()?;
    img.print_size();
    Ok(img)
}

/// `cargo ARGS` running the HIL tests, then the run's RAM figure.
fn hil_tests(args: &[&str], img: &firmware::Image) -> Result<()> {
    // Each test adds its stack peak (and, with `TAUT_STACK_CHAINS`, its
    // call chain): this run's only.
    let peaks = root().join("target/hil-stack-peaks.txt");
    let _ = std::fs::remove_file(&peaks);
    let _ = std::fs::remove_file(root().join("target/hil-stack-chains.txt"));
    let mut test = run::cargo_cmd(args, &root());
    run::status(test.env("TAUT_STACK_CHAINS", "1"))?;
    print_ram(img, &peaks)
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

/// Run `taut-sim` (the simulator CLI in simavr/) on the release image;
/// with `--bootloader HEX`, on a Mega whose flash holds only that
/// bootloader (the release image built, for avrdude to write).
fn sim(args: &[String]) -> Result<()> {
    let img = firmware::build_release()?;
    if args.iter().any(|a| a == "--bootloader") {
        println!(
            "== a Mega with only its bootloader; flash {}",
            img.hex.display()
        );
        return run::bin("taut-sim", args);
    }
    run::taut_sim(&img.elf, args)
}

#[cfg(test)]
mod tests {
    /// Every command `main` answers is in the help, with its arguments.
    #[test]
    fn the_help_lists_every_command() {
        let source = include_str!("main.rs");
        let commands: Vec<&str> = source
            .lines()
            .filter_map(|l| l.trim().strip_prefix('"')?.split('"').next())
            .filter(|c| c.chars().all(|c| c.is_ascii_lowercase()) && !c.is_empty())
            .collect();
        assert!(commands.len() >= 12, "{commands:?}");
        for c in commands {
            assert!(
                super::HELP.contains(&format!("\n  {c}")),
                "{c} missing from the help"
            );
        }
        assert!(super::HELP.contains("demo plotter [MACHINE]"));
        assert!(super::HELP.contains("sdimage DIR -o IMG"));
    }
}
