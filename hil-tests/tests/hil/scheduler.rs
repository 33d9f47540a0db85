//! The scheduler under load, the watchdog, and the RAM budget.

use hil_tests::{
    assert_ram_budget, assert_step_interrupt_never_masked_long, example_elf, sim::Outcome, sim::Sim,
};
use std::time::Duration;
use taut_logic::axis::Axis;
use taut_logic::pinmap::driver;

fn send(sim: &mut Sim, line: &str) {
    hil_tests::send_ok(sim, line, Duration::from_secs(2));
}

/// Every task busy: motion at the configured maximum step rate while a
/// sender streams commands as Grbl senders do (character counting: never
/// more bytes in flight than the receive ring holds), a card goes in and
/// the job reads and checks a 3000-connection pattern, and a button is
/// pressed. Every line is answered, no queue refuses anything, the pulse
/// train keeps its timing, the masked-span bound holds.
#[test]
fn no_message_lost_and_pulses_on_time_under_load() {
    let mut sim = hil_tests::load();
    let d = driver(Axis::Base);
    sim.probe_step_dir("base", d.step, d.dir, true);
    sim.probe(d.enable, "base_en");
    assert_eq!(
        sim.run_until_uart_contains("reset:", Duration::from_millis(50)),
        Outcome::Done
    );
    let poradi: Vec<String> = std::iter::once("3000".to_string())
        .chain((0..3000).map(|i| (i * 7 % 24).to_string()))
        .collect();
    let param: &[u8] = b"tvar = 6\nnails = 24\nradius_cm = 20\n";
    sim.insert_sd(hil_tests::card(&[
        ("param.txt", param),
        ("poradi.txt", poradi.join(",").as_bytes()),
    ]));
    // Found before the motion starts (an empty slot is not probed while
    // the machine moves); read and checked while it runs.
    hil_tests::wait_for(&mut sim, "state: reading", Duration::from_millis(1500));
    send(&mut sim, "M17");
    // 2 s at the machine's 2000 steps/s after a 4 s ramp up and down.
    let cfg = taut_logic::config::MachineConfig::STRING_ART.axes[Axis::Base.index()];
    let (rate, accel) = (cfg.max_rate as f64, cfg.accel as f64);
    let steps = (rate * 2.0 + rate * rate / accel) as usize;
    send(
        &mut sim,
        &format!("G0 C{:.4}", steps as f64 * 360.0 / 9600.0),
    );
    let lines = 1000;
    let line = "M114\n";
    let window = 120; // bytes in flight: CNCjs's character-counting window
    let (mut sent, mut in_flight): (usize, Vec<usize>) = (0, Vec::new());
    let mut pressed = false;
    let oks = |s: &Sim| s.uart_text().matches("\nok\n").count();
    let base_oks = oks(&sim);
    while sent < lines || !in_flight.is_empty() {
        let answered = oks(&sim) - base_oks;
        while in_flight.len() > lines.min(sent) - answered.min(sent) {
            in_flight.remove(0);
        }
        if sent == lines / 2 && !pressed {
            pressed = true;
            // The buttons task and the job: a zeroing button (the drill's,
            // which does not move here) pressed mid-stream.
            sim.press(taut_logic::pinmap::Button::ZeroDrill.pin());
        }
        if sent < lines && in_flight.iter().sum::<usize>() + line.len() <= window {
            sim.uart_send(line.as_bytes());
            in_flight.push(line.len());
            sent += 1;
        }
        let out = sim.run_for(Duration::from_micros(500));
        assert!(
            matches!(out, Outcome::Running | Outcome::Done),
            "{out:?}\n{}",
            sim.uart_text()
        );
        assert!(
            sim.time_s() < 20.0,
            "stalled: {} of {lines} answered\n{}",
            oks(&sim) - base_oks,
            sim.uart_text()
        );
    }
    assert_eq!(oks(&sim) - base_oks, lines, "every line answered once");
    let stream_end = sim.cycles();
    sim.release(taut_logic::pinmap::Button::ZeroDrill.pin());
    // The stream ends mid-move (the move takes 6 s): M400 waits for the rest.
    hil_tests::send_ok(&mut sim, "M400", Duration::from_secs(8));
    let text = sim.uart_text();
    assert!(
        text.contains("files ok: shape 6 nails 24 radius 200000um connections 3000")
            && text.contains("drill free"),
        "the job read the card and took the press under load:\n{text}"
    );
    send(&mut sim, "$Q");
    let text = sim.uart_text();
    let queues: Vec<&str> = text.lines().filter(|l| l.contains(" sent:")).collect();
    assert_eq!(queues.len(), 11, "every queue reported: {queues:#?}");
    assert!(
        queues.iter().all(|l| l.contains("refused:0 ")),
        "nothing refused: {queues:#?}"
    );
    assert!(
        text.contains("rx sent:") && !text.contains("rx sent:0"),
        "{text}"
    );
    assert!(
        text.contains("refused:0 high")
            && !text
                .lines()
                .any(|l| l.contains("rx") && !l.contains("refused:0")),
        "{text}"
    );
    assert!(!text.contains("step late"), "{text}");

    // Pulse timing: every cruise pulse within 2 µs of the fitted grid.
    let r: Vec<u64> = sim
        .probed("base_step")
        .edges()
        .iter()
        .filter(|e| e.high)
        .map(|e| e.cycle)
        .collect();
    assert_eq!(r.len(), steps);
    assert!(
        r[r.len() - 1] > stream_end,
        "the whole stream was answered while the base moved"
    );
    let ramp = (1.05 * rate * rate / (2.0 * accel)).ceil() as usize + 16;
    let cruise = &r[ramp..r.len() - ramp];
    let n = cruise.len() as f64;
    let period = (cruise[cruise.len() - 1] - cruise[0]) as f64 / (n - 1.0);
    let worst = cruise
        .iter()
        .enumerate()
        .map(|(k, &t)| ((t - cruise[0]) as f64 - k as f64 * period).abs() / 16.0)
        .fold(0.0, f64::max);
    assert!(
        worst <= 2.0,
        "a pulse {worst:.2} µs off its grid under load"
    );
    assert_step_interrupt_never_masked_long(&sim);
    assert_ram_budget(&sim);
}

#[test]
fn a_task_that_never_returns_is_reset_by_the_watchdog() {
    let mut sim = Sim::load(&example_elf("stuck_task")).unwrap();
    let out = sim.run_until_uart_contains("endless loop", Duration::from_millis(100));
    assert_eq!(out, Outcome::Done);
    assert!(sim.uart_text().contains("stuck_task reset:power-on"));
    // Fed only from the idle path: the watchdog (≈ 0.5 s) resets the board.
    let out = sim.run_for(Duration::from_secs(1));
    assert!(
        matches!(out, Outcome::WatchdogReset { count: 1 }),
        "{out:?}"
    );
    assert!(sim.time_s() > 0.45, "reset after {} s", sim.time_s());
    assert_eq!(
        sim.run_until_uart_contains("reset:watchdog", Duration::from_millis(100)),
        Outcome::Done
    );
}

#[test]
fn idle_release_image_stays_within_the_ram_budget() {
    let mut sim = hil_tests::load();
    sim.run_for(Duration::from_secs(2));
    send(&mut sim, "$$");
    send(&mut sim, "$S");
    assert!(
        sim.uart_text().contains("[stack peak"),
        "{}",
        sim.uart_text()
    );
    assert_ram_budget(&sim);
}
