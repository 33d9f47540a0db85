//! Settings and work coordinates survive a power cut at any moment of
//! their write, on the release image. For a `$n=` change, a `$machine=`
//! switch, a coordinate write (`$RST=#` zeroes stored offsets: the store's
//! coordinate record written as `Store::set_coords` writes it for `G10`)
//! and the first boot on a blank EEPROM, the write is run once with the
//! simulator's EEPROM watched, and what a cut leaves is taken every
//! millisecond of it (the bytes written so far, the one being written
//! torn to a seeded value): a cut at that millisecond would stop the same
//! run there. Each such EEPROM is then powered on: its `$$`, `$#` and `$N`
//! must be the old ones or the new ones, exactly, and nothing may be said
//! of corruption. The changes are written onto erased bytes and over a
//! board's older values. A seeded sample of the cuts here; every one
//! under `cargo xtask soak`.

use hil_tests::sim::Sim;
use hil_tests::{assert_ram_budget, machine, soak_or, wait_for, Rng};
use std::time::Duration;
use taut_logic::config::MachineConfig;
use taut_logic::coords::{CoordData, Slot};
use taut_logic::machine::Machine;
use taut_logic::settings::eeprom::{host, COORDS, SETTINGS};
use taut_logic::settings::grbl::{Extras, Numbered};
use taut_logic::settings::image;
use taut_logic::settings::record::Writer;
use taut_logic::units::Milli;

/// The store task's longest run (0.5 ms at 16 MHz): it compares a few
/// parts of a record a run and starts at most one byte's write. One run
/// may print the boot's warning line instead (a log line: 0.72 ms).
const STORE_RUN_CYCLES: u64 = 8_000;
const LOG_LINE_CYCLES: u64 = 12_000;

/// What a cut at one millisecond leaves.
struct Cut {
    at_ms: u32,
    /// Byte writes started since the change, the torn one included.
    writes: u64,
    /// The byte whose write the cut tore.
    torn: Option<u16>,
    eeprom: Vec<u8>,
}

/// Powers on with `before` (blank when `None`), sends `line` once booted
/// (none: the boot's own writes), and takes what a cut leaves every
/// millisecond from the write's first byte to its last; also the EEPROM
/// the whole write leaves.
fn cuts_of(before: Option<&[u8]>, line: Option<&str>, seed: u64) -> (Vec<Cut>, Vec<u8>) {
    let mut sim = machine();
    if let Some(e) = before {
        sim.set_eeprom(e);
    }
    sim.watch_eeprom();
    // The store task: every task waits behind each of its runs.
    let elf = hil_tests::firmware_elf();
    let store = taut_simavr::elf::function_address(&elf, "4taut5store")
        .unwrap()
        .unwrap();
    sim.watch_calls(store);
    if line.is_some() {
        wait_for(&mut sim, "reset:", Duration::from_millis(200));
        sim.run_for(Duration::from_millis(200));
    }
    let from = sim.eeprom_writes();
    if let Some(l) = line {
        sim.uart_send(format!("{l}\n").as_bytes());
    }
    let mut rng = Rng::new(seed);
    let mut cuts = Vec::new();
    let (mut ms, mut last_write_ms, mut seen) = (0u32, 0u32, 0u64);
    loop {
        sim.run_for(Duration::from_millis(1));
        ms += 1;
        let writes = sim.eeprom_writes() - from;
        if writes != seen {
            seen = writes;
            last_write_ms = ms;
        }
        if writes > 0 {
            let torn = [0xFF, 0x00, 0xA5, rng.below(256) as u8][rng.below(4) as usize];
            let (eeprom, torn) = sim.eeprom_after_cut(torn);
            cuts.push(Cut {
                at_ms: ms,
                writes,
                torn,
                eeprom,
            });
        }
        if writes > 0 && ms - last_write_ms > 100 && sim.eeprom_writing().is_none() {
            break;
        }
        assert!(ms < 10_000, "the write never ended\n{}", sim.uart_text());
    }
    let total = sim.eeprom_writes() - from;
    // A cut after the last byte was written is no cut in the write.
    cuts.retain(|c| c.writes < total || c.torn.is_some());
    assert!(cuts.len() >= 3, "{} cuts", cuts.len());
    // Each cut fell within the write: bytes of it written, bytes to come
    // or one torn.
    for c in &cuts {
        assert!(c.writes >= 1 && (c.writes < total || c.torn.is_some()));
    }
    let (runs, longest, _) = sim.call_summary(store).unwrap();
    let long: Vec<u64> = sim
        .call_runs(store)
        .iter()
        .map(|r| r.1)
        .filter(|&c| c >= STORE_RUN_CYCLES)
        .collect();
    assert!(
        long.len() <= 1 && longest < LOG_LINE_CYCLES,
        "store runs of {long:?} cycles ({runs} runs)"
    );
    assert_ram_budget(&sim);
    (cuts, sim.eeprom())
}

/// What a board powered on with `eeprom` holds: its `$$`, `$#` and `$N`,
/// and what it said at boot.
fn held(eeprom: &[u8]) -> (Vec<String>, String) {
    let mut sim = Sim::load(&hil_tests::firmware_elf()).unwrap();
    sim.set_eeprom(eeprom);
    // The banner and its log line end some 45 ms after power-on.
    wait_for(&mut sim, "reset:", Duration::from_millis(200));
    sim.run_for(Duration::from_millis(20));
    let mut listing = Vec::new();
    for line in ["$$", "$#", "$N"] {
        let from = sim.uart_bytes().len();
        hil_tests::send_ok(&mut sim, line, Duration::from_secs(2));
        listing.extend(
            sim.uart_text_from(from)
                .lines()
                .filter(|l| l.starts_with('$') || l.starts_with("[G") || l.starts_with("[TLO"))
                .map(String::from),
        );
    }
    (listing, sim.uart_text())
}

/// Every cut (a seeded sample of `sample` outside the soak) leaves the
/// old values or the new ones, and no word of corruption.
fn campaign(name: &str, before: Option<&[u8]>, line: Option<&str>, sample: usize) {
    let seed = name.bytes().map(u64::from).sum();
    let (cuts, after) = cuts_of(before, line, seed);
    let old = held(before.unwrap_or(&[0xFF; 4096])).0;
    let new = held(&after).0;
    if line.is_some() {
        assert_ne!(old, new, "{name}: the change changed nothing");
    }
    let mut rng = Rng::new(seed);
    let picked: Vec<&Cut> = match soak_or(true, false) {
        true => cuts.iter().collect(),
        // The last cuts too: the commit byte's write.
        false => (0..sample)
            .map(|_| &cuts[rng.below(cuts.len() as u64) as usize])
            .chain(cuts.iter().rev().take(2))
            .collect(),
    };
    let (mut olds, mut news) = (0, 0);
    for c in picked {
        let (listing, said) = held(&c.eeprom);
        assert!(
            !said.contains("corrupt") && !said.contains("refuses"),
            "{name}: cut at {} ms ({} bytes, torn {:?}):\n{said}",
            c.at_ms,
            c.writes,
            c.torn
        );
        match (listing == old, listing == new) {
            (true, _) => olds += 1,
            (_, true) => news += 1,
            _ => panic!(
                "{name}: cut at {} ms ({} bytes, torn {:?}): neither the old nor the new values:\n{}",
                c.at_ms,
                c.writes,
                c.torn,
                diff(&listing, &old, &new)
            ),
        }
    }
    println!(
        "{name}: {} ms of writes, {} cuts checked: {olds} old, {news} new",
        cuts.last().unwrap().at_ms - cuts[0].at_ms + 1,
        olds + news
    );
}

fn diff(got: &[String], old: &[String], new: &[String]) -> String {
    got.iter()
        .filter(|l| !old.contains(l) || !new.contains(l))
        .map(|l| {
            format!(
                "  {l} (old: {}, new: {})\n",
                old.contains(l),
                new.contains(l)
            )
        })
        .collect()
}

/// Some settings and offsets a maker tuned.
fn tuned_values(machine: Machine) -> (MachineConfig, Extras, CoordData) {
    let (mut cfg, mut ex) = (MachineConfig::defaults(machine), Extras::DEFAULT);
    Numbered::MaxRate(0)
        .set(&mut cfg, &mut ex, b"1875")
        .unwrap();
    Numbered::Accel(2).set(&mut cfg, &mut ex, b"2.5").unwrap();
    let mut coords = CoordData::ZERO;
    coords.set(Slot::G54, [Milli(-12_345), Milli(90_000), Milli(-1_500)]);
    coords.set(Slot::G30, [Milli(5_000), Milli(0), Milli(2_000)]);
    (cfg, ex, coords)
}

/// A board that kept them once: each record's copy 0 in force, copy 1
/// blank (a change is written onto erased bytes).
fn tuned(machine: Machine) -> Vec<u8> {
    let (cfg, ex, coords) = tuned_values(machine);
    host::eeprom(&cfg, &ex, &coords)
}

/// A board that kept other values before them: copy 0 holds the older
/// ones (sequence 1), copy 1 the tuned ones (sequence 2), so a change is
/// written over stale bytes of copy 0, as on a board in use.
fn worn(machine: Machine) -> Vec<u8> {
    let mut older = CoordData::ZERO;
    older.set(Slot::G54, [Milli(7_000), Milli(-3_250), Milli(40)]);
    older.set(Slot::G59, [Milli(-1), Milli(2), Milli(-3)]);
    older.set(Slot::G28, [Milli(100_000), Milli(-100_000), Milli(1)]);
    let mut e = host::eeprom(
        &MachineConfig::defaults(Machine::Flatbed),
        &Extras::DEFAULT,
        &older,
    );
    let (cfg, ex, coords) = tuned_values(machine);
    host::write(&mut e, Writer::new(SETTINGS, 1, 2), |k| {
        image::part(&cfg, &ex, k)
    });
    host::write(&mut e, Writer::new(COORDS, 1, 2), |k| {
        coords
            .part(k)
            .map(|b| ([b[0], b[1], b[2], b[3], 0, 0, 0, 0], 4))
    });
    // The tuned values are in force.
    assert_eq!(host::settings(&e), Some((cfg, ex)));
    e
}

#[test]
fn a_dollar_number_change_cut_anywhere_leaves_the_old_or_the_new_settings() {
    campaign(
        "$110=2345",
        Some(&worn(Machine::StringArt)),
        Some("$110=2345"),
        soak_or(0, 6),
    );
}

#[test]
fn a_machine_switch_cut_anywhere_leaves_the_old_or_the_new_machine() {
    campaign(
        "$machine=drum",
        Some(&tuned(Machine::StringArt)),
        Some("$machine=drum"),
        soak_or(0, 6),
    );
}

#[test]
fn a_coordinate_write_cut_anywhere_leaves_the_old_or_the_new_offsets() {
    campaign(
        "$RST=#",
        Some(&worn(Machine::StringArt)),
        Some("$RST=#"),
        soak_or(0, 6),
    );
}

#[test]
fn the_first_boot_cut_anywhere_leaves_the_defaults() {
    campaign("first boot", None, None, soak_or(0, 6));
}
