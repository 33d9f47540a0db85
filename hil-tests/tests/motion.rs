//! Moves sent over the serial console produce exactly the expected
//! pulses, with the configured pulse width and DIR set-up, and a velocity
//! profile within the configured acceleration.

use hil_tests::{firmware_elf, max_accel, rising, sim::Outcome, sim::Sim};
use std::time::Duration;
use taut_logic::axis::Axis;
use taut_logic::config::MachineConfig;
use taut_logic::pinmap::driver;

/// Boot, probe every driver, and wait for the banner.
fn boot() -> Sim {
    let mut sim = Sim::load(&firmware_elf()).unwrap();
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

/// A longer pulse setting is kept exactly too, on every pulse (within the
/// 2 µs the drop takes).
#[test]
fn a_longer_pulse_setting_gives_every_pulse_that_width() {
    let mut sim = boot();
    send(&mut sim, "$step_pulse_us=40", Duration::from_millis(100));
    send(&mut sim, "M17", Duration::from_millis(100));
    send(&mut sim, "G0 C10 X3 Z1", Duration::from_millis(100));
    send(&mut sim, "M400", Duration::from_secs(20));
    for axis in ["base", "radial", "drill"] {
        let step = sim.probed(&format!("{axis}_step"));
        let (min, max) = (
            step.min_high_cycles().unwrap(),
            step.max_high_cycles().unwrap(),
        );
        assert!(
            min >= 640 && max <= 640 + 32,
            "{axis} pulses {min}..{max} cycles"
        );
    }
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
