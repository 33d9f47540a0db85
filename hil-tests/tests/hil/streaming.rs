//! What senders stream never resets the board, loses a line or
//! loses a step. Each test streams moves the documented way (each line
//! after the previous `ok`) at the configured maximum rate and checks: no
//! watchdog reset, every line answered `ok`, and the final `M114` equal to
//! the sum of the moves and to the pulses counted on the pins.

use hil_tests::{
    boot_machine, log_tail, reported_steps, send_ok, sim::Outcome, sim::Sim, soak_or,
    steps_on_pins, Rng,
};
use std::time::Duration;
use taut_logic::config::MachineConfig;

/// How many random moves a seed streams: the full campaign under
/// `cargo xtask soak` (`TAUT_SOAK=1`), a tenth in the everyday run (slow
/// feeds make it long). The fixed-length streams always run whole.
fn moves(full: usize) -> usize {
    soak_or(full, full / 10)
}

/// Stream `lines`, each after the previous reply, optionally with a `?`
/// every `status_every` of simulated time; every reply must be `ok`.
/// Returns the longest time a `?` waited for its report, ms.
fn stream(sim: &mut Sim, lines: &[String], status_every: Option<Duration>) -> f64 {
    let mut next_status = sim.time_s();
    // `?` sent and not yet answered: when, and how many reports before.
    let mut asked: Option<(f64, usize)> = None;
    let mut worst = 0.0f64;
    let reports = |s: &Sim| s.uart_text().matches('<').count();
    for (n, line) in lines.iter().enumerate() {
        let start = sim.uart_bytes().len();
        sim.uart_send(format!("{line}\n").as_bytes());
        loop {
            let out = sim.run_for(Duration::from_micros(500));
            assert!(
                matches!(out, Outcome::Running),
                "line {n} {line:?}: {out:?}\n{}",
                log_tail(sim)
            );
            if let Some((at, before)) = asked {
                if reports(sim) > before {
                    worst = worst.max((sim.time_s() - at) * 1000.0);
                    asked = None;
                }
            }
            if let Some(every) = status_every {
                if asked.is_none() && sim.time_s() >= next_status {
                    asked = Some((sim.time_s(), reports(sim)));
                    // Slipped in ahead of the line being sent, as senders do.
                    sim.uart_send_at(Duration::from_secs_f64(sim.time_s()), b"?");
                    next_status = sim.time_s() + every.as_secs_f64();
                }
            }
            let text = sim.uart_text_from(start);
            let mut complete = text
                .split_inclusive('\n')
                .filter_map(|l| l.strip_suffix('\n'));
            if let Some(reply) = complete.find(|l| *l == "ok" || l.starts_with("error")) {
                assert_eq!(reply, "ok", "line {n} {line:?}\n{}", log_tail(sim));
                break;
            }
        }
    }
    worst
}

/// Stream, wait for the end of motion, and check the machine stands where
/// the moves add up to (`expected` steps), on the pins and in `M114`.
fn check_stream(sim: &mut Sim, lines: &[String], status: Option<Duration>, expected: [i64; 3]) {
    let worst_status_ms = stream(sim, lines, status);
    send_ok(sim, "M400", Duration::from_secs(600));
    assert_eq!(sim.watchdog_resets(), 0, "{}", log_tail(sim));
    assert_eq!(steps_on_pins(sim), expected, "pulses on the pins");
    assert_eq!(reported_steps(sim), expected, "M114");
    let text = sim.uart_text();
    assert!(!text.contains("step late"), "{}", log_tail(sim));
    if status.is_some() {
        // Answered from the receive path, whatever the console is doing.
        assert!(worst_status_ms <= 10.0, "a `?` waited {worst_status_ms} ms");
    }
    hil_tests::assert_ram_budget(sim);
}

/// Steps of an absolute target on the string-art machine's axes.
fn steps_of(c_deg: f64, x_mm: f64, z_mm: f64) -> [i64; 3] {
    let cfg = MachineConfig::STRING_ART;
    let to = |i: usize, v: f64| {
        let milli = taut_logic::units::Milli((v * 1000.0).round() as i32);
        cfg.axes[i].steps_per_unit.steps(milli) as i64
    };
    [to(0, c_deg), to(1, x_mm), to(2, z_mm)]
}

/// Relative moves of `mm` on the radial axis at the maximum rate from
/// 200 mm inside the board's edge, in runs of 100 that go out, out, back,
/// back (inside the carriage's travel, however many).
fn radial_pieces(mm: f64, n: usize) -> (Vec<String>, [i64; 3]) {
    let mut lines = vec!["G0 X-200".to_string(), "G91".to_string()];
    let mut x = -200.0;
    for k in 0..n {
        let d = if k / 100 % 4 < 2 { mm } else { -mm };
        lines.push(format!("G1 X{d} F60000"));
        x += d;
    }
    (lines, steps_of(0.0, (x * 1000.0f64).round() / 1000.0, 0.0))
}

fn boot_enabled() -> Sim {
    let mut sim = boot_machine();
    send_ok(&mut sim, "M17", Duration::from_secs(1));
    sim
}

#[test]
fn tiny_moves_at_full_rate_0_05_mm() {
    let (lines, expected) = radial_pieces(0.05, 5000);
    check_stream(&mut boot_enabled(), &lines, None, expected);
}

#[test]
fn tiny_moves_at_full_rate_0_1_mm() {
    let (lines, expected) = radial_pieces(0.1, 5000);
    check_stream(&mut boot_enabled(), &lines, None, expected);
}

#[test]
fn tiny_moves_at_full_rate_0_3_mm() {
    let (lines, expected) = radial_pieces(0.3, 5000);
    check_stream(&mut boot_enabled(), &lines, None, expected);
}

/// A circle of 5 mm radius drawn by the radial and drill axes in 2000
/// straight pieces (what a plotter's curves are), at the maximum feed.
#[test]
fn a_circle_of_2000_pieces() {
    let pieces = 2000;
    let (cx, cz, r) = (-10.0f64, -10.0f64, 5.0f64);
    let at = |k: usize| {
        let a = k as f64 * std::f64::consts::TAU / pieces as f64;
        (cx + r * a.cos(), cz + r * a.sin())
    };
    let mut lines = vec!["G90".to_string()];
    lines.extend((0..=pieces).map(|k| {
        let (x, z) = at(k);
        format!("G1 X{x:.3} Z{z:.3} F60000")
    }));
    let (x, z) = at(pieces);
    let (x, z) = (
        format!("{x:.3}").parse().unwrap(),
        format!("{z:.3}").parse().unwrap(),
    );
    check_stream(&mut boot_enabled(), &lines, None, steps_of(0.0, x, z));
}

/// Random move lengths (0.01–3 units) and feeds (10 units/min to the
/// maximum) on all three axes, absolute, from a list of seeds; the last
/// one with a `?` every 50 ms, each answered within 10 ms.
#[test]
fn random_moves_and_feeds_from_seeds() {
    for (seed, status) in [(1u64, false), (7, false), (1234, true)] {
        let mut rng = Rng::new(seed);
        let (mut c, mut x, mut z) = (0.0f64, -100.0f64, -10.0f64);
        let mut lines = vec!["G90".to_string()];
        for _ in 0..moves(3000) {
            let step = |rng: &mut Rng| (rng.below(3000) as f64 + 10.0) / 1000.0;
            let sign = |rng: &mut Rng| if rng.below(2) == 0 { -1.0 } else { 1.0 };
            match rng.below(3) {
                0 => c += sign(&mut rng) * step(&mut rng),
                1 => x = (x + sign(&mut rng) * step(&mut rng)).clamp(-400.0, 20.0),
                _ => z = (z + sign(&mut rng) * step(&mut rng)).clamp(-25.0, 10.0),
            }
            let feed = 10 + rng.below(6000);
            lines.push(format!("G1 C{c:.3} X{x:.3} Z{z:.3} F{feed}"));
        }
        let status = status.then_some(Duration::from_millis(50));
        let round = |v: f64| format!("{v:.3}").parse::<f64>().unwrap();
        let expected = steps_of(round(c), round(x), round(z));
        check_stream(&mut boot_enabled(), &lines, status, expected);
    }
}

/// Tiny moves at full rate with a `?` every 50 ms.
#[test]
fn tiny_moves_with_status_reports() {
    let (lines, expected) = radial_pieces(0.1, 5000);
    let mut sim = boot_enabled();
    // The greeting and the start-up log (≈ 250 bytes, 22 ms at 115200 baud)
    // go out first: a report can only follow bytes already queued, and
    // this measures the stream, not the boot.
    sim.run_for(Duration::from_millis(100));
    check_stream(&mut sim, &lines, Some(Duration::from_millis(50)), expected);
}

/// What a character-counting stream saw.
struct Counted {
    /// Every line's reply, in order.
    replies: Vec<String>,
    /// The most bytes sent and not yet answered.
    most_in_flight: usize,
    /// Status reports received.
    reports: usize,
    /// Steps on the pins over the held stretch (after the brake), by axis.
    held: [[i64; 3]; 2],
}

#[derive(Clone, Copy, PartialEq)]
enum Hold {
    Before,
    Braking,
    /// Since then (simulated s).
    Standing(f64),
    After,
}

/// Grbl's receive buffer, as senders count it.
const RX_BUFFER: usize = 128;

/// Character counting as CNCjs, UGS and bCNC stream by default: a line
/// goes as soon as it fits beside the bytes not yet answered (at most
/// all `RX_BUFFER`: taut's ring uses every byte), so the receive buffer stays full; `?` every 100 ms;
/// `!` when half the lines are answered and `~` 300 ms after the machine
/// stands.
fn stream_counting(sim: &mut Sim, lines: &[String]) -> Counted {
    let start = sim.uart_bytes().len();
    let mut read = start;
    let mut in_flight: std::collections::VecDeque<usize> = Default::default();
    let mut next = 0;
    let mut out = Counted {
        replies: Vec::new(),
        most_in_flight: 0,
        reports: 0,
        held: [[0; 3]; 2],
    };
    let mut next_status = sim.time_s();
    let mut hold = Hold::Before;
    let limit = sim.time_s() + 600.0;
    while out.replies.len() < lines.len() {
        while next < lines.len() {
            let len = lines[next].len() + 1;
            if in_flight.iter().sum::<usize>() + len > RX_BUFFER {
                break;
            }
            sim.uart_send(format!("{}\n", lines[next]).as_bytes());
            in_flight.push_back(len);
            next += 1;
        }
        out.most_in_flight = out.most_in_flight.max(in_flight.iter().sum());
        let outcome = sim.run_for(Duration::from_micros(500));
        assert!(
            matches!(outcome, Outcome::Running),
            "{outcome:?}\n{}",
            log_tail(sim)
        );
        let now = sim.time_s();
        if now >= next_status {
            sim.uart_send_at(Duration::from_secs_f64(now), b"?");
            next_status = now + 0.1;
        }
        // The hold: `!`; once a report says it stands (`Hold:0`), the
        // steps then and 300 ms later; then `~`.
        match hold {
            Hold::Before if out.replies.len() >= lines.len() / 2 => {
                sim.uart_send_at(Duration::from_secs_f64(now), b"!");
                hold = Hold::Braking;
            }
            Hold::Standing(at) if now >= at + 0.3 => {
                out.held[1] = steps_on_pins(sim);
                sim.uart_send_at(Duration::from_secs_f64(now), b"~");
                hold = Hold::After;
            }
            _ => {}
        }
        let bytes = sim.uart_bytes();
        if let Some(end) = bytes[read..].iter().rposition(|&b| b == b'\n') {
            let text = String::from_utf8_lossy(&bytes[read..read + end + 1]).into_owned();
            read += end + 1;
            for line in text.lines() {
                if line.starts_with('<') {
                    out.reports += 1;
                    if hold == Hold::Braking && line.starts_with("<Hold:0") {
                        out.held[0] = steps_on_pins(sim);
                        hold = Hold::Standing(sim.time_s());
                    }
                } else if line == "ok" || line.starts_with("error") {
                    assert!(
                        in_flight.pop_front().is_some(),
                        "a reply to nothing: {line}"
                    );
                    out.replies.push(line.to_string());
                }
            }
        }
        assert!(sim.time_s() < limit, "stuck\n{}", log_tail(sim));
    }
    out
}

/// The receive buffer kept full by character counting for a
/// whole file of short moves, with `?` every 100 ms and a feed hold and
/// cycle start in the middle: every line answered `ok` once, no byte
/// refused by the receive ring, the hold stands, the end exact.
#[test]
fn character_counting_keeps_the_buffer_full_with_reports_and_a_hold() {
    let (lines, expected) = radial_pieces(0.3, 1200);
    let mut sim = boot_enabled();
    sim.run_for(Duration::from_millis(100));
    let c = stream_counting(&mut sim, &lines);
    assert!(
        c.replies.iter().all(|r| r == "ok"),
        "{:?}",
        c.replies.iter().find(|r| *r != "ok")
    );
    assert_eq!(c.replies.len(), lines.len());
    assert!(
        c.most_in_flight >= RX_BUFFER - 20,
        "the buffer was not kept full: {}",
        c.most_in_flight
    );
    assert_ne!(c.held[1], [0; 3], "the hold never stood");
    assert_eq!(c.held[0], c.held[1], "steps while held");
    send_ok(&mut sim, "M400", Duration::from_secs(600));
    assert!(
        c.reports as f64 >= sim.time_s() * 5.0,
        "{} reports in {:.1} s",
        c.reports,
        sim.time_s()
    );
    assert_eq!(steps_on_pins(&sim), expected, "pulses on the pins");
    assert_eq!(reported_steps(&mut sim), expected, "M114");
    let start = sim.uart_bytes().len();
    send_ok(&mut sim, "$Q", Duration::from_secs(1));
    let q = sim.uart_text_from(start);
    let rx = q
        .lines()
        .find(|l| l.contains("rx sent:"))
        .unwrap_or_default();
    assert!(rx.contains(" refused:0 "), "{q}");
    assert_eq!(sim.watchdog_resets(), 0);
    hil_tests::assert_ram_budget(&sim);
}
