//! `cargo xtask demo`: the string-art machine's whole job on the simulated
//! Mega. A card image is made from `examples/card/` (a hexagon of 24 nails,
//! 30 connections), the release firmware reads it, drills every hole,
//! waits for nails, winds the pattern — the simulated operator pressing
//! green at each prompt — and `target/demo/` gets the pulse trace, the
//! report and a picture of the result rebuilt from the step pulses.

use crate::firmware;
use crate::run::{self, root, Result};

pub fn run() -> Result<()> {
    let img = firmware::build_release()?;
    img.print_size();
    let out = root().join("target/demo");
    std::fs::create_dir_all(&out)?;
    let card = out.join("card.img");
    let (report, vcd, png) = (
        out.join("report.json"),
        out.join("trace.vcd"),
        out.join("result.png"),
    );
    let folder = root().join("examples/card");
    println!("== card image {} from {}", card.display(), folder.display());
    run::bin(
        "taut-sdimage",
        &[
            folder.display().to_string(),
            "-o".into(),
            card.display().to_string(),
        ],
    )?;
    println!("== the simulated machine runs the job (green pressed at each prompt)");
    let wall = std::time::Instant::now();
    let path = |p: &std::path::Path| p.display().to_string();
    run::taut_sim(
        &img.elf,
        &[
            "--sd".into(),
            path(&card),
            "--auto-confirm".into(),
            "--vcd".into(),
            path(&vcd),
            "--report".into(),
            path(&report),
            "--png".into(),
            path(&png),
            "--echo".into(),
        ],
    )?;
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report)?)?;
    let job = &r["job"];
    println!(
        "\njob: {} ({} green presses), machine time {:.1} s, wall time {:.1} s",
        job["state"].as_str().unwrap_or("?"),
        job["green_presses"],
        r["sim_seconds"].as_f64().unwrap_or(0.0),
        wall.elapsed().as_secs_f64()
    );
    if job["finished"] != true {
        return Err("the job did not finish".into());
    }
    let e = crate::estimate::estimate(&folder)?;
    println!(
        "host estimate from the same files (cargo xtask estimate): {:.1} s of motion with this \
         firmware's planner, {:.1} s one axis after another (the original's blocking moves)",
        e.firmware.total_s(),
        e.sequential_s
    );
    println!(
        "written: {}\n         {}\n         {}",
        png.display(),
        vcd.display(),
        report.display()
    );
    Ok(())
}

/// `cargo xtask demo plotter [MACHINE]`: a plotter (the flatbed unless
/// named: drum, whiteboard, scara) draws `examples/plotter/star.gcode`,
/// streamed over its serial port as a sender does; `target/demo/` gets the
/// trace and the drawing rebuilt from the step and pen pulses.
pub fn plotter(machine: &str) -> Result<()> {
    let img = firmware::build_release()?;
    img.print_size();
    let out = root().join("target/demo");
    std::fs::create_dir_all(&out)?;
    let (vcd, png) = (
        out.join(format!("{machine}.vcd")),
        out.join(format!("{machine}.png")),
    );
    let gcode = root().join("examples/plotter/star.gcode");
    println!("== the simulated {machine} draws {}", gcode.display());
    let path = |p: &std::path::Path| p.display().to_string();
    run::taut_sim(
        &img.elf,
        &[
            "--machine".into(),
            machine.into(),
            "--send".into(),
            path(&gcode),
            "--vcd".into(),
            path(&vcd),
            "--png".into(),
            path(&png),
        ],
    )?;
    println!(
        "written: {}
         {}",
        png.display(),
        vcd.display()
    );
    Ok(())
}
