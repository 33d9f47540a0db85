//! `cargo xtask bench`: figures from simavr's cycle counter (`taut-bench`
//! in simavr/), written to target/bench.json and printed as a table.

use crate::firmware;
use crate::run::{cargo_cmd, root, status, Result};

pub fn run() -> Result<()> {
    let img = firmware::build_release()?;
    firmware::build_examples()?;
    let busy = firmware::release_dir().join("examples/busy.elf");
    let out = root().join("target/bench.json");
    println!("== benchmarks (simulated ATmega2560, cycle-exact)");
    let mut c = cargo_cmd(
        &[
            "run",
            "--quiet",
            "--release",
            "-p",
            "taut-simavr",
            "--bin",
            "taut-bench",
            "--",
        ],
        &root(),
    );
    c.arg(&img.elf).arg(&busy).arg(&out);
    status(&mut c)
}
