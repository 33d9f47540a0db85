//! Grbl 1.1 on the wire, in the formats its interface document
//! gives (the lines quoted there are checked byte for byte): the banner at
//! power-on and after Ctrl-X, `$I`, `$G`, `$#` and the status report's
//! buffer state, which senders size their streams by.

use hil_tests::sim::Sim;
use hil_tests::{boot_machine, log_tail, rising, send_ok, wait_for};
use std::time::Duration;
use taut_logic::planner::PLANNER_BLOCKS as BLOCKS;

fn send(sim: &mut Sim, line: &str) -> String {
    let from = sim.uart_bytes().len();
    send_ok(sim, line, Duration::from_secs(2));
    sim.uart_text_from(from)
}

/// What the firmware sends in the `ms` after `bytes` (real-time bytes,
/// not lines: nothing waits for an `ok`).
fn bytes_then(sim: &mut Sim, bytes: &[u8], ms: u64) -> String {
    let from = sim.uart_bytes().len();
    sim.uart_send(bytes);
    sim.run_for(Duration::from_millis(ms));
    sim.uart_text_from(from)
}

/// The reply lines of a command, its `ok` included: no log lines, nor the
/// end of one under way when the command was sent.
fn replies(text: &str) -> Vec<&str> {
    text.lines()
        .filter(|l| (l.starts_with('[') && !hil_tests::is_log_line(l)) || *l == "ok")
        .collect()
}

#[test]
fn banner_build_info_parser_state_offsets_and_status_in_grbl_formats() {
    let mut sim = boot_machine();
    wait_for(
        &mut sim,
        "Grbl 1.1h ['$' for help]\n",
        Duration::from_millis(50),
    );
    let version = env!("CARGO_PKG_VERSION");
    assert_eq!(
        replies(&send(&mut sim, "$I")),
        [
            format!("[VER:1.1h.taut-{version}:string_art]").as_str(),
            format!("[OPT:,{BLOCKS},128]").as_str(),
            "ok"
        ]
    );
    // Quoted from Grbl's interface document: the power-on state.
    assert_eq!(
        replies(&send(&mut sim, "$G")),
        ["[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]", "ok"]
    );
    send(&mut sim, "G91 G18 G1 F600");
    assert_eq!(
        replies(&send(&mut sim, "$G")),
        ["[GC:G1 G54 G18 G21 G91 G94 M5 M9 T0 F600 S0]", "ok"]
    );
    // taut keeps no work offsets: every one zero, in Grbl's format.
    let offsets = send(&mut sim, "$#");
    let expected = [
        "[G54:0.000,0.000,0.000]",
        "[G55:0.000,0.000,0.000]",
        "[G56:0.000,0.000,0.000]",
        "[G57:0.000,0.000,0.000]",
        "[G58:0.000,0.000,0.000]",
        "[G59:0.000,0.000,0.000]",
        "[G28:0.000,0.000,0.000]",
        "[G30:0.000,0.000,0.000]",
        "[G92:0.000,0.000,0.000]",
        "[TLO:0.000]",
        "[PRB:0.000,0.000,0.000:0]",
        "ok",
    ];
    assert_eq!(replies(&offsets), expected);
    // bCNC's greeting: two empty lines, two `ok`.
    assert_eq!(replies(&bytes_then(&mut sim, b"\n\n", 20)), ["ok", "ok"]);
    // The buffer state (every planner block and receive byte free), the
    // feed, and the work offset in the first report.
    let report = bytes_then(&mut sim, b"?", 20);
    assert_eq!(
        report,
        format!("<Idle|MPos:0.000,0.000,0.000|Bf:{BLOCKS},128|FS:0,0|WCO:0.000,0.000,0.000>\n"),
        "{}",
        log_tail(&sim)
    );
    // Ctrl-X: the banner again, as after a power-on.
    let after = bytes_then(&mut sim, &[0x18], 20);
    assert!(after.contains("Grbl 1.1h ['$' for help]\n"), "{after}");
}

/// Ctrl-X during motion: Grbl's alarm 3 (reset while in motion), the
/// greeting, and how to unlock; `?` says `Alarm` until `$X`, which
/// answers Grbl's caution.
#[test]
fn a_reset_in_motion_is_grbl_s_alarm_3_and_x_unlocks_it() {
    let mut sim = boot_machine();
    send(&mut sim, "M17");
    sim.uart_send(b"G0 C90\n");
    sim.run_for(Duration::from_millis(300));
    let after = bytes_then(&mut sim, &[0x18], 30);
    let lines: Vec<&str> = after.lines().collect();
    assert_eq!(
        lines[..2],
        ["ALARM:3", "Grbl 1.1h ['$' for help]"],
        "{after}"
    );
    assert_eq!(lines[2], "[MSG:'$H'|'$X' to unlock]", "{after}");
    assert!(bytes_then(&mut sim, b"?", 20).starts_with("<Alarm|"));
    assert_eq!(
        replies(&send(&mut sim, "$X")),
        ["[MSG:Caution: Unlocked]", "ok"]
    );
}

/// Grbl 1.1's extended real-time bytes (CNCjs and UGS send overrides and
/// jog cancels): taken out of the stream wherever they fall, so the line
/// around them stays whole; the safety door holds as `!` does.
#[test]
fn override_and_door_bytes_never_spoil_a_line() {
    let mut sim = boot_machine();
    send(&mut sim, "M17");
    sim.uart_send(b"G0 \x90C\x91\x9a9\x85\xa0\n");
    sim.run_for(Duration::from_millis(100));
    assert!(sim.uart_text().ends_with("ok\n"), "{}", log_tail(&sim));
    send(&mut sim, "M400");
    // 9° of the base at 9600 steps a turn.
    assert_eq!(hil_tests::steps_on_pins(&sim)[0], 240);
    send(&mut sim, "G0 C0");
    sim.run_for(Duration::from_millis(200));
    sim.uart_send(&[0x84]);
    sim.run_for(Duration::from_millis(1500));
    let report = bytes_then(&mut sim, b"?", 20);
    assert!(report.starts_with("<Door:0|"), "{report}");
    sim.uart_send(b"~");
    send(&mut sim, "M400");
    assert_eq!(hil_tests::steps_on_pins(&sim)[0], 0);
}

/// `$$` as Grbl 1.1 lists it (`$0=10` … `$132=200.000`: whole numbers for
/// switches and masks, three decimals for the rest), then taut's named
/// settings; `$110=` writes Grbl's units into the named setting behind it
/// (the string-art machine's X place is its radial carriage), and a value
/// taut cannot take is refused with Grbl's error 3 and the reason.
#[test]
fn numbered_settings_list_and_write_through_to_the_named_ones() {
    let mut sim = boot_machine();
    let listing = replies_all(&send(&mut sim, "$$"));
    assert_eq!(
        listing[..5],
        ["$0=5", "$1=255", "$2=0", "$3=0", "$4=1"],
        "{listing:?}"
    );
    for line in [
        "$11=0.010",
        "$100=32.000",
        "$110=3750.000",
        "$132=42.000",
        "$machine=string_art",
    ] {
        assert!(listing.contains(&line.to_string()), "{line} in {listing:?}");
    }
    assert_eq!(listing.last().map(String::as_str), Some("ok"));
    // 1875 mm/min at 32 steps/mm: 1000 steps/s.
    send(&mut sim, "$110=1875");
    let listing = replies_all(&send(&mut sim, "$$"));
    assert!(
        listing.contains(&"$110=1875.000".to_string()),
        "{listing:?}"
    );
    assert!(
        listing.contains(&"$radial_max_rate=1000".to_string()),
        "{listing:?}"
    );
    let from = sim.uart_bytes().len();
    match sim.send_line("$3=8", Duration::from_secs(2)) {
        Ok(hil_tests::sim::Reply::Error(e)) => {
            assert_eq!(e, "error:3 Invalid statement: expected 0 to 7 (col 4)")
        }
        other => panic!("{other:?}\n{}", log_tail(&sim)),
    }
    // On the wire as Grbl's: the code alone on its line (senders parse
    // what follows `error:` as the number), the words in a message before.
    assert_eq!(
        sim.uart_text_from(from),
        "[MSG:Invalid statement: expected 0 to 7 (col 4)]\nerror:3\n"
    );
}

/// The setting lines of a reply and its `ok`.
fn replies_all(text: &str) -> Vec<String> {
    text.lines()
        .filter(|l| l.starts_with('$') || *l == "ok")
        .map(str::to_string)
        .collect()
}

/// The report after `bytes` (ending in `?`), whole.
fn report_after(sim: &mut Sim, bytes: &[u8]) -> String {
    let from = sim.uart_bytes().len();
    sim.uart_send(bytes);
    let report = |s: &Sim| {
        let text = s.uart_text_from(from);
        text.split_inclusive('\n')
            .find(|l| l.starts_with('<') && l.ends_with(">\n"))
            .map(|l| l.trim_end().to_string())
    };
    let done = sim.run_until(|s| report(s).is_some(), Duration::from_millis(50));
    assert_eq!(done, hil_tests::sim::Outcome::Done, "{}", log_tail(sim));
    report(sim).unwrap()
}

/// The report after a `?`.
fn status(sim: &mut Sim) -> String {
    report_after(sim, b"?")
}

/// Interface.md: the work offset and the overrides "every so often" in
/// their own reports, `$10` choosing the position and the buffer state,
/// `$13` inches. The string-art words in Grbl's places: `X` (the radial
/// carriage) first, the base `C` (degrees, never inches) in Y's place,
/// `Z` third.
#[test]
fn status_fields_follow_dollar_10_and_13_and_the_words_take_grbl_s_places() {
    let mut sim = boot_machine();
    assert!(status(&mut sim).ends_with("|WCO:0.000,0.000,0.000>"));
    assert!(status(&mut sim).ends_with("|FS:0,0|Ov:100,100,100>"));
    send(&mut sim, "M17");
    send(&mut sim, "G0 X-25 C90 Z-1.2");
    send_ok(&mut sim, "M400", Duration::from_secs(30));
    let r = status(&mut sim);
    assert!(
        r.starts_with(&format!(
            "<Idle|MPos:-25.000,90.000,-1.200|Bf:{BLOCKS},128|FS:0,0"
        )),
        "{r}"
    );
    send(&mut sim, "$10=0");
    assert!(status(&mut sim).starts_with("<Idle|WPos:-25.000,90.000,-1.200|FS:0,0"));
    send(&mut sim, "$10=1");
    send(&mut sim, "$13=1");
    let r = status(&mut sim);
    assert!(
        r.starts_with("<Idle|MPos:-0.9843,90.000,-0.0472|FS:0.0,0"),
        "{r}"
    );
    send(&mut sim, "$13=0");
    // While it moves: `Run` and the feed along the path, mm/min.
    send(&mut sim, "G1 X-100 F600");
    sim.run_for(Duration::from_secs(2));
    let r = status(&mut sim);
    assert!(r.starts_with("<Run|MPos:-"), "{r}");
    assert!(r.contains("|FS:600,0"), "{r}");
}

/// Real-time bytes 0x91–0x94 step the feed override, 0x90 resets it,
/// 0x95–0x97 set the rapids': the moves queued and not yet begun run at
/// the new speed, the report says `Ov:` at once; a reset goes back to
/// 100 %. Measured on the pulses of the radial carriage (32 steps/mm).
#[test]
fn feed_and_rapid_overrides_change_the_speed_of_queued_moves() {
    let mut sim = boot_machine();
    send(&mut sim, "M17");
    send(&mut sim, "G91");
    // Steps/s over `n` pulses that end `before` the last one (past the
    // last move's braking).
    let rate = |sim: &Sim, n: usize, before: usize| {
        let r = rising(sim, "radial_step");
        let r = &r[r.len() - before - n..r.len() - before];
        (n - 1) as f64 * 16e6 / (r[n - 1] - r[0]) as f64
    };
    // The report that carries the overrides (the work offset may take
    // the first).
    let ov = |sim: &mut Sim| {
        let r = status(sim);
        match r.contains("|Ov:") {
            true => r,
            false => status(sim),
        }
    };
    // 13 moves of 1 mm at F600 (320 steps/s) queue up; halve the feed:
    // five 10 % steps, two of them back to back (before the task runs:
    // each press counts all the same).
    for _ in 0..13 {
        send(&mut sim, "G1 X-1 F600");
    }
    for _ in 0..3 {
        bytes_then(&mut sim, &[0x92], 5);
    }
    bytes_then(&mut sim, &[0x92, 0x92], 5);
    let r = ov(&mut sim);
    assert!(r.ends_with("|Ov:50,100,100>"), "{r}");
    send_ok(&mut sim, "M400", Duration::from_secs(30));
    let slow = rate(&sim, 64, 120);
    assert!((slow - 160.0).abs() < 3.0, "{slow} steps/s at 50 %");
    // 0x90: 100 % again, and 0x93 one more.
    for _ in 0..13 {
        send(&mut sim, "G1 X1 F600");
    }
    bytes_then(&mut sim, &[0x90], 5);
    bytes_then(&mut sim, &[0x93], 5);
    send_ok(&mut sim, "M400", Duration::from_secs(30));
    let full = rate(&sim, 64, 120);
    assert!((full - 323.2).abs() < 3.0, "{full} steps/s at 101 %");
    // Rapids at 25 %: 500 of 2000 steps/s.
    bytes_then(&mut sim, &[0x97], 5);
    send(&mut sim, "G0 X-40");
    send(&mut sim, "G0 X-40");
    send_ok(&mut sim, "M400", Duration::from_secs(30));
    let rapid = rate(&sim, 200, 300);
    assert!((rapid - 500.0).abs() < 5.0, "{rapid} steps/s rapid at 25 %");
    let r = ov(&mut sim);
    assert!(r.ends_with("|Ov:101,25,100>"), "{r}");
    // Ctrl-X: Grbl's defaults.
    bytes_then(&mut sim, &[0x18], 20);
    status(&mut sim);
    assert!(status(&mut sim).ends_with("|Ov:100,100,100>"));
}

/// Grbl's safety door (0x84) without a door switch: `Door:2` while it
/// stops, `Door:0` standing (the door reads closed, ready to resume),
/// `~` goes on.
#[test]
fn the_safety_door_byte_holds_as_door_states() {
    let mut sim = boot_machine();
    send(&mut sim, "M17");
    send(&mut sim, "G0 C180");
    sim.run_for(Duration::from_millis(1500));
    let r = report_after(&mut sim, &[0x84, b'?']);
    assert!(r.starts_with("<Door:2|"), "{r}");
    sim.run_for(Duration::from_secs(2));
    assert!(status(&mut sim).starts_with("<Door:0|"));
    sim.uart_send(b"~");
    sim.run_for(Duration::from_millis(100));
    assert!(status(&mut sim).starts_with("<Run|"));
    send_ok(&mut sim, "M400", Duration::from_secs(30));
    assert!(status(&mut sim).starts_with("<Idle|"));
}

/// The reply to `line`, which must be `error:<code> …`.
fn refused(sim: &mut Sim, line: &str, code: u8) -> String {
    match sim.send_line(line, Duration::from_secs(2)) {
        Ok(hil_tests::sim::Reply::Error(e)) if e.starts_with(&format!("error:{code} ")) => e,
        other => panic!("{line:?}: {other:?}\n{}", log_tail(sim)),
    }
}

/// jogging.md: `$J=` moves through the same interpreter (`G91`, `G20`
/// for the line only), `Jog` while it moves, error 15 beyond the soft
/// limits and 8 while other motion runs; 0x85 brakes to a controlled stop
/// and drops the jogs queued ("Jog Cancel ... flushing any remaining jog
/// commands in the buffer"), each line still answered once; a G-code line
/// while a jog moves is refused with error 9, as in alarm (`protocol.c`:
/// "Block if in alarm or jog mode").
#[test]
fn jogs_move_report_jog_and_cancel_with_a_controlled_stop() {
    let mut sim = boot_machine();
    send(&mut sim, "M17");
    // 10 mm at 600 mm/min on the radial carriage (32 steps/mm), relative
    // for this line only.
    send(&mut sim, "$J=G91 X-10 F600");
    sim.run_for(Duration::from_millis(300));
    assert!(status(&mut sim).starts_with("<Jog|"));
    refused(&mut sim, "G4 P0", 9);
    // The jog goes on to its end all the same.
    sim.run_for(Duration::from_millis(1500));
    assert_eq!(hil_tests::steps_on_pins(&sim), [0, -320, 0]);
    assert!(status(&mut sim).starts_with("<Idle|"));
    assert_eq!(
        replies(&send(&mut sim, "$G")),
        ["[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]", "ok"]
    );
    // Beyond the travel (−450 mm): refused before any step.
    refused(&mut sim, "$J=X-451 F600", 15);
    // A queue of jogs (CNCjs's continuous jog), cancelled mid-way.
    let from = sim.uart_bytes().len();
    for _ in 0..6 {
        sim.uart_send(b"$J=G91 X-20 F3000\n");
    }
    sim.run_for(Duration::from_millis(1500));
    let before = rising(&sim, "radial_step").len();
    sim.uart_send(&[0x85]);
    // From about 750 steps/s at 500 steps/s²: 1.5 s of braking.
    sim.run_for(Duration::from_millis(3000));
    let stopped = rising(&sim, "radial_step");
    assert!(stopped.len() > before, "it braked, not stopped dead");
    let last = *stopped.last().unwrap();
    assert!(
        sim.cycles() - last > 16_000_000 / 2,
        "standing: {} pulses, the last {} ms ago\n{}",
        stopped.len(),
        (sim.cycles() - last) / 16_000,
        log_tail(&sim)
    );
    let text = sim.uart_text_from(from);
    assert_eq!(
        text.matches("ok\n").count(),
        6,
        "every jog answered once: {text}"
    );
    assert!(!text.contains("error"), "{text}");
    assert!(
        hil_tests::steps_on_pins(&sim)[1] > -320 - 6 * 640,
        "the rest dropped"
    );
    // Braked within the acceleration (500 steps/s²).
    assert!(hil_tests::max_accel(&stopped[before.saturating_sub(400)..], 32) < 500.0 * 1.1);
    assert!(status(&mut sim).starts_with("<Idle|"));
    // The position the pulses left is where the interpreter goes on from.
    let at = hil_tests::steps_on_pins(&sim)[1];
    send(&mut sim, "G91 G0 X1");
    send_ok(&mut sim, "M400", Duration::from_secs(5));
    assert_eq!(hil_tests::steps_on_pins(&sim)[1], at + 32);
    // Not while other motion runs (Grbl's error 8).
    sim.uart_send(b"G0 X-50\n");
    sim.run_for(Duration::from_millis(200));
    refused(&mut sim, "$J=X0 F100", 8);
}

/// A word of no channel of the machine (`Y` and `A` on the string-art
/// machine) is refused as Grbl refuses a letter it does not know (error
/// 20), nothing moves and nothing of the line is taken: still `G90 G0`.
#[test]
fn a_word_of_no_channel_is_error_20_and_nothing_of_its_line_is_taken() {
    let mut sim = boot_machine();
    send(&mut sim, "M17");
    refused(&mut sim, "G91 G1 X1 Y2 F600", 20);
    refused(&mut sim, "G0 A5", 20);
    sim.run_for(Duration::from_millis(300));
    assert_eq!(hil_tests::steps_on_pins(&sim), [0, 0, 0], "nothing moved");
    // Absolute: the second `X1` stays where the first went (32 steps/mm).
    for _ in 0..2 {
        send_ok(&mut sim, "X1", Duration::from_secs(2));
    }
    send_ok(&mut sim, "M400", Duration::from_secs(5));
    assert_eq!(hil_tests::steps_on_pins(&sim), [0, 32, 0]);
}

/// `$C` (commands.md): lines are parsed and checked, nothing moves;
/// `Check` in reports; errors still come; `$C` again leaves it with a
/// soft reset (`[MSG:Disabled]`, the greeting) and the modal state is
/// Grbl's default again.
#[test]
fn check_mode_checks_lines_without_moving() {
    let mut sim = boot_machine();
    send(&mut sim, "M17");
    assert_eq!(replies(&send(&mut sim, "$C")), ["[MSG:Enabled]", "ok"]);
    assert!(status(&mut sim).starts_with("<Check|"));
    send(&mut sim, "G91 G1 X-10 F600");
    send(&mut sim, "G18 G2 Z-1 X-1 R1");
    refused(&mut sim, "G1 X-500", 15);
    refused(&mut sim, "$J=X-1 F10", 8);
    sim.run_for(Duration::from_millis(300));
    assert_eq!(hil_tests::steps_on_pins(&sim), [0, 0, 0], "nothing moved");
    let from = sim.uart_bytes().len();
    send(&mut sim, "$C");
    sim.run_for(Duration::from_millis(20));
    let off = sim.uart_text_from(from);
    assert!(
        off.contains("[MSG:Disabled]\nok\nGrbl 1.1h ['$' for help]\n"),
        "{off}"
    );
    assert_eq!(
        replies(&send(&mut sim, "$G")),
        ["[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]", "ok"]
    );
    send(&mut sim, "G0 X-1");
    send_ok(&mut sim, "M400", Duration::from_secs(5));
    assert_eq!(
        hil_tests::steps_on_pins(&sim),
        [0, -32, 0],
        "from where it stood"
    );
}

/// `$N` lists the startup lines (taut keeps none: empty, as a new
/// Grbl's); `$RST=$` brings the machine's defaults back; `$SLP` switches
/// the drivers off and sleeps until Ctrl-X, after which motion is locked
/// (the motors may have been turned) until `$X`.
#[test]
fn startup_lines_restore_and_sleep() {
    let mut sim = boot_machine();
    assert_eq!(replies_all(&send(&mut sim, "$N")), ["$N0=", "$N1=", "ok"]);
    send(&mut sim, "$110=1875");
    assert_eq!(
        replies(&send(&mut sim, "$RST=$")),
        ["[MSG:Restoring defaults]", "ok"]
    );
    assert!(replies_all(&send(&mut sim, "$$")).contains(&"$110=3750.000".to_string()));
    send(&mut sim, "$RST=#");
    send(&mut sim, "M17");
    assert!(sim.pin_level(taut_logic::pinmap::driver(taut_logic::axis::Axis::Radial).enable));
    let slept = send(&mut sim, "$SLP");
    sim.run_for(Duration::from_millis(50));
    assert!(sim.uart_text().contains("ok\n[MSG:Sleeping]\n"), "{slept}");
    assert!(!sim.pin_level(taut_logic::pinmap::driver(taut_logic::axis::Axis::Radial).enable));
    assert!(status(&mut sim).starts_with("<Sleep|"));
    // Lines wait unread until the reset.
    sim.uart_send(b"G0 X-1\n");
    sim.run_for(Duration::from_millis(200));
    assert!(!sim.uart_text().ends_with("ok\n"));
    let woken = bytes_then(&mut sim, &[0x18], 50);
    assert!(
        woken.contains("Grbl 1.1h ['$' for help]\n[MSG:'$H'|'$X' to unlock]\n"),
        "{woken}"
    );
    assert!(status(&mut sim).starts_with("<Alarm|"));
    refused(&mut sim, "G0 X-1", 9);
    send(&mut sim, "$X");
    assert!(status(&mut sim).starts_with("<Idle|"));
}

/// LinuxCNC's operator message `(MSG, text)`, as grblHAL says it: a line's
/// `[MSG:text]` before its `ok`, on a line alone or beside G-code (a
/// plotter file's pen change names the next pen so); cut at 40
/// characters; another comment says nothing, and a refused line neither.
#[test]
fn a_msg_comment_is_said_before_its_line_s_ok() {
    let mut sim = boot_machine();
    send(&mut sim, "$machine=flatbed");
    send(&mut sim, "$homing_at_start=0");
    assert_eq!(
        replies(&send(&mut sim, "(MSG, load the red pen)")),
        ["[MSG:load the red pen]", "ok"]
    );
    assert_eq!(
        replies(&send(&mut sim, "G1 X2 F600 (msg,first pass)")),
        ["[MSG:first pass]", "ok"]
    );
    let long = "x".repeat(60);
    assert_eq!(
        replies(&send(&mut sim, &format!("(MSG,{long})"))),
        [format!("[MSG:{}]", &long[..40]).as_str(), "ok"]
    );
    assert_eq!(replies(&send(&mut sim, "(a comment) G1 X3")), ["ok"]);
    let from = sim.uart_bytes().len();
    let refused = sim.send_line("G1 X-1000 (MSG, never)", Duration::from_secs(2));
    assert!(
        matches!(refused, Ok(hil_tests::sim::Reply::Error(_))),
        "{refused:?}"
    );
    assert!(
        !sim.uart_text_from(from).contains("never"),
        "{}",
        log_tail(&sim)
    );
}
