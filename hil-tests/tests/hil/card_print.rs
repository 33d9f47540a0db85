//! A plotter prints G-code from the SD card without a PC, as
//! Marlin does (`M20`, `M23`, `M24`, `M25`, `M27`, `M524`, the green
//! button), through the same interpreter as the serial line; the drawing
//! is rebuilt from the pulses alone. Files are named as PCs save them
//! (long names, CRLF line ends, comments, codes taut does not do), and a
//! card pulled mid-print loses no line and doubles none.

use hil_tests::drawing::{assert_drawn_from_the_pulses, drawing, home, Drawing, PenWords};
use hil_tests::sim::{Reply, Sim};
use hil_tests::{boot_machine, card, log_tail, press, send_ok, settle, steps_on_pins, wait_for};
use std::time::Duration;
use taut_logic::machine::Machine;
use taut_logic::pinmap::Button;

const FLATBED: Machine = Machine::Flatbed;
/// A step of its 40 steps/mm, diagonally, and a little.
const WITHIN: f64 = 0.046;

fn send(sim: &mut Sim, line: &str) {
    send_ok(sim, line, Duration::from_secs(10));
}

fn error(sim: &mut Sim, line: &str) -> String {
    match sim.send_line(line, Duration::from_secs(5)) {
        Ok(Reply::Error(e)) => e,
        other => panic!("{line}: {other:?}\n{}", log_tail(sim)),
    }
}

/// The drawing as a PC's tool saves it: a header comment, CRLF line ends,
/// an `M117` message taut does not do, a comment line after every line
/// (files far longer than the reader's look-ahead: a card pulled
/// mid-print is pulled mid-file), no newline after the last line.
fn file_of(d: &Drawing) -> Vec<u8> {
    let mut text = String::from(
        "; drawing.gcode, made by a tool\r\nG21 G90 (mm, absolute)\r\nM117 Drawing...\r\n",
    );
    let comment = format!("; {}", "-".repeat(70));
    let lines: Vec<String> = d
        .lines
        .iter()
        .map(|l| format!("{l}\r\n{comment}"))
        .collect();
    text.push_str(&lines.join("\r\n"));
    text.into_bytes()
}

/// A flatbed standing at zero (no switch here: no homing), drivers on,
/// with `files` on its card.
fn flatbed_with(files: &[(&str, &[u8])]) -> Sim {
    let mut sim = boot_machine();
    sim.insert_sd(card(files));
    send(&mut sim, "$machine=flatbed");
    send(&mut sim, "$homing_at_start=0");
    send(&mut sim, "M17");
    wait_for(&mut sim, "MiB FAT", Duration::from_secs(3));
    sim
}

/// The print under way runs to its end and the machine stands; its
/// pulses drew `d`.
fn print_ends_drawn(sim: &mut Sim, machine: Machine, d: &Drawing, within: f64) {
    let done = |s: &Sim| s.uart_text().matches("Done printing file").count();
    let before = done(sim);
    let ended = sim.run_until(|s| done(s) > before, Duration::from_secs(120));
    assert_eq!(ended, hil_tests::sim::Outcome::Done, "{}", log_tail(sim));
    send(sim, "M400");
    assert_drawn_from_the_pulses(sim, machine, d, within);
}

#[test]
fn m20_lists_m23_selects_by_long_name_and_m24_prints_the_drawing() {
    let d = drawing(PenWords::Unicorn, home(FLATBED), 10.0, 10.0);
    let bytes = file_of(&d);
    let mut sim = flatbed_with(&[("star drawing.gcode", &bytes), ("NOTES.TXT", b"hello")]);
    let from = sim.uart_bytes().len();
    send(&mut sim, "M20");
    let list = sim.uart_text_from(from);
    // `NAME.EXT size long name`, the long name only where it differs.
    let star = format!("\nSTARDR~1.GCO {} star drawing.gcode\n", bytes.len());
    for line in [
        "Begin file list\n",
        &star,
        "\nNOTES.TXT 5\n",
        "End file list\nok\n",
    ] {
        assert!(list.contains(line), "{line:?} in\n{list}");
    }
    assert_eq!(
        error(&mut sim, "M23 nothere.nc").split(' ').next(),
        Some("error:65")
    );
    assert_eq!(error(&mut sim, "M24").split(' ').next(), Some("error:76"));
    let from = sim.uart_bytes().len();
    send(&mut sim, "M23 STAR DRAWING.GCODE");
    assert!(sim.uart_text_from(from).contains(&format!(
        "File opened: star drawing.gcode Size: {}\nFile selected\n",
        bytes.len()
    )));
    assert_eq!(steps_on_pins(&sim), [0, 0, 0], "selecting moves nothing");
    send(&mut sim, "M24");
    // While it prints, the serial line may look but not move.
    sim.run_for(Duration::from_millis(300));
    assert_eq!(
        error(&mut sim, "G0 X50").split(' ').next(),
        Some("error:67")
    );
    assert_eq!(
        error(&mut sim, "$machine=drum").split(' ').next(),
        Some("error:67")
    );
    assert_eq!(
        error(&mut sim, "M23 notes.txt").split(' ').next(),
        Some("error:67")
    );
    // `M114` only reads: answered while the print goes on.
    let from = sim.uart_bytes().len();
    send(&mut sim, "M114");
    assert!(
        sim.uart_text_from(from).contains(" Count X:"),
        "{}",
        sim.uart_text_from(from)
    );
    let from = sim.uart_bytes().len();
    send(&mut sim, "M27");
    assert!(
        sim.uart_text_from(from).contains("SD printing byte "),
        "{}",
        sim.uart_text_from(from)
    );
    wait_for(&mut sim, "Done printing file", Duration::from_secs(60));
    send(&mut sim, "M400");
    let log = sim.uart_text();
    // The message taut does not do is named with its file and line, and
    // the print went on.
    assert!(
        log.contains("star drawing.gcode:3:1: error:20 "),
        "{}",
        log_tail(&sim)
    );
    assert_eq!(log.matches("error:").count(), 6, "{}", log_tail(&sim));
    assert_drawn_from_the_pulses(&sim, FLATBED, &d, WITHIN);
    let from = sim.uart_bytes().len();
    send(&mut sim, "M27");
    assert!(sim.uart_text_from(from).contains("Not SD printing"));
}

#[test]
fn the_green_button_prints_the_first_gcode_file_and_a_pulled_card_loses_no_line() {
    let d = drawing(PenWords::Spindle, home(FLATBED), 30.0, 20.0);
    let bytes = file_of(&d);
    let mut sim = flatbed_with(&[("README.TXT", b"not g-code"), ("PLOT.NC", &bytes)]);
    press(&mut sim, Button::Confirm, 100);
    wait_for(&mut sim, "printing PLOT.NC", Duration::from_secs(2));
    // Pulled in the middle of the drawing, put back a second later.
    sim.run_for(Duration::from_millis(2500));
    let image = sim.remove_sd().unwrap();
    wait_for(
        &mut sim,
        "card out: print stopped before line",
        Duration::from_secs(3),
    );
    settle(&mut sim);
    let standing = steps_on_pins(&sim);
    sim.run_for(Duration::from_secs(1));
    assert_eq!(
        steps_on_pins(&sim),
        standing,
        "the queued moves ended; nothing more"
    );
    sim.insert_sd(image);
    wait_for(&mut sim, "card back", Duration::from_secs(3));
    send(&mut sim, "M24");
    wait_for(&mut sim, "Done printing file", Duration::from_secs(60));
    send(&mut sim, "M400");
    let log = sim.uart_text();
    for l in log
        .lines()
        .filter(|l| l.contains("print") || l.contains("card"))
    {
        eprintln!("{l}");
    }
    assert!(log.contains("print goes on at line "));
    // Every pulse on the toolpath and the end on target: a line lost or
    // done twice would leave the path or end elsewhere (relative moves
    // are not needed: the octant lines go out and back to the centre, so
    // a doubled line would pass the centre twice, harmless, but a lost
    // one leaves a tip undrawn).
    assert_drawn_from_the_pulses(&sim, FLATBED, &d, WITHIN);
    // The next print of the file reads it whole, from its first line: the
    // lost print's place is not kept.
    let from = sim.uart_bytes().len();
    send(&mut sim, "M23 plot.nc");
    send(&mut sim, "M24");
    print_ends_drawn(&mut sim, FLATBED, &d, WITHIN);
    let again = sim.uart_text_from(from);
    assert!(!again.contains("print goes on"), "{again}");
    // Its M117 line (line 3) is met again: the file was read from the top.
    assert!(again.contains("PLOT.NC:3:1: error:20 "), "{again}");
}

#[test]
fn a_file_line_out_of_reach_stops_the_print_with_its_line_and_moves_nothing_more() {
    let text = b"G21\nG0 X10 Y10\nM400\nG1 X500 Y10 F600 ; beyond X's 140 mm\nG1 X20 Y20 F600\n";
    let mut sim = flatbed_with(&[("FAR.GCO", text)]);
    send(&mut sim, "M23 far.gco");
    send(&mut sim, "M24");
    wait_for(&mut sim, "print stopped", Duration::from_secs(10));
    sim.run_for(Duration::from_secs(2));
    let log = sim.uart_text();
    assert!(log.contains("FAR.GCO:4: error:15 "), "{}", log_tail(&sim));
    assert!(!log.contains("Done printing file"));
    // 40 steps/mm: at (10, 10), never further.
    assert_eq!(steps_on_pins(&sim)[..2], [400, 400]);
    // The stream is free again.
    send(&mut sim, "G0 X0 Y0");
}

#[test]
fn m25_holds_the_print_and_m24_goes_on() {
    let d = drawing(PenWords::Z, home(FLATBED), 15.0, 15.0);
    let bytes = file_of(&d);
    let mut sim = flatbed_with(&[("Z.GCO", &bytes)]);
    send(&mut sim, "M23 z.gco");
    send(&mut sim, "M24");
    sim.run_for(Duration::from_millis(1500));
    send(&mut sim, "M25");
    sim.run_for(Duration::from_millis(800));
    let held = steps_on_pins(&sim);
    sim.run_for(Duration::from_secs(2));
    assert_eq!(steps_on_pins(&sim), held, "held");
    send(&mut sim, "M24");
    print_ends_drawn(&mut sim, FLATBED, &d, WITHIN);
}

/// From a list of seeds: files of random line lengths and line ends, the
/// card pulled at a random moment and put back after a random while, a
/// feed hold (`!`, then `~`) at another; every print ends with the whole
/// drawing, rebuilt from the pulses.
#[test]
fn seeded_pulls_and_holds_mid_print_still_draw_the_whole_drawing() {
    use hil_tests::{soak_or, Rng};
    for seed in soak_or(vec![1u64, 2, 3, 4, 5, 6, 7, 8, 9, 10], vec![41, 42, 43]) {
        let mut rng = Rng::new(seed);
        let at = [rng.between(5.0, 60.0), rng.between(5.0, 60.0)];
        let d = drawing(
            PenWords::Unicorn,
            home(FLATBED),
            at[0].round(),
            at[1].round(),
        );
        let mut text = String::new();
        for line in &d.lines {
            let end = if rng.below(2) == 0 { "\n" } else { "\r\n" };
            let pad = "-".repeat(rng.below(76) as usize);
            text.push_str(&format!("{line}{end};{pad}{end}"));
        }
        let mut sim = flatbed_with(&[("SEED.GCO", text.as_bytes())]);
        send(&mut sim, "M23 seed.gco");
        send(&mut sim, "M24");
        let (pull, hold) = (rng.between(0.2, 6.0), rng.between(0.2, 6.0));
        let (back, resume) = (rng.between(0.1, 2.0), rng.between(0.1, 1.0));
        let start = sim.time_s();
        sim.run_for(Duration::from_secs_f64(pull.min(hold)));
        let first_pull = pull <= hold;
        let act = |sim: &mut Sim, pulling: bool| {
            if pulling {
                let mounts = sim.uart_text().matches("MiB FAT").count();
                let image = sim.remove_sd().unwrap();
                sim.run_for(Duration::from_secs_f64(back));
                sim.insert_sd(image);
                // Mounted again: looked for once a second, but not while the
                // moves already planned before the pull are still drawn.
                let again = sim.run_until(
                    |s| s.uart_text().matches("MiB FAT").count() > mounts,
                    Duration::from_secs(20),
                );
                assert_eq!(again, hil_tests::sim::Outcome::Done, "{}", log_tail(sim));
                // Lost only if it noticed while lines were left to read.
                if sim.uart_text().contains("card out: print stopped") {
                    send(sim, "M24");
                }
            } else {
                sim.uart_send(b"!");
                sim.run_for(Duration::from_secs_f64(resume));
                sim.uart_send(b"~");
            }
        };
        act(&mut sim, first_pull);
        let elapsed = sim.time_s() - start;
        let second = if first_pull { hold } else { pull };
        if second > elapsed {
            sim.run_for(Duration::from_secs_f64(second - elapsed));
        }
        act(&mut sim, !first_pull);
        wait_for(&mut sim, "Done printing file", Duration::from_secs(60));
        send(&mut sim, "M400");
        eprintln!(
            "seed {seed}: pulled at {pull:.2} s for {back:.2} s, held at {hold:.2} s for {resume:.2} s; {}",
            match sim.uart_text().contains("print goes on at line") {
                true => "went on after the pull",
                false => "the pull came after the last line was read",
            }
        );
        assert_drawn_from_the_pulses(&sim, FLATBED, &d, WITHIN);
        // Nothing starved the steps, the pull included.
        assert!(!sim.uart_text().contains("underruns"), "{}", log_tail(&sim));
    }
}

/// A file as other tools save it: a UTF-8 byte-order mark, `%` program
/// delimiters, a header comment far past 80 characters. The card is read
/// by the serial line's rules (Grbl's: comments are thrown away as they
/// are read, `%` passed over): nothing but the `M117` message is refused,
/// and the drawing is whole.
#[test]
fn a_byte_order_mark_percent_and_a_long_comment_print_as_over_serial() {
    let d = drawing(PenWords::Unicorn, home(FLATBED), 10.0, 10.0);
    let mut bytes = b"\xEF\xBB\xBF%\r\n".to_vec();
    bytes.extend(format!("(Generated by Inkscape: {})\r\n", "x".repeat(300)).bytes());
    bytes.extend(file_of(&d));
    bytes.extend(b"\r\n%\r\n");
    let mut sim = flatbed_with(&[("UNICORN.GCO", &bytes)]);
    send(&mut sim, "M23 unicorn.gco");
    send(&mut sim, "M24");
    print_ends_drawn(&mut sim, FLATBED, &d, WITHIN);
    let log = sim.uart_text();
    assert_eq!(log.matches("error:").count(), 1, "{}", log_tail(&sim));
    assert!(log.contains(":5:1: error:20 "), "{}", log_tail(&sim));
}

/// Every plotter prints from the card what it draws over the serial line
/// (`machines.rs`), checked the same way from its pulses.
#[test]
fn every_plotter_prints_its_drawing_from_the_card() {
    for (machine, pen, at, within) in [
        (Machine::Drum, PenWords::Spindle, [5.0, 5.0], 0.15),
        (Machine::Whiteboard, PenWords::Unicorn, [-10.0, -10.0], 0.1),
        (Machine::Scara, PenWords::Z, [90.0, 140.0], 0.3),
    ] {
        let d = drawing(pen, home(machine), at[0], at[1]);
        let mut sim = boot_machine();
        sim.insert_sd(card(&[("DRAWING.NC", &file_of(&d))]));
        send(&mut sim, &format!("$machine={}", machine.name()));
        send(&mut sim, "M17");
        wait_for(&mut sim, "MiB FAT", Duration::from_secs(3));
        send(&mut sim, "M23 drawing.nc");
        send(&mut sim, "M24");
        print_ends_drawn(&mut sim, machine, &d, within);
    }
}

/// A card with no job (`param.txt`) whose `machine.txt` names a plotter
/// makes the machine that plotter, with the file's settings, kept in
/// EEPROM across a power cycle; its drawing then prints.
#[test]
fn a_plotter_card_s_machine_txt_switches_the_machine_and_keeps_it() {
    use hil_tests::machine;
    let d = drawing(PenWords::Unicorn, home(Machine::Whiteboard), -10.0, -10.0);
    let files: &[(&str, &[u8])] = &[
        (
            "machine.txt",
            b"machine = whiteboard  # seed 003\npen_settle_ms = 200\n",
        ),
        ("PLOT.GCO", &file_of(&d)),
    ];
    let mut sim = boot_machine();
    sim.insert_sd(card(files));
    wait_for(
        &mut sim,
        "machine.txt: the card is for the whiteboard",
        Duration::from_secs(3),
    );
    send(&mut sim, "M17");
    send(&mut sim, "M23 plot.gco");
    send(&mut sim, "M24");
    print_ends_drawn(&mut sim, Machine::Whiteboard, &d, 0.1);
    sim.run_for(Duration::from_secs(3));
    let eeprom = sim.eeprom();
    let mut sim = machine();
    sim.set_eeprom(&eeprom);
    // The boot's log line ends ~50 ms after power-on on a plotter's
    // EEPROM (its last bytes wait for the UART).
    wait_for(&mut sim, "reset:", Duration::from_millis(200));
    let from = sim.uart_bytes().len();
    send(&mut sim, "$$");
    let settings = sim.uart_text_from(from);
    for s in [
        "$machine=whiteboard\n",
        "$pen_settle_ms=200\n",
        "$left_max_rate=",
    ] {
        assert!(settings.contains(s), "{s} in\n{settings}");
    }
}

/// A card file of seeded lines in the shapes PCs' tools write (LF, CRLF
/// or CR line ends, capitals or not, leading spaces, comments in brackets
/// and after `;`, blank and comment-only lines, lines of 4 to over 100
/// bytes, running across the card's 512-byte blocks) prints as its lines
/// say: no error, every line's end reached in order, the last exactly.
/// The reader hands a line's bytes on from the block in place, a run at a
/// time; this is its stress.
#[test]
fn a_card_file_of_seeded_line_shapes_prints_as_its_lines_say() {
    use hil_tests::senders::assert_path_through;
    use hil_tests::{soak_or, Rng};
    for seed in soak_or(vec![61u64, 62, 63, 64, 65, 66], vec![61]) {
        let mut rng = Rng::new(seed);
        let mut text = b"G21 G90\n".to_vec();
        let mut ends = Vec::new();
        for k in 0..400 {
            let eol: &[u8] = match rng.below(3) {
                0 => b"\n",
                1 => b"\r\n",
                _ => b"\r",
            };
            match rng.below(12) {
                0 => {
                    text.extend(format!("; {}", "-".repeat(rng.below(90) as usize)).bytes());
                    text.extend(eol);
                    continue;
                }
                1 => {
                    text.extend(eol);
                    continue;
                }
                _ => {}
            }
            // To the µm, inside a 10 mm square; 40 steps a mm.
            let at = [rng.between(5.0, 15.0), rng.between(5.0, 15.0)]
                .map(|v| (v * 1000.0).round() / 1000.0);
            let mut line = " ".repeat(rng.below(3) as usize);
            line.push_str(&format!("G1 X{} Y{}", at[0], at[1]));
            if k == 0 || rng.below(8) == 0 {
                line.push_str(&format!(" F{}", 2000 + 500 * rng.below(3)));
            }
            if rng.below(3) == 0 {
                line.push_str(&format!(" ({})", "c".repeat(rng.below(60) as usize)));
            }
            if rng.below(3) == 0 {
                line.push_str(&format!(" ; {}", "=".repeat(rng.below(40) as usize)));
            }
            if rng.below(2) == 0 {
                line = line.to_lowercase();
            }
            text.extend(line.bytes());
            text.extend(eol);
            ends.push(at.map(|v| (v * 40.0).round() as i64));
        }
        assert!(text.len() > 8 * 512, "{} bytes: several blocks", text.len());
        let mut sim = flatbed_with(&[("SHAPES.GCO", &text)]);
        send(&mut sim, "M23 shapes.gco");
        send(&mut sim, "M24");
        let ended = sim.run_until(
            |s| s.uart_text().contains("Done printing file"),
            Duration::from_secs(200),
        );
        assert_eq!(
            ended,
            hil_tests::sim::Outcome::Done,
            "seed {seed}: {}",
            log_tail(&sim)
        );
        send(&mut sim, "M400");
        assert!(
            !sim.uart_text().contains("error:"),
            "seed {seed}: {}",
            log_tail(&sim)
        );
        assert_path_through(&mut sim, &ends);
        let last = ends[ends.len() - 1];
        assert_eq!(steps_on_pins(&sim)[..2], last, "seed {seed}");
    }
}
