//! One image, five machines. Each plotter and the arm is chosen
//! with `$machine=`, draws over the serial port, and its drawing is rebuilt
//! from the step, direction and pen pulses alone through its own forward
//! kinematics, point by point against the toolpath the G-code defines:
//! drawn while the pen PWM is at the down angle, travel while it is up.

use hil_tests::drawing::{assert_drawn_from_the_pulses, drawing, home, PenWords};
use hil_tests::sim::Sim;
use hil_tests::{assert_ram_budget, boot_machine, log_tail, send_ok, track};
use std::time::Duration;
use taut_logic::machine::Machine;

fn send(sim: &mut Sim, line: &str) {
    send_ok(sim, line, Duration::from_secs(60));
}

/// Draws on `machine` over the serial line and checks every pulse against
/// the toolpath, within `within` mm.
fn drawn_from_the_pulses(machine: Machine, pen: PenWords, at: [f64; 2], within: f64) {
    let mut sim = boot_machine();
    send(&mut sim, &format!("$machine={}", machine.name()));
    send(&mut sim, "M17");
    let d = drawing(pen, home(machine), at[0], at[1]);
    for line in &d.lines {
        send(&mut sim, line);
    }
    assert_drawn_from_the_pulses(&sim, machine, &d, within);
}

#[test]
fn the_drum_plotter_draws_its_toolpath() {
    // Its 28BYJ-48s half-stepped through their coils (x_in*, y_in*): Y
    // 14.5 half-steps a mm of paper (0.07 mm each).
    drawn_from_the_pulses(Machine::Drum, PenWords::Spindle, [5.0, 5.0], 0.1);
}

#[test]
fn the_flatbed_plotter_draws_its_toolpath() {
    // 0.025 mm a step: a step of each axis off, or the chord tolerance.
    drawn_from_the_pulses(Machine::Flatbed, PenWords::Z, [5.0, 5.0], 0.046);
}

#[test]
fn the_whiteboard_machine_draws_its_toolpath() {
    // 17.5 steps per mm of chain: a step of both moves the pen ~0.08 mm.
    drawn_from_the_pulses(Machine::Whiteboard, PenWords::Unicorn, [-10.0, -10.0], 0.1);
}

#[test]
fn the_scara_arm_draws_its_toolpath() {
    // 26.7 steps a degree: at 300 mm from the shoulder (the arm straight,
    // where it starts) a shoulder step is 0.2 mm, an elbow step 0.1 mm.
    drawn_from_the_pulses(Machine::Scara, PenWords::Spindle, [90.0, 140.0], 0.3);
}

/// `M0` holds once the motion before it is done, until the green button or
/// `~`; `M1` is ignored (no optional-stop switch, as Grbl); `G20` takes
/// inches, converted once.
#[test]
fn a_plotter_pauses_at_m0_and_takes_inches() {
    use hil_tests::{press, steps_on_pins};
    use taut_logic::pinmap::Button;
    let mut sim = boot_machine();
    send(&mut sim, "$machine=flatbed");
    send(&mut sim, "M17");
    // Sent ahead, as a streaming sender does.
    sim.uart_send(b"G0 X10\nM0\nG0 X20\nM1\nG20 G0 X1\n");
    let status = |sim: &mut Sim| {
        let start = sim.uart_bytes().len();
        sim.uart_send(b"?");
        sim.run_for(Duration::from_millis(20));
        sim.uart_text_from(start)
    };
    sim.run_for(Duration::from_secs(2));
    assert!(status(&mut sim).contains("<Hold:0|"), "{}", log_tail(&sim));
    assert_eq!(steps_on_pins(&sim)[0], 400, "stopped at X10 (40 steps/mm)");
    press(&mut sim, Button::Confirm, 100);
    sim.run_for(Duration::from_secs(3));
    // 1 in = 25.4 mm = 1016 steps: M1 did not stop it at X20.
    assert_eq!(
        steps_on_pins(&sim)[0],
        1016,
        "the green button went on, past M1"
    );
    assert!(status(&mut sim).contains("<Idle|"));
}

/// The flatbed homes X against its MIN switch (X_MIN, D3) at power-on and
/// on `$H`: seek, pull off, locate slowly, pull off 1 mm, and X is then
/// 1.000 (`G28` goes to the stored G28 position, not home). The harness closes the switch 3 mm (120 steps) below where X
/// stood at power-on.
#[test]
fn the_flatbed_homes_x_against_its_switch_at_power_on_and_on_dollar_h() {
    use hil_tests::{machine, steps_on_pins, wait_for};
    use taut_logic::axis::Axis;
    use taut_logic::pinmap::{driver, Button};
    let eeprom = {
        let mut sim = boot_machine();
        send(&mut sim, "$machine=flatbed");
        sim.run_for(Duration::from_secs(2));
        sim.eeprom()
    };
    let mut sim = machine();
    sim.set_eeprom(&eeprom);
    let x = driver(Axis::Base);
    sim.endstop(Button::ZeroBase.pin(), x.step, x.dir, true, -120);
    wait_for(&mut sim, "homing", Duration::from_secs(1));
    sim.uart_send(b"?");
    wait_for(&mut sim, "<Home|", Duration::from_millis(50));
    wait_for(&mut sim, "homed", Duration::from_secs(20));
    // Pulled off the switch by 1 mm: 40 steps above it, and that is X1.000.
    assert_eq!(steps_on_pins(&sim)[0], -80, "{}", log_tail(&sim));
    assert_eq!(hil_tests::reported_steps(&mut sim)[0], 40);
    send(&mut sim, "M17");
    send(&mut sim, "G0 X10");
    send(&mut sim, "M400");
    assert_eq!(steps_on_pins(&sim)[0], -120 + 400);
    // A soft-limit violation is refused before any step.
    let before = steps_on_pins(&sim);
    match sim.send_line("G0 X150", Duration::from_secs(2)) {
        Ok(hil_tests::sim::Reply::Error(e)) => assert!(e.starts_with("error:15 "), "{e}"),
        other => panic!("{other:?}"),
    }
    sim.run_for(Duration::from_millis(300));
    assert_eq!(steps_on_pins(&sim), before);
    send(&mut sim, "$H");
    assert_eq!(steps_on_pins(&sim)[0], -80);
    assert_ram_budget(&sim);
}

/// Without its switch, homing fails with Grbl's alarm 9 ("could not find
/// limit switch"), the line answered `ok` as Grbl's, and G-code waits for
/// `$H` or `$X` (Grbl's lock, error 9); a machine with no homing axes answers Grbl's
/// error 5 (setting disabled).
#[test]
fn homing_without_a_switch_fails_and_locks_motion() {
    let mut sim = boot_machine();
    match sim.send_line("$H", Duration::from_secs(2)) {
        Ok(hil_tests::sim::Reply::Error(e)) => assert!(e.starts_with("error:5 "), "{e}"),
        other => panic!("{other:?}"),
    }
    send(&mut sim, "$machine=flatbed");
    send(&mut sim, "$homing_seek=4000");
    let from = sim.uart_bytes().len();
    send_ok(&mut sim, "$H", Duration::from_secs(20));
    let text = sim.uart_text_from(from);
    assert!(text.ends_with("ALARM:9\nok\n"), "{text}");
    match sim.send_line("G0 X1", Duration::from_secs(2)) {
        Ok(hil_tests::sim::Reply::Error(e)) => assert!(e.starts_with("error:9 "), "{e}"),
        other => panic!("{other:?}"),
    }
}

/// What plotter tools emit that taut does not do (`M117` messages, tool
/// changes) is answered with an error, moves nothing, and the stream goes
/// on; a tool number alone (`T1`) is kept, as Grbl keeps it.
#[test]
fn unknown_but_harmless_codes_are_refused_and_the_stream_goes_on() {
    use hil_tests::steps_on_pins;
    let mut sim = boot_machine();
    send(&mut sim, "$machine=drum");
    send(&mut sim, "M17");
    for (line, code) in [
        ("M117 Drawing...", "error:20 "),
        ("M6", "error:20 "),
        ("M106 S255", "error:20 "),
    ] {
        match sim.send_line(line, Duration::from_secs(2)) {
            Ok(hil_tests::sim::Reply::Error(e)) => assert!(e.starts_with(code), "{line}: {e}"),
            other => panic!("{line}: {other:?}"),
        }
    }
    sim.run_for(Duration::from_millis(200));
    // The drum's motors step through their coils (x_in*, y_in*).
    let coils = |sim: &Sim| [0, 1].map(|axis| sim.coil_track(axis).position());
    assert_eq!(steps_on_pins(&sim), [0, 0, 0], "nothing moved");
    assert_eq!(coils(&sim), [0, 0], "nothing moved");
    send(&mut sim, "G0 X1");
    send(&mut sim, "M400");
    // 4096 half-steps per 40 mm of belt: 1 mm is 102.4, rounded once.
    assert_eq!(coils(&sim), [102, 0]);
}

/// A flatbed (not homing: no switch here), drivers on, standing at
/// `(x, y)` mm.
fn flatbed_at(x: f64, y: f64) -> Sim {
    let mut sim = boot_machine();
    send(&mut sim, "$machine=flatbed");
    send(&mut sim, "$homing_at_start=0");
    send(&mut sim, "M17");
    send(&mut sim, &format!("G0 X{x} Y{y}"));
    send(&mut sim, "M400");
    sim
}

/// A 1 mm-radius circle asked at the flatbed's full speed (50 mm/s, 12
/// chords a turn) streams without starving the step queue: a chord is cut
/// and planned only while the queue holds enough motion (the corners
/// between chords slow the pen to about 10 mm/s, the junction deviation's
/// physics, as in Grbl).
#[test]
fn a_full_speed_1_mm_circle_never_starves_the_step_queue() {
    let mut sim = flatbed_at(11.0, 10.0);
    let from = track(&sim).len();
    for _ in 0..5 {
        send(&mut sim, "G2 X11 Y10 I-1 J0 F3000");
    }
    send(&mut sim, "M400");
    let path = &track(&sim)[from..];
    let end = path.last().unwrap().1;
    assert_eq!([end[0], end[1]], [440, 400], "back where it began");
    assert!(path.len() > 5 * 200, "five turns of 251 steps");
    // 31.4 mm: about 10 mm/s along the circle, its corners the limit.
    let seconds = (path.last().unwrap().0 - path[0].0) as f64 / 16e6;
    assert!(seconds < 4.0, "five turns took {seconds:.2} s");
    // The logger reports step-queue underruns once a second.
    sim.run_for(Duration::from_millis(1500));
    assert!(!sim.uart_text().contains("underruns"), "{}", log_tail(&sim));
}

/// Seed 001's test patterns run on any plotter, answered once: `$T7`'s
/// lines reach their eight tips (a sign or octant slip would miss one),
/// and each pattern ends where it began.
#[test]
fn seed_001_test_patterns_draw_and_end_where_they_began() {
    let mut sim = flatbed_at(40.0, 40.0);
    let from = track(&sim).len();
    let start = sim.uart_bytes().len();
    send(&mut sim, "$T7");
    send(&mut sim, "M400");
    let replies = sim.uart_text_from(start).matches("ok\n").count();
    assert_eq!(replies, 2, "one ok for the pattern, one for M400");
    let path = &track(&sim)[from..];
    let at = |x: f64, y: f64| [(x * 40.0).round() as i64, (y * 40.0).round() as i64];
    for (dx, dy) in [
        (20.0, 8.0),
        (8.0, 20.0),
        (-8.0, 20.0),
        (-20.0, 8.0),
        (-20.0, -8.0),
        (-8.0, -20.0),
        (8.0, -20.0),
        (20.0, -8.0),
    ] {
        let tip = at(40.0 + dx, 40.0 + dy);
        assert!(
            path.iter().any(|(_, s)| [s[0], s[1]] == tip),
            "never at the tip {dx},{dy}"
        );
    }
    assert_eq!(
        [path.last().unwrap().1[0], path.last().unwrap().1[1]],
        at(40.0, 40.0)
    );
    for t in ["$T5", "$T6"] {
        send(&mut sim, t);
    }
    send(&mut sim, "M400");
    send(&mut sim, "$T1");
    send(&mut sim, "M400");
    assert_eq!(hil_tests::steps_on_pins(&sim)[..2], [0, 0], "$T1: over 0,0");
}

/// `taut-sim --png` pictures a plotter in its own coordinates: the flatbed
/// homes X against its switch at power-on (3 mm below where it stood),
/// and the drawing is where the G-code put it, not 3 mm off.
#[test]
fn the_picture_counts_from_the_homed_zero_not_from_power_on() {
    use hil_tests::sim::picture::render_plot;
    use hil_tests::wait_for;
    use taut_logic::config::MachineConfig;
    use taut_logic::pinmap::Button;
    use taut_logic::settings::eeprom::host;
    let cfg = MachineConfig::defaults(Machine::Flatbed);
    let mut sim = hil_tests::load();
    sim.set_eeprom(&host::eeprom(
        &cfg,
        &Default::default(),
        &Default::default(),
    ));
    sim.probe_machine(Machine::Flatbed);
    for b in Button::ALL {
        sim.release(b.pin());
    }
    let endstops = sim.fit_machine_endstops(&cfg, 3.0);
    wait_for(&mut sim, "homed", Duration::from_secs(20));
    for line in [
        "M17",
        "M5",
        "G0 X10 Y10",
        "M3",
        "G1 X30 Y10 F1200",
        "G1 X30 Y20",
        "M5",
        "M400",
    ] {
        send(&mut sim, line);
    }
    let png = std::env::temp_dir().join(format!("taut-hil-origin-{}.png", std::process::id()));
    let origin = endstops.power_on_origin(&sim, &cfg);
    let plot = render_plot(&sim.vcd_signals(), &cfg, origin, &png).unwrap();
    std::fs::remove_file(&png).unwrap();
    let near = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs() < 0.03 && (a[1] - b[1]).abs() < 0.03;
    assert!(
        near(plot.min, [10.0, 10.0]) && near(plot.max, [30.0, 20.0]),
        "drawn over {:?}..{:?}, origin {origin:?}",
        plot.min,
        plot.max
    );
    assert_eq!(
        origin[0],
        -(-120),
        "X stood 3 mm (120 steps) above its switch"
    );
}
