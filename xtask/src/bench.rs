//! `cargo xtask bench`: figures from simavr's cycle counter and the image,
//! written to target/bench.json and printed as a table.

use crate::firmware;
use crate::run::{root, taut_sim, Result};
use serde_json::{json, Map, Value};

pub fn run() -> Result<()> {
    let img = firmware::build_release()?;
    firmware::build_examples()?;
    let mut figures = Map::new();
    figures.insert("flash_bytes".into(), json!(img.flash_bytes));
    figures.insert("ram_static_bytes".into(), json!(img.ram_static_bytes));
    figures.insert("ram_data_bytes".into(), json!(img.data_bytes));

    let tmp = root().join("target/bench");
    std::fs::create_dir_all(&tmp)?;
    // Idle: the release image sleeping between 1 kHz ticks.
    let idle = sim_report(&img.elf, &tmp.join("idle.json"), "20")?;
    figures.insert(
        "sim_mhz_idle".into(),
        json!(round1(idle["sim_mhz"].as_f64().unwrap_or(0.0))),
    );
    figures.insert("peak_stack_bytes".into(), idle["peak_stack_bytes"].clone());
    // Busy: an image that never sleeps.
    let busy_elf = firmware::release_dir().join("examples/busy.elf");
    let busy = sim_report(&busy_elf, &tmp.join("busy.json"), "2")?;
    figures.insert(
        "sim_mhz_busy".into(),
        json!(round1(busy["sim_mhz"].as_f64().unwrap_or(0.0))),
    );

    let out = root().join("target/bench.json");
    std::fs::write(
        &out,
        serde_json::to_string_pretty(&Value::Object(figures.clone()))?,
    )?;
    println!("\n{:<24} {:>14}", "figure", "value");
    for (k, v) in &figures {
        println!("{k:<24} {v:>14}");
    }
    println!("\nwritten: {}", out.display());
    Ok(())
}

fn sim_report(elf: &std::path::Path, report: &std::path::Path, seconds: &str) -> Result<Value> {
    taut_sim(
        elf,
        &[
            "--for".into(),
            seconds.into(),
            "--report".into(),
            report.display().to_string(),
        ],
    )?;
    Ok(serde_json::from_str(&std::fs::read_to_string(report)?)?)
}

fn round1(x: f64) -> f64 {
    (x * 10.0).round() / 10.0
}
