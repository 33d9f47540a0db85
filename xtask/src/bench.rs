//! `cargo xtask bench`: figures from simavr's cycle counter (`taut-bench`
//! in simavr/), written to target/bench.json and printed as a table, the
//! string-art job's machine time worked out on the host (`cargo xtask
//! estimate`), then the host tools' string-art figures (`taut bench`).

use crate::firmware;
use crate::run::{self, root, Result};
use serde_json::{json, Map, Value};
use taut_logic::files::FileName;
use taut_logic::stringart::estimate::{self, CardEstimate};

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
    let mut figures: Map<String, Value> = serde_json::from_str(&std::fs::read_to_string(&out)?)?;
    println!("\n== machine time of the string-art job (host, the firmware's own planner)");
    let demo = crate::estimate::estimate(&root().join("examples/card"))?;
    let seed = seed_size_job()?;
    for (prefix, e) in [("job", &demo), ("job_250x3000", &seed)] {
        for (name, value) in [
            ("time_s", e.firmware.total_s()),
            ("time_sequential_s", e.sequential_s),
            ("time_ratio", e.ratio()),
        ] {
            let key = format!("{prefix}_{name}");
            println!("{key:<36} {value:.3}");
            figures.insert(key, json!((value * 1000.0).round() / 1000.0));
        }
    }
    std::fs::write(&out, serde_json::to_string_pretty(&figures)?)?;
    println!("\n== string art on the host (taut bench)");
    run::studio(&["bench".into(), "--json".into(), out.display().to_string()])
}

/// The seed's example size: a 250-nail circle of 40.2 cm and 3 000
/// connections, each at least 20 nails from the last (a fixed pseudo-random
/// pattern).
fn seed_size_job() -> Result<CardEstimate> {
    const NAILS: u64 = 250;
    let mut x: u64 = 0x2545_F491_4F6C_DD1D;
    let mut next = || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let mut nail = 0u64;
    let mut poradi = String::from("3000");
    for _ in 0..3000 {
        nail = (nail + 20 + next() % (NAILS - 39)) % NAILS;
        poradi += &format!(",{nail}");
    }
    let param = b"tvar = 0\npocet_hrebiku = 250\npolomer_matrice = 40.2\n";
    estimate::card(|f| match f {
        FileName::Param => Some(&param[..]),
        FileName::Machine => None,
        FileName::Poradi => Some(poradi.as_bytes()),
    })
    .map_err(|e| format!("the 250-nail job: {e:?}").into())
}
