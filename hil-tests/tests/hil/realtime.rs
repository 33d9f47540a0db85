//! Stopping works at any moment — `!` brakes on the path and
//! `~` finishes at the exact target, Ctrl-X stops at once and locks motion
//! until the position is set, `?` is answered within 10 ms whatever the
//! console is doing — and nothing moves that was not asked for: soft
//! limits, a job owning the machine, settings at odds with each other.

use hil_tests::sim::sdcard::SdImage;
use hil_tests::sim::{Reply, Sim};
use hil_tests::{
    assert_ram_budget, boot_machine, log_tail, max_accel, press, reported_steps, rising,
    sample_card_dir, send_ok, settle, steps_on_pins, wait_for,
};
use std::time::Duration;
use taut_logic::axis::Axis;
use taut_logic::config::MachineConfig;
use taut_logic::pinmap::Button;

const BASE: MachineConfig = MachineConfig::STRING_ART;

fn send(sim: &mut Sim, line: &str) {
    send_ok(sim, line, Duration::from_secs(2));
}

/// The reply to `line`, which must be an error with this code.
fn refused(sim: &mut Sim, line: &str, code: u8) -> String {
    match sim.send_line(line, Duration::from_secs(2)) {
        Ok(Reply::Error(e)) if e.starts_with(&format!("error:{code} ")) => e,
        other => panic!("{line:?}: {other:?}\n{}", log_tail(sim)),
    }
}

fn enabled() -> Sim {
    let mut sim = boot_machine();
    send(&mut sim, "M17");
    sim
}

/// Send `?` and return the report and how long it took to start, ms.
fn status(sim: &mut Sim) -> (String, f64) {
    let start = sim.uart_bytes().len();
    let t0 = sim.time_s();
    sim.uart_send_at(Duration::from_secs_f64(t0), b"?");
    let mut first = None;
    let done = sim.run_until(
        |s| {
            let text = s.uart_text_from(start);
            if first.is_none() && text.contains('<') {
                first = Some(s.time_s());
            }
            text.lines().any(|l| l.starts_with('<') && l.ends_with('>')) && text.contains(">\n")
        },
        Duration::from_millis(100),
    );
    assert_eq!(done, hil_tests::sim::Outcome::Done, "{}", log_tail(sim));
    let text = sim.uart_text_from(start);
    let report = text
        .lines()
        .find(|l| l.starts_with('<'))
        .unwrap()
        .to_string();
    (report, (first.unwrap() - t0) * 1000.0)
}

fn base_pulses(sim: &Sim) -> usize {
    rising(sim, "base_step").len()
}

/// `!` during a long move brakes to a stop on the path, within the
/// acceleration, well short of the target; nothing moves while held; `~`
/// goes on and the move ends on its exact target.
#[test]
fn feed_hold_brakes_and_resume_ends_on_the_exact_target() {
    let mut sim = enabled();
    send(&mut sim, "G0 C180"); // 4800 steps: 4 s to full speed and back
    sim.run_for(Duration::from_millis(2500));
    let asked = sim.cycles();
    sim.uart_send(b"!");
    sim.run_for(Duration::from_millis(3000));
    let (report, ms) = status(&mut sim);
    assert!(report.starts_with("<Hold:0|"), "{report}");
    assert!(ms <= 10.0, "status after {ms} ms");
    // Braking begins once the motion already queued (≤ 90 ms) has run:
    // the fastest step comes within 100 ms of the `!`, and from there the
    // machine stops in v²/2a steps.
    let r = rising(&sim, "base_step");
    let (peak, fastest) = r
        .windows(2)
        .enumerate()
        .filter(|(_, w)| w[0] > asked)
        .map(|(k, w)| (k, w[1] - w[0]))
        .min_by_key(|&(_, iv)| iv)
        .unwrap();
    let after_ms = (r[peak] - asked) as f64 / 16e3;
    assert!(
        after_ms <= 100.0,
        "braking began {after_ms:.1} ms after `!`"
    );
    let v = 16e6 / fastest as f64;
    let braking = v * v / (2.0 * BASE.axes[0].accel as f64);
    let held = r.len();
    assert!(
        (held - peak) as f64 <= braking * 1.02 + 2.0,
        "{} steps to stop from {v:.0} steps/s, at most {braking:.0}",
        held - peak
    );
    assert!(held < 4800, "held short of the target");
    sim.run_for(Duration::from_secs(1));
    assert_eq!(base_pulses(&sim), held, "nothing moves while held");
    sim.uart_send(b"~");
    send_ok(&mut sim, "M400", Duration::from_secs(20));
    assert_eq!(steps_on_pins(&sim), [4800, 0, 0]);
    assert_eq!(reported_steps(&mut sim), [4800, 0, 0]);
    let a = max_accel(&rising(&sim, "base_step"), 64);
    assert!(
        a <= BASE.axes[0].accel as f64 * 1.05,
        "braking and restarting within the acceleration: {a:.0} steps/s²"
    );
    assert!(!sim.uart_text().contains("underruns"), "{}", log_tail(&sim));
    assert_ram_budget(&sim);
}

/// Ctrl-X mid-move: the pulses stop at once, the position is what they
/// made (`M114`), and G-code waits for `$X` (Grbl's lock, error 9);
/// drivers stay on.
#[test]
fn ctrl_x_stops_at_once_and_locks_motion_until_the_position_is_set() {
    let mut sim = enabled();
    send(&mut sim, "G0 C180");
    sim.run_for(Duration::from_millis(3000));
    sim.uart_send(b"\x18");
    let sent = sim.time_s();
    sim.run_for(Duration::from_millis(500));
    let rises = rising(&sim, "base_step");
    let last = *rises.last().unwrap() as f64 / 16e6;
    // The byte itself takes 87 µs on the wire.
    assert!(
        last - sent < 0.000_2,
        "last pulse {:.3} ms after Ctrl-X was sent",
        (last - sent) * 1000.0
    );
    let stopped = steps_on_pins(&sim);
    assert!(stopped[0] > 0 && stopped[0] < 4800);
    assert_eq!(reported_steps(&mut sim), stopped);
    assert!(status(&mut sim).0.starts_with("<Alarm|"));
    assert!(sim.uart_text().contains("position unknown"));
    refused(&mut sim, "G0 C10", 9);
    assert!(sim.pin_level(taut_logic::pinmap::driver(Axis::Base).enable));
    send(&mut sim, "$X");
    assert!(status(&mut sim).0.starts_with("<Idle|"));
    send(&mut sim, "G91 G0 C-1");
    send(&mut sim, "M400");
    assert_eq!(steps_on_pins(&sim)[0], stopped[0] - 27, "1° = 26.67 steps");
    // A reset with the machine standing keeps the position known.
    sim.uart_send(b"\x18");
    sim.run_for(Duration::from_millis(50));
    assert!(status(&mut sim).0.starts_with("<Idle|"));
    assert_ram_budget(&sim);
}

/// `?` is answered within 10 ms while the console waits: behind a full
/// planner, and during a dwell.
#[test]
fn status_within_10_ms_behind_a_full_planner_and_during_a_dwell() {
    let mut sim = enabled();
    send(&mut sim, "G91");
    // The planner's moves fill it; the next line waits for room. Sent as a
    // sender with flow control does: never more than the receive
    // ring holds unread.
    let lines = taut_logic::planner::PLANNER_BLOCKS + 1;
    for batch in [lines / 2, lines - lines / 2] {
        for _ in 0..batch {
            sim.uart_send(b"G0 C5\n");
        }
        sim.run_for(Duration::from_millis(250));
    }
    for _ in 0..5 {
        let (report, ms) = status(&mut sim);
        assert!(report.starts_with("<Run|"), "{report}");
        assert!(ms <= 10.0, "status after {ms:.2} ms behind a full planner");
        sim.run_for(Duration::from_millis(137));
    }
    send_ok(&mut sim, "M400", Duration::from_secs(30));
    sim.uart_send(b"G4 P2\n");
    sim.run_for(Duration::from_millis(300));
    let (report, ms) = status(&mut sim);
    assert!(
        report.starts_with("<Idle|") && ms <= 10.0,
        "{report} after {ms} ms"
    );
}

/// Soft limits: a target outside an axis's travel is refused before any
/// step; the base turns freely; a feed below 10/min is refused.
#[test]
fn soft_limits_and_slow_feeds_are_refused_with_zero_steps() {
    let mut sim = enabled();
    refused(&mut sim, "G0 X100", 15);
    refused(&mut sim, "G0 X-451", 15);
    refused(&mut sim, "G0 Z-31", 15);
    refused(&mut sim, "G0 X2147483.647", 15);
    refused(&mut sim, "G1 X1 F5", 72);
    // Grbl's: F0 is no feed rate.
    refused(&mut sim, "G1 X1 F0", 22);
    sim.run_for(Duration::from_millis(500));
    assert_eq!(steps_on_pins(&sim), [0, 0, 0], "nothing moved");
    // Limits are machine coordinates: a G92 offset never moves them.
    send(&mut sim, "G92 X-440");
    refused(&mut sim, "G0 X29", 15);
    send(&mut sim, "G0 X-411");
    send(&mut sim, "G0 C720");
    send_ok(&mut sim, "M400", Duration::from_secs(60));
    assert_eq!(steps_on_pins(&sim), [19200, 29 * 32, 0]);
}

/// The sample job's card in, green pressed: drilling.
fn drilling() -> Sim {
    let mut sim = boot_machine();
    sim.insert_sd(SdImage::from_path(&sample_card_dir()).unwrap());
    wait_for(&mut sim, "press green to drill", Duration::from_secs(3));
    press(&mut sim, Button::Confirm, 150);
    wait_for(&mut sim, "state: drilling", Duration::from_secs(1));
    sim
}

/// While the job drills (and while it is paused) the console refuses
/// motion, drivers and settings, and still answers reads and `?`.
#[test]
fn the_console_cannot_move_the_machine_during_a_job() {
    let mut sim = drilling();
    sim.run_for(Duration::from_millis(1500));
    for line in [
        "G0 C10",
        "G91 G1 X1 F100",
        "M18",
        "M17",
        "G92 C0",
        "$base_max_rate=100",
    ] {
        refused(&mut sim, line, 71);
    }
    send(&mut sim, "M114");
    assert!(status(&mut sim).0.starts_with("<Run|"));
    // Paused inside the job: still the job's.
    press(&mut sim, Button::Confirm, 2200);
    wait_for(&mut sim, ">>> paused", Duration::from_secs(30));
    // The hole in progress is finished first.
    settle(&mut sim);
    let paused = steps_on_pins(&sim);
    refused(&mut sim, "G0 C10", 71);
    sim.run_for(Duration::from_secs(2));
    assert_eq!(steps_on_pins(&sim), paused, "zero steps from the console");
    assert_ram_budget(&sim);
}

/// `!` while drilling holds the machine where it is (drill and all), `~`
/// goes on; Ctrl-X ends the job with the drivers holding.
#[test]
fn hold_and_ctrl_x_during_a_job() {
    let mut sim = drilling();
    wait_for(&mut sim, "drill 1/24", Duration::from_secs(30));
    sim.run_for(Duration::from_millis(700));
    sim.uart_send(b"!");
    sim.run_for(Duration::from_secs(3));
    let held = steps_on_pins(&sim);
    sim.run_for(Duration::from_secs(2));
    assert_eq!(steps_on_pins(&sim), held, "held");
    assert!(status(&mut sim).0.starts_with("<Hold:0|"));
    sim.uart_send(b"~");
    wait_for(&mut sim, "drill 2/24", Duration::from_secs(30));
    sim.uart_send(b"\x18");
    wait_for(
        &mut sim,
        "job stopped by Ctrl-X",
        Duration::from_millis(100),
    );
    wait_for(&mut sim, "state: end", Duration::from_millis(100));
    let stopped = steps_on_pins(&sim);
    sim.run_for(Duration::from_secs(3));
    assert_eq!(steps_on_pins(&sim), stopped, "nothing moves after Ctrl-X");
    for axis in [Axis::Base, Axis::Radial, Axis::Drill] {
        let d = taut_logic::pinmap::driver(axis);
        assert!(sim.pin_level(d.enable), "{axis:?} driver holds");
    }
    // The job is over: the console may move the machine again (`$X` first
    // when Ctrl-X stopped it moving).
    send(&mut sim, "$X");
    send(&mut sim, "G0 C0");
    assert_ram_budget(&sim);
}

/// Settings at odds with each other are refused with the reason, and a
/// reply longer than the TX ring's share is never cut.
#[test]
fn refused_settings_say_why_and_long_replies_are_whole() {
    let mut sim = boot_machine();
    let e = refused(&mut sim, "$step_pulse_us=255", 3);
    assert!(
        e.contains("pulse over half a step at base_max_rate: 250 us at most"),
        "{e}"
    );
    let e = refused(&mut sim, "$x=-5", 3);
    assert!(e.contains("unknown key"), "{e}");
    let e = refused(&mut sim, "$base_max_rate=0", 3);
    assert!(e.contains("expected 1 to 200000"), "{e}");
    let e = refused(&mut sim, "$radial_travel_min=50", 3);
    assert!(e.contains("travel_min above travel_max"), "{e}");
    send(&mut sim, "$step_pulse_us=200");
    send(&mut sim, "$step_pulse_us=5");
    // Offsets far out, each line of `$#` whole.
    send(&mut sim, "G10 L2 P1 C-999999 X-999999 Z-999999");
    // G92 = MPos - WCS - WPos.
    send(&mut sim, "G92 C1 X1 Z1");
    let start = sim.uart_bytes().len();
    send(&mut sim, "$#");
    let text = sim.uart_text_from(start);
    assert!(
        text.starts_with("[G54:-999999.000,-999999.000,-999999.000]\n"),
        "{text:?}"
    );
    assert!(
        text.contains("\n[G92:999998.000,999998.000,999998.000]\n"),
        "{text:?}"
    );
}

/// Hold and resume at seeded random moments of a stream of moves: every
/// step of every move is made, no more.
#[test]
fn holds_at_random_moments_of_a_stream_lose_no_step() {
    let mut sim = enabled();
    let mut seed = 0x2545_F491_4F6C_DD1Du64;
    let mut next = |n: u64| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed % n
    };
    let mut c = 0i64;
    send(&mut sim, "G90");
    for k in 0..60 {
        c += next(40) as i64 - 15;
        let oks = |s: &Sim| {
            s.uart_text()
                .split_inclusive('\n')
                .filter(|l| *l == "ok\n")
                .count()
        };
        let before = oks(&sim);
        sim.uart_send(format!("G1 C{c} X{} F{}\n", -(k % 7) as i64, 300 + next(4000)).as_bytes());
        // Wait for the `ok`, with a hold now and then at a random moment.
        if next(4) == 0 {
            sim.run_for(Duration::from_millis(next(300)));
            sim.uart_send(b"!");
            sim.run_for(Duration::from_millis(50 + next(800)));
            sim.uart_send(b"~");
        }
        let out = sim.run_until(|s| oks(s) > before, Duration::from_secs(30));
        assert_eq!(out, hil_tests::sim::Outcome::Done, "{}", log_tail(&sim));
    }
    send_ok(&mut sim, "M400", Duration::from_secs(120));
    let spu = BASE.axes[0].steps_per_unit;
    let c_steps = spu.steps(taut_logic::units::Milli(c as i32 * 1000)) as i64;
    let x_steps = -(59 % 7) * 32;
    assert_eq!(steps_on_pins(&sim), [c_steps, x_steps, 0]);
    assert_eq!(reported_steps(&mut sim), [c_steps, x_steps, 0]);
    assert!(!sim.uart_text().contains("error"), "{}", log_tail(&sim));
}
