//! The buttons on the release image — a zeroing button's two
//! presses take the current position as that axis's zero (driver off in
//! between); a long press of green pauses drilling after the current hole
//! and a short one resumes. (The serial `!`, `~` and Ctrl-X: `realtime.rs`.)

use hil_tests::sim::operator::message;
use hil_tests::sim::sdcard::SdImage;
use hil_tests::sim::Sim;
use hil_tests::{
    all_pulses, assert_ram_budget, assert_step_interrupt_never_masked_long, boot_machine, press,
    pulses, sample_card_dir, send_ok, settle, wait_for,
};
use std::time::Duration;
use taut_logic::axis::Axis;
use taut_logic::config::MachineConfig;
use taut_logic::pinmap::{driver, Button};

/// Booted with the sample card, in the preparation state before drilling.
fn prepared() -> Sim {
    let mut sim = boot_machine();
    sim.insert_sd(SdImage::from_path(&sample_card_dir()).unwrap());
    wait_for(&mut sim, "press green to drill", Duration::from_secs(3));
    sim
}

fn driver_on(sim: &Sim, axis: Axis) -> bool {
    let active_high = MachineConfig::STRING_ART.axes[axis.index()].enable_active_high;
    sim.pin_level(driver(axis).enable) == active_high
}

fn base_steps(sim: &Sim) -> i64 {
    let d = driver(Axis::Base);
    sim.net_steps(d.step, d.dir, true)
}

fn log_has(sim: &Sim, text: &str) -> bool {
    sim.uart_text().lines().any(|l| message(l) == Some(text))
}

#[test]
fn two_presses_of_a_zeroing_button_move_that_axis_zero() {
    let mut sim = prepared();
    assert!(driver_on(&sim, Axis::Base));
    // The operator turns the board 15° (here over the console) to line
    // nail 0 up, then zeroes the base there.
    send_ok(&mut sim, "G0 C15", Duration::from_millis(200));
    send_ok(&mut sim, "M400", Duration::from_secs(10));
    let jog = base_steps(&sim);
    assert_eq!(jog, 400, "15° of 9600 steps a turn");

    // A bouncing contact: one press.
    let pin = Button::ZeroBase.pin();
    sim.press_with_bounce(pin, 6, Duration::from_millis(2));
    sim.run_for(Duration::from_millis(150));
    sim.release_with_bounce(pin, 6, Duration::from_millis(2));
    sim.run_for(Duration::from_millis(150));
    let frees = sim
        .uart_text()
        .lines()
        .filter(|l| message(l) == Some("base free"))
        .count();
    assert_eq!(frees, 1, "{}", sim.uart_text());
    assert!(!driver_on(&sim, Axis::Base), "first press: driver off");
    assert!(driver_on(&sim, Axis::Radial) && driver_on(&sim, Axis::Drill));
    // A long press counts once.
    press(&mut sim, Button::ZeroBase, 2500);
    assert!(log_has(&sim, "base zeroed"), "{}", sim.uart_text());
    assert!(driver_on(&sim, Axis::Base), "second press: driver on again");
    send_ok(&mut sim, "M114", Duration::from_millis(200));
    assert!(
        sim.uart_text().contains("Count C:0 "),
        "{}",
        sim.uart_text()
    );

    // Drilling starts from the new zero: nail 0 is where the board stands.
    press(&mut sim, Button::Confirm, 150);
    wait_for(&mut sim, "drill 1/24", Duration::from_secs(30));
    assert_eq!(base_steps(&sim), jog, "hole 0 drilled at the new zero");
    assert_step_interrupt_never_masked_long(&sim);
    assert_ram_budget(&sim);
}

#[test]
fn a_long_press_pauses_after_the_hole_and_a_short_press_resumes() {
    let mut sim = prepared();
    press(&mut sim, Button::Confirm, 150);
    wait_for(&mut sim, "drill 1/24", Duration::from_secs(30));
    press(&mut sim, Button::Confirm, 2200);
    wait_for(
        &mut sim,
        ">>> paused: press green to resume",
        Duration::from_secs(30),
    );
    assert!(log_has(&sim, "state: paused"));
    // The hole being drilled is finished, then the machine stands: drill
    // raised, drivers holding.
    let stopped = settle(&mut sim);
    sim.run_for(Duration::from_secs(3));
    let still = all_pulses(&sim);
    assert_eq!(stopped, still, "nothing moves while paused");
    assert!([Axis::Base, Axis::Radial, Axis::Drill]
        .iter()
        .all(|&a| driver_on(&sim, a)));
    let d = driver(Axis::Drill);
    assert!(
        sim.net_steps(d.step, d.dir, true) <= 0,
        "drill out of the board: {} {}",
        sim.net_steps(d.step, d.dir, true),
        sim.uart_text()
    );

    press(&mut sim, Button::Confirm, 150);
    wait_for(&mut sim, "resumed", Duration::from_secs(1));
    sim.run_for(Duration::from_secs(2));
    assert!(pulses(&sim, Axis::Base) + pulses(&sim, Axis::Drill) > still[0] + still[2]);
    assert_ram_budget(&sim);
}
