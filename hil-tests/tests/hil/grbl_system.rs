//! Grbl 1.1's `$` commands on the release image, reply for reply against
//! what Grbl's own source prints (gnea/grbl 1.1h, `grbl/system.c`,
//! `report.c`, `settings.c`; the line cited beside each case). Where taut
//! answers otherwise on purpose it is said here and in docs/console.md:
//! an error's words come first in a `[MSG:…]` line (Grbl prints the bare
//! `error:<n>`, which follows), and taut's named settings follow Grbl's
//! numbered ones in `$$`.

use hil_tests::sim::{Reply, Sim};
use hil_tests::{assert_ram_budget, boot_machine, log_tail, send_ok, wait_for};
use std::time::Duration;

/// The lines a command brings, its `ok` or `error:` included; log lines
/// (`[MSG:I 1234 …]`) left out.
fn transcript(sim: &mut Sim, line: &str) -> Vec<String> {
    let from = sim.uart_bytes().len();
    // A line under way (a boot log line) is not the command's.
    let mid_line = from > 0 && sim.uart_bytes()[from - 1] != b'\n';
    let _ = sim.send_line(line, Duration::from_secs(3));
    sim.run_for(Duration::from_millis(30));
    let text = sim.uart_text_from(from);
    let text = match mid_line {
        true => text.split_once('\n').map_or("", |(_, rest)| rest),
        false => &text,
    };
    lines(text)
}

fn lines(text: &str) -> Vec<String> {
    text.lines()
        .filter(|l| !l.is_empty() && !hil_tests::is_log_line(l) && !l.starts_with('<'))
        .map(String::from)
        .collect()
}

fn send(sim: &mut Sim, line: &str) {
    send_ok(sim, line, Duration::from_secs(3));
}

const BANNER: &str = "Grbl 1.1h ['$' for help]";

#[test]
fn help_settings_and_build_info_as_grbl_prints_them() {
    let mut sim = boot_machine();
    wait_for(&mut sim, BANNER, Duration::from_millis(50));
    // system.c:129 `case 0 : report_grbl_help()`; report.c:177.
    assert_eq!(
        transcript(&mut sim, "$"),
        [
            "[HLP:$$ $# $G $I $N $x=val $Nx=line $J=line $SLP $C $X $H ~ ! ? ctrl-x]",
            "ok"
        ]
    );
    // report.c:183-222 `report_grbl_settings`: `$0`…`$6`, `$10`…`$13`,
    // `$20`…`$27`, `$30`…`$32`, `$100`…`$132`; whole numbers through
    // `report_util_uint8_setting` (report.c:94), the rest with
    // `N_DECIMAL_SETTINGVALUE` = 3 decimals (report.c:99), `$30`/`$31`
    // with `N_DECIMAL_RPMVALUE` = 0.
    let listing = transcript(&mut sim, "$$");
    let numbers: Vec<&str> = listing
        .iter()
        .filter_map(|l| l.strip_prefix('$')?.split_once('=').map(|(k, _)| k))
        .take_while(|k| k.bytes().all(|b| b.is_ascii_digit()))
        .collect();
    assert_eq!(
        numbers,
        [
            "0", "1", "2", "3", "4", "5", "6", "10", "11", "12", "13", "20", "21", "22", "23",
            "24", "25", "26", "27", "30", "31", "32", "100", "101", "102", "110", "111", "112",
            "120", "121", "122", "130", "131", "132"
        ]
    );
    for (line, why) in [
        ("$1=255", "uint8"),
        ("$4=1", "uint8, a bool"),
        ("$11=0.010", "3 decimals"),
        ("$26=250", "uint8"),
        ("$30=1000", "0 decimals"),
        ("$110=3750.000", "3 decimals"),
    ] {
        assert!(
            listing.contains(&line.to_string()),
            "{line} ({why}) in {listing:?}"
        );
    }
    // Then taut's named settings, and Grbl's `ok`.
    assert!(listing.contains(&"$machine=string_art".to_string()));
    assert_eq!(listing.last().map(String::as_str), Some("ok"));
    // report.c:372 `[VER:` GRBL_VERSION `.` build `:` the info line `]`
    // (taut's build is `taut-<version>`, its default info the machine),
    // report.c:375 `[OPT:` … `,` blocks `,` receive bytes `]`.
    let version = hil_tests::firmware_version();
    let info = transcript(&mut sim, "$I");
    assert_eq!(info[0], format!("[VER:1.1h.taut-{version}:string_art]"));
    assert!(info[1].starts_with("[OPT:"), "{info:?}");
    assert_eq!(info[2], "ok");
    // system.c:211 `$I=` stores the line (capitals and no spaces, as
    // Grbl's reader leaves every line: protocol.c).
    assert_eq!(transcript(&mut sim, "$I=my plotter"), ["ok"]);
    assert_eq!(
        transcript(&mut sim, "$I")[0],
        format!("[VER:1.1h.taut-{version}:MYPLOTTER]")
    );
    assert_ram_budget(&sim);
}

#[test]
fn settings_errors_are_grbl_s() {
    let mut sim = boot_machine();
    // settings.c:194: a negative value is error 4.
    assert_eq!(
        transcript(&mut sim, "$110=-5"),
        ["[MSG:Value < 0 (col 6)]", "error:4"]
    );
    // system.c:264: `read_float` fails, error 2.
    assert_eq!(
        transcript(&mut sim, "$110=abc"),
        [
            "[MSG:Bad number format: expected a number (col 6)]",
            "error:2"
        ]
    );
    // settings.c:298: a number Grbl has no setting of, error 3.
    assert_eq!(
        transcript(&mut sim, "$7=1"),
        ["[MSG:Invalid statement (col 4)]", "error:3"]
    );
    // system.c:221: `$RST=` of anything else, error 3.
    assert_eq!(
        transcript(&mut sim, "$RST=x").last().map(String::as_str),
        Some("error:3")
    );
    // Read back as typed (Grbl keeps the float typed): 2345 mm/min at 32
    // steps/mm is 1250.67 steps/s, run as 1251, listed as typed.
    send(&mut sim, "$110=2345");
    let listing = transcript(&mut sim, "$$");
    assert!(
        listing.contains(&"$110=2345.000".to_string()),
        "{listing:?}"
    );
    assert!(listing.contains(&"$radial_max_rate=1251".to_string()));
    // A setting with no part here is stored and listed as Grbl's.
    send(&mut sim, "$21=1");
    send(&mut sim, "$32=1");
    let listing = transcript(&mut sim, "$$");
    assert!(listing.contains(&"$21=1".to_string()), "{listing:?}");
    assert!(listing.contains(&"$32=1".to_string()));
}

/// `$N` (system.c:239-244, report.c:352 `$N<n>=<line>`), `$N0=` run to
/// check it before it is stored (system.c:260-266), run at
/// boot and after a reset with their answer `>line:ok`
/// (system.c:98 `system_execute_startup`, report.c:361).
#[test]
fn startup_lines_are_listed_stored_and_run_as_grbl_runs_them() {
    let mut sim = boot_machine();
    assert_eq!(transcript(&mut sim, "$N"), ["$N0=", "$N1=", "ok"]);
    assert_eq!(transcript(&mut sim, "$N0=g21 g91 (relative)"), ["ok"]);
    assert_eq!(transcript(&mut sim, "$N1=G0X-1"), ["ok"]);
    // Grbl runs the line to check it (system.c:262): it moved; `$N1=`
    // waits for the machine to stand (error 8 while it moves).
    send_ok(&mut sim, "M400", Duration::from_secs(5));
    // A line the parser refuses is not stored: its error.
    let bad = transcript(&mut sim, "$N1=G0 X1 X2");
    assert_eq!(bad.last().map(String::as_str), Some("error:25"), "{bad:?}");
    // A `$` line is no G-code: `gc_execute_line` wants a letter (error 1).
    let dollar = transcript(&mut sim, "$N1=$H");
    assert_eq!(
        dollar.last().map(String::as_str),
        Some("error:1"),
        "{dollar:?}"
    );
    assert_eq!(
        transcript(&mut sim, "$N"),
        ["$N0=G21G91", "$N1=G0X-1", "ok"]
    );
    // The next boot runs them, after the banner.
    let ee = sim.eeprom();
    let mut again = hil_tests::machine();
    again.set_eeprom(&ee);
    wait_for(&mut again, ">G0X-1:ok", Duration::from_secs(1));
    let text = again.uart_text();
    let boot = lines(&text);
    let at = boot.iter().position(|l| l == BANNER).unwrap();
    assert_eq!(boot[at + 1..at + 3], [">G21G91:ok", ">G0X-1:ok"], "{text}");
    // In force: relative moves (G91), and the carriage went 1 mm in.
    send_ok(&mut again, "M400", Duration::from_secs(5));
    assert_eq!(hil_tests::steps_on_pins(&again)[1], -32);
    // Ctrl-X runs them again (Grbl's main loop after a soft reset).
    let from = again.uart_bytes().len();
    again.uart_send(&[0x18]);
    again.run_for(Duration::from_millis(300));
    let after = lines(&again.uart_text_from(from));
    let at = after.iter().position(|l| l == BANNER).unwrap();
    assert_eq!(
        after[at + 1..at + 3],
        [">G21G91:ok", ">G0X-1:ok"],
        "{after:?}"
    );
    // `$N0=` clears one, once the machine stands (Grbl's "IDLE only").
    assert_eq!(
        transcript(&mut again, "$N0=").last().map(String::as_str),
        Some("error:8")
    );
    send_ok(&mut again, "M400", Duration::from_secs(5));
    assert_eq!(transcript(&mut again, "$N0="), ["ok"]);
    assert_eq!(transcript(&mut again, "$N"), ["$N0=", "$N1=G0X-1", "ok"]);
    // A Ctrl-X while a kept line is being written: the write goes on
    // (Grbl's is done before it reads the reset), the startup lines run
    // once it is kept, and the next `$N1=` waits for it, not refused.
    again.watch_eeprom();
    let (from, writes) = (again.uart_bytes().len(), again.eeprom_writes());
    again.uart_send(b"$N0=G21\n");
    while again.eeprom_writes() == writes {
        again.run_for(Duration::from_millis(1));
        assert!(
            again.uart_bytes().len() - from < 200,
            "{}",
            log_tail(&again)
        );
    }
    // The write began and is not done: no `ok` yet.
    assert!(!lines(&again.uart_text_from(from)).contains(&"ok".to_string()));
    again.uart_send(&[0x18]);
    again.run_for(Duration::from_millis(500));
    let after = lines(&again.uart_text_from(from));
    let at = after.iter().position(|l| l == BANNER);
    let at = at.unwrap_or_else(|| panic!("{}", again.uart_text_from(from)));
    assert_eq!(after[at + 1..], [">G21:ok", ">G0X-1:ok"], "{after:?}");
    send_ok(&mut again, "M400", Duration::from_secs(5));
    assert_eq!(transcript(&mut again, "$N1=G90"), ["ok"]);
    assert_eq!(transcript(&mut again, "$N"), ["$N0=G21", "$N1=G90", "ok"]);
    assert_ram_budget(&again);
}

/// `$RST=` (system.c:221-235): `[MSG:Restoring defaults]`, `ok`, then
/// Grbl's soft reset (`mc_reset`) with its banner; `$C` (system.c:145-158)
/// `[MSG:Enabled]`, and off `[MSG:Disabled]` with a soft reset too;
/// `$SLP` (system.c:202, protocol.c:632) `ok` then `[MSG:Sleeping]`.
#[test]
fn restore_check_mode_and_sleep_reply_as_grbl() {
    let mut sim = boot_machine();
    send(&mut sim, "$110=1875");
    send(&mut sim, "$N0=G21");
    for what in ["$", "#", "*"] {
        assert_eq!(
            transcript(&mut sim, &format!("$RST={what}")),
            ["[MSG:Restoring defaults]", "ok", BANNER, ">G21:ok"]
                [..if what == "*" { 3 } else { 4 }],
            "$RST={what}"
        );
    }
    let listing = transcript(&mut sim, "$$");
    assert!(listing.contains(&"$110=3750.000".to_string()));
    assert_eq!(transcript(&mut sim, "$N"), ["$N0=", "$N1=", "ok"]);
    assert_eq!(transcript(&mut sim, "$C"), ["[MSG:Enabled]", "ok"]);
    assert_eq!(transcript(&mut sim, "G0 X-5"), ["ok"]);
    assert_eq!(transcript(&mut sim, "$C"), ["[MSG:Disabled]", "ok", BANNER]);
    assert_eq!(transcript(&mut sim, "$SLP"), ["ok", "[MSG:Sleeping]"]);
    if let Ok(Reply::Ok) = sim.send_line("$$", Duration::from_millis(200)) {
        panic!("asleep: lines wait for a reset\n{}", log_tail(&sim));
    }
}
