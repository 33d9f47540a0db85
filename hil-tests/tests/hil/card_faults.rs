//! The card as users treat it — a block that never reads, a
//! card pulled during a jog, swapped for another pattern mid-winding, not
//! FAT at all — and patterns of the sizes real jobs have, up to the
//! documented limit and past it.

use hil_tests::sim::operator::Operator;
use hil_tests::sim::replay::{board_from_param, JobReplay};
use hil_tests::sim::sdcard::{CardFault, SdCard, SdImage};
use hil_tests::sim::{Outcome, Sim};
use hil_tests::{
    assert_ram_budget, boot_machine, card, log_tail, press, pulses, rising, send_ok, steps_on_pins,
    wait_for,
};
use std::time::Duration;
use taut_logic::axis::Axis;
use taut_logic::pinmap::Button;

const PARAM: &[u8] = b"tvar = 6\npocet_hrebiku = 24\npolomer_matrice = 20.0\n";

/// How many wraps the big-pattern test follows from the VCD: all
/// 100 under `cargo xtask soak` (`TAUT_SOAK=1`), 20 in the everyday run.
fn wraps_to_check() -> usize {
    if std::env::var_os("TAUT_SOAK").is_some() {
        100
    } else {
        20
    }
}

fn count(sim: &Sim, text: &str) -> usize {
    sim.uart_text().matches(text).count()
}

fn press_green(sim: &mut Sim) {
    press(sim, Button::Confirm, 150);
}

/// Runs until the log shows `text` (within `limit_s` of machine time),
/// asking `?` every `every`: the longest a report took to start, ms.
fn worst_status_until(sim: &mut Sim, text: &str, limit_s: f64, every: Duration) -> f64 {
    let mut worst = 0.0f64;
    while !sim.uart_text().contains(text) {
        assert!(sim.time_s() < limit_s, "{}", log_tail(sim));
        let start = sim.uart_bytes().len();
        let t0 = sim.time_s();
        sim.uart_send(b"?");
        let out = sim.run_until(
            |s| s.uart_bytes()[start..].contains(&b'<'),
            Duration::from_millis(100),
        );
        assert_eq!(out, Outcome::Done, "{}", log_tail(sim));
        worst = worst.max((sim.time_s() - t0) * 1000.0);
        sim.run_for(every);
    }
    worst
}

/// `count` nail indices of `nails`, comma-separated after the count: a
/// walk that never wraps a nail twice in a row.
fn pattern(count: usize, nails: usize) -> Vec<u8> {
    let mut text = count.to_string();
    let mut at = 0;
    for k in 0..count {
        at = (at + 1 + (k * 7) % (nails - 1)) % nails;
        text.push(',');
        text.push_str(&at.to_string());
    }
    text.into_bytes()
}

/// A block that never reads: named once with its block, the files fail
/// once, and the card is left alone (no re-reading loop) until it is
/// taken out; a good card then reads.
#[test]
fn a_block_that_always_fails_is_reported_once_and_not_read_again() {
    let image = card(&[("param.txt", PARAM), ("poradi.txt", b"3,0,7,13")]);
    let block = image.first_block_of("poradi.txt").unwrap();
    let mut sd = SdCard::new(image.clone());
    sd.inject(CardFault::BadBlock(block));
    let mut sim = boot_machine();
    sim.insert_sd(sd);
    let failing = format!("card: block {block} error token 3 times: the card is failing");
    wait_for(&mut sim, &failing, Duration::from_secs(3));
    wait_for(&mut sim, "state: bad files", Duration::from_millis(200));
    let reads = sim.sd_stats().unwrap();
    sim.run_for(Duration::from_secs(10));
    assert_eq!(count(&sim, &failing), 1, "{}", log_tail(&sim));
    assert_eq!(count(&sim, "reading it again"), 2);
    assert_eq!(
        sim.sd_stats().unwrap().blocks_read,
        reads.blocks_read,
        "the faulty card is not read again"
    );
    assert_eq!(sim.watchdog_resets(), 0);
    let _ = sim.remove_sd();
    wait_for(&mut sim, "card out", Duration::from_millis(1500));
    sim.insert_sd(image);
    wait_for(&mut sim, "files ok:", Duration::from_millis(1500));
    assert_ram_budget(&sim);
}

/// A card with no FAT volume says so, and how to fix it.
#[test]
fn a_card_without_fat_says_format_it() {
    let blank = SdImage::blank(32 * 1024);
    let mut sim = boot_machine();
    sim.insert_sd(blank);
    wait_for(
        &mut sim,
        "card: no FAT16/FAT32 volume on the card: format it FAT32",
        Duration::from_millis(1500),
    );
    sim.run_for(Duration::from_secs(3));
    assert_eq!(count(&sim, "no FAT16/FAT32 volume"), 1, "said once");
}

/// A board the needle cannot wind (nails too close) is refused with its
/// reason, the file to change and what to change, said once; nothing moves.
#[test]
fn a_board_too_dense_for_the_needle_says_why_and_where() {
    let image = card(&[
        ("param.txt", b"shape = 0\nnails = 3000\nradius_cm = 30\n"),
        ("poradi.txt", b"3,0,7,13"),
    ]);
    let mut sim = boot_machine();
    sim.insert_sd(image);
    let why = "bad board (param.txt): nail 0 too close: fewer nails or larger radius]";
    wait_for(&mut sim, why, Duration::from_secs(5));
    sim.run_for(Duration::from_secs(3));
    assert_eq!(count(&sim, "bad board"), 1, "said once");
    assert_eq!(steps_on_pins(&sim), [0, 0, 0], "nothing moved");
}

/// The card pulled while a console jog runs (before drilling): the jog
/// brakes to a stop first, and only then do the drivers go off.
#[test]
fn a_card_pulled_during_a_jog_stops_the_motion_before_the_drivers_go_off() {
    let mut sim = boot_machine();
    sim.insert_sd(card(&[("param.txt", PARAM), ("poradi.txt", b"3,0,7,13")]));
    wait_for(&mut sim, "press green to drill", Duration::from_secs(3));
    send_ok(&mut sim, "G0 C720", Duration::from_secs(1));
    sim.run_for(Duration::from_millis(2500));
    let _ = sim.remove_sd();
    wait_for(&mut sim, "card out", Duration::from_millis(1500));
    sim.run_for(Duration::from_secs(5));
    let base = rising(&sim, "base_step");
    assert!(base.len() < 19_200, "the jog was stopped short of its end");
    let en = sim.probed("base_en");
    let off = en
        .edges()
        .iter()
        .rev()
        .find(|e| !e.high)
        .expect("driver off");
    assert!(
        off.cycle > *base.last().unwrap(),
        "driver off after the last step"
    );
    // Braked, not cut: the last steps slow down.
    let n = base.len();
    assert!(base[n - 1] - base[n - 2] > 2 * (base[n - 40] - base[n - 41]));
    assert_eq!(steps_on_pins(&sim)[0], n as i64);
    assert_ram_budget(&sim);
}

/// Mid-winding, the card is swapped for another job with the same board
/// and count but another pattern: it is refused and the machine stays
/// paused; the right card back, green resumes and the job ends.
#[test]
fn a_card_swapped_mid_winding_is_refused_until_the_right_one_is_back() {
    let param: &[u8] = b"shape = 0\nnails = 6\nradius_cm = 20\n";
    let good = card(&[("param.txt", param), ("poradi.txt", b"8,0,3,1,4,2,5,0,2")]);
    let other = card(&[("param.txt", param), ("poradi.txt", b"8,0,2,4,1,3,5,0,3")]);
    let mut sim = boot_machine();
    sim.insert_sd(good.clone());
    let mut operator = Operator::confirming();
    while !sim.uart_text().contains("wind 3/8") {
        assert!(sim.time_s() < 400.0, "{}", log_tail(&sim));
        sim.run_for(Duration::from_millis(10));
        operator.step(&mut sim);
    }
    let _ = sim.remove_sd();
    wait_for(&mut sim, ">>> insert card", Duration::from_secs(60));
    sim.run_for(Duration::from_secs(20));
    sim.insert_sd(other);
    wait_for(&mut sim, "wrong card", Duration::from_millis(1500));
    let stopped = steps_on_pins(&sim);
    press_green(&mut sim);
    sim.run_for(Duration::from_secs(3));
    assert_eq!(
        steps_on_pins(&sim),
        stopped,
        "nothing wound from another card"
    );
    let _ = sim.remove_sd();
    sim.run_for(Duration::from_millis(1500));
    sim.insert_sd(good);
    wait_for(&mut sim, "card ok", Duration::from_millis(1500));
    press_green(&mut sim);
    wait_for(&mut sim, "state: end", Duration::from_secs(300));
    assert!(sim.uart_text().contains("wind 8/8"));
    assert_ram_budget(&sim);
}

/// A 10 000-connection pattern (36 KB, what real string-art jobs have) is
/// read, checked and wound: the first wraps are checked from the pulses.
#[test]
fn a_10000_connection_pattern_is_checked_and_wound() {
    let text = pattern(10_000, 6);
    assert!(text.len() > 20_000);
    let image = card(&[
        ("param.txt", b"shape = 0\nnails = 6\nradius_cm = 20\n"),
        ("poradi.txt", &text),
    ]);
    let mut sim = boot_machine();
    sim.insert_sd(image);
    wait_for(
        &mut sim,
        "files ok: shape 0 nails 6 radius 200000um connections 10000",
        Duration::from_secs(10),
    );
    assert_eq!(sim.watchdog_resets(), 0);
    let mut operator = Operator::confirming();
    let wraps = wraps_to_check();
    let param = b"shape = 0\nnails = 6\nradius_cm = 20\n";
    let config = taut_logic::config::MachineConfig::STRING_ART;
    let board = board_from_param(param).unwrap();
    let indices: Vec<u16> = String::from_utf8(text)
        .unwrap()
        .split(',')
        .skip(1)
        .map(|n| n.parse().unwrap())
        .collect();
    let job = loop {
        for _ in 0..2500 {
            assert_eq!(sim.run_for(Duration::from_millis(20)), Outcome::Running);
            operator.step(&mut sim);
        }
        assert!(sim.time_s() < 3000.0, "{}", log_tail(&sim));
        assert_eq!(sim.watchdog_resets(), 0, "{}", log_tail(&sim));
        let job = JobReplay::from_signals(&sim.vcd_signals(), board, &config).unwrap();
        if job.wraps().len() > wraps {
            break job;
        }
    };
    assert_eq!(&job.wrapped_nails()[..wraps], &indices[..wraps]);
    assert!(job.crossings_outside_gaps().is_empty());
    assert!(job.moves_while_plunged().is_empty());
    // 1 % is 100 wraps: a progress line at least every 10 s all the same,
    // give or take the wrap that ends the ten seconds. (ms, wraps done.)
    let lines: Vec<(u64, u64)> = sim
        .uart_text()
        .lines()
        .filter_map(|l| {
            let (_, rest) = l.split_once("job: wind ")?;
            let ms = l.split(' ').nth(1)?.parse().ok()?;
            Some((ms, rest.split('/').next()?.parse().ok()?))
        })
        .collect();
    assert!(lines.len() >= 4, "{lines:?}");
    let (first, last) = (lines[1], lines[lines.len() - 1]);
    let wrap_ms = (last.0 - first.0) / (last.1 - first.1).max(1);
    assert!(
        lines[1..]
            .windows(2)
            .all(|w| w[1].0 - w[0].0 <= 10_000 + 2 * wrap_ms),
        "a wrap {wrap_ms} ms: {lines:?}"
    );
    assert_ram_budget(&sim);
}

/// A 100 000-connection pattern is read and checked while `?` keeps being
/// answered in time.
#[test]
fn a_100000_connection_pattern_is_checked_without_stalling_the_console() {
    let text = pattern(100_000, 24);
    let image = card(&[("param.txt", PARAM), ("poradi.txt", &text)]);
    let mut sim = boot_machine();
    sim.insert_sd(image);
    wait_for(&mut sim, "state: reading", Duration::from_secs(2));
    let worst = worst_status_until(&mut sim, "files ok:", 60.0, Duration::from_millis(200));
    // The rest of the line may still be on the wire.
    wait_for(&mut sim, "connections 100000", Duration::from_millis(100));
    assert!(worst <= 10.0, "`?` waited {worst:.1} ms during the check");
    assert_eq!(sim.watchdog_resets(), 0);
}

/// The documented limit, 1 000 000 connections (4.9 MB): read and checked
/// in about a minute of machine time, with `?` answered in time and a jog
/// running meanwhile. Soak only (`cargo xtask soak`).
#[test]
#[ignore = "soak: a minute of machine time at full load"]
fn a_million_connection_pattern_is_checked_while_the_machine_works() {
    let text = pattern(1_000_000, 24);
    let image = card(&[("param.txt", PARAM), ("poradi.txt", &text)]);
    let mut sim = boot_machine();
    sim.insert_sd(image);
    wait_for(&mut sim, "state: reading", Duration::from_secs(2));
    send_ok(&mut sim, "M17", Duration::from_secs(1));
    send_ok(&mut sim, "G0 C3600", Duration::from_secs(1));
    let worst = worst_status_until(&mut sim, "files ok:", 300.0, Duration::from_millis(500));
    wait_for(&mut sim, "connections 1000000", Duration::from_millis(100));
    assert!(worst <= 10.0, "`?` waited {worst:.1} ms during the check");
    send_ok(&mut sim, "M400", Duration::from_secs(300));
    assert_eq!(steps_on_pins(&sim)[0], 96_000, "the jog ran to its end");
    assert_eq!(sim.watchdog_resets(), 0);
}

/// A 15 MB pattern declaring more connections than the limit is refused
/// once, and then the machine waits quietly: no reset, no re-reading.
#[test]
fn an_oversized_pattern_is_refused_once_then_quiet() {
    let mut text = b"4000000".to_vec();
    text.resize(15 * 1024 * 1024, b',');
    let image = card(&[("param.txt", PARAM), ("poradi.txt", &text)]);
    let mut sim = boot_machine();
    sim.insert_sd(image);
    let refusal = "poradi.txt:1:1: expected 1 to 1000000";
    wait_for(&mut sim, refusal, Duration::from_secs(5));
    sim.run_for(Duration::from_secs(30));
    assert_eq!(count(&sim, refusal), 1, "{}", log_tail(&sim));
    assert_eq!(sim.watchdog_resets(), 0);
    assert!(
        log_tail(&sim).ends_with(">>> bad files: replace card]\n"),
        "{}",
        log_tail(&sim)
    );
    for axis in [Axis::Base, Axis::Radial, Axis::Drill] {
        assert_eq!(pulses(&sim, axis), 0, "{axis:?} moved");
    }
}

/// An MBR whose first partition (FAT32, LBA) starts at `start`, `size`
/// blocks long.
fn mbr(start: u32, size: u32) -> [u8; 512] {
    let mut b = [0u8; 512];
    b[446 + 4] = 0x0C;
    b[446 + 8..446 + 12].copy_from_slice(&start.to_le_bytes());
    b[446 + 12..446 + 16].copy_from_slice(&size.to_le_bytes());
    b[510] = 0x55;
    b[511] = 0xAA;
    b
}

/// A card whose partition lies past its end (an image made for a bigger
/// card, a bad partition table): one line saying so and what to do, the
/// card taken as bad (never `insert card` while it is in), no retry
/// every second; whether the partition starts past the end or only ends
/// there. A good card then reads.
#[test]
fn a_partition_past_the_cards_end_is_said_once() {
    let files = card(&[("param.txt", PARAM), ("poradi.txt", b"3,0,7,13")]);
    // The volume alone, without the image's MBR if it has one.
    let first = files.block(0);
    let start = match first[0] {
        0xEB | 0xE9 => 0,
        _ => u32::from_le_bytes(first[454..458].try_into().unwrap()) as usize,
    };
    let volume = files.bytes()[start * 512..].to_vec();
    let blocks = (volume.len() / 512) as u32;
    // Starts past the end of a 4 MiB card.
    let mut starts_past = SdImage::blank(8192);
    starts_past.write_block(0, &mbr(8192 + 2048, blocks));
    // At block 2048 of a card that holds half of it.
    let mut bytes = mbr(2048, blocks).to_vec();
    bytes.resize(2048 * 512, 0);
    bytes.extend_from_slice(&volume[..volume.len() / 2]);
    let ends_past = SdImage::from_bytes(bytes);
    for (image, block) in [(starts_past, 8192 + 2048), (ends_past, 2048 + blocks - 1)] {
        let cap = image.blocks();
        let mut sim = boot_machine();
        wait_for(&mut sim, ">>> insert card", Duration::from_secs(1));
        let from = sim.uart_bytes().len();
        sim.insert_sd(image);
        let said =
            format!("card: partition past the end (block {block} of {cap}): format the card");
        wait_for(&mut sim, &said, Duration::from_secs(3));
        wait_for(
            &mut sim,
            ">>> bad files: replace card",
            Duration::from_secs(1),
        );
        sim.run_for(Duration::from_secs(10));
        let log = sim.uart_text_from(from);
        assert_eq!(log.matches(&said).count(), 1, "{log}");
        assert!(!log.contains("read failed"), "{log}");
        assert!(!log.contains("insert card"), "{log}");
        assert_eq!(sim.watchdog_resets(), 0);
        let _ = sim.remove_sd();
        wait_for(&mut sim, "card out", Duration::from_millis(1500));
        sim.insert_sd(files.clone());
        wait_for(&mut sim, "files ok:", Duration::from_millis(1500));
        assert_ram_budget(&sim);
    }
}

/// One CRC error on the once-a-second presence check (its CSD) is asked
/// again, not taken for a pull.
#[test]
fn a_crc_glitch_on_the_presence_check_is_not_a_removal() {
    let mut sim = boot_machine();
    sim.insert_sd(card(&[("param.txt", PARAM), ("poradi.txt", b"3,0,7,13")]));
    wait_for(&mut sim, "press green to drill", Duration::from_secs(3));
    let from = sim.uart_bytes().len();
    // Standing in prep drill, no file open: the next block the card
    // sends is the next check's CSD (CMD9).
    let at = Duration::from_secs_f64(sim.time_s() + 0.2);
    sim.sd_fault_at(at, CardFault::CrcNext);
    sim.run_for(Duration::from_millis(100));
    let csds = sim.sd_stats().unwrap().cmd(9);
    wait_for(
        &mut sim,
        "card: CSD CRC error, asking again",
        Duration::from_secs(2),
    );
    // The glitch happened, and the CSD was asked for again at once.
    assert_eq!(sim.sd_stats().unwrap().cmd(9), csds + 2);
    sim.run_for(Duration::from_secs(3));
    let log = sim.uart_text_from(from);
    assert!(!log.contains("card out"), "{log}");
    assert!(!log.contains("state:"), "{log}");
    // A real pull is still one.
    let _ = sim.remove_sd();
    wait_for(&mut sim, "card out", Duration::from_millis(2000));
    assert_ram_budget(&sim);
}

/// The card pulled at seeded moments while winding (the pattern's next
/// bytes waiting for their wraps in the reader's queue) is noticed within
/// 2 s each time; put back, the job goes on and winds every wrap once.
#[test]
fn a_card_pulled_mid_winding_is_noticed_within_2_s() {
    let text = pattern(40, 6);
    let image = card(&[
        ("param.txt", b"shape = 0\nnails = 6\nradius_cm = 20\n"),
        ("machine.txt", hil_tests::QUICK_MACHINE_TXT.as_bytes()),
        ("poradi.txt", &text),
    ]);
    let mut sim = boot_machine();
    sim.insert_sd(image.clone());
    let mut op = Operator::confirming();
    run(
        &mut sim,
        &mut op,
        &|_, op| matches!(&op.progress, Some((p, done, _)) if p == "wind" && *done >= 2),
    );
    let mut rng = hil_tests::Rng::new(28);
    for pull in 0..3 {
        let until = sim.time_s() + rng.between(0.1, 4.0);
        run(&mut sim, &mut op, &|s, _| s.time_s() >= until);
        let from = sim.uart_bytes().len();
        let pulled = sim.time_s();
        let _ = sim.remove_sd();
        let out = sim.run_until(
            |s| s.uart_text_from(from).contains("pattern lost"),
            Duration::from_secs(5),
        );
        assert_eq!(out, Outcome::Done, "pull {pull}: {}", log_tail(&sim));
        let took = sim.time_s() - pulled;
        assert!(took <= 2.0, "pull {pull}: noticed after {took:.2} s");
        sim.run_for(Duration::from_secs(2));
        sim.insert_sd(image.clone());
        wait_for(&mut sim, "card ok", Duration::from_secs(2));
    }
    run(&mut sim, &mut op, &|_, op: &Operator| op.finished);
    assert!(sim.uart_text().contains("wind 40/40"), "{}", log_tail(&sim));
    assert_eq!(sim.watchdog_resets(), 0);
    assert_ram_budget(&sim);
}

/// The operator at work until `until` holds (at most 900 s of machine time).
fn run(sim: &mut Sim, op: &mut Operator, until: &dyn Fn(&Sim, &Operator) -> bool) {
    while !until(sim, op) {
        assert_eq!(sim.run_for(Duration::from_millis(10)), Outcome::Running);
        op.step(sim);
        assert!(sim.time_s() < 900.0, "{}", log_tail(sim));
    }
}
