//! Moves sent over the serial console produce exactly the expected
//! pulses, with the configured pulse width and DIR set-up, and a velocity
//! profile within the configured acceleration.

use hil_tests::{max_accel, rising, sim::Outcome, sim::Sim};
use std::time::Duration;
use taut_logic::axis::Axis;
use taut_logic::config::MachineConfig;
use taut_logic::pinmap::driver;

/// Boot, probe every driver, and wait for the banner.
fn boot() -> Sim {
    let mut sim = hil_tests::load();
    for axis in [Axis::Base, Axis::Radial, Axis::Drill] {
        let d = driver(axis);
        sim.probe_step_dir(axis.name(), d.step, d.dir, true);
        sim.probe(d.enable, &format!("{}_en", axis.name()));
    }
    assert_eq!(
        sim.run_until_uart_contains("reset:", Duration::from_millis(50)),
        Outcome::Done
    );
    sim
}

/// Send one line and wait for its `ok`.
fn send(sim: &mut Sim, line: &str, timeout: Duration) {
    hil_tests::send_ok(sim, line, timeout);
}

fn steps(sim: &Sim, axis: Axis) -> i64 {
    let d = driver(axis);
    sim.net_steps(d.step, d.dir, true)
}

#[test]
fn absolute_moves_give_exact_pulse_counts() {
    let mut sim = boot();
    send(&mut sim, "M17", Duration::from_millis(100));
    send(&mut sim, "G1 C90 X10 F6000", Duration::from_millis(100));
    send(&mut sim, "G0 Z-2.5", Duration::from_millis(100));
    send(&mut sim, "M400", Duration::from_secs(10));
    assert_eq!(steps(&sim, Axis::Base), 2400);
    assert_eq!(steps(&sim, Axis::Radial), 320);
    assert_eq!(steps(&sim, Axis::Drill), -333); // 2.5 mm × 133.33 = 333.3
    send(&mut sim, "G0 C0 X0 Z0", Duration::from_millis(100));
    send(&mut sim, "M400", Duration::from_secs(10));
    for axis in [Axis::Base, Axis::Radial, Axis::Drill] {
        assert_eq!(steps(&sim, axis), 0, "{axis:?} back at zero");
    }
    send(&mut sim, "M114", Duration::from_millis(100));
    assert!(
        sim.uart_text().contains("C:0.000 X:0.000 Z:0.000"),
        "{}",
        sim.uart_text()
    );
}

/// Cycles from the compare match to where the interrupt's general path
/// (a segment's first event, the DDA) can end a pulse: pulses set shorter
/// last this long there.
const PULSE_FLOOR: u64 = 130;

/// Where the assembly path takes the next segment itself, a pulse set
/// shorter lasts until that is done (~14.4 µs).
const SEGMENT_FLOOR: u64 = 232;

/// Every pulse is as wide as set, from 5 to 200 µs, on one, two and three
/// axes, at every event: inside a segment, where the assembly path takes
/// the next segment (single-axis and equal-count moves: once a pulse there
/// ended early, at 14.4 µs, whatever was set), and on the DDA's general
/// path; a single-axis move also at the highest rate the width allows (up
/// to 20 000 steps/s). Each move is replayed edge by edge (every rise has
/// its fall, as many as the move's steps); a pulse lasts the set width, or
/// the path's floor when that is longer, and at most 2 µs more. Prints the
/// narrowest and widest pulse of each move and its peak rate.
#[test]
fn every_pulse_is_as_wide_as_set_on_one_two_and_three_axes() {
    let mut sim = boot();
    // Quick ramps: the moves cruise above 651 steps/s, where every event
    // fits the 16-bit timer and segments take the assembly path.
    for axis in ["base", "radial", "drill"] {
        send(
            &mut sim,
            &format!("${axis}_accel=4000"),
            Duration::from_millis(100),
        );
    }
    send(&mut sim, "G91", Duration::from_millis(100));
    let names = ["base", "radial", "drill"];
    let mut from = [0usize; 3];
    let mut at = [0i64; 3];
    let us_of = |c: u64| c as f64 / 16.0;
    eprintln!("step_pulse_us  move                 per moving axis: pulses, narrowest..widest µs");
    for (k, us) in [5u64, 10, 20, 40, 100, 200].into_iter().enumerate() {
        send(
            &mut sim,
            &format!("$step_pulse_us={us}"),
            Duration::from_millis(100),
        );
        let set = us * 16;
        // There and back, within the carriage's and the drill's travel.
        let s = [1.0, -1.0][k % 2];
        // The fastest the setting allows (a period of twice the pulse),
        // up to 20 000 steps/s: the assembly path at full stretch.
        let fastest = (500_000 / us).min(20_000);
        for (line, rate) in [
            // One axis (the assembly path, segment after segment).
            (format!("G0 X{}", -20.0 * s), None),
            (format!("G0 C{}", -30.0 * s), None),
            // Two, in step (320 each, the two STEP ports) and not.
            (format!("G0 X{} Z{}", 10.0 * s, 2.4 * s), None),
            (format!("G0 C{} X{}", 20.0 * s, 5.0 * s), None),
            // Three.
            (format!("G0 C{} X{} Z{}", 10.0 * s, 3.0 * s, s), None),
            // One axis at its fastest, there and back.
            ("G0 X-200".to_string(), Some(fastest)),
            ("G0 X200".to_string(), Some(fastest)),
        ] {
            if let Some(rate) = rate {
                send(
                    &mut sim,
                    &format!("$radial_max_rate={rate}"),
                    Duration::from_millis(100),
                );
                send(&mut sim, "$radial_accel=100000", Duration::from_millis(100));
            }
            send(&mut sim, &line, Duration::from_millis(100));
            send(&mut sim, "M400", Duration::from_secs(60));
            if rate.is_some() {
                send(
                    &mut sim,
                    "$radial_max_rate=2000",
                    Duration::from_millis(100),
                );
                send(&mut sim, "$radial_accel=4000", Duration::from_millis(100));
            }
            let mut row = String::new();
            for (i, axis) in names.into_iter().enumerate() {
                let step = sim.probed(&format!("{axis}_step"));
                let edges = &step.edges()[from[i]..];
                from[i] = step.edges().len();
                let now = steps(&sim, [Axis::Base, Axis::Radial, Axis::Drill][i]);
                let moved = (now - at[i]).unsigned_abs() as usize;
                at[i] = now;
                // Rise, fall, rise, fall…: every pulse complete.
                assert!(
                    edges
                        .iter()
                        .enumerate()
                        .all(|(j, e)| e.high == (j % 2 == 0)),
                    "{axis} at {us} µs, {line}: edges out of order"
                );
                assert_eq!(edges.len(), 2 * moved, "{axis} at {us} µs, {line}");
                if moved == 0 {
                    continue;
                }
                let widths: Vec<u64> = edges.chunks(2).map(|w| w[1].cycle - w[0].cycle).collect();
                let short = widths.iter().filter(|&&w| w < set).count();
                let (min, max) = (*widths.iter().min().unwrap(), *widths.iter().max().unwrap());
                assert!(
                    short == 0 && max <= set.max(SEGMENT_FLOOR) + 32,
                    "{axis} at {us} µs, {line}: {short} of {} pulses short, {:.2}..{:.2} µs",
                    widths.len(),
                    us_of(min),
                    us_of(max)
                );
                let period = edges.chunks(2).map(|w| w[0].cycle).collect::<Vec<_>>();
                let peak = period
                    .windows(2)
                    .map(|w| w[1] - w[0])
                    .min()
                    .unwrap_or(u64::MAX);
                row += &format!(
                    "  {axis} {}: {:.2}..{:.2} (peak {:.0}/s)",
                    widths.len(),
                    us_of(min),
                    us_of(max),
                    16e6 / peak as f64
                );
            }
            eprintln!("{us:>8}       {line:<20}{row}");
        }
    }
    // No step late (the firmware's warning; an underrun, the step queue
    // running dry, is the throughput's business and only printed here).
    let text = sim.uart_text();
    let warnings: Vec<&str> = text.lines().filter(|l| l.contains("taut: step")).collect();
    if !warnings.is_empty() {
        eprintln!("{}", warnings.join("\n"));
    }
    assert!(warnings.iter().all(|l| l.contains("late:0 ")), "{text}");
}

#[test]
fn pulse_width_and_dir_setup_hold_the_tb6600_timing() {
    let mut sim = boot();
    send(&mut sim, "M17", Duration::from_millis(100));
    // Direction reversals on every axis.
    for line in [
        "G0 C10 X3 Z1",
        "G0 C0 X0 Z0",
        "G0 C-5 X-2 Z-1",
        "G0 C0 X0 Z0",
    ] {
        send(&mut sim, line, Duration::from_millis(100));
    }
    send(&mut sim, "M400", Duration::from_secs(20));
    let pulse = MachineConfig::STRING_ART.pulse;
    for axis in ["base", "radial", "drill"] {
        let step = sim.probed(&format!("{axis}_step"));
        // Every pulse as long as set, and no longer than the general
        // path's entry (~130 cycles) needs before it can drop it.
        let (min, max) = (
            step.min_high_cycles().unwrap(),
            step.max_high_cycles().unwrap(),
        );
        let set = pulse.step_pulse_us as u64 * 16;
        assert!(
            min >= set && max <= set.max(PULSE_FLOOR) + 32,
            "{axis} pulses {min}..{max} cycles, set {set}"
        );
        // DIR set-up: every DIR edge is at least 5 µs before the next STEP rise
        // (and after the previous STEP fall).
        let rises = rising(&sim, &format!("{axis}_step"));
        let dir = sim.probed(&format!("{axis}_dir"));
        assert!(
            dir.edge_count() >= 3,
            "{axis} DIR changed {} times",
            dir.edge_count()
        );
        for e in dir.edges() {
            if let Some(next) = rises.iter().find(|&&r| r > e.cycle) {
                let setup_us = (next - e.cycle) as f64 / 16.0;
                assert!(
                    setup_us >= pulse.dir_setup_us as f64,
                    "{axis} DIR set-up {setup_us} µs"
                );
            }
        }
    }
    assert_eq!(steps(&sim, Axis::Base), 0);
    assert!(!sim.uart_text().contains("late"), "{}", sim.uart_text());
}

#[test]
fn velocity_profile_stays_within_the_configured_acceleration() {
    let mut sim = boot();
    send(&mut sim, "M17", Duration::from_millis(100));
    send(&mut sim, "G0 C360", Duration::from_millis(100));
    send(&mut sim, "M400", Duration::from_secs(20));
    let rises = rising(&sim, "base_step");
    assert_eq!(rises.len(), 9600);
    let cfg = MachineConfig::STRING_ART.axes[Axis::Base.index()];
    let a = max_accel(&rises, 64);
    assert!(
        a <= cfg.accel as f64 * 1.02,
        "acceleration {a:.1} steps/s² > {} + 2 %",
        cfg.accel
    );
    // Cruise reached and never exceeded.
    let fastest = rises
        .windows(65)
        .map(|w| 64.0 * 16e6 / (w[64] - w[0]) as f64)
        .fold(0.0, f64::max);
    assert!(
        fastest <= cfg.max_rate as f64 * 1.01 && fastest >= cfg.max_rate as f64 * 0.98,
        "top speed {fastest}"
    );
}

#[test]
fn three_hundred_sixty_relative_degrees_make_exactly_one_turn() {
    let mut sim = boot();
    send(&mut sim, "M17", Duration::from_millis(100));
    for _ in 0..360 {
        // The planner holds 16 moves; at 500 steps/s² the first ones are slow.
        send(&mut sim, "G91 G1 C1 F60000", Duration::from_secs(2));
    }
    send(&mut sim, "M400", Duration::from_secs(30));
    assert_eq!(steps(&sim, Axis::Base), 9600);
    send(&mut sim, "M114", Duration::from_millis(100));
    assert!(
        sim.uart_text().contains("Count C:9600 X:0 Z:0"),
        "{}",
        sim.uart_text()
    );
}

/// `?` sent at set times (as `taut-sim --at` does), even into the middle of
/// a streamed line, gets a status report, and every line still gets its
/// own `ok` and its moves.
#[test]
fn status_queries_at_set_times_leave_streamed_lines_whole() {
    let mut sim = boot();
    send(&mut sim, "M17", Duration::from_millis(100));
    send(&mut sim, "G91", Duration::from_millis(100));
    let now = Duration::from_secs_f64(sim.time_s());
    // Bytes go one per 87 µs: this `?` lands after the line's third byte.
    sim.uart_send_at(now + Duration::from_micros(200), b"?");
    sim.uart_send_at(now + Duration::from_millis(300), b"?");
    send(&mut sim, "G1 X10 F1200", Duration::from_millis(100));
    sim.run_for(Duration::from_millis(400));
    send(&mut sim, "G1 X-10", Duration::from_millis(100));
    send(&mut sim, "M400", Duration::from_secs(3));
    let text = sim.uart_text();
    let reports: Vec<&str> = text.lines().filter(|l| l.starts_with('<')).collect();
    assert_eq!(reports.len(), 2, "{text}");
    assert!(reports[0].starts_with("<Idle|"), "{reports:?}");
    assert!(reports[1].starts_with("<Run|"), "{reports:?}");
    assert!(!text.contains("error"), "{text}");
    assert!(sim.probed("radial_step").rising_count() > 0);
    assert_eq!(steps(&sim, Axis::Radial), 0, "there and back");
}

/// A line that fails changes no modal state: after `G91 G1 X1` without a
/// feed rate (error 22) the console is still in `G90 G0`.
#[test]
fn a_refused_line_leaves_the_modes_as_they_were() {
    let mut sim = boot();
    send(&mut sim, "M17", Duration::from_millis(100));
    match sim.send_line("G91 G1 X1", Duration::from_millis(100)) {
        Ok(hil_tests::sim::Reply::Error(e)) => assert!(e.starts_with("error:22 "), "{e}"),
        other => panic!("{other:?}"),
    }
    send(&mut sim, "X5", Duration::from_millis(100));
    send(&mut sim, "X5", Duration::from_millis(100));
    send(&mut sim, "M400", Duration::from_secs(5));
    assert_eq!(
        steps(&sim, Axis::Radial),
        160,
        "absolute: 5 mm once, not twice"
    );
}
