//! The harness against real firmware images (firmware/examples/): a crash, a
//! hang and a stack overflow are each reported as such, and a blink pattern
//! is counted edge for edge.

use hil_tests::example_elf;
use hil_tests::sim::{vcd, Outcome, Sim};
use std::time::Duration;

const LED: u8 = 13;

fn boot(example: &str) -> Sim {
    let mut sim = Sim::load(&example_elf(example)).unwrap();
    sim.probe(LED, "led");
    sim
}

#[test]
fn null_function_pointer_is_a_crash() {
    let mut sim = boot("crash");
    let end = sim.run_for(Duration::from_millis(100));
    let text = sim.elf().unwrap().text_bytes;
    assert!(
        matches!(end, Outcome::Crashed { pc } if pc > 0 && pc < text),
        "{end:?}"
    );
    assert!(sim.pin_level(LED), "got as far as the LED before crashing");
    assert!(sim.time_s() < 0.001, "caught at once, not at the timeout");
}

#[test]
fn sleep_with_interrupts_disabled_is_a_hang() {
    let mut sim = boot("hang");
    let end = sim.run_for(Duration::from_millis(100));
    assert!(matches!(end, Outcome::Hung { .. }), "{end:?}");
    assert!(sim.pin_level(LED));
}

#[test]
fn runaway_recursion_is_a_stack_overflow() {
    let mut sim = boot("stack_overflow");
    let limit = sim.elf().unwrap().static_ram_end;
    assert!(sim.elf().unwrap().bss_bytes >= 32, "the sentry array");
    assert_eq!(sim.ram_limit(), limit);
    let end = sim.run_for(Duration::from_millis(100));
    let Outcome::StackOverflow { sp, limit: seen } = end else {
        panic!("{end:?}")
    };
    assert_eq!(seen, limit);
    // Caught at the first frame that reaches into the statics (a frame is
    // allocated at once, so SP may jump a few dozen bytes past the line).
    assert!(
        sp + 1 < limit && sp + 64 > limit,
        "sp {sp:#x}, limit {limit:#x}"
    );
    assert_eq!(sim.lowest_sp(), sp);
    assert_eq!(sim.peak_stack_bytes(), 0x21FF - sp);
}

#[test]
fn blink_edges_are_counted_exactly() {
    let mut sim = boot("blink");
    let end = sim.run_for(Duration::from_millis(20));
    assert_eq!(end, Outcome::Running, "sleeps with interrupts on: no hang");
    let led = sim.probed("led");
    assert_eq!(led.edge_count(), 6);
    assert_eq!(led.rising_count(), 3);
    let high = led.min_high_us().unwrap();
    let period = led.min_period_us().unwrap();
    assert!((1000.0..1010.0).contains(&high), "high {high} us");
    assert!((2000.0..2020.0).contains(&period), "period {period} us");
    assert!(sim.sim_mhz().unwrap() > 1.0);

    let report = sim.report(end);
    assert_eq!(report.pins[0].edges, 6);
    assert!(report.to_json().contains("\"end\": \"Running\""));

    let path = std::env::temp_dir().join(format!("taut-blink-{}.vcd", std::process::id()));
    sim.write_vcd(&path).unwrap();
    let signals = vcd::parse(&std::fs::read_to_string(&path).unwrap()).unwrap();
    std::fs::remove_file(&path).unwrap();
    assert_eq!(signals.len(), 1);
    assert_eq!(signals[0].name, "led");
    assert_eq!(signals[0].changes.len(), 6);
}

/// The image's 64-bit product (`firmware/src/rt/mul64.rs`, in place of
/// libgcc's) agrees with one built from 16-bit pieces, and is the one the
/// compiler's `*` calls; the segment maths' assembly division agrees with
/// the compiler's; the image's `memcpy` and `memset` (`rt/mem.S`) agree
/// with byte loops: on every case `arith_check` tries.
#[test]
fn the_images_wide_arithmetic_is_exact() {
    let elf = example_elf("arith_check");
    let mut sim = Sim::load(&elf).unwrap();
    sim.probe(LED, "led");
    sim.probe(10, "copies");
    let end = sim.run_until(|s| s.pin_level(12), Duration::from_secs(2));
    assert_eq!(end, Outcome::Done, "the check ran to its end");
    assert!(
        sim.pin_level(11),
        "every product, quotient, root, copy and clear agrees"
    );
    let e = sim.probed("led").edges();
    assert_eq!(e.len(), 2, "one timed batch");
    let per = (e[1].cycle - e[0].cycle) as f64 / 256.0;
    println!("__muldi3, two 32-bit factors: {per:.0} cycles a product with the loop");
    let e = sim.probed("copies").edges();
    assert_eq!(e.len(), 2, "one timed batch of copies");
    let per = (e[1].cycle - e[0].cycle) as f64 / 64.0;
    println!("memcpy, 64 bytes: {per:.0} cycles a copy with the loop");
    // Four bytes a turn, ~5 cycles a byte: 417 with this loop, where
    // avr-libc's byte a turn (8 cycles a byte) took 607.
    assert!(per < 500.0, "a 64-byte copy took {per:.0} cycles");
    // libgcc's is left out: its helper would be there with it.
    let symbols = std::process::Command::new("avr-nm")
        .arg(&elf)
        .output()
        .unwrap();
    let symbols = String::from_utf8_lossy(&symbols.stdout);
    assert!(
        !symbols.contains("__muldi3_6"),
        "libgcc's __muldi3 linked in"
    );
}
