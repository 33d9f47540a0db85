//! Issue 12: Grbl 1.1 on the wire, in the formats its interface document
//! gives (the lines quoted there are checked byte for byte): the banner at
//! power-on and after Ctrl-X, `$I`, `$G`, `$#` and the status report's
//! buffer state, which senders size their streams by.

use hil_tests::sim::Sim;
use hil_tests::{boot_machine, log_tail, send_ok, wait_for};
use std::time::Duration;

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
    // Ours read `[MSG:I 1234 module: …]`; Grbl's own (`[MSG:Caution: …]`) stay.
    let log = |l: &str| {
        let b = l.as_bytes();
        l.starts_with("[MSG:")
            && b.get(6) == Some(&b' ')
            && b.get(7).is_some_and(u8::is_ascii_digit)
    };
    text.lines()
        .filter(|l| (l.starts_with('[') && !log(l)) || *l == "ok")
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
            "[OPT:,13,128]",
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
    // The buffer state: every planner block and receive byte free.
    let report = bytes_then(&mut sim, b"?", 20);
    assert_eq!(
        report,
        "<Idle|MPos:0.000,0.000,0.000|Bf:13,128>\n",
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
    assert!(
        lines[2].ends_with("position unknown until G92, $X or zeroing]"),
        "{after}"
    );
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
    assert!(report.starts_with("<Hold:0|"), "{report}");
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
        listing[..4],
        ["$0=5", "$1=255", "$3=0", "$10=3"],
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
    match sim.send_line("$21=1", Duration::from_secs(2)) {
        Ok(hil_tests::sim::Reply::Error(e)) => {
            assert_eq!(e, "error:3 Invalid statement: expected 0 to 0 (col 5)")
        }
        other => panic!("{other:?}\n{}", log_tail(&sim)),
    }
}

/// The setting lines of a reply and its `ok`.
fn replies_all(text: &str) -> Vec<String> {
    text.lines()
        .filter(|l| l.starts_with('$') || *l == "ok")
        .map(str::to_string)
        .collect()
}
