//! The drivers switch on when motion starts and off after the step idle
//! delay (Grbl's `$1`, `$4`; Marlin's `M17`, `M18`/`M84`, `M18 S`), on
//! every machine, and no STEP edge ever reaches a driver that is off: the
//! end check of every HIL test (`hil_tests::drivers`) reads each run's
//! ENABLE, DIR and STEP edges; these tests add what a file without `M17`
//! (Inkscape's, vpype's, the project's own star) gets.

use hil_tests::sim::Sim;
use hil_tests::{boot_machine, log_tail, send_ok, steps_on_pins};
use std::time::Duration;
use taut_logic::axis::Axis;
use taut_logic::pinmap::driver;

fn send(sim: &mut Sim, line: &str) {
    send_ok(sim, line, Duration::from_secs(60));
}

fn star() -> Vec<String> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/plotter/star.gcode"
    );
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect()
}

/// Last ENABLE edge of `axis`'s driver: (cycle, on), the polarity active
/// high.
fn last_enable(sim: &Sim, axis: Axis) -> Option<(u64, bool)> {
    let name = format!("{}_en", axis.name());
    sim.probed(&name).edges().last().map(|e| (e.cycle, e.high))
}

fn enabled(sim: &Sim, axis: Axis) -> bool {
    sim.pin_level(driver(axis).enable)
}

fn last_step(sim: &Sim, axis: Axis) -> u64 {
    let name = format!("{}_step", axis.name());
    sim.probed(&name).edges().last().map_or(0, |e| e.cycle)
}

/// The project's star, as Inkscape or vpype would send it (no `M17`), on
/// each plotter with STEP/DIR drivers: every motor moves with its driver
/// on (the end check), the drivers were off before, and they hold after
/// (`$1=255`, the default of these machines: a hanging pen or a SCARA arm
/// would fall).
#[test]
fn a_file_without_m17_moves_every_plotter_with_its_drivers_on() {
    for machine in ["flatbed", "whiteboard", "scara"] {
        let mut sim = boot_machine();
        send(&mut sim, &format!("$machine={machine}"));
        send(&mut sim, "$homing_at_start=0");
        for axis in [Axis::Base, Axis::Radial] {
            assert!(!enabled(&sim, axis), "{machine}: {axis:?} on before motion");
        }
        for line in star() {
            send(&mut sim, &line);
        }
        send(&mut sim, "M400");
        sim.run_for(Duration::from_secs(1));
        let pulses = hil_tests::all_pulses(&sim);
        assert!(
            pulses[0] > 1000 && pulses[1] > 1000,
            "{machine}: {pulses:?} pulses"
        );
        for axis in [Axis::Base, Axis::Radial] {
            assert!(
                enabled(&sim, axis),
                "{machine}: {axis:?} released at $1=255"
            );
        }
        // The spare Z never moved: its driver stayed off.
        assert!(!enabled(&sim, Axis::Drill), "{machine}: Z switched on");
        assert!(!sim.uart_text().contains("error"), "{}", log_tail(&sim));
    }
}

/// `$1=25` (Grbl's default): the drivers go off 25 ms after the machine
/// stands, on again when it moves; `$1=255` keeps them on.
#[test]
fn the_step_idle_delay_switches_the_drivers_off_once_the_machine_stands() {
    let mut sim = boot_machine();
    send(&mut sim, "$machine=flatbed");
    send(&mut sim, "$homing_at_start=0");
    send(&mut sim, "$1=25");
    assert!(sim.uart_text_from(0).contains("ok"));
    for round in 0..3 {
        send(&mut sim, &format!("G0 X{}", 5 * (round + 1)));
        send(&mut sim, "M400");
        sim.run_for(Duration::from_millis(100));
        let stop = last_step(&sim, Axis::Base);
        let (off, on) = last_enable(&sim, Axis::Base).unwrap();
        assert!(!on, "round {round}: still on\n{}", log_tail(&sim));
        let ms = (off - stop) as f64 / 16e3;
        assert!(
            (25.0..27.0).contains(&ms),
            "round {round}: off {ms:.2} ms after the last step"
        );
    }
    send(&mut sim, "$1=255");
    send(&mut sim, "G0 X0");
    send(&mut sim, "M400");
    sim.run_for(Duration::from_secs(2));
    assert!(enabled(&sim, Axis::Base), "$1=255 keeps them on");
    assert_eq!(steps_on_pins(&sim)[0], 0);
    // Listed as Grbl lists it.
    let start = sim.uart_bytes().len();
    send(&mut sim, "$$");
    let list = sim.uart_text_from(start);
    assert!(list.contains("$1=255\n"), "{list}");
    assert!(list.contains("$step_idle_delay_ms=255\n"), "{list}");
}

/// `M17` holds the drivers through the idle delay until `M18`/`M84`;
/// `M18` switches them off at once (once motion is done) and the next move
/// on again; `M18 S1` releases them a second after the machine stands,
/// `M84 S0` never (Marlin).
#[test]
fn m17_holds_m18_releases_and_m18_s_sets_the_delay() {
    let mut sim = boot_machine();
    send(&mut sim, "$machine=flatbed");
    send(&mut sim, "$homing_at_start=0");
    send(&mut sim, "$1=10");
    send(&mut sim, "M17");
    for axis in [Axis::Base, Axis::Radial, Axis::Drill] {
        assert!(enabled(&sim, axis), "M17: {axis:?}");
    }
    send(&mut sim, "G0 X5 Y5");
    send(&mut sim, "M400");
    sim.run_for(Duration::from_millis(500));
    assert!(enabled(&sim, Axis::Base), "M17 holds through $1");
    send(&mut sim, "M18");
    for axis in [Axis::Base, Axis::Radial, Axis::Drill] {
        assert!(!enabled(&sim, axis), "M18: {axis:?}");
    }
    send(&mut sim, "G0 X0");
    send(&mut sim, "M400");
    sim.run_for(Duration::from_millis(5));
    assert!(enabled(&sim, Axis::Base), "moving again");
    sim.run_for(Duration::from_millis(50));
    assert!(!enabled(&sim, Axis::Base), "released after $1=10");
    // M18 S1: a second.
    send(&mut sim, "M18 S1");
    send(&mut sim, "G0 X3");
    send(&mut sim, "M400");
    let stop = last_step(&sim, Axis::Base);
    sim.run_for(Duration::from_millis(1500));
    let (off, on) = last_enable(&sim, Axis::Base).unwrap();
    assert!(!on);
    let s = (off - stop) as f64 / 16e6;
    assert!((1.0..1.01).contains(&s), "off {s:.3} s after the last step");
    // M84 S0: never.
    send(&mut sim, "M84 S0");
    send(&mut sim, "G0 X0");
    send(&mut sim, "M400");
    sim.run_for(Duration::from_secs(3));
    assert!(enabled(&sim, Axis::Base), "M84 S0 keeps them on");
    // M18 with axis words is not Grbl's (nor taut's): refused, nothing off.
    assert!(matches!(
        sim.send_line("M18 X1", Duration::from_secs(1)),
        Ok(hil_tests::sim::Reply::Error(_))
    ));
    assert!(enabled(&sim, Axis::Base));
}

/// `$4=0`: ENABLE low switches a driver on (Grbl's own polarity); the
/// end check reads the pins so.
#[test]
fn dollar_4_inverts_the_enable_pins() {
    let mut sim = boot_machine();
    send(&mut sim, "$machine=flatbed");
    send(&mut sim, "$homing_at_start=0");
    send(&mut sim, "$4=0");
    hil_tests::drivers::expect_enable_active_high([false; 3]);
    // Off is high now.
    for axis in [Axis::Base, Axis::Radial, Axis::Drill] {
        assert!(enabled(&sim, axis), "{axis:?} off, ENABLE high");
    }
    send(&mut sim, "G0 X5 Y5");
    send(&mut sim, "M400");
    assert!(!enabled(&sim, Axis::Base) && !enabled(&sim, Axis::Radial));
    assert!(enabled(&sim, Axis::Drill), "the spare Z stays off");
    let start = sim.uart_bytes().len();
    send(&mut sim, "$$");
    let list = sim.uart_text_from(start);
    assert!(list.contains("$4=0\n"), "{list}");
    assert!(list.contains("$x_enable_active_high=0\n"), "{list}");
}
