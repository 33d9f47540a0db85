//! Issue 4: moves sent over the serial console produce exactly the expected
//! pulses, with the configured pulse width and DIR set-up, and a velocity
//! profile within the configured acceleration.

use hil_tests::{firmware_elf, sim::Outcome, sim::Sim};
use std::time::Duration;
use taut_logic::axis::Axis;
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

/// Send one line and wait for its `ok` (or fail on `error`).
fn send(sim: &mut Sim, line: &str, timeout: Duration) {
    let before = sim.uart_text().matches("ok\n").count();
    sim.uart_send(format!("{line}\n").as_bytes());
    let out = sim.run_until(
        |s| {
            let t = s.uart_text();
            t.matches("ok\n").count() > before || t.contains("error:")
        },
        timeout,
    );
    let text = sim.uart_text();
    assert_eq!(out, Outcome::Done, "no reply to {line:?}; UART: {text}");
    assert!(!text.contains("error:"), "{line:?} failed: {text}");
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
