//! Every line sent gets its one reply, in every state. While the flatbed
//! homes at power-on the console reads nothing and the 128-byte receive
//! ring fills: a line longer than the ring then loses bytes, and still
//! ends — in `error:11`, as Grbl answers a line it could not keep — where
//! before its end was lost with it and a sender waited for ever. A
//! character-counting sender's full 128 bytes fit as they always did.

use hil_tests::sim::Sim;
use hil_tests::{flatbed_with_x_switch, log_tail, reported_steps, wait_for, Rng};
use std::time::Duration;

/// The flatbed chosen (kept in EEPROM), booted again with its X switch
/// `far` steps below where it stands: it homes at power-on meanwhile.
fn flatbed_homing(far: i64) -> Sim {
    let mut sim = flatbed_with_x_switch(-far);
    // Sent before the UART is set up a byte would be lost on the wire.
    wait_for(&mut sim, "reset:", Duration::from_millis(500));
    assert!(!sim.uart_text().contains("homed"), "{}", sim.uart_text());
    sim
}

/// The whole `ok` and `error:N` lines from `from` on.
fn replies(sim: &Sim, from: usize) -> Vec<String> {
    let text = sim.uart_text_from(from);
    text[..text.rfind('\n').map_or(0, |i| i + 1)]
        .lines()
        .filter(|l| *l == "ok" || l.starts_with("error:"))
        .map(str::to_string)
        .collect()
}

/// Runs until `n` replies have come from `from` on (or 30 s).
fn await_replies(sim: &mut Sim, from: usize, n: usize) -> Vec<String> {
    sim.run_until(|s| replies(s, from).len() >= n, Duration::from_secs(30));
    replies(sim, from)
}

/// A move to `x` padded by a comment to `len` bytes with its end: fine
/// for Grbl's parser at any length (comments are not kept).
fn padded_move(x: u32, len: usize) -> String {
    let line = format!("G1 X{x} F3000 (");
    format!(
        "{line}{})\n",
        "c".repeat(len.saturating_sub(line.len() + 2))
    )
}

/// Seeded: a line of 129–600 bytes sent as the board boots, while it
/// homes; then, once it has answered, lines of any length sent one at a
/// time as a sender waits for each reply. The long first line lost bytes
/// in the full ring: `error:11`, and no motion; every later line is read
/// as it comes (`ok`) and moves.
#[test]
fn a_line_longer_than_the_ring_during_power_on_homing_is_answered() {
    for seed in 1..=3u64 {
        let mut rng = Rng::new(seed);
        let mut sim = flatbed_homing(2000);
        let long = 129 + rng.below(472) as usize;
        sim.uart_send(padded_move(50, long).as_bytes());
        let first = await_replies(&mut sim, 0, 1);
        assert_eq!(
            first,
            ["error:11"],
            "seed {seed}, {long} B\n{}",
            log_tail(&sim)
        );
        assert!(
            sim.uart_text_from(0).contains("homed"),
            "seed {seed}: the reply came after the homing\n{}",
            log_tail(&sim)
        );
        let homed = reported_steps(&mut sim);
        for k in 0..5u32 {
            let len = 8 + rng.below(600) as usize;
            let from = sim.uart_bytes().len();
            sim.uart_send(padded_move(10 + k, len).as_bytes());
            let got = await_replies(&mut sim, from, 1);
            assert_eq!(
                got,
                ["ok"],
                "seed {seed}, line {k} of {len} B\n{}",
                log_tail(&sim)
            );
        }
        sim.run_for(Duration::from_secs(2));
        let end = reported_steps(&mut sim);
        // The last move went to X14 (40 steps a mm); the refused X50 never ran.
        assert_eq!(end[0], 14 * 40, "seed {seed}: {homed:?} -> {end:?}");
    }
}

/// A character-counting sender's window, 128 bytes of whole lines sent at
/// once while the board homes, all kept (the ring's last slot takes the
/// last line's end): 128 bytes, every line `ok`, in order, and the moves
/// made.
#[test]
fn a_counting_sender_s_full_window_during_homing_is_kept_whole() {
    let mut sim = flatbed_homing(2000);
    let mut window = String::new();
    let mut x = 0;
    while window.len() + 16 <= 128 {
        x += 1;
        window += &format!("G1 X{x} F3000\n");
    }
    // Up to exactly 128 bytes with a line of spaces padding it.
    let pad = 128 - window.len() - 5;
    window += &format!("G4{}P0\n", " ".repeat(pad));
    assert_eq!(window.len(), 128);
    let lines = window.lines().count();
    sim.uart_send(window.as_bytes());
    let got = await_replies(&mut sim, 0, lines);
    assert_eq!(got, vec!["ok"; lines], "{}", log_tail(&sim));
    assert!(sim.uart_text().contains("homed"), "{}", log_tail(&sim));
    sim.run_for(Duration::from_secs(2));
    assert_eq!(reported_steps(&mut sim)[0], x * 40);
}
