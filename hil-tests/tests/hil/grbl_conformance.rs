//! Grbl 1.1 conformance on the release image: for each scenario, the
//! replies Grbl 1.1h gives, line by line (written from Grbl's documents
//! and source — `protocol.c`, `gcode.c`, `report.c`, `doc/markdown` —
//! with the line or section beside each case), then the positions
//! (`MPos`, `WPos`, `WCO`) and `$#` / `$G` after the scenario. Where taut
//! answers otherwise on purpose (soft limits refuse the line with error
//! 15 where Grbl raises ALARM:2; taut explains an error in a `[MSG:…]`
//! line before it, left out here), `docs/console.md` says why.

use hil_tests::sim::Sim;
use hil_tests::{assert_ram_budget, flatbed_with_x_switch, log_tail, send_ok, wait_for};
use std::time::Duration;

/// Grbl's reply lines to one line: `ok` / `error:N` and the feedback
/// before it (`[MSG:…]`, `[GC:…]`, `[G54:…]`…); taut's log lines and
/// the explanation it puts before an `error:` are left out.
fn replies(text: &str) -> Vec<String> {
    let log = |l: &str| {
        let b = l.as_bytes();
        l.starts_with("[MSG:")
            && b.get(6) == Some(&b' ')
            && b.get(7).is_some_and(u8::is_ascii_digit)
    };
    // Whole lines only.
    let text = &text[..text.rfind('\n').map_or(0, |i| i + 1)];
    // A line under way when the command was sent is not its reply.
    let text = text
        .split_once('\n')
        .map_or("", |(first, rest)| match first.is_empty() {
            true => rest,
            false => text,
        });
    let lines: Vec<&str> = text
        .lines()
        .filter(|l| !log(l) && !l.starts_with('<') && !l.is_empty())
        .collect();
    let mut out = Vec::new();
    for (i, l) in lines.iter().enumerate() {
        let explains =
            l.starts_with("[MSG:") && lines.get(i + 1).is_some_and(|n| n.starts_with("error:"));
        if !explains {
            out.push(l.to_string());
        }
        if *l == "ok" || l.starts_with("error:") {
            break;
        }
    }
    out
}

/// Sends `bytes` (a line with its end) and runs until it is answered.
fn transcript_bytes(sim: &mut Sim, bytes: &[u8]) -> Vec<String> {
    let from = sim.uart_bytes().len();
    sim.uart_send(bytes);
    let mut out = Vec::new();
    sim.run_until(
        |s| {
            out = replies(&s.uart_text_from(from));
            out.last()
                .is_some_and(|l| l == "ok" || l.starts_with("error:"))
        },
        Duration::from_secs(30),
    );
    out
}

fn transcript(sim: &mut Sim, line: &str) -> Vec<String> {
    transcript_bytes(sim, format!("{line}\n").as_bytes())
}

/// Sends each line and checks Grbl's replies to it.
fn expect(sim: &mut Sim, cases: &[(&str, &[&str], &str)]) {
    for (line, expected, why) in cases {
        let got = transcript(sim, line);
        assert_eq!(got, *expected, "{line:?} ({why})\n{}", log_tail(sim));
    }
}

/// The fields of a status report (`?`), as text.
struct Report {
    mpos: String,
    wpos: String,
    wco: String,
}

fn field(report: &str, name: &str) -> Option<String> {
    let at = report.find(&format!("{name}:"))?;
    let rest = &report[at + name.len() + 1..];
    Some(rest[..rest.find(['|', '>']).unwrap()].to_string())
}

/// `?` with `$10=3` (machine position, buffer) then with `$10=2` (work
/// position), and the work offset (its `WCO:` field comes at least every
/// 10th idle report: report.c's refresh counter).
fn positions(sim: &mut Sim) -> Report {
    let ask = |sim: &mut Sim| {
        let from = sim.uart_bytes().len();
        sim.uart_send(b"?");
        let mut report = None;
        sim.run_until(
            |s| {
                let text = s.uart_text_from(from);
                report = text
                    .lines()
                    .find(|l| l.starts_with('<') && l.ends_with('>'))
                    .map(str::to_string);
                report.is_some()
            },
            Duration::from_millis(200),
        );
        report.expect("a status report")
    };
    // Settings are changed with the machine standing (Grbl's error 8).
    send_ok(sim, "M400", Duration::from_secs(60));
    let mpos = field(&ask(sim), "MPos").expect("MPos");
    send_ok(sim, "$10=2", Duration::from_secs(2));
    let mut wpos = None;
    let mut wco = None;
    for _ in 0..12 {
        let r = ask(sim);
        wpos = field(&r, "WPos").or(wpos);
        wco = field(&r, "WCO").or(wco);
        if wco.is_some() && wpos.is_some() {
            break;
        }
    }
    send_ok(sim, "$10=3", Duration::from_secs(2));
    Report {
        mpos,
        wpos: wpos.expect("WPos"),
        wco: wco.expect("WCO within 10 reports"),
    }
}

/// `$#` and `$G` as Grbl prints them (report.c `report_ngc_parameters`,
/// `report_gcode_modes`).
fn offsets_and_modes(sim: &mut Sim) -> (Vec<String>, String) {
    let mut offsets = transcript(sim, "$#");
    assert_eq!(offsets.pop().as_deref(), Some("ok"));
    let modes = transcript(sim, "$G");
    assert_eq!(modes.len(), 2, "{modes:?}");
    (offsets, modes[0].clone())
}

/// The flatbed, homed: a first boot switches to it (kept in EEPROM), the
/// next homes X against its simulated switch at power-on (X at 1.000, the
/// pull-off above the switch at the travel's 0).
pub fn homed_flatbed() -> Sim {
    let mut sim = flatbed_with_x_switch(-120);
    wait_for(&mut sim, "homed", Duration::from_secs(20));
    send_ok(&mut sim, "M17", Duration::from_secs(2));
    sim
}

const OK: &[&str] = &["ok"];

/// Comments of any length, the 79 characters a line keeps, `%`, `N`,
/// `/`, spaces inside numbers, a byte-order mark: as `protocol.c` reads a
/// line and `gcode.c` its words.
#[test]
fn comments_line_length_percent_and_line_numbers() {
    let mut sim = homed_flatbed();
    let long = format!(
        "G21 G90 (Generated by Inkscape: {}) ; {}",
        "x".repeat(200),
        "y".repeat(200)
    );
    let kept_79 = format!("G4P{}", "0".repeat(76));
    let kept_80 = format!("G4P{}", "0".repeat(77));
    expect(
        &mut sim,
        &[
            (
                &long,
                OK,
                "protocol.c 118, 125: comment characters are thrown away as they come",
            ),
            (
                "(only a comment)",
                OK,
                "protocol.c 90: an empty line is answered ok",
            ),
            (
                &kept_79,
                OK,
                "protocol.c 141: 79 characters kept fit LINE_BUFFER_SIZE 80",
            ),
            (
                &kept_80,
                &["error:11"],
                "protocol.c 141-143, 88: overflow, error after the line end",
            ),
            (
                "%",
                &["error:1"],
                "gcode.c 118: % is no letter (the % feature is commented out, protocol.c 134)",
            ),
            ("N10 G0 X10", OK, "gcode.c 309: N anywhere"),
            (
                "N10000001 X11",
                &["error:27"],
                "gcode.c 364: N above 10 000 000",
            ),
            ("N-1 X11", &["error:4"], "gcode.c 340: N negative"),
            ("N5.5 G0 X11", OK, "gcode.c 309: trunc(N)"),
            (
                "/G0 X12",
                OK,
                "protocol.c 122: block delete not supported, the character ignored",
            ),
            ("G0 X1 3", OK, "protocol.c 120: spaces dropped, X13"),
            ("g0 x14", OK, "protocol.c 143: letters upper-cased"),
        ],
    );
    // A UTF-8 byte-order mark: taken out by the receive interrupt as
    // Grbl's real-time range (0x80 and up) takes it.
    assert_eq!(transcript_bytes(&mut sim, b"\xEF\xBB\xBFG0 X15\n"), OK);
    let r = positions(&mut sim);
    assert_eq!(
        (r.mpos.as_str(), r.wpos.as_str(), r.wco.as_str()),
        (
            "15.000,0.000,0.000",
            "15.000,0.000,0.000",
            "0.000,0.000,0.000"
        )
    );
    let (offsets, modes) = offsets_and_modes(&mut sim);
    assert_eq!(offsets[0], "[G54:0.000,0.000,0.000]");
    assert_eq!(modes, "[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]");
    assert_ram_budget(&sim);
}

/// Work coordinates: G10 L20/L2, G92 as an offset, G92.1, G53, G54–G59,
/// G28/G30 with their stored positions; soft limits stay in machine
/// coordinates (an offset never moves the travel).
#[test]
fn work_coordinates_offsets_and_stored_positions() {
    let mut sim = homed_flatbed();
    expect(
        &mut sim,
        &[
            ("G0 X70 Y50", OK, "the middle of the bed"),
            (
                "G10 L20 P1 X0 Y0",
                OK,
                "gcode.c 549: WCS = MPos - G92 - WPos",
            ),
        ],
    );
    let r = positions(&mut sim);
    assert_eq!(
        (r.mpos.as_str(), r.wpos.as_str(), r.wco.as_str()),
        (
            "70.000,50.000,0.000",
            "0.000,0.000,0.000",
            "70.000,50.000,0.000"
        )
    );
    expect(
        &mut sim,
        &[
            (
                "G0 X10 Y10",
                OK,
                "gcode.c 592: absolute targets add the work offset",
            ),
            ("G92 X0", OK, "gcode.c 569: G92 = MPos - WCS - WPos"),
            (
                "G0 X139",
                &["error:15"],
                "taut: out of the 0-140 mm travel in machine coordinates (Grbl: ALARM:2)",
            ),
            ("G0 X-81", &["error:15"], "taut: below the travel"),
            (
                "G53 G0 X5",
                OK,
                "gcode.c 588: G53 moves in machine coordinates for one line",
            ),
            ("G92.1", OK, "gcode.c 1026: the G92 offset cleared"),
            ("G10 L2 P2 X20 Y5", OK, "gcode.c 553: G55 set, not active"),
            ("G55", OK, "gcode.c 987"),
            ("G0 X0 Y0", OK, "the G55 zero"),
        ],
    );
    let r = positions(&mut sim);
    assert_eq!(
        (r.mpos.as_str(), r.wpos.as_str(), r.wco.as_str()),
        (
            "20.000,5.000,0.000",
            "0.000,0.000,0.000",
            "20.000,5.000,0.000"
        )
    );
    expect(
        &mut sim,
        &[
            ("G54", OK, ""),
            ("G0 X30 Y40", OK, "machine 100, 90"),
            (
                "G28.1",
                OK,
                "gcode.c 1017: the machine position kept as G28's",
            ),
            ("G0 X0 Y0", OK, ""),
            ("G30.1", OK, "gcode.c 1020"),
            ("G0 X10", OK, ""),
            ("G28", OK, "gcode.c 1009: to the G28 position"),
            (
                "G30 Y20",
                OK,
                "gcode.c 605: through Y20, then only Y goes to G30's",
            ),
            ("G10 L2 P7 X0", &["error:29"], "gcode.c 535"),
            ("G10 L3 P1 X0", &["error:20"], "gcode.c 539"),
            ("G10 L20 P1", &["error:26"], "gcode.c 532"),
            ("G92", &["error:26"], "gcode.c 563"),
            ("G53 G2 X1 I1 F100", &["error:30"], "gcode.c 630"),
        ],
    );
    let r = positions(&mut sim);
    assert_eq!(
        (r.mpos.as_str(), r.wpos.as_str(), r.wco.as_str()),
        (
            "100.000,50.000,0.000",
            "30.000,0.000,0.000",
            "70.000,50.000,0.000"
        )
    );
    let (offsets, modes) = offsets_and_modes(&mut sim);
    assert_eq!(
        offsets,
        [
            "[G54:70.000,50.000,0.000]",
            "[G55:20.000,5.000,0.000]",
            "[G56:0.000,0.000,0.000]",
            "[G57:0.000,0.000,0.000]",
            "[G58:0.000,0.000,0.000]",
            "[G59:0.000,0.000,0.000]",
            "[G28:100.000,90.000,0.000]",
            "[G30:70.000,50.000,0.000]",
            "[G92:0.000,0.000,0.000]",
            "[TLO:0.000]",
            "[PRB:0.000,0.000,0.000:0]",
        ]
    );
    assert_eq!(modes, "[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]");
    // The safety hole closed: at X20, G92 X0, then G0 X139 went 19 mm past
    // the 140 mm travel. Now it is refused and nothing moves.
    expect(
        &mut sim,
        &[("G53 G0 X20", OK, ""), ("G92 X0", OK, ""), ("M400", OK, "")],
    );
    let before = hil_tests::steps_on_pins(&sim);
    expect(
        &mut sim,
        &[("G0 X139", &["error:15"], "the travel is machine 0-140")],
    );
    sim.run_for(Duration::from_millis(300));
    assert_eq!(hil_tests::steps_on_pins(&sim), before);
    expect(
        &mut sim,
        &[("G0 X120", OK, "machine 140: the end of the travel")],
    );
    let r = positions(&mut sim);
    assert_eq!(r.mpos, "140.000,50.000,0.000");
    assert_eq!(r.wpos, "120.000,0.000,0.000");
    assert_ram_budget(&sim);
}

/// Modal groups and error numbers in gcode.c's order, the modes Grbl
/// accepts and ignores, `M2`'s program end, `M1`.
#[test]
fn modal_groups_errors_and_program_end() {
    let mut sim = homed_flatbed();
    expect(
        &mut sim,
        &[
            (
                "G21 G90 G17 G94",
                OK,
                "a preamble, every word its own group",
            ),
            (
                "G61 G40 G49 G80 G91.1 T1 M7",
                OK,
                "gcode.c 204, 213, 191, 228, 261: accepted, nothing to do",
            ),
            ("M8", OK, "gcode.c 261: coolant, kept for $G"),
            ("M9", OK, ""),
            ("X5", &["error:31"], "gcode.c 640: axis words in G80"),
            (
                "G0 G1 X5",
                &["error:24"],
                "gcode.c 165: two commands use axis words",
            ),
            (
                "G90 G91",
                &["error:21"],
                "gcode.c 238: one word per modal group",
            ),
            ("M3 M5", &["error:21"], "gcode.c 287"),
            ("G1.5 X1", &["error:23"], "gcode.c 235: non-integer command"),
            ("X1 X2", &["error:25"], "gcode.c 337"),
            ("G1 X1 F-1", &["error:4"], "gcode.c 340"),
            ("T256", &["error:38"], "gcode.c 316"),
            ("G5 X1", &["error:20"], "gcode.c 233"),
            ("G4", &["error:28"], "gcode.c 456"),
            (
                "G2 X1 F100",
                &["error:35"],
                "gcode.c 846 (G2 in G17 without I or J)",
            ),
            ("G2 Z1 I1 F100", &["error:32"], "gcode.c 688"),
            ("G1 X1 P1 F100", &["error:36"], "gcode.c 859"),
            ("G43.1 X1", &["error:37"], "gcode.c 491"),
            (
                "G93 G1 X10",
                &["error:22"],
                "gcode.c 401: inverse time needs F",
            ),
            ("G94 G1 X10 F600 S1000", OK, "laser-style S on a move"),
            ("S500", OK, "S alone"),
            ("M4 S12000", OK, "M4 with any S"),
            ("M5 S0", OK, ""),
            ("M1", OK, "gcode.c 250: optional stop, ignored"),
        ],
    );
    let modes = transcript(&mut sim, "$G");
    assert_eq!(
        modes,
        ["[GC:G1 G54 G17 G21 G90 G94 M5 M9 T0 F600 S0]", "ok"]
    );
    expect(
        &mut sim,
        &[
            ("G91 G18 M3 M7", OK, ""),
            (
                "M2",
                &["[MSG:Pgm End]", "ok"],
                "gcode.c 1077-1104: program end",
            ),
        ],
    );
    let r = positions(&mut sim);
    assert_eq!(r.mpos, "10.000,0.000,0.000");
    let (offsets, modes) = offsets_and_modes(&mut sim);
    assert_eq!(offsets[8], "[G92:0.000,0.000,0.000]");
    assert_eq!(modes, "[GC:G1 G54 G17 G21 G90 G94 M5 M9 T0 F600 S0]");
    assert_ram_budget(&sim);
}

/// A plotter's pen from spindle words: `M3`/`M4` with any `S` lower it
/// to `pen_down`, `M5` raises it, `M300 S` sets its angle, and a line
/// with X/Y and a pen `Z` sets the pen first, then moves.
#[test]
fn the_pen_from_spindle_words() {
    use hil_tests::pen_deg_at;
    let mut sim = homed_flatbed();
    let cfg = taut_logic::config::MachineConfig::defaults(taut_logic::machine::Machine::Flatbed);
    let pen = |sim: &mut Sim| {
        sim.run_for(Duration::from_millis(100));
        pen_deg_at(sim, sim.cycles()).unwrap().round() as u8
    };
    expect(&mut sim, &[("M3 S1000", OK, "pen down, whatever S")]);
    assert_eq!(pen(&mut sim), cfg.pen.down_deg);
    expect(&mut sim, &[("M5", OK, "pen up")]);
    assert_eq!(pen(&mut sim), cfg.pen.up_deg);
    expect(&mut sim, &[("M4 S1", OK, "")]);
    assert_eq!(pen(&mut sim), cfg.pen.down_deg);
    expect(
        &mut sim,
        &[("M300 S40", OK, "the unicorn extension's angle")],
    );
    assert_eq!(pen(&mut sim), 40);
    expect(&mut sim, &[("G0 Z5", OK, "Z above 0: up")]);
    assert_eq!(pen(&mut sim), cfg.pen.up_deg);
    // gcodetools' move: the pen goes down first, then the carriage moves.
    let start = sim.cycles();
    expect(&mut sim, &[("G01 X20 Y5 Z-0.1 F400", OK, "")]);
    send_ok(&mut sim, "M400", Duration::from_secs(10));
    let first_step = hil_tests::track(&sim)
        .into_iter()
        .find(|(c, _)| *c > start)
        .unwrap_or_else(|| panic!("the move stepped\n{}", log_tail(&sim)))
        .0;
    let deg = pen_deg_at(&sim, first_step).unwrap().round() as u8;
    assert_eq!(
        deg, cfg.pen.down_deg,
        "the pen was down before the first step"
    );
    let r = positions(&mut sim);
    assert_eq!(r.mpos, "20.000,5.000,-0.100");
    assert_ram_budget(&sim);
}

/// The programmed position is kept exactly and rounded to steps once
/// (Grbl's unrounded `gc_state.position`): 2 000 × `G91 G1 X0.0125` is
/// 25 mm (1 000 steps of 0.025 mm), and 2 000 × `Y0.00049` inch is
/// 24.892 mm (996 steps), which `M114` shows.
#[test]
fn two_thousand_small_relative_moves_add_up_exactly() {
    let mut sim = homed_flatbed();
    send_ok(&mut sim, "G53 G0 X20 Y0", Duration::from_secs(10));
    send_ok(&mut sim, "G91 G1 F3000", Duration::from_secs(2));
    stream(&mut sim, &vec!["X0.0125"; 2000]);
    send_ok(&mut sim, "G20", Duration::from_secs(2));
    stream(&mut sim, &vec!["Y0.00049"; 2000]);
    send_ok(&mut sim, "M400", Duration::from_secs(60));
    let from = sim.uart_bytes().len();
    send_ok(&mut sim, "M114", Duration::from_secs(2));
    let text = sim.uart_text_from(from);
    let m114 = text
        .lines()
        .find(|l| l.contains("Count"))
        .unwrap()
        .to_string();
    assert_eq!(
        m114, "X:45.000 Y:24.900 Z:0.000 Count X:1800 Y:996 Z:0",
        "{text}"
    );
    let r = positions(&mut sim);
    assert_eq!(r.mpos, "45.000,24.900,0.000");
    assert_ram_budget(&sim);
}

/// 10 000 relative moves of seeded random sizes (1–4 decimals in mm, then
/// 1–5 in inches, either sign, a random walk about the bed's middle):
/// `M114` is their exact sum rounded to steps once, on both axes.
#[test]
fn ten_thousand_random_relative_moves_end_at_their_sum_rounded_once() {
    let mut sim = homed_flatbed();
    send_ok(&mut sim, "G53 G0 X70 Y50", Duration::from_secs(10));
    send_ok(&mut sim, "G91 G1 F6000", Duration::from_secs(2));
    let mut seed: u64 = 0x5eed_2710;
    let mut next = |n: u64| {
        seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (seed >> 33) % n
    };
    // Machine position in nanometres, exactly.
    let mut nm = [70_000_000i128, 50_000_000];
    let mut lines = Vec::new();
    for i in 0..10_000 {
        let inch = i >= 5_000;
        if i == 5_000 {
            lines.push("G20".to_string());
        }
        let axis = next(2) as usize;
        let places = 1 + next(if inch { 5 } else { 4 }) as u32;
        let scale = 10u64.pow(places);
        // Up to 0.2 mm or 0.008 in, towards the middle when far from it.
        let most = if inch {
            8 * scale / 1000
        } else {
            2 * scale / 10
        };
        let size = next(most + 1) as i128;
        let middle = [70_000_000i128, 50_000_000][axis];
        let negative = match (nm[axis] - middle).abs() > 20_000_000 {
            true => nm[axis] > middle,
            false => next(2) == 1,
        };
        let w = if negative { -size } else { size };
        let unit_nm = 10i128.pow(6 - places);
        nm[axis] += if inch {
            w * unit_nm * 254 / 10
        } else {
            w * unit_nm
        };
        let letter = ['X', 'Y'][axis];
        let sign = if negative { "-" } else { "" };
        let s = size as u64;
        lines.push(format!(
            "{letter}{sign}{}.{:0p$}",
            s / scale,
            s % scale,
            p = places as usize
        ));
    }
    let refs: Vec<&str> = lines.iter().map(String::as_str).collect();
    stream(&mut sim, &refs);
    send_ok(&mut sim, "M400", Duration::from_secs(60));
    // 40 steps a mm: a step is 25 000 nm, rounded once, half up.
    let steps = nm.map(|v| ((v + 12_500).div_euclid(25_000)) as i64);
    let mm = |s: i64| format!("{}.{:03}", s / 40, (s % 40) * 25);
    let expected = format!(
        "X:{} Y:{} Z:0.000 Count X:{} Y:{} Z:0",
        mm(steps[0]),
        mm(steps[1]),
        steps[0],
        steps[1]
    );
    let from = sim.uart_bytes().len();
    send_ok(&mut sim, "M114", Duration::from_secs(2));
    let text = sim.uart_text_from(from);
    let m114 = text.lines().find(|l| l.contains("Count")).unwrap_or("");
    assert_eq!(m114, expected, "{text}");
    assert_eq!(
        hil_tests::steps_on_pins(&sim)[..2],
        [steps[0] - 120, steps[1]],
        "the pulses (X's switch 120 steps below where it stood at power-on)"
    );
    assert_ram_budget(&sim);
}

/// `G10` offsets and `G28.1` positions are kept in EEPROM (Grbl's
/// `settings_write_coord_data`): after a power cycle `$#` lists them and
/// `G54` is in force (`WCO`); `G92` is not kept.
#[test]
fn work_offsets_survive_a_power_cycle() {
    let mut sim = homed_flatbed();
    expect(
        &mut sim,
        &[
            ("G0 X70 Y50", OK, ""),
            ("G10 L20 P1 X0 Y0", OK, "gcode.c 549"),
            ("G10 L2 P3 X1.5 Y-2.25", OK, "gcode.c 553"),
            ("G53 G0 X30 Y20", OK, ""),
            ("G28.1", OK, "gcode.c 1017"),
            ("G92 X7", OK, "not kept"),
            ("M400", OK, "settings wait for the machine to stand"),
            ("$homing_at_start=0", OK, "the next boot without its switch"),
        ],
    );
    sim.run_for(Duration::from_secs(1));
    let eeprom = sim.eeprom();
    let mut again = hil_tests::machine();
    again.set_eeprom(&eeprom);
    wait_for(&mut again, "Grbl 1.1h", Duration::from_secs(5));
    again.run_for(Duration::from_millis(500));
    let (offsets, modes) = offsets_and_modes(&mut again);
    assert_eq!(offsets[0], "[G54:70.000,50.000,0.000]");
    assert_eq!(offsets[2], "[G56:1.500,-2.250,0.000]");
    assert_eq!(offsets[6], "[G28:30.000,20.000,0.000]");
    assert_eq!(offsets[8], "[G92:0.000,0.000,0.000]");
    assert!(modes.contains(" G54 "), "{modes}");
}

/// Streams `lines` by character counting (Grbl's 128-byte receive
/// buffer), every one answered `ok`.
fn stream(sim: &mut Sim, lines: &[&str]) {
    let mut in_flight = std::collections::VecDeque::new();
    let (mut next, mut answered) = (0, 0);
    let start = sim.uart_bytes().len();
    while answered < lines.len() {
        while next < lines.len() && in_flight.iter().sum::<usize>() + lines[next].len() + 1 < 128 {
            sim.uart_send(format!("{}\n", lines[next]).as_bytes());
            in_flight.push_back(lines[next].len() + 1);
            next += 1;
        }
        sim.run_for(Duration::from_millis(2));
        let text = sim.uart_text_from(start);
        assert!(!text.contains("error:"), "{}", log_tail(sim));
        let now = text.matches("ok\n").count();
        for _ in answered..now {
            in_flight.pop_front();
        }
        answered = now;
    }
}
