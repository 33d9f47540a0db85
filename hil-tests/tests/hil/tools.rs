//! The operator's tools on the release image, checked from the
//! step pulses: `$wrap_test` wraps the one nail asked for and comes back,
//! `$drift` goes to a nail's angle and says where the base is, `$wrap_step=1`
//! winds exactly one wrap while paused, `$wrap_step=-1` has the last wrap
//! wound again, and every tool is refused while the machine moves.

use hil_tests::sim::operator::{Operator, Seen};
use hil_tests::sim::replay::JobReplay;
use hil_tests::sim::{Outcome, Sim};
use hil_tests::{assert_ram_budget, card, machine, quick_string_art, QUICK_MACHINE_TXT};
use std::time::Duration;
use taut_logic::geometry::{Board, StepScale};
use taut_logic::pinmap::Button;
use taut_logic::units::Milli;

const NAILS: u16 = 12;
const PATTERN: [u16; 8] = [5, 0, 7, 3, 10, 2, 8, 1];

fn ns(sim: &Sim) -> u64 {
    (sim.time_s() * 1e9) as u64
}

/// Runs with `op` reading the log until `done` holds of what it saw.
fn run_until(
    sim: &mut Sim,
    op: &mut Operator,
    mut done: impl FnMut(&Sim, &Operator, &[Seen]) -> bool,
) {
    let limit = sim.time_s() + 120.0;
    loop {
        assert_eq!(sim.run_for(Duration::from_millis(10)), Outcome::Running);
        let seen = op.step(sim);
        if done(sim, op, &seen) {
            return;
        }
        assert!(sim.time_s() < limit, "timed out:\n{}", sim.uart_text());
    }
}

fn say(sim: &mut Sim, op: &mut Operator, line: &str, answer: &str) -> String {
    let from = sim.uart_bytes().len();
    sim.uart_send(format!("{line}\n").as_bytes());
    run_until(sim, op, |s, _, _| s.uart_text_from(from).contains(answer));
    sim.uart_text_from(from)
}

fn press(sim: &mut Sim, op: &mut Operator, hold: Duration) {
    sim.press(Button::Confirm.pin());
    run_until(sim, op, |_, _, _| true);
    let until = sim.time_s() + hold.as_secs_f64();
    run_until(sim, op, |s, _, _| s.time_s() >= until);
    sim.release(Button::Confirm.pin());
}

/// `drift check: nail 5: base at 500 steps, expected 500: …`: both counts.
fn drift_counts(text: &str) -> (i64, i64) {
    let line = text
        .lines()
        .find(|l| l.contains("drift check: nail"))
        .unwrap();
    let number = |after: &str| -> i64 {
        let rest = &line[line.find(after).unwrap() + after.len()..];
        let end = rest
            .find(|c: char| c != '-' && !c.is_ascii_digit())
            .unwrap();
        rest[..end].parse().unwrap()
    };
    (number("base at "), number("expected "))
}

#[test]
fn tools_wrap_drift_step_and_step_back_on_the_pulses() {
    let poradi = format!(
        "{},{}\n",
        PATTERN.len(),
        PATTERN.map(|n| n.to_string()).join(",")
    );
    let mut sim = machine();
    sim.insert_sd(card(&[
        (
            "param.txt",
            b"tvar = 0\npocet_hrebiku = 12\npolomer_matrice = 20.0\n",
        ),
        ("poradi.txt", poradi.as_bytes()),
        ("machine.txt", QUICK_MACHINE_TXT.as_bytes()),
    ]));
    let mut op = Operator::confirming();
    let state = |name: &str| {
        let name = name.to_string();
        move |_: &Sim, op: &Operator, _: &[Seen]| op.state.as_deref() == Some(name.as_str())
    };
    run_until(&mut sim, &mut op, state("drilling"));
    // The operator stays at the nails prompt: the tools first.
    op.confirm = false;
    run_until(&mut sim, &mut op, |s, _, _| {
        s.uart_text().contains("press green to wind")
    });

    // Wrap test on nail 3; a tool sent while it moves is refused.
    let from_ns = ns(&sim);
    let from = sim.uart_bytes().len();
    sim.uart_send(b"$wrap_test=3\n");
    sim.run_for(Duration::from_millis(100));
    sim.uart_send(b"$drift=1\n");
    run_until(&mut sim, &mut op, |s, _, _| {
        s.uart_text_from(from).contains("wrap test done")
    });
    let text = sim.uart_text_from(from);
    assert!(text.contains("tool refused: the machine moves"), "{text}");
    assert!(!text.contains("drift check: nail 1"), "{text}");
    let to_ns = ns(&sim);

    // Drift check on nail 5: the base where the nail is, then back.
    let text = say(&mut sim, &mut op, "$drift=5", "drift check done");
    let (at, expected) = drift_counts(&text);
    assert_eq!(at, expected, "{text}");
    let drift_done_ns = ns(&sim);

    // Not now: a step while not winding.
    say(
        &mut sim,
        &mut op,
        "$wrap_step=1",
        "tool refused: not in this state",
    );

    // Wind; pause after the second wrap with a long press of green.
    press(&mut sim, &mut op, Duration::from_millis(150));
    let winding_ns = ns(&sim);
    run_until(&mut sim, &mut op, |_, _, seen| {
        seen.iter()
            .any(|s| matches!(s, Seen::Progress(p, 2, _) if p == "wind"))
    });
    press(&mut sim, &mut op, Duration::from_millis(2600));
    run_until(&mut sim, &mut op, state("paused"));
    let step_ns = ns(&sim);
    let text = say(&mut sim, &mut op, "$wrap_step=1", "press green to resume");
    assert!(!text.contains("tool refused"), "{text}");
    let back_ns = ns(&sim);
    let text = say(
        &mut sim,
        &mut op,
        "$wrap_step=-1",
        "jumped: green resumes there",
    );
    assert!(!text.contains("tool refused"), "{text}");
    press(&mut sim, &mut op, Duration::from_millis(150));
    op.confirm = true;
    run_until(&mut sim, &mut op, |_, op, _| op.finished);

    let cfg = quick_string_art();
    let board = Board::new(0, NAILS, Milli(200_000)).unwrap();
    let mut job = JobReplay::from_signals(&sim.vcd_signals(), board, &cfg).unwrap();
    // The wrap test: nail 3 only, through gaps, back at the zero pose.
    job.set_winding(from_ns, to_ns);
    assert_eq!(job.wrapped_nails(), [3]);
    assert!(job.crossings_outside_gaps().is_empty());
    let at = |axis: usize, t: u64| {
        let e = job
            .events()
            .iter()
            .rev()
            .find(|e| e.axis == axis && e.at_ns <= t);
        e.map_or(0, |e| e.pos)
    };
    let (base, radial) = (|t| at(0, t), |t| at(1, t));
    let turn = i64::from(StepScale::from_config(&cfg).steps_per_turn);
    let pose = (base(to_ns).rem_euclid(turn), radial(to_ns));
    assert_eq!(pose, (0, 0), "the wrap test ends at the zero pose");
    assert_eq!(
        base(drift_done_ns),
        base(to_ns),
        "the drift check comes back"
    );

    // Winding: the step wound one wrap; the step back had it wound again.
    job.set_winding(winding_ns, step_ns);
    let before = job.wrapped_nails().len();
    job.set_winding(winding_ns, back_ns);
    let stepped = job.wrapped_nails().len();
    assert_eq!(stepped, before + 1, "one wrap per $wrap_step=1");
    job.set_winding(winding_ns, u64::MAX);
    let expected: Vec<u16> = [&PATTERN[..stepped], &PATTERN[stepped - 1..]].concat();
    assert_eq!(job.wrapped_nails(), expected);
    assert!(job.crossings_outside_gaps().is_empty());
    assert_ram_budget(&sim);
}
