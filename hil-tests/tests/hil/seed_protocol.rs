//! Seed 003's own line protocol beside Grbl's, on the release image: its
//! maker's "magnus" stream (`files/seed003_magnus.txt`, as printed in the
//! seed) drawn on the whiteboard step for step, read back from the STEP,
//! DIR and pen pins alone; a malformed line answered `?` (and
//! `error:1`) with nothing moved; `K` while 64 bytes or more wait; G-code and `$` lines in the
//! same session.

use hil_tests::sim::Sim;
use hil_tests::{assert_ram_budget, boot_machine, pen_deg_at, send_ok, settle, track};
use std::time::Duration;
use taut_logic::config::MachineConfig;
use taut_logic::machine::Machine;

const MAGNUS: &str = include_str!("../../files/seed003_magnus.txt");

fn send(sim: &mut Sim, line: &str) {
    send_ok(sim, line, Duration::from_secs(30));
}

/// A seed line's steps (left, right) and whether the pen is up.
fn seed_line(line: &str) -> ([i64; 2], bool) {
    let n = |s: &str| s.parse::<i64>().unwrap();
    (
        [n(&line[0..5]), n(&line[5..10])],
        line.ends_with(['u', 'U']),
    )
}

/// Pen PWM pulse widths in µs with the cycle each began, in order.
fn pen_pulses(sim: &Sim) -> Vec<(u64, f64)> {
    let edges = sim.probed("pen_pwm").edges();
    edges
        .windows(2)
        .filter(|w| w[0].high && !w[1].high)
        .map(|w| (w[0].cycle, (w[1].cycle - w[0].cycle) as f64 / 16.0))
        .collect()
}

/// How often the pen went from up to down or back, read from its pulses'
/// widths (a pulse cut by the change is neither), and whether it started
/// up.
fn pen_changes(sim: &Sim, up: u8, down: u8) -> (usize, bool) {
    let at = |deg: u8| 1000.0 + f64::from(deg) * 1000.0 / 180.0;
    let ups: Vec<bool> = pen_pulses(sim)
        .into_iter()
        .filter_map(|(_, w)| match w {
            w if (w - at(up)).abs() < 10.0 => Some(true),
            w if (w - at(down)).abs() < 10.0 => Some(false),
            _ => None,
        })
        .collect();

    (ups.windows(2).filter(|w| w[0] != w[1]).count(), ups[0])
}

#[test]
fn the_seeds_magnus_stream_is_drawn_step_for_step() {
    let mut sim = boot_machine();
    send(&mut sim, "$machine=whiteboard");
    let pen = MachineConfig::defaults(Machine::Whiteboard).pen;
    let before = track(&sim).len();
    let lines: Vec<&str> = MAGNUS.lines().collect();
    assert_eq!(lines.len(), 59);
    for line in &lines {
        send(&mut sim, line);
    }
    settle(&mut sim);
    let steps = &track(&sim)[before..];
    // Every STEP edge of each line, in order: one motor one step at a
    // time in the line's direction, never more than half a step off the
    // straight line from its start to its end in motor space (both
    // finish together) once both motors took an event's steps (a step
    // and a half between the two edges), ending exactly on its end.
    let mut at = [0i64; 2];
    let mut k = 0;
    let mut pen_up = true;
    let mut changes = 0;
    for (n, line) in lines.iter().enumerate() {
        let (d, up) = seed_line(line);
        changes += (up != pen_up) as usize;
        pen_up = up;
        let count = (d[0].abs() + d[1].abs()) as usize;
        let seg = &steps[k..k + count];
        let from = at;
        for (cycle, p) in seg {
            let moved = [p[0] - at[0], p[1] - at[1]];
            assert!(
                moved[0].abs() + moved[1].abs() == 1
                    && moved[0] * d[0] >= 0
                    && moved[1] * d[1] >= 0,
                "line {n} {line}: a step {moved:?} at cycle {cycle}"
            );
            at = [p[0], p[1]];
            // Distance from the line in steps: the cross product over the
            // longer motor's steps.
            let (u, v) = ((at[0] - from[0]) as f64, (at[1] - from[1]) as f64);
            let off = (u * d[1] as f64 - v * d[0] as f64).abs() / d[0].abs().max(d[1].abs()) as f64;
            assert!(
                off <= 1.5,
                "line {n} {line}: {off} steps off its line at {at:?}"
            );
            let deg = pen_deg_at(&sim, *cycle).expect("no pen pulses");
            let want = if up { pen.up_deg } else { pen.down_deg } as f64;
            assert!((deg - want).abs() < 1.0, "line {n} {line}: pen at {deg}°");
        }
        assert_eq!(at, [from[0] + d[0], from[1] + d[1]], "line {n} {line}");
        k += count;
    }
    assert_eq!(k, steps.len(), "steps after the stream's last line");
    // Net and every edge, per motor: 4784 and -4288 net, 19938 and 22950
    // edges.
    let (net, edges) = lines
        .iter()
        .map(|l| seed_line(l).0)
        .fold(([0, 0], [0, 0]), |(n, e), d| {
            (
                [n[0] + d[0], n[1] + d[1]],
                [e[0] + d[0].abs(), e[1] + d[1].abs()],
            )
        });
    assert_eq!((net, edges), ([4784, -4288], [19938, 22950]));
    assert_eq!(at, net);
    // The pen is up from power-on: every change of the stream, no other.
    assert_eq!(
        pen_changes(&sim, pen.up_deg, pen.down_deg),
        (changes, true),
        "pen changes"
    );
    // G-code and `$` lines in the same session: back to the drawing's
    // origin, where the stream started.
    send(&mut sim, "$$");
    send(&mut sim, "G1 X0 Y0 F3000");
    settle(&mut sim);
    let end = track(&sim).last().unwrap().1;
    assert!(end[0].abs() <= 1 && end[1].abs() <= 1, "back at {end:?}");
    assert_ram_budget(&sim);
}

#[test]
fn a_malformed_seed_line_is_answered_with_a_question_mark_and_k_says_wait() {
    let mut sim = boot_machine();
    send(&mut sim, "$machine=whiteboard");
    let from = sim.uart_bytes().len();
    sim.uart_send(b"+0615-0950x\n");
    sim.run_for(Duration::from_millis(50));
    // The seed's `?`, then Grbl's `error:1` (no command letter) for
    // senders that count characters.
    let out = sim.uart_text_from(from);
    assert!(
        out.starts_with("?\n") && out.ends_with("\nerror:1\n"),
        "{out}"
    );
    assert!(track(&sim).is_empty(), "a malformed line moved");
    // Nine lines at once (108 bytes): the second waits for the pen to
    // rise while the rest arrive; while 64 bytes or more wait unread the
    // seed's `K` follows a line's answer; every line is answered `ok` and
    // drawn.
    let from = sim.uart_bytes().len();
    let burst = format!("+0010-0010n\n{}", "+0010-0010u\n".repeat(8));
    sim.uart_send(burst.as_bytes());
    sim.run_for(Duration::from_secs(3));
    let out = sim.uart_text_from(from);
    assert_eq!(out.lines().filter(|l| *l == "ok").count(), 9, "{out}");
    assert!(out.lines().any(|l| l == "K"), "{out}");
    settle(&mut sim);
    assert_eq!(track(&sim).last().unwrap().1[..2], [90, -90]);
    assert_ram_budget(&sim);
}
