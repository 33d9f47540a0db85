//! `cargo xtask bench`: figures from simavr's cycle counter (`taut-bench`
//! in simavr/), written to target/bench.json and printed as a table, the
//! string-art job's machine time worked out on the host (`cargo xtask
//! estimate`), then the host tools' string-art figures (`taut bench`);
//! last, docs/benchmarks.md generated from them all (`bench_page`).

use crate::firmware;
use crate::run::{self, root, Result};
use serde_json::{json, Map, Value};
use taut_logic::files::FileName;
use taut_logic::stringart::estimate::{self, CardEstimate};

pub fn run(args: &[String]) -> Result<()> {
    let out = root().join("target/bench.json");
    match args {
        [] => {}
        [page] if page == "--page" => return write_page(&out),
        _ => {
            return Err(
                "bench: `bench` or `bench --page` (the page again from target/bench.json)".into(),
            )
        }
    }
    let host = host_figures();
    let img = firmware::build_release()?;
    firmware::build_examples()?;
    let busy = firmware::release_dir().join("examples/busy.elf");
    println!("== benchmarks (simulated ATmega2560, cycle-exact)");
    let args = [
        img.elf.display().to_string(),
        busy.display().to_string(),
        out.display().to_string(),
    ];
    run::bin("taut-bench", &args)?;
    let mut figures: Map<String, Value> = serde_json::from_str(&std::fs::read_to_string(&out)?)?;
    let ram = ["ram_static_bytes", "stack_peak_bytes"]
        .map(|k| figures.get(k).and_then(Value::as_u64).unwrap_or(0));
    figures.insert("ram_static_plus_stack_bytes".into(), json!(ram[0] + ram[1]));
    figures.extend(host);
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
    println!("\n== checkpoint (EEPROM wear, resume)");
    for (key, value) in checkpoint_figures(&img.elf)? {
        println!("{key:<36} {value}");
        figures.insert(key.into(), value);
    }
    std::fs::write(&out, serde_json::to_string_pretty(&figures)?)?;
    println!("\n== string art on the host (taut bench)");
    run::studio(&["bench".into(), "--json".into(), out.display().to_string()])?;
    write_page(&out)
}

/// The host's cores and load when the bench starts: the wall-clock
/// figures depend on them.
fn host_figures() -> Map<String, Value> {
    let mut m = Map::new();
    if let Ok(n) = std::thread::available_parallelism() {
        m.insert("host_cores".into(), json!(n.get()));
    }
    let load = std::fs::read_to_string("/proc/loadavg").ok();
    if let Some(l) = load
        .as_deref()
        .and_then(|t| t.split(' ').next()?.parse::<f64>().ok())
    {
        m.insert("host_load_average".into(), json!(l));
    }
    m
}

/// docs/benchmarks.md from every figure in `json`; the bars missed are
/// named (the page marks them too).
fn write_page(json: &std::path::Path) -> Result<()> {
    let figures: Map<String, Value> = serde_json::from_str(&std::fs::read_to_string(json)?)?;
    let (page, missed) = crate::bench_page::render(&figures);
    let path = root().join("docs/benchmarks.md");
    std::fs::write(&path, page)?;
    println!("\n== written: {}", path.display());
    for m in &missed {
        println!("bar missed: {m}");
    }
    Ok(())
}

/// EEPROM wear of a 250-hole, 3 000-wrap job (datasheet endurance
/// 100 000 writes per cell), and the simulated time from power-on to the
/// resume prompt after a cut while winding (a 12-nail card on quick axes,
/// cut at its second wrap's log line, then powered on with its EEPROM).
fn checkpoint_figures(elf: &std::path::Path) -> Result<Vec<(&'static str, Value)>> {
    use taut_logic::checkpoint;
    let (holes, wraps) = (250, 3000);
    let dir = root().join("target/bench-resume");
    std::fs::create_dir_all(&dir)?;
    std::fs::write(
        dir.join("param.txt"),
        "tvar = 0\npocet_hrebiku = 12\npolomer_matrice = 20.0\n",
    )?;
    std::fs::write(dir.join("poradi.txt"), "6,5,0,7,3,10,2\n")?;
    std::fs::write(
        dir.join("machine.txt"),
        "base_steps_per_unit = 1200/360\nradial_steps_per_unit = 4\ndrill_steps_per_unit = 200/12\n\
         base_accel = 8000\nradial_accel = 8000\ndrill_accel = 8000\n",
    )?;
    let eeprom = dir.join("eeprom.bin");
    let _ = std::fs::remove_file(&eeprom);
    let report = dir.join("report.json");
    let sim = |cut_on: &str| -> Result<Value> {
        let args: Vec<String> = [
            &elf.display().to_string(),
            "--sd",
            &dir.display().to_string(),
            "--auto-confirm",
            "--eeprom",
            &eeprom.display().to_string(),
            "--power-cut-on",
            cut_on,
            "--for",
            "120",
            "--report",
            &report.display().to_string(),
        ]
        .map(String::from)
        .to_vec();
        run::bin("taut-sim", &args)?;
        Ok(serde_json::from_str(&std::fs::read_to_string(&report)?)?)
    };
    sim("wind 2/")?;
    let resumed = sim(">>> resume ")?;
    let prompt_s = resumed["sim_seconds"]
        .as_f64()
        .ok_or("report: no sim_seconds")?;
    if resumed["ended"].as_str() != Some("power cut") {
        return Err("the resumed run did not reach its prompt".into());
    }
    Ok(vec![
        (
            "eeprom_writes_per_job",
            json!(checkpoint::byte_writes_per_job(holes, wraps)),
        ),
        (
            "eeprom_cell_writes_per_job",
            json!(checkpoint::cell_writes_per_job(holes, wraps)),
        ),
        (
            "jobs_before_wear_out",
            json!(checkpoint::jobs_before_wear_out(holes, wraps, 100_000)),
        ),
        ("resume_prompt_ms", json!((prompt_s * 1000.0).round())),
    ])
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
