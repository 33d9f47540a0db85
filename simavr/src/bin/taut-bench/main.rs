//! `taut-bench FIRMWARE_ELF BUSY_ELF OUT_JSON`: the figures of `cargo xtask
//! bench`, from simavr's cycle counter (exact and repeatable), written as
//! JSON and printed as a table. `taut-bench --feed FIRMWARE_ELF` measures
//! the feed ratios alone (any image, an older one too).
//!
//! Step rates: the highest cruise rate at which every STEP pulse of a
//! one-second cruise lands within 2 µs of its ideal time: a uniform grid,
//! fitted (offset and period) to the cruise; the grid's deviation from the
//! nominal rate is reported separately in ppm. Multi-axis moves step every axis at every
//! event (equal step counts), so the aggregate rate is 3× the event rate.

use serde_json::{json, Map, Value};
use std::path::Path;
use std::time::{Duration, Instant};
use taut_logic::axis::Axis;
use taut_logic::config::MachineConfig;
use taut_logic::machine::Machine;
use taut_simavr::sdcard::SdImage;
use taut_simavr::{Outcome, Reply, Sim};

mod curve;
mod grbl;
mod stream;

/// Timer3 COMPA vector (byte address): the step interrupt.
const STEP_VECTOR: u32 = 0x80;
const TOLERANCE_US: f64 = 2.0;
const AXES3: [Axis; 3] = [Axis::Base, Axis::Radial, Axis::Drill];

fn send(sim: &mut Sim, line: &str, timeout: Duration) {
    match sim.send_line(line, timeout) {
        Ok(Reply::Ok) => {}
        other => panic!("{line}: {other:?}\n{}", sim.uart_text()),
    }
}

fn rises(sim: &Sim, axis: Axis) -> Vec<u64> {
    let name = format!("{}_step", axis.name());
    sim.probed(&name)
        .edges()
        .iter()
        .filter(|e| e.high)
        .map(|e| e.cycle)
        .collect()
}

/// Acceleration the cruise runs use, steps/s²: ramps of a few hundred
/// steps, so nearly every pulse is a cruise pulse.
const BENCH_ACCEL: f64 = 2_000_000.0;

/// Pulse timing of a cruise at nominal `rate`: (largest deviation in µs of
/// any cruise pulse from the least-squares uniform grid, rate error of that
/// grid in ppm). The cruise is every pulse but the ramps: v²/2a events at
/// each end, doubled (the planner's own ramp may run a little longer). Deviation is jitter; the rate error is speed
/// accuracy (a 16 MHz crystal is good to ±50 ppm).
fn cruise_timing(r: &[u64], rate: f64) -> Option<(f64, f64)> {
    let ramp = 2 * (rate * rate / (2.0 * BENCH_ACCEL)).ceil() as usize + 16;
    let (first, last) = (ramp, r.len().checked_sub(ramp + 1)?);
    let n = last.checked_sub(first)? + 1;
    if (n as f64) < rate * 0.9 {
        return None;
    }
    // Least squares t = a + b·k over the cruise.
    let (mut sk, mut st, mut skk, mut skt) = (0.0, 0.0, 0.0, 0.0);
    let t0 = r[first] as f64;
    for k in 0..n {
        let (x, y) = (k as f64, r[first + k] as f64 - t0);
        sk += x;
        st += y;
        skk += x * x;
        skt += x * y;
    }
    let nf = n as f64;
    let b = (nf * skt - sk * st) / (nf * skk - sk * sk);
    let a = (st - b * sk) / nf;
    let worst = (0..n)
        .map(|k| (r[first + k] as f64 - t0 - a - b * k as f64).abs())
        .fold(0.0, f64::max);
    Some((worst / 16.0, (16e6 / rate / b - 1.0) * 1e6))
}

/// One cruise at `rate` events/s on `axes`: the worst pulse deviation (µs),
/// the step interrupt's mean cycles and the worst rate error (ppm), or None
/// if it could not hold the rate.
fn cruise(elf: &Path, axes: &[Axis], rate: u32) -> Option<(f64, f64, f64)> {
    let mut sim = Sim::boot(elf);
    for a in axes {
        send(
            &mut sim,
            &format!("${}_max_rate={rate}", a.name()),
            Duration::from_millis(200),
        );
        send(
            &mut sim,
            &format!("${}_accel=2000000", a.name()),
            Duration::from_millis(200),
        );
        // A cruise of 1.3 s runs far past the machine's travel.
        send(
            &mut sim,
            &format!("${}_soft_limits=0", a.name()),
            Duration::from_millis(200),
        );
    }
    send(&mut sim, "M17", Duration::from_millis(200));
    // 1.3 s worth of events on every axis, equal counts.
    let events = (rate as f64 * 1.3) as i64;
    let words: Vec<String> = axes
        .iter()
        .map(|a| {
            let (letter, per_unit) = match a {
                Axis::Base => ("C", 9600.0 / 360.0),
                Axis::Radial => ("X", 32.0),
                Axis::Drill => ("Z", 1600.0 / 12.0),
            };
            format!("{letter}{:.3}", events as f64 / per_unit)
        })
        .collect();
    send(
        &mut sim,
        &format!("G0 {}", words.join(" ")),
        Duration::from_millis(200),
    );
    sim.send_line("M400", Duration::from_secs(5)).ok()?;
    let (mut worst, mut ppm): (f64, f64) = (0.0, 0.0);
    for a in axes {
        let r = rises(&sim, *a);
        if (r.len() as i64 - events).abs() > 1 {
            return None;
        }
        let (err, rate_ppm) = cruise_timing(&r, rate as f64)?;
        worst = worst.max(err);
        ppm = if rate_ppm.abs() > ppm.abs() {
            rate_ppm
        } else {
            ppm
        };
    }
    let (_, mean, _) = sim.masked_stats(STEP_VECTOR)?;
    Some((worst, mean, ppm))
}

/// Highest rate (events/s, to 1 kHz) whose cruise stays within tolerance:
/// (rate, worst deviation µs, ISR mean cycles, rate error ppm).
fn max_rate(elf: &Path, axes: &[Axis]) -> (u32, f64, f64, f64) {
    let ok = |rate| {
        let c = cruise(elf, axes, rate);
        if std::env::var_os("TAUT_BENCH_VERBOSE").is_some() {
            eprintln!("{} axes at {rate} Hz: {c:?}", axes.len());
        }
        c.filter(|c| c.0 <= TOLERANCE_US)
    };
    // The firmware refuses rates whose step period is under twice the
    // pulse: the default 5 µs pulse allows 100 000 steps/s.
    let pulse_us = taut_logic::config::MachineConfig::STRING_ART
        .pulse
        .step_pulse_us as u32;
    let (mut lo, mut hi) = (5_000u32, 500_000 / pulse_us + 1_000);
    let mut best = ok(lo)
        .map(|c| (lo, c.0, c.1, c.2))
        .unwrap_or((0, f64::NAN, f64::NAN, f64::NAN));
    while hi - lo > 1_000 {
        let mid = (lo + hi) / 2 / 1000 * 1000;
        match ok(mid) {
            Some(c) => {
                lo = mid;
                best = (mid, c.0, c.1, c.2);
            }
            None => hi = mid,
        }
    }
    best
}

/// Worst deviation (µs) of a default-speed `G0 C360` from the exact
/// trapezoid (a = 500 steps/s², v = 2000 steps/s, from standstill).
fn default_speed_error_us(elf: &Path) -> (f64, f64, u16) {
    let mut sim = Sim::boot(elf);
    send(&mut sim, "M17", Duration::from_millis(200));
    send(&mut sim, "G0 C360", Duration::from_millis(200));
    send(&mut sim, "M400", Duration::from_secs(20));
    let r = rises(&sim, Axis::Base);
    let (a, v, n) = (500.0f64, 2000.0f64, r.len());
    let ramp = v * v / (2.0 * a);
    let t_ramp = v / a;
    let cruise_steps = n as f64 - 2.0 * ramp;
    let ideal = |k: f64| -> f64 {
        if k <= ramp {
            (2.0 * k / a).sqrt()
        } else if k <= ramp + cruise_steps {
            t_ramp + (k - ramp) / v
        } else {
            let total = 2.0 * t_ramp + cruise_steps / v;
            total - (2.0 * (n as f64 - k) / a).sqrt()
        }
    };
    let t0 = r[0] as f64 / 16e6 - ideal(1.0);
    let worst = (0..n)
        .map(|i| (r[i] as f64 / 16e6 - t0 - ideal((i + 1) as f64)).abs())
        .fold(0.0, f64::max);
    let masked = sim.max_masked_cycles(STEP_VECTOR).0 as f64;
    (worst * 1e6, masked, sim.peak_stack_bytes())
}

/// USART0_RX vector (byte address).
const RX_VECTOR: u32 = 0x64;

/// Receive interrupt → task-start latency, cycles (worst, 90th percentile)
/// and the deepest stack, for `byte` sent every 5 ms (slipped in ahead of
/// any line being sent, as senders do) to the task whose symbol ends in
/// `task`, while the job reads the sample card and the console streams
/// 0.1 mm moves at the maximum feed (each line after the previous `ok`):
/// the planner full, every task busy.
fn latency_cycles(elf: &Path, card: &Path, task: &str, byte: u8) -> (u64, u64, u16) {
    let entry = taut_simavr::elf::function_address(elf, task)
        .expect("ELF symbols")
        .expect("the task");
    let mut sim = Sim::boot(elf);
    sim.insert_sd(SdImage::from_path(card).expect("sample card"));
    send(&mut sim, "M17", Duration::from_millis(100));
    send(&mut sim, "G0 X-200", Duration::from_millis(100));
    send(&mut sim, "G91", Duration::from_millis(100));
    let oks = |s: &Sim| {
        s.uart_text()
            .split_inclusive('\n')
            .filter(|l| *l == "ok\n")
            .count()
    };
    let mut sent = oks(&sim);
    sim.watch_pc(RX_VECTOR);
    sim.watch_pc(entry);
    let mut asked = Vec::new();
    for _ in 0..400 {
        if oks(&sim) >= sent {
            sim.uart_send(b"G1 X0.1 F60000\n");
            sent += 1;
        }
        let now = sim.cycles();
        asked.push(now);
        sim.uart_send_at(Duration::from_secs_f64(sim.time_s()), &[byte]);
        sim.run_for(Duration::from_millis(5));
    }
    // The last byte's task may start after its 5 ms.
    sim.run_for(Duration::from_millis(50));
    let (rx, starts) = (sim.pc_hits(RX_VECTOR), sim.pc_hits(entry));
    let mut latency: Vec<u64> = asked
        .iter()
        .map(|&at| {
            // The byte's own receive interrupt: the first after it was sent.
            let r = rx[rx.partition_point(|&c| c < at)];
            let i = starts.partition_point(|&c| c < r);
            starts.get(i).expect("the task ran after each byte") - r
        })
        .collect();
    latency.sort_unstable();
    let worst = latency[latency.len() - 1];
    (
        worst,
        latency[latency.len() * 9 / 10],
        sim.peak_stack_bytes(),
    )
}

/// The firmware's own millisecond stamp of the first log line containing `text`.
fn log_ms(sim: &Sim, text: &str) -> u64 {
    let line = sim
        .uart_text()
        .lines()
        .find(|l| l.contains(text))
        .unwrap_or_else(|| panic!("{text:?} in the log:\n{}", sim.uart_text()))
        .to_string();
    line.split(' ')
        .nth(1)
        .and_then(|ms| ms.parse().ok())
        .expect("[L ms module] line")
}

/// A card folder with `param.txt` (the sample's) and `poradi.txt`.
fn card_dir(name: &str, poradi: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("taut-bench-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("param.txt"),
        "tvar = 6\npocet_hrebiku = 24\npolomer_matrice = 20\n",
    )
    .unwrap();
    std::fs::write(dir.join("poradi.txt"), poradi).unwrap();
    dir
}

/// A pattern of `count` connections on 24 nails.
fn pattern(count: u32) -> String {
    let mut s = count.to_string();
    for i in 0..count {
        s.push_str(&format!(",{}", i * 7 % 24));
    }
    s
}

/// `sd_poradi_parse_ms`: the release image reading and checking a card
/// with a 3000-connection `poradi.txt`, from `state: reading` to
/// `files ok` (param.txt included), by the firmware's own clock.
fn sd_poradi_parse_ms(elf: &Path) -> u64 {
    let dir = card_dir("poradi", &pattern(3000));
    let mut sim = Sim::boot(elf);
    sim.insert_sd(SdImage::from_path(&dir).unwrap());
    std::fs::remove_dir_all(&dir).unwrap();
    let end = sim.run_until_uart_contains("files ok", Duration::from_secs(5));
    assert_eq!(end, Outcome::Done, "{}", sim.uart_text());
    log_ms(&sim, "files ok") - log_ms(&sim, "state: reading")
}

/// `sd_read_kib_per_s`: `examples/sd_read.rs` streams a 256 KiB file
/// through the card reader into its queue (drained at once).
fn sd_read_kib_per_s(elf: &Path) -> f64 {
    let dir = card_dir("read", &"0123456789,".repeat(256 * 1024 / 11));
    let mut sim = Sim::load(elf).expect("sd_read image");
    sim.insert_sd(SdImage::from_path(&dir).unwrap());
    std::fs::remove_dir_all(&dir).unwrap();
    let end = sim.run_until_uart_contains(" us]\n", Duration::from_secs(30));
    assert_eq!(end, Outcome::Done, "{}", sim.uart_text());
    let text = sim.uart_text();
    let words: Vec<&str> = text.lines().last().unwrap().split(' ').collect();
    // `[MSG:I ms sd_read: read <bytes> B in <us> us]`
    let bytes: f64 = words[4].parse().unwrap();
    let us: f64 = words[7].parse().unwrap();
    bytes / 1024.0 / (us / 1e6)
}

fn sim_mhz(elf: &Path, seconds: u64) -> f64 {
    let mut sim = Sim::load(elf).expect("image loads");
    let wall = Instant::now();
    sim.run_for(Duration::from_secs(seconds));
    sim.cycles() as f64 / wall.elapsed().as_secs_f64() / 1e6
}

/// The sample job's drilling and its first 30 s of winding, the operator
/// pressing green at once: the share of cycles the MCU is awake in each
/// (percent), and the longest run of segment preparation
/// (`prepare_segments`, cycles).
fn job_figures(elf: &Path, card: &Path) -> (f64, f64, u64) {
    let motion = taut_simavr::elf::function_address(elf, "4taut16prepare_segments")
        .expect("ELF symbols")
        .expect("prepare_segments");
    let mut sim = Sim::boot(elf);
    sim.insert_sd(SdImage::from_path(card).expect("sample card"));
    sim.watch_calls(motion);
    let mut marks = taut_simavr::operator::Operator::confirming().job_phases(&mut sim);
    sim.run_for(Duration::from_secs(30));
    marks.push(taut_simavr::operator::awake_and_all(&sim));
    let busy = |a: usize| {
        let ((w0, t0), (w1, t1)) = (marks[a], marks[a + 1]);
        100.0 * (w1 - w0) as f64 / (t1 - t0) as f64
    };
    let longest = sim.call_runs(motion).iter().map(|r| r.1).max().unwrap_or(0);
    (busy(0), busy(2), longest)
}

/// The sample job simulated whole as `cargo xtask demo` runs it (the
/// operator pressing green at once): simulated MHz per wall second and
/// the wall seconds it took (bars: at least 750 MHz, at most 15 s).
fn demo_job(elf: &Path, card: &Path) -> (f64, f64) {
    let mut sim = Sim::boot(elf);
    sim.insert_sd(SdImage::from_path(card).expect("sample card"));
    let mut op = taut_simavr::operator::Operator::confirming();
    let wall = Instant::now();
    while !op.finished {
        assert_eq!(sim.run_for(Duration::from_millis(10)), Outcome::Running);
        op.step(&mut sim);
        assert!(sim.time_s() < 2000.0, "{}", sim.uart_text());
    }
    let s = wall.elapsed().as_secs_f64();
    (sim.cycles() as f64 / s / 1e6, s)
}

fn round(x: f64, digits: i32) -> f64 {
    let k = 10f64.powi(digits);
    (x * k).round() / k
}

/// Cycles per operation of the three batches of `kin_cycles.elf`: a
/// polargraph inverse, a SCARA inverse, a chord of a 1 mm circle cut,
/// converted and planned. Each batch of 64 runs while D13 is high.
fn kinematics_cycles(elf: &Path) -> [u64; 3] {
    let mut sim = Sim::load(elf).expect("kin_cycles image");
    sim.probe(13, "batch");
    sim.run_for(Duration::from_secs(2));
    let edges = sim.probed("batch").edges().to_vec();
    assert_eq!(edges.len(), 6, "three batches");
    [0, 1, 2].map(|i| (edges[2 * i + 1].cycle - edges[2 * i].cycle) / 64)
}

/// Cycles of `segment_cycles.elf`'s batches: one 64-bit square root, one
/// trapezoid made, one event time read off it, and one segment of a
/// default-speed move cut (mean), with the move's segment count.
fn segment_cycles(elf: &Path) -> ([u64; 4], u64) {
    let mut sim = Sim::load(elf).expect("segment_cycles image");
    sim.probe(13, "batch");
    sim.probe(12, "segment");
    sim.run_for(Duration::from_secs(5));
    assert!(
        sim.pin_level(11),
        "the assembly division or square root is wrong"
    );
    let edges = sim.probed("batch").edges().to_vec();
    assert_eq!(edges.len(), 8, "four batches");
    let segments = sim.probed("segment").edge_count() as u64;
    let per = [64, 64, 64, segments];
    (
        [0, 1, 2, 3].map(|i| (edges[2 * i + 1].cycle - edges[2 * i].cycle) / per[i]),
        segments,
    )
}

/// `?` received (its receive interrupt) to the report's last byte queued
/// (the return of `realtime::status`), µs: worst and 90th percentile,
/// under the load of [`latency_cycles`] (planner full, the job reading),
/// a `?` every 25 ms (a report takes ~6 ms on the wire: faster polling
/// measures the UART's backlog, not the firmware).
fn status_report_latency_us(elf: &Path, card: &Path) -> (f64, f64) {
    let status = taut_simavr::elf::function_address(elf, "8realtime6status")
        .expect("ELF symbols")
        .expect("realtime::status");
    let mut sim = Sim::boot(elf);
    sim.insert_sd(SdImage::from_path(card).expect("sample card"));
    for line in ["M17", "G0 X-200", "G91"] {
        send(&mut sim, line, Duration::from_millis(100));
    }
    sim.watch_pc(RX_VECTOR);
    sim.watch_calls(status);
    let oks = |s: &Sim| s.uart_text().matches("ok\n").count();
    let mut sent = oks(&sim);
    let mut asked = Vec::new();
    for k in 0..1000 {
        if oks(&sim) >= sent {
            sim.uart_send(b"G1 X0.1 F60000\n");
            sent += 1;
        }
        if k % 5 == 0 {
            asked.push(sim.cycles());
            sim.uart_send_at(Duration::from_secs_f64(sim.time_s()), b"?");
        }
        sim.run_for(Duration::from_millis(5));
    }
    sim.run_for(Duration::from_millis(50));
    let rx = sim.pc_hits(RX_VECTOR);
    let runs = sim.call_runs(status);
    let mut us: Vec<f64> = asked
        .iter()
        .map(|&at| {
            let r = rx[rx.partition_point(|&c| c < at)];
            let (start, len) = runs[runs.partition_point(|&(c, _)| c < r)];
            (start + len - r) as f64 / 16.0
        })
        .collect();
    us.sort_by(f64::total_cmp);
    (us[us.len() - 1], us[us.len() * 9 / 10])
}

/// Lines of 1 mm moves at the maximum feed answered per second when
/// streamed by character counting (each line sent once it fits beside
/// the unanswered bytes in Grbl's 128), from the 100th answer to the
/// 300th; beside it the UART's bound (115 200 baud, 10 bits a byte), the
/// host estimate's (`GcodeTime`: the same planner, handing a block on
/// only when full, so its look-ahead is a block or two deeper than the
/// machine's, whose preparer holds the running ones), and from `?`
/// reports (one per 50 ms) the planner's mean free blocks and whether a
/// whole line always waited in the receive buffer (`Bf:<blocks>,<bytes>`):
/// lines waiting beside a planner with less than a block free on average
/// mean the planner is the limit, not the UART or the reading of lines.
fn stream_lines_per_s(elf: &Path) -> (f64, f64, f64, f64, bool) {
    let mut sim = Sim::boot(elf);
    for line in ["M17", "G0 X-200", "G91"] {
        send(&mut sim, line, Duration::from_millis(100));
    }
    let lines: Vec<String> = (0..400)
        .map(|k| format!("G1 X{} F60000", if k / 100 % 4 < 2 { 1 } else { -1 }))
        .collect();
    let mut timing = taut_logic::interp::estimate::GcodeTime::new(&MachineConfig::STRING_ART)
        .expect("kinematics");
    timing.push(b"G91\n");
    for l in &lines[100..300] {
        timing.push(format!("{l}\n").as_bytes());
    }
    let motion_bound = 200.0 / timing.finish();
    let line_bytes = lines[0].len() + 1;
    let uart_bound = 11_520.0 / line_bytes as f64;
    let start = sim.uart_bytes().len();
    let (mut next, mut answered, mut in_flight) = (0, 0, std::collections::VecDeque::new());
    let (mut t100, mut t300, mut polls) = (0.0, 0.0, 0);
    while answered < 300 {
        while next < lines.len() && in_flight.iter().sum::<usize>() + line_bytes < 128 {
            sim.uart_send(format!("{}\n", lines[next]).as_bytes());
            in_flight.push_back(line_bytes);
            next += 1;
        }
        polls += 1;
        if answered >= 100 && polls % 100 == 0 {
            sim.uart_send(b"?");
        }
        assert_eq!(sim.run_for(Duration::from_micros(500)), Outcome::Running);
        let now = sim.uart_text_from(start).matches("ok\n").count();
        for _ in answered..now {
            in_flight.pop_front();
        }
        if answered < 100 && now >= 100 {
            t100 = sim.time_s();
        }
        if answered < 300 && now >= 300 {
            t300 = sim.time_s();
        }
        answered = now;
        assert!(sim.time_s() < 120.0, "the stream stalled");
    }
    let text = sim.uart_text_from(start);
    let reports: Vec<&str> = text.lines().filter(|l| l.starts_with('<')).collect();
    let bf: Vec<(f64, usize)> = reports
        .iter()
        .filter_map(|r| {
            let f = r.split("|Bf:").nth(1)?.split('|').next()?;
            let (blocks, bytes) = f.split_once(',')?;
            Some((blocks.parse().ok()?, bytes.parse().ok()?))
        })
        .collect();
    let free = bf.iter().map(|b| b.0).sum::<f64>() / bf.len().max(1) as f64;
    let waiting = bf.iter().all(|&(_, rx_free)| rx_free + line_bytes <= 128);
    (
        200.0 / (t300 - t100),
        uart_bound,
        motion_bound,
        free,
        waiting,
    )
}

/// A line: from, to (mm), feed (mm/min).
type Line = ([f64; 2], [f64; 2], f64);

/// The arm's lines: the two a user timed at 2.38 s and 1.11 s (40 mm at
/// F600, 4.1 s on the flatbed), and two long ones at higher feeds.
const SCARA_LINES: [Line; 4] = [
    ([80.0, 150.0], [80.0, 190.0], 600.0),
    ([60.0, 200.0], [100.0, 200.0], 600.0),
    ([40.0, 100.0], [160.0, 100.0], 3000.0),
    ([100.0, 60.0], [100.0, 180.0], 1500.0),
];

/// The whiteboard's: 40 mm at F600 from its origin, and three across
/// the board.
const WHITEBOARD_LINES: [Line; 4] = [
    ([0.0, 0.0], [40.0, 0.0], 600.0),
    ([-200.0, -100.0], [200.0, 100.0], 3000.0),
    ([0.0, -300.0], [0.0, 200.0], 1500.0),
    ([-400.0, 200.0], [-300.0, -200.0], 900.0),
];

/// Each line's time on `machine`, from its first step to its last, over
/// its trapezoid along the pen (its length at the feed, ramps at the
/// machine's `pen_accel`, from rest to rest): 1 is the feed kept (a hair
/// under: the first step comes a fraction of a step's travel after the
/// start), above 1 where a joint's limits hold the pen back, below 1
/// faster than asked.
fn feed_ratios(elf: &Path, machine: Machine, lines: &[Line]) -> Vec<f64> {
    let cfg = MachineConfig::defaults(machine);
    let mut sim = Sim::boot(elf);
    let t = Duration::from_secs(120);
    send(&mut sim, &format!("$machine={}", machine.name()), t);
    send(&mut sim, "M17", t);
    lines
        .iter()
        .map(|(a, b, feed)| {
            send(&mut sim, &format!("G0 X{} Y{}", a[0], a[1]), t);
            send(&mut sim, "M400", t);
            let before = [Axis::Base, Axis::Radial].map(|j| rises(&sim, j).len());
            send(&mut sim, &format!("G1 X{} Y{} F{feed}", b[0], b[1]), t);
            send(&mut sim, "M400", t);
            let (mut first, mut last) = (u64::MAX, 0);
            for (j, n) in [Axis::Base, Axis::Radial].iter().zip(before) {
                let r = rises(&sim, *j);
                if let (Some(f), Some(l)) = (r[n..].first(), r[n..].last()) {
                    (first, last) = (first.min(*f), last.max(*l));
                }
            }
            let seconds = (last - first) as f64 / 16e6;
            let v = feed.min(cfg.pen_max_feed as f64) / 60.0;
            let accel = cfg.pen_accel as f64;
            let length = (b[0] - a[0]).hypot(b[1] - a[1]);
            let ideal = match v * v / accel >= length {
                true => 2.0 * (length / accel).sqrt(),
                false => v / accel + length / v,
            };
            println!(
                "{:<10} {a:?} → {b:?} F{feed}: {seconds:.3} s, trapezoid {ideal:.3} s, ratio {:.3}",
                machine.name().to_string(),
                seconds / ideal
            );
            seconds / ideal
        })
        .collect()
}

/// `feed_ratio_<machine>_min` / `_max` of the machines' lines.
fn feed_figures(elf: &Path, f: &mut Map<String, Value>) {
    for (machine, lines) in [
        (Machine::Scara, &SCARA_LINES),
        (Machine::Whiteboard, &WHITEBOARD_LINES),
    ] {
        let r = feed_ratios(elf, machine, lines);
        let name = machine.name().to_string();
        let (lo, hi) = r
            .iter()
            .fold((f64::MAX, 0.0f64), |(lo, hi), &x| (lo.min(x), hi.max(x)));
        f.insert(format!("feed_ratio_{name}_min"), json!(round(lo, 3)));
        f.insert(format!("feed_ratio_{name}_max"), json!(round(hi, 3)));
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if let [flag, fw, rest @ ..] = &args[..] {
        if flag == "--stream" {
            let mut f = Map::new();
            let only = rest.first().map(String::as_str);
            stream::stream_figures(Path::new(fw), &mut f, only);
            grbl::grbl_figures(&mut f, only);
            println!(
                "{}",
                serde_json::to_string_pretty(&Value::Object(f)).unwrap()
            );
            return;
        }
    }
    if let [flag, elf] = &args[..] {
        if flag == "--segment" {
            // `segment_cycles.elf` alone: root, profile, event time, segment.
            let (c, n) = segment_cycles(Path::new(elf));
            println!(
                "cycles: root {}, profile {}, event time {}, segment {} ({n} segments)",
                c[0], c[1], c[2], c[3]
            );
            return;
        }
    }
    if let [flag, fw] = &args[..] {
        if flag == "--feed" || flag == "--curve" {
            let mut f = Map::new();
            match flag.as_str() {
                "--feed" => feed_figures(Path::new(fw), &mut f),
                _ => curve::curve_figures(Path::new(fw), &mut f),
            }
            println!(
                "{}",
                serde_json::to_string_pretty(&Value::Object(f)).unwrap()
            );
            return;
        }
    }
    let [fw, busy, out] = &args[..] else {
        eprintln!("usage: taut-bench FIRMWARE_ELF BUSY_ELF OUT_JSON");
        std::process::exit(2);
    };
    let (fw, busy) = (Path::new(fw), Path::new(busy));
    let mut f = Map::new();
    let info = *Sim::load(fw)
        .expect("firmware loads")
        .elf()
        .expect("ELF symbols");
    f.insert("flash_bytes".into(), json!(info.flash_bytes()));
    f.insert("ram_static_bytes".into(), json!(info.ram_static_bytes()));
    f.insert("data_bytes".into(), json!(info.data_bytes));

    let (rate1, err1, isr1, ppm1) = max_rate(fw, &[Axis::Base]);
    f.insert("step_rate_1axis_hz".into(), json!(rate1));
    f.insert("step_rate_1axis_error_us".into(), json!(round(err1, 3)));
    f.insert(
        "step_rate_1axis_rate_error_ppm".into(),
        json!(round(ppm1, 2)),
    );
    f.insert("isr_cycles_per_step".into(), json!(round(isr1, 1)));
    let (rate3, err3, isr3, ppm3) = max_rate(fw, &AXES3);
    f.insert("step_rate_3axis_hz".into(), json!(rate3 * 3));
    f.insert("step_rate_3axis_error_us".into(), json!(round(err3, 3)));
    f.insert(
        "step_rate_3axis_rate_error_ppm".into(),
        json!(round(ppm3, 2)),
    );
    f.insert("isr_cycles_per_event_3axis".into(), json!(round(isr3, 1)));
    let (err, masked, stack) = default_speed_error_us(fw);
    f.insert("timing_error_max_us".into(), json!(round(err, 3)));
    f.insert("step_isr_max_masked_cycles".into(), json!(masked));

    let card = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/card");
    let (worst, p90, status_stack) = latency_cycles(fw, &card, "4taut8realtime", b'?');
    f.insert("status_latency_cycles".into(), json!(worst));
    f.insert("status_latency_p90_cycles".into(), json!(p90));
    let (worst, p90) = status_report_latency_us(fw, &card);
    f.insert("status_report_latency_us".into(), json!(round(worst, 1)));
    f.insert("status_report_latency_p90_us".into(), json!(round(p90, 1)));
    let (rate, uart, motion, free, waiting) = stream_lines_per_s(fw);
    f.insert("stream_lines_per_s".into(), json!(round(rate, 1)));
    f.insert(
        "stream_uart_bound_lines_per_s".into(),
        json!(round(uart, 1)),
    );
    f.insert(
        "stream_estimate_lines_per_s".into(),
        json!(round(motion, 1)),
    );
    f.insert(
        "stream_planner_free_blocks_mean".into(),
        json!(round(free, 2)),
    );
    f.insert("stream_lines_always_waiting".into(), json!(waiting));
    let limit = match rate {
        _ if waiting && free < 1.0 => "planner (lines wait for its room)",
        r if r >= 0.9 * uart => "uart",
        _ => "firmware line intake (planner has room, uart not busy)",
    };
    f.insert("stream_limit".into(), json!(limit));
    // A real-time `?` also interrupts a line in flight: the console sees
    // a line's bytes arrive mid-stream, which is what this measures.
    let (worst, p90, console_stack) = latency_cycles(fw, &card, "4taut7console", b' ');
    f.insert("dispatch_latency_cycles".into(), json!(worst));
    f.insert("dispatch_latency_p90_cycles".into(), json!(p90));
    // Deepest of the cruise and the loaded runs.
    f.insert(
        "stack_peak_bytes".into(),
        json!(stack.max(status_stack).max(console_stack)),
    );
    f.insert("sd_poradi_parse_ms".into(), json!(sd_poradi_parse_ms(fw)));
    let sd_read = busy.with_file_name("sd_read.elf");
    f.insert(
        "sd_read_kib_per_s".into(),
        json!(round(sd_read_kib_per_s(&sd_read), 1)),
    );
    let [polargraph, scara, chord] = kinematics_cycles(&busy.with_file_name("kin_cycles.elf"));
    f.insert("polargraph_inverse_cycles".into(), json!(polargraph));
    f.insert("scara_inverse_cycles".into(), json!(scara));
    f.insert("arc_segments_per_s".into(), json!(16_000_000 / chord));
    let ([root, new, time, segment], segments) =
        segment_cycles(&busy.with_file_name("segment_cycles.elf"));
    f.insert("isqrt64_cycles".into(), json!(root));
    f.insert("trapezoid_new_cycles".into(), json!(new));
    f.insert("trapezoid_time_cycles".into(), json!(time));
    f.insert("segment_cycles_mean".into(), json!(segment));
    f.insert("segments_per_default_move".into(), json!(segments));
    let (drilling, winding, prep) = job_figures(fw, &card);
    f.insert(
        "cpu_busy_percent_drilling".into(),
        json!(round(drilling, 1)),
    );
    f.insert("cpu_busy_percent_winding".into(), json!(round(winding, 1)));
    f.insert("segment_prep_max_cycles".into(), json!(prep));
    feed_figures(fw, &mut f);
    stream::stream_figures(fw, &mut f, None);
    grbl::grbl_figures(&mut f, None);
    curve::curve_figures(fw, &mut f);
    let (mhz, wall) = demo_job(fw, &card);
    f.insert("sim_mhz".into(), json!(round(mhz, 1)));
    f.insert("demo_wall_s".into(), json!(round(wall, 2)));
    f.insert("sim_mhz_idle".into(), json!(round(sim_mhz(fw, 20), 1)));
    f.insert("sim_mhz_busy".into(), json!(round(sim_mhz(busy, 2), 1)));

    let v = Value::Object(f.clone());
    std::fs::write(out, serde_json::to_string_pretty(&v).unwrap()).expect("write bench JSON");
    println!("\n{:<28} {:>12}", "figure", "value");
    for (k, v) in &f {
        println!("{k:<28} {v:>12}");
    }
    println!("\nwritten: {out}");
}
