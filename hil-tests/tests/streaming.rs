//! Issue 10: what senders stream never resets the board, loses a line or
//! loses a step. Each test streams moves the documented way (each line
//! after the previous `ok`) at the configured maximum rate and checks: no
//! watchdog reset, every line answered `ok`, and the final `M114` equal to
//! the sum of the moves and to the pulses counted on the pins.

use hil_tests::{boot_machine, pulses, send_ok, sim::Outcome, sim::Sim};
use std::time::Duration;
use taut_logic::axis::Axis;
use taut_logic::config::MachineConfig;

/// A tiny seeded generator (xorshift): the same moves on every run.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

/// How many moves a stress test streams: the 5000 under
/// `cargo xtask soak` (`TAUT_SOAK=1`), a tenth in the everyday run.
fn moves(full: usize) -> usize {
    if std::env::var_os("TAUT_SOAK").is_some() {
        full
    } else {
        full / 10
    }
}

/// Stream `lines`, each after the previous reply, optionally with a `?`
/// every `status_every` of simulated time; every reply must be `ok`.
fn stream(sim: &mut Sim, lines: &[String], status_every: Option<Duration>) {
    let mut next_status = sim.time_s();
    for (n, line) in lines.iter().enumerate() {
        let start = sim.uart_bytes().len();
        sim.uart_send(format!("{line}\n").as_bytes());
        loop {
            let out = sim.run_for(Duration::from_micros(500));
            assert!(
                matches!(out, Outcome::Running),
                "line {n} {line:?}: {out:?}\n{}",
                tail(sim)
            );
            if let Some(every) = status_every {
                if sim.time_s() >= next_status {
                    sim.uart_send(b"?");
                    next_status = sim.time_s() + every.as_secs_f64();
                }
            }
            let text = String::from_utf8_lossy(&sim.uart_bytes()[start..]).into_owned();
            if let Some(reply) = text.lines().find(|l| *l == "ok" || l.starts_with("error")) {
                assert_eq!(reply, "ok", "line {n} {line:?}\n{}", tail(sim));
                break;
            }
        }
    }
}

fn tail(sim: &Sim) -> String {
    let t = sim.uart_text();
    t[t.len().saturating_sub(2000)..].to_string()
}

/// The executed position `M114` reports, in steps (`Count C:… X:… Z:…`).
fn reported_steps(sim: &mut Sim) -> [i64; 3] {
    let start = sim.uart_bytes().len();
    send_ok(sim, "M114", Duration::from_secs(1));
    let text = String::from_utf8_lossy(&sim.uart_bytes()[start..]).into_owned();
    let count = text
        .lines()
        .find_map(|l| l.split_once("Count "))
        .unwrap_or_else(|| panic!("no M114 line in {text:?}"))
        .1;
    let mut out = [0; 3];
    for (i, word) in count.split_whitespace().take(3).enumerate() {
        out[i] = word[2..].parse().unwrap();
    }
    out
}

fn steps_on_pins(sim: &Sim) -> [i64; 3] {
    let net = |axis: Axis| {
        let d = taut_logic::pinmap::driver(axis);
        sim.net_steps(d.step, d.dir, true)
    };
    [net(Axis::Base), net(Axis::Radial), net(Axis::Drill)]
}

/// Stream, wait for the end of motion, and check the machine stands where
/// the moves add up to (`expected` steps), on the pins and in `M114`.
fn check_stream(sim: &mut Sim, lines: &[String], status: Option<Duration>, expected: [i64; 3]) {
    stream(sim, lines, status);
    send_ok(sim, "M400", Duration::from_secs(600));
    assert_eq!(sim.watchdog_resets(), 0, "{}", tail(sim));
    assert_eq!(steps_on_pins(sim), expected, "pulses on the pins");
    assert_eq!(reported_steps(sim), expected, "M114");
    let text = sim.uart_text();
    assert!(!text.contains("step late"), "{}", tail(sim));
    hil_tests::assert_ram_budget(sim);
}

/// Relative moves of `mm` on the radial axis at the maximum rate, in runs
/// of 100 that go out, out, back (inside the carriage's travel).
fn radial_pieces(mm: f64, n: usize) -> (Vec<String>, [i64; 3]) {
    let mut lines = vec!["G91".to_string()];
    let mut um = 0i32;
    for k in 0..n {
        let d = if k / 100 % 3 == 2 { -mm } else { mm };
        lines.push(format!("G1 X{d} F60000"));
        um += (d * 1000.0).round() as i32;
    }
    let spu = MachineConfig::STRING_ART.axes[Axis::Radial.index()].steps_per_unit;
    (
        lines,
        [0, spu.steps(taut_logic::units::Milli(um)) as i64, 0],
    )
}

fn boot_enabled() -> Sim {
    let mut sim = boot_machine();
    send_ok(&mut sim, "M17", Duration::from_secs(1));
    sim
}

#[test]
fn tiny_moves_at_full_rate_0_05_mm() {
    let (lines, expected) = radial_pieces(0.05, moves(5000));
    check_stream(&mut boot_enabled(), &lines, None, expected);
}

#[test]
fn tiny_moves_at_full_rate_0_1_mm() {
    let (lines, expected) = radial_pieces(0.1, moves(5000));
    check_stream(&mut boot_enabled(), &lines, None, expected);
}

#[test]
fn tiny_moves_at_full_rate_0_3_mm() {
    let (lines, expected) = radial_pieces(0.3, moves(5000));
    check_stream(&mut boot_enabled(), &lines, None, expected);
}
