//! The release firmware reads its job from a virtual SD card: a
//! good card is read and checked, a late card is found, every bad file ends
//! in its one message with nothing moved, and a card pulled while being
//! read is reported and read again when it is back.

use hil_tests::sim::operator::message;
use hil_tests::sim::{Outcome, Sim};
use hil_tests::{
    assert_ram_budget, assert_step_interrupt_never_masked_long, boot_machine, card, pulses,
    sample_card_dir, wait_for,
};
use std::time::Duration;
use taut_logic::axis::Axis;

const PARAM: &[u8] = b"tvar = 6\npocet_hrebiku = 24\npolomer_matrice = 20.0\n";
const PORADI: &[u8] = b"3,0,7,13";

/// Log messages (without level, time and module) so far.
fn messages(sim: &Sim) -> Vec<String> {
    sim.uart_text()
        .lines()
        .filter_map(|l| message(l).map(str::to_string))
        .collect()
}

fn no_motion(sim: &Sim) {
    for axis in [Axis::Base, Axis::Radial, Axis::Drill] {
        assert_eq!(pulses(sim, axis), 0, "{axis:?} moved:\n{}", sim.uart_text());
    }
}

#[test]
fn the_sample_card_is_read_and_checked_before_anything_can_start() {
    let mut sim = boot_machine();
    sim.insert_sd(hil_tests::sim::sdcard::SdImage::from_path(&sample_card_dir()).unwrap());
    wait_for(&mut sim, "press green to drill", Duration::from_secs(2));
    let log = messages(&sim);
    let at = |m: &str| {
        log.iter()
            .position(|l| l == m)
            .unwrap_or_else(|| panic!("{m:?} in {log:#?}"))
    };
    assert!(
        log.iter()
            .any(|l| l.starts_with("card: ") && l.ends_with("MiB FAT16")),
        "{log:#?}"
    );
    assert!(
        at("state: waiting for card") < at("state: reading")
            && at("state: reading")
                < at("files ok: shape 6 nails 24 radius 200000um connections 30")
            && at("files ok: shape 6 nails 24 radius 200000um connections 30")
                < at("state: prep drill")
    );
    // Waiting for green: nothing moves by itself.
    sim.run_for(Duration::from_secs(2));
    no_motion(&sim);
    // Card I/O never holds the step interrupt off.
    assert_step_interrupt_never_masked_long(&sim);
    assert_ram_budget(&sim);
}

/// FAT16 and FAT32, SDSC and SDHC cards, names in any case: the same files
/// read the same.
#[test]
fn fat16_fat32_sdsc_and_sdhc_cards_all_read() {
    use hil_tests::sim::sdcard::{CardKind, SdCard, SdConfig, SdImage};
    use hil_tests::sim::sdimage::FatChoice;
    let dir = std::env::temp_dir().join(format!("taut-hil-kinds-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("PARAM.TXT"), PARAM).unwrap();
    std::fs::write(dir.join("Poradi.Txt"), PORADI).unwrap();
    for fat in [FatChoice::Fat16, FatChoice::Fat32] {
        for kind in [CardKind::Sdsc, CardKind::Sdhc] {
            let image = SdImage::from_dir(&dir, fat).unwrap();
            let config = SdConfig {
                kind,
                ..SdConfig::default()
            };
            let mut sim = boot_machine();
            sim.insert_sd(SdCard::with_config(image, config));
            let fat_name = if fat == FatChoice::Fat32 {
                "FAT32"
            } else {
                "FAT16"
            };
            wait_for(&mut sim, fat_name, Duration::from_millis(1500));
            wait_for(
                &mut sim,
                "files ok: shape 6 nails 24 radius 200000um connections 3",
                Duration::from_secs(1),
            );
            no_motion(&sim);
            assert_ram_budget(&sim);
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Files saved with CR-only line ends (old Mac editors) read like any.
#[test]
fn files_with_cr_only_line_ends_are_read() {
    let mut sim = boot_machine();
    sim.insert_sd(card(&[
        (
            "param.txt",
            b"tvar = 6\rpocet_hrebiku = 24\rpolomer_matrice = 20.0\r",
        ),
        ("poradi.txt", b"3,0,\r7,\r13\r"),
    ]));
    wait_for(&mut sim, "files ok:", Duration::from_millis(1500));
}

#[test]
fn a_card_inserted_three_seconds_after_boot_is_found() {
    let mut sim = boot_machine();
    sim.sd_insert_at(
        Duration::from_secs(3),
        card(&[("param.txt", PARAM), ("poradi.txt", PORADI)]),
    );
    wait_for(&mut sim, ">>> insert card", Duration::from_millis(200));
    sim.run_for(Duration::from_millis(2900));
    assert!(!sim.uart_text().contains("card: "), "no card yet");
    // Looked for once a second: found within a second of going in.
    wait_for(&mut sim, "files ok:", Duration::from_millis(1200));
    assert!(sim.time_s() < 4.1, "found at {:.2} s", sim.time_s());
    no_motion(&sim);
    assert_ram_budget(&sim);
}

/// A block that comes with a bad CRC once is read again, and the files
/// check out. Then the card is pulled and put back at set times (as
/// `taut-sim --pull-card-at/--reinsert-at` do).
#[test]
fn a_bad_crc_once_and_a_card_pulled_and_put_back_end_in_a_good_read() {
    use hil_tests::sim::sdcard::{CardFault, SdCard};
    let image = card(&[("param.txt", PARAM), ("poradi.txt", PORADI)]);
    let block = image.first_block_of("poradi.txt").unwrap();
    let mut sd = SdCard::new(image);
    sd.inject(CardFault::CrcOnce(block));
    let mut sim = boot_machine();
    sim.insert_sd(sd);
    wait_for(
        &mut sim,
        &format!("card: block {block} CRC error, reading it again"),
        Duration::from_millis(1500),
    );
    wait_for(&mut sim, "files ok:", Duration::from_millis(100));
    assert!(!sim.uart_text().contains("card out"), "{}", sim.uart_text());
    let now = Duration::from_secs_f64(sim.time_s());
    sim.sd_remove_at(now + Duration::from_millis(500));
    sim.sd_reinsert_at(now + Duration::from_millis(2500));
    let seen = sim.uart_bytes().len();
    let wait_for_new = |sim: &mut Sim, text: &str, timeout: Duration| {
        let new = |s: &Sim| s.uart_text_from(seen).contains(text);
        let end = sim.run_until(new, timeout);
        assert_eq!(end, Outcome::Done, "{text:?}:\n{}", sim.uart_text());
    };
    wait_for_new(&mut sim, "card out", Duration::from_millis(2000));
    assert!(!sim.sd_present());
    wait_for_new(&mut sim, "files ok:", Duration::from_millis(3000));
    assert!(sim.time_s() > (now + Duration::from_millis(2500)).as_secs_f64());
    let after = sim.uart_text_from(seen);
    assert!(!after.contains("read failed"), "{after}");
    no_motion(&sim);
    assert_ram_budget(&sim);
}

/// Every way the job files can be wrong, and the one line each gets.
#[test]
fn every_bad_file_gets_its_message_and_nothing_moves() {
    let big_param = b"tvar = 0\npocet_hrebiku = 24\npolomer_matrice = 20\n";
    type Files<'a> = &'a [(&'a str, &'a [u8])];
    let cases: &[(Files, &str)] = &[
        (&[("poradi.txt", PORADI)], "param.txt: file not found"),
        (&[("param.txt", PARAM)], "poradi.txt: file not found"),
        (
            &[("param.txt", b""), ("poradi.txt", PORADI)],
            "param.txt: empty file",
        ),
        (
            &[
                ("param.txt", b"tvar = 6\nnails = 24\nbarva = 3\n"),
                ("poradi.txt", PORADI),
            ],
            "param.txt:3:1: unknown key",
        ),
        (
            &[
                ("param.txt", b"tvar = 6\npolomer_matrice = 20\n"),
                ("poradi.txt", PORADI),
            ],
            "param.txt: missing key pocet_hrebiku (nails)",
        ),
        (
            &[
                ("param.txt", b"tvar = 2\nnails = 24\nradius_cm = 20\n"),
                ("poradi.txt", PORADI),
            ],
            "param.txt:1:8: expected 0 or 3 to 1000",
        ),
        (
            &[
                ("param.txt", b"tvar = 6\nnails = 2\nradius_cm = 20\n"),
                ("poradi.txt", PORADI),
            ],
            "param.txt:2:9: expected 3 to 10000",
        ),
        (
            &[
                ("param.txt", b"tvar = 6\nnails = 24\nradius_cm = 2\n"),
                ("poradi.txt", PORADI),
            ],
            "param.txt:3:13: expected more than 3.8094 cm",
        ),
        (
            &[
                ("param.txt", b"tvar = 6\nnails = x24\nradius_cm = 20\n"),
                ("poradi.txt", PORADI),
            ],
            "param.txt:2:9: expected a number",
        ),
        (
            &[("param.txt", big_param), ("poradi.txt", b"3,0,7,24")],
            "poradi.txt:1:7: nail 24 out of range (nails: 24)",
        ),
        (
            &[("param.txt", big_param), ("poradi.txt", b"4,0,7,13")],
            "poradi.txt:1:1: declared 4 connections, found 3",
        ),
        (
            &[("param.txt", big_param), ("poradi.txt", b"3,0;7,13")],
            "poradi.txt:1:4: expected ','",
        ),
        (
            &[("param.txt", big_param), ("poradi.txt", b"")],
            "poradi.txt: empty file",
        ),
        (
            &[
                ("param.txt", big_param),
                ("machine.txt", b"base_max_rate = -5\n"),
                ("poradi.txt", PORADI),
            ],
            "machine.txt:1:17: expected a number",
        ),
        (
            &[
                ("param.txt", b"\xFF\xFEt\0v\0a\0r\0 \0=\0"),
                ("poradi.txt", PORADI),
            ],
            "param.txt:1:2: UTF-16 text: save it as UTF-8 or ASCII",
        ),
        (
            &[("param.txt", big_param), ("poradi.txt", b"3,\x000,7")],
            "poradi.txt:1:3: not a text file (byte 0)",
        ),
        (
            &[
                ("param.txt", big_param),
                ("machine.txt", b"step_pulse_us = 255\n"),
                ("poradi.txt", PORADI),
            ],
            "machine.txt:1:17: pulse over half a step at base_max_rate: 250 us at most",
        ),
    ];
    let mut failures = Vec::new();
    for (files, expected) in cases {
        let mut sim = boot_machine();
        sim.insert_sd(card(files));
        if sim.run_until_uart_contains("bad files: replace card", Duration::from_secs(2))
            != Outcome::Done
        {
            failures.push(format!("{expected:?}: never refused\n{}", sim.uart_text()));
            continue;
        }
        let errors: Vec<String> = sim
            .uart_text()
            .lines()
            .filter(|l| l.starts_with("[MSG:E"))
            .filter_map(|l| message(l).map(str::to_string))
            .collect();
        if errors != [expected.to_string()] {
            failures.push(format!("{expected:?}: got {errors:?}"));
        }
        // Nothing moves, whatever is pressed, until the card is replaced.
        sim.press(taut_logic::pinmap::Button::Confirm.pin());
        sim.run_for(Duration::from_millis(300));
        sim.release(taut_logic::pinmap::Button::Confirm.pin());
        sim.run_for(Duration::from_millis(500));
        no_motion(&sim);
        assert!(
            sim.uart_text().ends_with(">>> bad files: replace card\n")
                || !sim.uart_text().contains("state: prep drill")
        );
        assert_ram_budget(&sim);
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn a_card_pulled_while_being_read_is_reported_and_read_again_when_back() {
    // A long pattern, so the card is still being read when it goes.
    let poradi: String = std::iter::once("3000".to_string())
        .chain((0..3000).map(|i| (i * 7 % 24).to_string()))
        .collect::<Vec<_>>()
        .join(",");
    let image = card(&[("param.txt", PARAM), ("poradi.txt", poradi.as_bytes())]);
    let mut sim = boot_machine();
    sim.insert_sd(image.clone());
    // Probed for once a second.
    wait_for(&mut sim, "state: reading", Duration::from_millis(1500));
    sim.run_for(Duration::from_millis(20));
    assert!(!sim.uart_text().contains("files ok"), "still reading");
    let _ = sim.remove_sd();
    wait_for(&mut sim, "card out", Duration::from_millis(500));
    wait_for(&mut sim, ">>> insert card", Duration::from_millis(500));
    let before = sim.uart_text().len();
    sim.insert_sd(image);
    wait_for(&mut sim, "press green to drill", Duration::from_secs(3));
    let after = &sim.uart_text()[before..];
    assert!(
        after.contains("files ok: shape 6 nails 24 radius 200000um connections 3000"),
        "{after}"
    );
    no_motion(&sim);
    assert_ram_budget(&sim);
}

#[test]
fn a_card_pulled_while_winding_pauses_the_job_until_it_is_back() {
    use hil_tests::sim::operator::Operator;
    use taut_logic::pinmap::Button;
    // A small job: 6 nails on a circle, 12 wraps.
    let image = card(&[
        ("param.txt", b"shape = 0\nnails = 6\nradius_cm = 20\n"),
        ("poradi.txt", b"12,0,3,1,4,2,5,0,2,4,1,3,5"),
    ]);
    let mut sim = boot_machine();
    sim.insert_sd(image.clone());
    let mut operator = Operator::confirming();
    let mut run_until = |sim: &mut Sim, text: &str, limit_s: f64| {
        while !sim.uart_text().contains(text) {
            assert!(
                sim.time_s() < limit_s,
                "no {text:?} by {limit_s} s:\n{}",
                sim.uart_text()
            );
            sim.run_for(Duration::from_millis(10));
            operator.step(sim);
        }
    };
    run_until(&mut sim, "wind 3/12", 300.0);
    let _ = sim.remove_sd();
    wait_for(&mut sim, "pattern lost", Duration::from_secs(60));
    wait_for(&mut sim, ">>> insert card", Duration::from_secs(30));
    // The wrap in progress is finished, then the machine stands, drivers on.
    sim.run_for(Duration::from_secs(20));
    let stopped: Vec<usize> = [Axis::Base, Axis::Radial].map(|a| pulses(&sim, a)).into();
    sim.run_for(Duration::from_secs(3));
    let still: Vec<usize> = [Axis::Base, Axis::Radial].map(|a| pulses(&sim, a)).into();
    assert_eq!(stopped, still, "nothing moves without the pattern");
    assert!(!sim.uart_text().contains("wind 12/12"));

    sim.insert_sd(image);
    wait_for(&mut sim, "card ok", Duration::from_millis(1500));
    wait_for(
        &mut sim,
        ">>> paused: press green to resume",
        Duration::from_secs(1),
    );
    sim.press(Button::Confirm.pin());
    sim.run_for(Duration::from_millis(150));
    sim.release(Button::Confirm.pin());
    run_until(&mut sim, "state: end", 600.0);
    let log = messages(&sim);
    let wound: Vec<&String> = log.iter().filter(|l| l.starts_with("wind ")).collect();
    assert!(wound.last().unwrap().starts_with("wind 12/12"), "{wound:?}");
    no_errors(&sim);
    assert_step_interrupt_never_masked_long(&sim);
    assert_ram_budget(&sim);
}

fn no_errors(sim: &Sim) {
    assert!(!sim.uart_text().contains("[MSG:E "), "{}", sim.uart_text());
}
