//! The release firmware boots in simavr, prints its banner within
//! 50 ms of machine time, and blinks its status LED exactly as designed.

use hil_tests::{firmware_version, sim::Outcome};
use std::time::Duration;
use taut_logic::pinmap::STATUS_LED;

#[test]
fn banner_within_50_ms_with_version_and_reset_cause() {
    let mut sim = hil_tests::load();
    let out = sim.run_until_uart_contains("reset:", Duration::from_millis(50));
    assert_eq!(
        out,
        Outcome::Done,
        "no banner within 50 ms; UART: {:?}",
        sim.uart_text()
    );
    // The line is complete once its newline is out.
    sim.run_until(
        |s| {
            s.uart_text()
                .split("reset:")
                .nth(1)
                .is_some_and(|t| t.contains('\n'))
        },
        Duration::from_millis(50),
    );
    let text = sim.uart_text();
    // Grbl 1.1's greeting first: what senders wait for.
    assert!(text.starts_with("Grbl 1.1h ['$' for help]\n"), "{text}");
    let banner = text
        .lines()
        .find(|l| l.contains("taut "))
        .expect("banner line");
    assert!(banner.starts_with("[MSG:I "), "log line format: {banner}");
    assert!(
        banner.contains(&format!("taut {} git ", firmware_version())),
        "{banner}"
    );
    assert!(banner.contains("atmega2560 16MHz"), "{banner}");
    assert!(banner.ends_with("reset:power-on]"), "{banner}");
    assert!(sim.time_s() < 0.050);
}

#[test]
fn status_led_blinks_three_times_at_boot_then_stays_off() {
    let mut sim = hil_tests::load();
    sim.probe(STATUS_LED, "led");
    assert_eq!(sim.run_for(Duration::from_secs(2)), Outcome::Running);
    let led = sim.probed("led");
    // 3 flashes of 100 ms: 3 rising and 3 falling edges, nothing after.
    assert_eq!(led.edge_count(), 6);
    assert_eq!(led.rising_count(), 3);
    let high_us = led.min_high_us().unwrap();
    assert!(
        (99_000.0..=101_000.0).contains(&high_us),
        "flash length {high_us} µs"
    );
    assert!(!led.level());
}

#[test]
fn idle_firmware_sleeps_and_keeps_its_stack_small() {
    let mut sim = hil_tests::load();
    assert_eq!(sim.run_for(Duration::from_secs(1)), Outcome::Running);
    let elf = sim.elf().unwrap();
    let stack = sim.peak_stack_bytes() as u32;
    assert!(stack > 0 && stack < 1024, "peak stack {stack} B");
    assert!(elf.ram_static_bytes() + stack < 6 * 1024);
}
