use super::*;
use crate::settings::{listed, set, COUNT as NAMED};
use crate::text::error::tests::show;
use crate::units::StepsPerUnit;
use std::string::String;
use std::vec::Vec;

fn listing(cfg: &MachineConfig) -> Vec<String> {
    (0..)
        .map_while(|i| listed(i, cfg))
        .map(|l| show(&l))
        .collect()
}

/// Grbl's settings.md lists `$$` as `$0=10`, `$1=25`, `$2=0`, `$3=0`,
/// …, `$10=1`, `$11=0.010`, `$12=0.002`, `$13=0`, `$20=0`, …, `$100=250.000`,
/// `$110=500.000`, `$120=10.000`, `$130=200.000`: whole numbers for
/// switches and masks, three decimals for lengths, rates and
/// accelerations. taut lists the numbers that mean something here, then
/// its named settings.
#[test]
fn dollar_dollar_lists_grbl_s_numbers_then_the_named_settings() {
    let lines = listing(&MachineConfig::STRING_ART);
    assert_eq!(lines.len(), COUNT + NAMED);
    assert_eq!(
        lines[..COUNT],
        [
            "$0=5",
            "$1=255",
            "$3=0",
            "$4=1",
            "$10=3",
            "$11=0.010",
            "$12=0.010",
            "$13=0",
            "$20=1",
            "$21=0",
            "$22=0",
            "$27=1.000",
            // X: the radial carriage, 32 steps/mm, 2000 steps/s, 500
            // steps/s², −450…30 mm.
            "$100=32.000",
            // Y: the base (C), 9600 steps a turn, in degrees.
            "$101=26.667",
            // Z: the drill, 1600 steps per 12 mm.
            "$102=133.333",
            "$110=3750.000",
            "$111=4500.000",
            "$112=900.000",
            "$120=15.625",
            "$121=18.750",
            "$122=3.750",
            "$130=480.000",
            "$131=0.000",
            "$132=42.000",
        ]
    );
    assert_eq!(lines[COUNT], "$machine=string_art");
    assert_eq!(lines[COUNT + 2], "$base_max_rate=2000");
    // A plotter's channels are in their own places.
    let flatbed = listing(&MachineConfig::defaults(Machine::Flatbed));
    assert_eq!(flatbed[10], "$22=1");
    assert_eq!(flatbed[12], "$100=40.000");
    assert_eq!(flatbed[15], "$110=3000.000");
    assert_eq!(flatbed[21], "$130=140.000");
    // The drum's 28BYJ-48s: 4096 half-steps per 40 mm, their coils
    // released 250 ms after it stands.
    let drum = listing(&MachineConfig::defaults(Machine::Drum));
    assert_eq!(drum[1], "$1=250");
    assert_eq!(drum[12], "$100=102.400");
}

#[test]
fn numbers_index_and_name_each_other() {
    for i in 0..COUNT {
        let n = Numbered::at(i).unwrap();
        assert_eq!(Numbered::from_number(n.number()), Some(n));
        assert_eq!(Numbered::parse(show(&n.number()).as_bytes()), Some(n));
    }
    assert_eq!(Numbered::at(COUNT), None);
    for absent in [2u8, 5, 6, 14, 23, 24, 25, 26, 30, 31, 32, 103, 113, 140] {
        assert_eq!(Numbered::from_number(absent), None, "${absent}");
    }
    assert_eq!(Numbered::parse(b"1000"), None);
    assert_eq!(Numbered::parse(b"x"), None);
}

#[test]
fn writes_in_grbl_s_units_land_in_the_named_settings() {
    let mut cfg = MachineConfig::STRING_ART;
    // 1875 mm/min at 32 steps/mm is 1000 steps/s.
    set(&mut cfg, "110", "1875").unwrap();
    assert_eq!(cfg.axes[1].max_rate, 1000);
    set(&mut cfg, "120", " 25.5 ").unwrap();
    assert_eq!(cfg.axes[1].accel, 816);
    set(&mut cfg, "101", "40").unwrap();
    assert_eq!(cfg.axes[0].steps_per_unit, StepsPerUnit::new(40, 1));
    set(&mut cfg, "102", "133.5").unwrap();
    assert_eq!(cfg.axes[2].steps_per_unit, StepsPerUnit::new(267, 2));
    // Bits in X, Y, Z order: the radial carriage and the drill.
    set(&mut cfg, "3", "5").unwrap();
    let inverted = cfg.axes.map(|a| !a.dir_high_is_positive);
    assert_eq!(inverted, [false, true, true]);
    // The travel keeps its upper end.
    set(&mut cfg, "130", "400").unwrap();
    assert_eq!(cfg.axes[1].travel, (Milli(-370_000), Milli(30_000)));
    set(&mut cfg, "11", "0.02").unwrap();
    assert_eq!(cfg.junction_deviation_um, 20);
    set(&mut cfg, "12", "0.002").unwrap();
    assert_eq!(cfg.arc_tolerance_um, 2);
    set(&mut cfg, "27", "2.5").unwrap();
    assert_eq!(cfg.homing.pull_off_um, 2500);
    set(&mut cfg, "0", "10").unwrap();
    assert_eq!(cfg.pulse.step_pulse_us, 10);
    set(&mut cfg, "10", "2").unwrap();
    assert_eq!(cfg.status_report, 2);
    set(&mut cfg, "13", "1").unwrap();
    assert!(cfg.report_inches);
    // Soft limits off everywhere, then on where a travel is set (the base
    // turns freely).
    set(&mut cfg, "20", "0").unwrap();
    assert!(cfg.axes.iter().all(|a| !a.soft_limits));
    set(&mut cfg, "20", "1").unwrap();
    assert_eq!(cfg.axes.map(|a| a.soft_limits), [false, true, true]);
    // The step idle delay, ms (255: the drivers stay on); the ENABLE
    // polarity of every driver (1: high is on).
    set(&mut cfg, "1", "25").unwrap();
    assert_eq!(cfg.idle_delay_ms, 25);
    set(&mut cfg, "4", "0").unwrap();
    assert!(cfg.axes.iter().all(|a| !a.enable_active_high));
    set(&mut cfg, "4", "1").unwrap();
    assert!(cfg.axes.iter().all(|a| a.enable_active_high));
    // What cannot change here accepts only its value.
    set(&mut cfg, "21", "0").unwrap();
}

#[test]
fn refused_writes_say_why_and_change_nothing() {
    let mut cfg = MachineConfig::STRING_ART;
    let error = |cfg: &mut MachineConfig, k, v| {
        let e = set(cfg, k, v).unwrap_err();
        (e.at, show(&e.kind))
    };
    assert_eq!(error(&mut cfg, "21", "1"), (0, "expected 0 to 0".into()));
    assert_eq!(error(&mut cfg, "1", "256"), (0, "expected 0 to 255".into()));
    assert_eq!(error(&mut cfg, "4", "2"), (0, "expected 0 to 1".into()));
    assert_eq!(error(&mut cfg, "3", "8"), (0, "expected 0 to 7".into()));
    assert_eq!(error(&mut cfg, "10", "4"), (0, "expected 0 to 3".into()));
    assert_eq!(
        error(&mut cfg, "110", " 1x"),
        (2, "expected a number".into())
    );
    assert_eq!(
        error(&mut cfg, "110", "0"),
        (0, "expected 1 to 200000".into())
    );
    // Homing needs the channels named: the string-art machine has none.
    assert_eq!(
        error(&mut cfg, "22", "1"),
        (0, "invalid homing_axes".into())
    );
    // A pulse too long for the rate, as by name.
    assert_eq!(
        error(&mut cfg, "0", "255"),
        (
            0,
            "pulse over half a step at base_max_rate: 250 us at most".into()
        )
    );
    assert_eq!(error(&mut cfg, "2", "0"), (0, "unknown key".into()));
    assert_eq!(cfg, MachineConfig::STRING_ART);
    // Homing on and off where the machine has switches.
    let mut flatbed = MachineConfig::defaults(Machine::Flatbed);
    set(&mut flatbed, "22", "0").unwrap();
    assert_eq!(flatbed.homing.axes, 0);
}

/// A sender writes back what `$$` showed (UGS's settings editor): the
/// listing stays as it was, on every machine.
#[test]
fn every_listed_number_reads_back() {
    for machine in Machine::ALL {
        let cfg = MachineConfig::defaults(machine);
        let before = listing(&cfg);
        let mut copy = cfg;
        for line in &before[..COUNT] {
            let (key, value) = line[1..].split_once('=').unwrap();
            set(&mut copy, key, value).unwrap_or_else(|e| panic!("{line}: {e:?}"));
        }
        assert_eq!(listing(&copy), before, "{machine:?}");
    }
}
