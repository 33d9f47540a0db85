//! What a ready console waits for (the bench's `dispatch_latency_cycles`):
//! the bench's load — the sample card in the slot, 0.1 mm moves at the
//! maximum feed, each line after the previous `ok`, a byte every 5 ms —
//! then the three longest waits (receive interrupt → `Console` task) with
//! the task runs inside each, and each task's longest run and 99th
//! percentile (cycles).
//! Run from the workspace root after `cargo xtask build`:
//! `cargo run --release -p taut-simavr --example console_waits`.
use std::path::Path;
use std::time::Duration;
use taut_simavr::sdcard::SdImage;
use taut_simavr::Sim;

/// USART0_RX vector (byte address).
const RX_VECTOR: u32 = 0x64;

fn main() {
    let elf = Path::new("firmware/target/avr-none/release/taut.elf");
    let tasks = [
        "4taut7console",
        "4taut8realtime",
        "4taut16prepare_segments",
        "4taut3job",
        "4taut4card",
        "4taut5store",
        "4taut6timers",
        "4taut7buttons",
        "4taut3led",
    ];
    let f = |p: &str| taut_simavr::elf::function_address(elf, p).unwrap().unwrap();
    let pcs: Vec<u32> = tasks.iter().map(|n| f(n)).collect();
    // What the longest motion runs are made of.
    let inner: Vec<(&str, u32)> = [
        "Preparer8ramp_run",
        "Preparer5ahead",
        "Preparer3fit",
        "Preparer7segment",
        "Trapezoid7advance",
        "Preparer13advance_block",
        "Planner9plan_part",
        "5units9div_round",
        "11round_div32",
        "10div_to_u32",
        "__muldi3",
        "Trapezoid5timed",
        "Preparer10is_stopped",
        "memcpy",
    ]
    .into_iter()
    .filter_map(|n| Some((n, taut_simavr::elf::function_address(elf, n).ok()??)))
    .collect();
    let mut sim = Sim::load(elf).unwrap();
    for &pc in pcs.iter().chain(inner.iter().map(|(_, pc)| pc)) {
        sim.watch_calls(pc);
    }
    sim.run_until_uart_contains("reset:", Duration::from_millis(50));
    sim.insert_sd(SdImage::from_path(Path::new("examples/card")).unwrap());
    for line in ["M17", "G0 X-200", "G91"] {
        let _ = sim.send_line(line, Duration::from_millis(100));
    }
    let oks = |s: &Sim| {
        s.uart_text()
            .split_inclusive('\n')
            .filter(|l| *l == "ok\n")
            .count()
    };
    let mut sent = oks(&sim);
    if std::env::var_os("PROFILE").is_some() {
        sim.enable_profile();
    }
    sim.watch_pc(RX_VECTOR);
    sim.watch_pc(pcs[0]);
    let mut asked = Vec::new();
    for _ in 0..400 {
        if oks(&sim) >= sent {
            sim.uart_send(b"G1 X0.1 F60000\n");
            sent += 1;
        }
        asked.push(sim.cycles());
        sim.uart_send_at(Duration::from_secs_f64(sim.time_s()), b" ");
        sim.run_for(Duration::from_millis(5));
    }
    sim.run_for(Duration::from_millis(50));
    let (rx, starts) = (sim.pc_hits(RX_VECTOR), sim.pc_hits(pcs[0]));
    let mut waits: Vec<(u64, u64, u64)> = asked
        .iter()
        .map(|&at| {
            let r = rx[rx.partition_point(|&c| c < at)];
            let s = starts[starts.partition_point(|&c| c < r)];
            (s - r, r, s)
        })
        .collect();
    waits.sort();
    for &(wait, rx, start) in waits.iter().rev().take(3) {
        println!("console waited {wait}:");
        for (i, &pc) in pcs.iter().enumerate() {
            for run in sim.call_runs(pc).iter() {
                if run.0 + run.1 > rx && run.0 < start {
                    let at = run.0 as i64 - rx as i64;
                    println!("  {:<16} at {at:>+7} for {:>6}", tasks[i], run.1);
                }
            }
        }
    }
    if let Some(prof) = sim.profile() {
        for (c, n) in prof.by_function(elf).unwrap().iter().take(25) {
            println!("{c:>12} {n}");
        }
    }
    let mut runs = sim.call_runs(pcs[2]).to_vec();
    runs.sort_by_key(|r| std::cmp::Reverse(r.1));
    for &(start, len) in runs.iter().take(3) {
        print!("motion run {len}:");
        for &(name, pc) in &inner {
            for r in sim.call_runs(pc) {
                if r.0 >= start && r.0 < start + len {
                    print!(" {name}={}", r.1);
                }
            }
        }
        println!();
    }
    for (i, &pc) in pcs.iter().enumerate() {
        if let Some((n, max, p99)) = sim.call_summary(pc) {
            println!("{:<16} runs {n:>6} max {max:>7} p99 {p99:>7}", tasks[i]);
        }
    }
}
