//! `cargo xtask bench`: figures from simavr's cycle counter (`taut-bench`
//! in simavr/), written to target/bench.json and printed as a table; then
//! the host tools' string-art figures (`taut bench`) added to it.

use crate::firmware;
use crate::run::{self, root, Result};

pub fn run() -> Result<()> {
    let img = firmware::build_release()?;
    firmware::build_examples()?;
    let busy = firmware::release_dir().join("examples/busy.elf");
    let out = root().join("target/bench.json");
    println!("== benchmarks (simulated ATmega2560, cycle-exact)");
    let args = [
        img.elf.display().to_string(),
        busy.display().to_string(),
        out.display().to_string(),
    ];
    run::bin("taut-bench", &args)?;
    println!("\n== string art on the host (taut bench)");
    run::studio(&["bench".into(), "--json".into(), out.display().to_string()])
}
