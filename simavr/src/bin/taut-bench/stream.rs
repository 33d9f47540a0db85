//! Streams of short segments: `stream_<machine>_<len>_<source>_*`. A
//! circle cut into chords of 0.05 mm or 0.2 mm at F1500 on the flatbed,
//! the whiteboard and the SCARA arm, sent over the serial port by
//! character counting (each line once it fits beside the unanswered bytes
//! in Grbl's 128) or printed from the card. Figures: lines carried out per
//! second and the step-queue underruns the firmware counted (the logger's
//! `underruns:N`), which must stay 0: the queue running dry inside a
//! planned move is a fault.
//!
//! To see why: `TAUT_BENCH_PROFILE=N` prints where each case's cycles go
//! and the tasks' longest runs; `TAUT_BENCH_WATCH=<hex address>` the
//! times the firmware reached that address (an underrun's count, say)
//! with the console's and segment preparation's runs and the STEP pulses
//! around;
//! `TAUT_BENCH_UART=DIR` keeps each case's UART text.

use crate::curve::GRBL_MEGA_BLOCKS;
use serde_json::{json, Map, Value};
use std::path::Path;
use std::time::Duration;
use taut_logic::interp::estimate::GcodeTime;
use taut_logic::machine::Machine;
use taut_logic::planner::PLANNER_BLOCKS;
use taut_simavr::sdcard::SdImage;
use taut_simavr::sdimage::FatChoice;
use taut_simavr::{Outcome, Reply, Sim};

/// The machines, each with a circle's centre and radius (mm) inside its
/// reach.
pub(crate) const MACHINES: [(Machine, [f64; 2], f64); 3] = [
    (Machine::Flatbed, [40.0, 40.0], 20.0),
    (Machine::Whiteboard, [0.0, 0.0], 20.0),
    (Machine::Scara, [100.0, 150.0], 10.0),
];

/// Chord lengths (mm) and their names in the figures' keys.
pub(crate) const SEGMENTS: [(f64, &str); 2] = [(0.05, "50um"), (0.2, "200um")];

pub(crate) const FEED: u32 = 1500;

/// Lines of a case: enough for a few seconds of drawing.
pub(crate) fn line_count(segment: f64) -> usize {
    if segment < 0.1 {
        1200
    } else {
        400
    }
}

/// The chords' end points, starting at angle 0, going round (several
/// turns if need be), rounded to µm as a sender writes them.
pub(crate) fn chords(centre: [f64; 2], r: f64, segment: f64, n: usize) -> Vec<[f64; 2]> {
    let step = 2.0 * (segment / (2.0 * r)).asin();
    (0..=n)
        .map(|k| {
            let a = step * k as f64;
            [centre[0] + r * a.cos(), centre[1] + r * a.sin()]
                .map(|v| (v * 1000.0).round() / 1000.0)
        })
        .collect()
}

/// The G-code lines after the start: the first carries the feed.
pub(crate) fn lines(points: &[[f64; 2]], feed: u32) -> Vec<String> {
    points[1..]
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let feed = if k == 0 {
                format!(" F{feed}")
            } else {
                String::new()
            };
            format!("G1 X{} Y{}{feed}", p[0], p[1])
        })
        .collect()
}

pub(crate) fn send(sim: &mut Sim, line: &str) {
    match sim.send_line(line, Duration::from_secs(30)) {
        Ok(Reply::Ok) => {}
        other => panic!("{line}: {other:?}\n{}", sim.uart_text()),
    }
}

/// The firmware's underrun count: its logger reports a change once a
/// second (`step late:L underruns:U`).
pub(crate) fn underruns(sim: &Sim) -> u64 {
    sim.uart_text()
        .lines()
        .rfind(|l| l.contains("underruns:"))
        .and_then(|l| {
            l.split("underruns:")
                .nth(1)?
                .trim_end_matches(']')
                .trim()
                .parse()
                .ok()
        })
        .unwrap_or(0)
}

/// What the planner allows: the lines per second of the same stream
/// from the first tenth to the last on the host (`GcodeTime`: the
/// firmware's parser, executor and planner), with no limit from the CPU
/// or the UART: the time of the stream cut after its last tenth less
/// that of the stream cut after its first (each run out to a stop: the
/// two stops' ramps cancel). Short moves at speed are bound by the
/// look-ahead: the machine must be able to stop within the planned
/// blocks. `N`: the planner's depth (the firmware's, or Grbl-Mega's 36
/// to show what a deeper one allows).
fn planner_bound<const N: usize>(machine: Machine, start: [f64; 2], lines: &[String]) -> f64 {
    let seconds = |k: usize| {
        let cfg = taut_logic::config::MachineConfig::defaults(machine);
        let mut t = GcodeTime::<N>::with_depth(&cfg).expect("kinematics");
        t.push(format!("G90 G21\nG0 X{} Y{}\n", start[0], start[1]).as_bytes());
        for l in &lines[..k] {
            t.push(format!("{l}\n").as_bytes());
        }
        assert_eq!(t.refused, 0);
        t.finish()
    };
    let n = lines.len();
    let (from, to) = (n / 10, n - n / 10);
    (to - from) as f64 / (seconds(to) - seconds(from))
}

/// A machine at the circle's start, drivers on; with `card` inserted.
pub(crate) fn ready(elf: &Path, machine: Machine, start: [f64; 2], card: Option<SdImage>) -> Sim {
    let mut sim = Sim::boot(elf);
    let has_card = card.is_some();
    if let Some(c) = card {
        sim.insert_sd(c);
    }
    send(&mut sim, &format!("$machine={}", machine.name()));
    send(&mut sim, "$homing_at_start=0");
    send(&mut sim, "M17");
    if has_card {
        let mounted = sim.run_until_uart_contains("MiB FAT", Duration::from_secs(3));
        assert_eq!(mounted, Outcome::Done, "{}", sim.uart_text());
    }
    send(&mut sim, "G90 G21");
    send(&mut sim, &format!("G0 X{} Y{}", start[0], start[1]));
    send(&mut sim, "M400");
    sim
}

/// Lines per second answered `ok` from the first tenth of the stream to
/// its last tenth, by character counting.
pub(crate) fn over_serial(sim: &mut Sim, lines: &[String]) -> f64 {
    let start = sim.uart_bytes().len();
    let n = lines.len();
    let (from, to) = (n / 10, n - n / 10);
    let (mut next, mut answered) = (0, 0);
    let mut in_flight = std::collections::VecDeque::new();
    let (mut t_from, mut t_to) = (0.0, 0.0);
    while answered < n {
        while next < n && in_flight.iter().sum::<usize>() + lines[next].len() < 128 {
            sim.uart_send(format!("{}\n", lines[next]).as_bytes());
            in_flight.push_back(lines[next].len() + 1);
            next += 1;
        }
        assert_eq!(sim.run_for(Duration::from_micros(250)), Outcome::Running);
        let text = sim.uart_text_from(start);
        assert!(!text.contains("error:"), "{text}");
        // Grbl ends its lines with CR LF.
        let now = text.matches("ok\n").count() + text.matches("ok\r\n").count();
        for _ in answered..now {
            in_flight.pop_front();
        }
        if answered < from && now >= from {
            t_from = sim.time_s();
        }
        if answered < to && now >= to {
            t_to = sim.time_s();
        }
        answered = now;
        assert!(sim.time_s() < 300.0, "the stream stalled");
    }
    (to - from) as f64 / (t_to - t_from)
}

/// Lines per second of the file printed from the card: `M24` answered →
/// `Done printing file`.
fn from_card(sim: &mut Sim, n: usize) -> f64 {
    send(sim, "M23 stream.nc");
    send(sim, "M24");
    let t0 = sim.time_s();
    let done = sim.run_until_uart_contains("Done printing file", Duration::from_secs(300));
    assert_eq!(done, Outcome::Done, "{}", sim.uart_text());
    n as f64 / (sim.time_s() - t0)
}

/// A card holding `text` as `stream.nc`.
fn card(text: &str) -> SdImage {
    let dir = std::env::temp_dir().join(format!("taut-bench-stream-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("stream.nc"), text).unwrap();
    let image = SdImage::from_dir(&dir, FatChoice::Auto).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    image
}

/// Every case's figures into `f`; `only` keeps the keys holding it.
pub fn stream_figures(elf: &Path, f: &mut Map<String, Value>, only: Option<&str>) {
    for (machine, centre, r) in MACHINES {
        for (segment, len) in SEGMENTS {
            let points = chords(centre, r, segment, line_count(segment));
            let lines = lines(&points, FEED);
            let key = format!("stream_{}_{len}", machine.name());
            if only.is_none_or(|o| key.contains(o)) {
                let bound = planner_bound::<PLANNER_BLOCKS>(machine, points[0], &lines);
                let deep = planner_bound::<GRBL_MEGA_BLOCKS>(machine, points[0], &lines);
                println!(
                    "{key:<36} {bound:>7.1} lines/s the planner allows ({deep:.1} at 36 blocks)"
                );
                f.insert(
                    format!("{key}_planner_bound_lines_per_s"),
                    json!((bound * 10.0).round() / 10.0),
                );
                f.insert(
                    format!("{key}_planner_36_bound_lines_per_s"),
                    json!((deep * 10.0).round() / 10.0),
                );
            }
            for source in ["serial", "card"] {
                let key = format!("stream_{}_{len}_{source}", machine.name());
                if only.is_some_and(|o| !key.contains(o)) {
                    continue;
                }
                let text: String = lines.iter().map(|l| format!("{l}\n")).collect();
                let with_card = (source == "card").then(|| card(&text));
                let mut sim = ready(elf, machine, points[0], with_card);
                let before = underruns(&sim);
                let watch = std::env::var("TAUT_BENCH_WATCH")
                    .ok()
                    .map(|w| u32::from_str_radix(w.trim_start_matches("0x"), 16).unwrap());
                if let Some(w) = watch {
                    sim.watch_pc(w);
                }
                let profile = std::env::var("TAUT_BENCH_PROFILE").ok();
                let tasks = ["4taut7console", "4taut16prepare_segments"]
                    .map(|t| taut_simavr::elf::function_address(elf, t).unwrap().unwrap());
                if profile.is_some() {
                    sim.enable_call_profile(elf).unwrap();
                    for t in tasks {
                        sim.watch_calls(t);
                    }
                }
                let rate = match source {
                    "serial" => over_serial(&mut sim, &lines),
                    _ => from_card(&mut sim, lines.len()),
                };
                send(&mut sim, "M400");
                // The logger's next report.
                sim.run_for(Duration::from_millis(1100));
                let under = underruns(&sim) - before;
                println!("{key:<36} {rate:>7.1} lines/s, {under} underruns");
                if let Ok(dir) = std::env::var("TAUT_BENCH_UART") {
                    std::fs::write(Path::new(&dir).join(format!("{key}.txt")), sim.uart_text())
                        .unwrap();
                }
                if let Some(w) = watch {
                    for &hit in sim.pc_hits(w) {
                        println!("hit at {:.4} s", hit as f64 / 16e6);
                        // The pulses around it: a stop, a start, a gap.
                        for axis in ["base", "radial"] {
                            let e: Vec<String> = sim
                                .probed(&format!("{axis}_step"))
                                .edges()
                                .iter()
                                .filter(|e| {
                                    e.high && e.cycle + 800_000 > hit && e.cycle < hit + 160_000
                                })
                                .map(|e| format!("{:.2}", (e.cycle as f64 - hit as f64) / 16e3))
                                .collect();
                            println!("   {axis} pulses, ms from it: {}", e.join(" "));
                        }
                        for t in tasks {
                            let runs: Vec<String> = sim
                                .call_runs(t)
                                .iter()
                                .filter(|(at, _)| *at + 400_000 > hit && *at < hit + 16_000)
                                .map(|(at, n)| format!("{:.4}+{n}", *at as f64 / 16e6))
                                .collect();
                            println!("   {t:#x}: {}", runs.join(" "));
                        }
                    }
                }
                if profile.is_some() {
                    for t in tasks {
                        let mut runs = sim.call_runs(t).to_vec();
                        runs.sort_by_key(|r| std::cmp::Reverse(r.1));
                        let longest: Vec<String> = runs
                            .iter()
                            .take(6)
                            .map(|(at, n)| format!("{n} at {:.3} s", *at as f64 / 16e6))
                            .collect();
                        println!("  longest runs of {t:#x}: {}", longest.join(", "));
                        let total: u64 = runs.iter().map(|r| r.1).sum();
                        println!("  all runs of {t:#x}: {} runs, {total} cycles", runs.len());
                    }
                }
                if let (Some(n), Some(p)) = (profile, sim.profile()) {
                    print_profile(elf, p, n.parse().unwrap_or(30));
                }
                f.insert(
                    format!("{key}_lines_per_s"),
                    json!((rate * 10.0).round() / 10.0),
                );
                f.insert(format!("{key}_underruns"), json!(under));
            }
        }
    }
}

/// `TAUT_BENCH_PROFILE=N`: the N functions the case spent the most
/// cycles in (their own instructions, callees apart), with their share.
pub(crate) fn print_profile(elf: &Path, p: &taut_simavr::profile::Profile, n: usize) {
    let total = p.total() as f64;
    println!("  own cycles:");
    for (cycles, name) in p.by_function(elf).unwrap().iter().take(n) {
        println!(
            "  {:>5.1} % {cycles:>11} {name}",
            *cycles as f64 * 100.0 / total
        );
    }
    println!("  hottest words:");
    for (pc, cycles) in p.hottest(n) {
        println!(
            "  {:>5.1} % {cycles:>11} {pc:#x}",
            cycles as f64 * 100.0 / total
        );
    }
    println!("  with callees (calls):");
    for (cycles, calls, name) in p.inclusive().iter().take(n) {
        println!(
            "  {:>5.1} % {cycles:>11} {calls:>8} {name}",
            *cycles as f64 * 100.0 / total
        );
    }
    // `TAUT_BENCH_CALLEES=a,b`: what functions whose names hold a or b
    // called.
    for caller in std::env::var("TAUT_BENCH_CALLEES")
        .unwrap_or_default()
        .split(',')
    {
        if caller.is_empty() {
            continue;
        }
        println!("  callees of {caller}:");
        for (cycles, name) in p.callees_of(caller).iter().take(12) {
            println!(
                "  {:>5.1} % {cycles:>11} {name}",
                *cycles as f64 * 100.0 / total
            );
        }
    }
    for callee in [
        "memcpy",
        "__muldi3",
        "memset",
        "__udivdi3",
        "__divdi3",
        "__mulsf3",
        "__divsf3",
        "__mulsf3x",
        "__udivmodsi4",
        "__gesf2",
        "__udivmodhi4",
        "__udivmodqi4",
        "__divmodhi4",
        "__cmpsf2",
        "__addsf3",
        "__subsf3",
    ] {
        println!("  callers of {callee}:");
        for (cycles, name) in p.callers_of(callee).iter().take(12) {
            println!(
                "  {:>5.1} % {cycles:>11} {name}",
                *cycles as f64 * 100.0 / total
            );
        }
    }
}
