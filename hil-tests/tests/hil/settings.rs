//! The settings survive a power cycle in EEPROM, two copies each; a blank
//! EEPROM gives the defaults with one warning line, a copy gone bad is
//! passed over in silence for the other, both gone bad give the defaults
//! with one warning, never garbage; a board flashed with format version 6
//! keeps its settings, and one written before a setting was added keeps
//! its own with the machine's default for the new one. (A cut in the
//! middle of a write: `settings_cut.rs`.)

use hil_tests::sim::Sim;
use hil_tests::{boot_machine, log_tail, send_ok, wait_for};
use std::time::Duration;
use taut_logic::config::{Driver, MachineConfig, KEEP_DRIVERS_ON};
use taut_logic::coords::CoordData;
use taut_logic::machine::Machine;
use taut_logic::settings::eeprom::{host, MARKER, SETTINGS};
use taut_logic::settings::grbl::Extras;
use taut_logic::settings::image::{self, legacy};
use taut_logic::settings::record::{Writer, HEAD};
use taut_logic::settings::set;

fn send(sim: &mut Sim, line: &str) {
    send_ok(sim, line, Duration::from_secs(2));
}

/// The settings the EEPROM holds, decoded as the firmware would.
fn stored(sim: &Sim) -> Option<MachineConfig> {
    host::settings(&sim.eeprom()).map(|(cfg, _)| cfg)
}

/// The same image powered up again with `eeprom` (all a power cut keeps).
fn power_on(eeprom: &[u8]) -> Sim {
    let mut sim = hil_tests::load();
    sim.set_eeprom(eeprom);
    wait_for(&mut sim, "reset:", Duration::from_millis(50));
    sim
}

fn listed(sim: &mut Sim, name: &str) -> String {
    let start = sim.uart_bytes().len();
    send(sim, "$$");
    let text = sim.uart_text_from(start);
    let prefix = format!("${name}=");
    text.lines()
        .find_map(|l| l.strip_prefix(&prefix))
        .unwrap_or_else(|| panic!("{name} in {text}"))
        .to_string()
}

#[test]
fn settings_survive_a_power_cycle() {
    let mut sim = boot_machine();
    wait_for(
        &mut sim,
        "settings: EEPROM blank: defaults",
        Duration::from_millis(100),
    );
    // Every record once, a byte a run of the lowest task, then the marker.
    sim.run_for(Duration::from_secs(3));
    assert_eq!(
        stored(&sim),
        Some(MachineConfig::STRING_ART),
        "defaults written"
    );
    assert_eq!(sim.eeprom()[..5], MARKER);
    send(&mut sim, "$base_max_rate=1500");
    send(&mut sim, "$radial_travel_min=-300");
    sim.run_for(Duration::from_millis(800));
    let mut again = power_on(&sim.eeprom());
    again.run_for(Duration::from_millis(100));
    assert!(
        !again.uart_text().contains("settings:"),
        "{}",
        again.uart_text()
    );
    assert_eq!(listed(&mut again, "base_max_rate"), "1500");
    assert_eq!(listed(&mut again, "radial_travel_min"), "-300.000");
    // In force, not only listed: the soft limit moved with it.
    send(&mut again, "G0 X-299");
    // Another machine, and one of its settings, kept too.
    send_ok(&mut again, "M400", Duration::from_secs(30));
    send(&mut again, "$machine=flatbed");
    send(&mut again, "$x_travel_max=150");
    // No X switch is fitted here (homing has its own test).
    send(&mut again, "$homing_at_start=0");
    again.run_for(Duration::from_secs(2));
    let mut third = power_on(&again.eeprom());
    assert_eq!(listed(&mut third, "machine"), "flatbed");
    assert_eq!(listed(&mut third, "x_travel_max"), "150.000");
    assert_eq!(listed(&mut third, "homing_at_start"), "0");
}

#[test]
fn a_bad_copy_is_passed_over_and_two_give_the_defaults_with_one_warning() {
    let mut sim = boot_machine();
    sim.run_for(Duration::from_secs(3));
    send(&mut sim, "$base_accel=750");
    sim.run_for(Duration::from_secs(1));
    send(&mut sim, "$base_accel=740");
    sim.run_for(Duration::from_secs(1));
    let good = sim.eeprom();
    // The newer copy (740) flipped in its payload: the older (750) holds,
    // and nothing is said.
    let newer = (0..2u8)
        .max_by_key(|&c| {
            let at = SETTINGS.copy(c) as usize;
            u16::from_le_bytes([good[at + 3], good[at + 4]])
        })
        .unwrap();
    let mut one = good.clone();
    one[SETTINGS.copy(newer) as usize + 40] ^= 0x04;
    let mut again = power_on(&one);
    again.run_for(Duration::from_millis(300));
    assert!(
        !again.uart_text().contains("settings:"),
        "{}",
        log_tail(&again)
    );
    assert_eq!(listed(&mut again, "base_accel"), "750");
    // Both: the defaults, one warning line, written back whole.
    let mut both = one.clone();
    both[SETTINGS.copy(1 - newer) as usize + 40] ^= 0x04;
    let mut third = power_on(&both);
    third.run_for(Duration::from_secs(2));
    let text = third.uart_text();
    assert_eq!(
        text.matches("settings: EEPROM corrupt (checksum): defaults")
            .count(),
        1,
        "{}",
        log_tail(&third)
    );
    assert_eq!(listed(&mut third, "base_accel"), "500");
    assert_eq!(stored(&third), Some(MachineConfig::STRING_ART), "rewritten");
}

/// A board flashed before kept its settings in one copy of format 6 at
/// byte 0: the first boot takes them (and says so once), writes them in
/// two copies, then marks the EEPROM; a stale checkpoint area is dropped
/// without a word; the next boot is silent.
#[test]
fn a_version_6_board_keeps_its_settings() {
    let mut cfg = MachineConfig::defaults(Machine::Drum);
    set(&mut cfg, "x_max_rate", "700").unwrap();
    set(&mut cfg, "pen_down", "25").unwrap();
    let mut ee = vec![0xFF; 4096];
    let v6: Vec<u8> = legacy::bytes(&cfg).collect();
    ee[..v6.len()].copy_from_slice(&v6);
    // Records of the old checkpoint ring where the new records go.
    for (i, b) in ee[576..1600].iter_mut().enumerate() {
        *b = (i * 37 % 251) as u8;
    }
    let mut sim = power_on(&ee);
    sim.run_for(Duration::from_secs(3));
    let text = sim.uart_text();
    assert!(
        text.contains("settings: carried over from format version 6"),
        "{text}"
    );
    assert!(!text.contains("corrupt"), "{text}");
    assert_eq!(listed(&mut sim, "x_max_rate"), "700");
    assert_eq!(listed(&mut sim, "pen_down"), "25");
    assert_eq!(sim.eeprom()[..5], MARKER);
    // What format 6 had not, as that firmware drove it: STEP/DIR drivers,
    // always on (not today's drum on its coils).
    assert_eq!(listed(&mut sim, "x_driver"), "stepdir");
    assert_eq!(listed(&mut sim, "step_idle_delay_ms"), "255");
    let mut was = cfg;
    for a in &mut was.axes {
        a.driver = Driver::StepDir;
    }
    was.idle_delay_ms = KEEP_DRIVERS_ON;
    assert_eq!(stored(&sim), Some(was));
    let mut again = power_on(&sim.eeprom());
    again.run_for(Duration::from_millis(300));
    let text = again.uart_text();
    assert!(
        !text.contains("settings:") && !text.contains("checkpoint"),
        "{text}"
    );
    assert_eq!(listed(&mut again, "machine"), "drum");
}

/// A whiteboard's settings record as a firmware with only version 6's
/// settings wrote it (the count 48, no pen speed or acceleration): the
/// board keeps its settings silently, the new ones its machine's
/// defaults; the next change writes them all.
#[test]
fn a_record_from_before_a_setting_was_added_keeps_the_rest() {
    let mut cfg = MachineConfig::defaults(Machine::Whiteboard);
    set(&mut cfg, "left_max_rate", "1700").unwrap();
    // Not in the record: a firmware that read past its count would find
    // zeros (refused) or this.
    let mut board = cfg;
    set(&mut board, "pen_accel", "77").unwrap();
    let mut ee = host::eeprom(&board, &Extras::DEFAULT, &CoordData::ZERO);
    let named = 1 + Extras::PARTS;
    host::write(&mut ee, Writer::new(SETTINGS, 1, 2), |k| {
        let (b, n) = image::part(&board, &Extras::DEFAULT, k)?;
        Some(match k as usize {
            0 => ([image::V6 as u8, 0, 0, 0, 0, 0, 0, 0], 1),
            k if k >= named + image::V6 => ([0; 8], n),
            _ => (b, n),
        })
    });
    // Only that copy committed.
    ee[SETTINGS.copy(0) as usize] = 0xFF;
    let ours = |ee: &[u8]| host::settings(ee).map(|(c, _)| c);
    assert_eq!(ours(&ee), Some(cfg), "read as the firmware does");
    let mut sim = power_on(&ee);
    sim.run_for(Duration::from_millis(300));
    let text = sim.uart_text();
    assert!(!text.contains("settings:"), "{text}");
    assert_eq!(listed(&mut sim, "left_max_rate"), "1700");
    assert_eq!(listed(&mut sim, "pen_accel"), "50", "the whiteboard's");
    send(&mut sim, "$pen_accel=40");
    sim.run_for(Duration::from_secs(3));
    let mut want = cfg;
    set(&mut want, "pen_accel", "40").unwrap();
    assert_eq!(ours(&sim.eeprom()), Some(want));
    // Written into copy 0, with every setting this firmware knows.
    let count = sim.eeprom()[(SETTINGS.copy(0) + HEAD) as usize];
    assert_eq!(!count, image::STORED as u8);
}
