//! The settings survive a power cycle in EEPROM; a blank or corrupt EEPROM
//! gives the defaults with one warning line, never garbage.

use hil_tests::sim::Sim;
use hil_tests::{boot_machine, log_tail, send_ok, wait_for};
use std::time::Duration;
use taut_logic::config::MachineConfig;
use taut_logic::settings::image;

fn send(sim: &mut Sim, line: &str) {
    send_ok(sim, line, Duration::from_secs(2));
}

/// The settings the EEPROM holds, decoded as the firmware would.
fn stored(sim: &Sim) -> Result<MachineConfig, image::Unusable> {
    let ee = sim.eeprom();
    image::decode(|i| ee[i], &MachineConfig::STRING_ART)
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
    // 199 bytes at 3.4 ms each, a byte a run of the lowest task.
    sim.run_for(Duration::from_secs(2));
    assert_eq!(
        stored(&sim),
        Ok(MachineConfig::STRING_ART),
        "defaults written"
    );
    send(&mut sim, "$base_max_rate=1500");
    send(&mut sim, "$radial_travel_min=-300");
    sim.run_for(Duration::from_millis(500));
    let mut again = power_on(&sim.eeprom());
    sim.run_for(Duration::from_millis(100));
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
fn a_corrupt_eeprom_gives_the_defaults_with_one_warning() {
    let mut sim = boot_machine();
    send(&mut sim, "$base_accel=750");
    sim.run_for(Duration::from_secs(1));
    let mut ee = sim.eeprom();
    ee[20] ^= 0x04;
    let mut again = power_on(&ee);
    again.run_for(Duration::from_secs(1));
    let text = again.uart_text();
    assert_eq!(
        text.matches("settings: EEPROM corrupt (checksum): defaults")
            .count(),
        1,
        "{}",
        log_tail(&again)
    );
    assert_eq!(listed(&mut again, "base_accel"), "500");
    assert_eq!(
        stored(&again),
        Ok(MachineConfig::STRING_ART),
        "rewritten whole"
    );
}
