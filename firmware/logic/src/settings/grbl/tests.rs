use super::*;
use crate::settings::{listed, COUNT as NAMED};
use crate::text::error::tests::show;
use std::string::String;
use std::vec::Vec;

fn listing(cfg: &MachineConfig, ex: &Extras) -> Vec<String> {
    (0..)
        .map_while(|i| listed(i, cfg, ex))
        .map(|l| show(&l))
        .collect()
}

fn set(cfg: &mut MachineConfig, ex: &mut Extras, key: &str, value: &str) -> Result<(), SetError> {
    Numbered::parse(key.as_bytes())
        .flatten()
        .unwrap()
        .set(cfg, ex, value.as_bytes())
}

/// Grbl's `report_grbl_settings` (report.c) prints `$0`…`$6`, `$10`…`$13`,
/// `$20`…`$27`, `$30`…`$32`, then `$100`…`$132`: whole numbers for
/// switches, masks and times (`report_util_uint8_setting`), `$30`/`$31`
/// with no decimals (`N_DECIMAL_RPMVALUE`), three decimals for the rest
/// (`N_DECIMAL_SETTINGVALUE`). taut then lists its named settings.
#[test]
fn dollar_dollar_lists_grbl_s_34_numbers_then_the_named_settings() {
    let lines = listing(&MachineConfig::STRING_ART, &Extras::DEFAULT);
    assert_eq!(lines.len(), COUNT + NAMED + 2);
    assert_eq!(COUNT, 34);
    assert_eq!(lines[lines.len() - 2], "$flow=off");
    // UART1's TX is the string-art machine's zero_drill button: off.
    assert_eq!(lines.last().unwrap(), "$uart1_baud=0");
    assert_eq!(
        lines[..COUNT],
        [
            "$0=5",
            "$1=255",
            "$2=0",
            "$3=0",
            // The string-art machine's drivers are on while ENABLE is high.
            "$4=1",
            "$5=0",
            "$6=0",
            "$10=3",
            "$11=0.010",
            "$12=0.010",
            "$13=0",
            "$20=1",
            "$21=0",
            "$22=0",
            "$23=0",
            // 100 steps/s locate, 1000 seek, on the radial's 32 steps/mm.
            "$24=187.500",
            "$25=1875.000",
            "$26=250",
            "$27=1.000",
            "$30=1000",
            "$31=0",
            "$32=0",
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
    let flatbed = listing(&MachineConfig::defaults(Machine::Flatbed), &Extras::DEFAULT);
    assert!(flatbed.contains(&"$22=1".into()));
    assert!(flatbed.contains(&"$100=40.000".into()));
    assert!(flatbed.contains(&"$110=3000.000".into()));
    assert!(flatbed.contains(&"$130=140.000".into()));
    // The drum's 28BYJ-48s: 4096 half-steps per 40 mm, their coils
    // released 250 ms after it stands.
    let drum = listing(&MachineConfig::defaults(Machine::Drum), &Extras::DEFAULT);
    assert_eq!(drum[1], "$1=250");
    assert!(drum.contains(&"$100=102.400".into()));
}

#[test]
fn numbers_index_and_name_each_other() {
    for i in 0..COUNT {
        let n = Numbered::at(i).unwrap();
        assert_eq!(Numbered::from_number(n.number()), Some(n));
        assert_eq!(Numbered::parse(show(&n.number()).as_bytes()), Some(Some(n)));
    }
    assert_eq!(Numbered::at(COUNT), None);
    for absent in [7u8, 9, 14, 19, 28, 29, 33, 103, 113, 140, 255] {
        assert_eq!(Numbered::from_number(absent), None, "${absent}");
    }
    assert_eq!(Numbered::parse(b"1000"), Some(None));
    assert_eq!(Numbered::parse(b"x"), None);
    assert_eq!(Numbered::parse(b"1x"), None);
}

/// Grbl stores the number typed (a float) and prints it with three
/// decimals: `$110=2345` lists `2345.000`, though 2345 mm/min at 32
/// steps/mm is 1250.67 steps/s, which taut runs as 1251.
#[test]
fn rates_read_back_as_typed() {
    let (mut cfg, mut ex) = (MachineConfig::STRING_ART, Extras::DEFAULT);
    set(&mut cfg, &mut ex, "110", "2345").unwrap();
    assert_eq!(cfg.axes[1].max_rate, 1251);
    set(&mut cfg, &mut ex, "120", "33.3").unwrap();
    set(&mut cfg, &mut ex, "24", "123.4").unwrap();
    set(&mut cfg, &mut ex, "25", "1234.5").unwrap();
    let lines = listing(&cfg, &ex);
    for l in [
        "$110=2345.000",
        "$120=33.300",
        "$24=123.400",
        "$25=1234.500",
    ] {
        assert!(lines.contains(&l.into()), "{l} in {lines:?}");
    }
    // Set by name since: listed as its steps make it.
    crate::settings::set(&mut cfg, "radial_max_rate", "1000").unwrap();
    assert!(listing(&cfg, &ex).contains(&"$110=1875.000".into()));
    // `$100` keeps `$110` and `$120` in units, as Grbl's: their steps
    // change with it.
    set(&mut cfg, &mut ex, "110", "2345").unwrap();
    set(&mut cfg, &mut ex, "100", "64").unwrap();
    assert_eq!(cfg.axes[1].max_rate, 2501);
    let lines = listing(&cfg, &ex);
    for l in ["$100=64.000", "$110=2345.000", "$120=33.300"] {
        assert!(lines.contains(&l.into()), "{l} in {lines:?}");
    }
    // By name, steps stay steps.
    crate::settings::set(&mut cfg, "radial_steps_per_unit", "32").unwrap();
    assert_eq!(cfg.axes[1].max_rate, 2501);
}

#[test]
fn writes_in_grbl_s_units_land_in_the_named_settings() {
    let (mut cfg, mut ex) = (MachineConfig::STRING_ART, Extras::DEFAULT);
    // 1875 mm/min at 32 steps/mm is 1000 steps/s.
    set(&mut cfg, &mut ex, "110", "1875").unwrap();
    assert_eq!(cfg.axes[1].max_rate, 1000);
    set(&mut cfg, &mut ex, "120", " 25.5 ").unwrap();
    assert_eq!(cfg.axes[1].accel, 816);
    set(&mut cfg, &mut ex, "101", "40").unwrap();
    assert_eq!(cfg.axes[0].steps_per_unit, StepsPerUnit::new(40, 1));
    set(&mut cfg, &mut ex, "102", "133.5").unwrap();
    assert_eq!(cfg.axes[2].steps_per_unit, StepsPerUnit::new(267, 2));
    set(&mut cfg, &mut ex, "102", "1600/12").unwrap();
    assert_eq!(cfg.axes[2].steps_per_unit, StepsPerUnit::new(1600, 12));
    // Bits in X, Y, Z order: the radial carriage and the drill.
    set(&mut cfg, &mut ex, "3", "5").unwrap();
    let inverted = cfg.axes.map(|a| !a.dir_high_is_positive);
    assert_eq!(inverted, [false, true, true]);
    set(&mut cfg, &mut ex, "4", "0").unwrap();
    assert!(cfg.axes.iter().all(|a| !a.enable_active_high));
    set(&mut cfg, &mut ex, "4", "1").unwrap();
    assert!(cfg.axes.iter().all(|a| a.enable_active_high));
    // The step idle delay is the named setting the drivers read (Grbl
    // truncates a whole-number setting's decimals).
    set(&mut cfg, &mut ex, "1", "25.9").unwrap();
    assert_eq!(cfg.idle_delay_ms, 25);
    // The travel keeps its upper end.
    set(&mut cfg, &mut ex, "130", "400").unwrap();
    assert_eq!(cfg.axes[1].travel, (Milli(-370_000), Milli(30_000)));
    set(&mut cfg, &mut ex, "11", "0.02").unwrap();
    assert_eq!(cfg.junction_deviation_um, 20);
    set(&mut cfg, &mut ex, "12", "0.002").unwrap();
    assert_eq!(cfg.arc_tolerance_um, 2);
    set(&mut cfg, &mut ex, "27", "2.5").unwrap();
    assert_eq!(cfg.homing.pull_off_um, 2500);
    set(&mut cfg, &mut ex, "0", "10").unwrap();
    assert_eq!(cfg.pulse.step_pulse_us, 10);
    set(&mut cfg, &mut ex, "10", "2").unwrap();
    assert_eq!(cfg.status_report, 2);
    set(&mut cfg, &mut ex, "13", "1").unwrap();
    assert!(cfg.report_inches);
    // Soft limits off everywhere, then on where a travel is set (the base
    // turns freely).
    set(&mut cfg, &mut ex, "20", "0").unwrap();
    assert!(cfg.axes.iter().all(|a| !a.soft_limits));
    set(&mut cfg, &mut ex, "20", "1").unwrap();
    assert_eq!(cfg.axes.map(|a| a.soft_limits), [false, true, true]);
    // Grbl's settings with no name here are kept as given (Grbl
    // truncates a whole-number setting's decimals).
    for (k, v) in [
        ("2", "5"),
        ("5", "1"),
        ("6", "1"),
        ("21", "1"),
        ("23", "3"),
        ("26", "100"),
        ("30", "24000"),
        ("31", "100"),
        ("32", "1"),
    ] {
        set(&mut cfg, &mut ex, k, v).unwrap();
    }
    assert_eq!(ex.bytes[BYTE_STEP_INVERT], 5);
    assert_eq!(
        ex.flags(),
        FLAG_LIMIT_INVERT | FLAG_PROBE_INVERT | FLAG_HARD_LIMITS | FLAG_LASER
    );
    assert_eq!(
        (ex.bytes[BYTE_HOMING_DIR], ex.bytes[BYTE_DEBOUNCE]),
        (3, 100)
    );
    assert_eq!(ex.spindle, [24000, 100]);
    let lines = listing(&cfg, &ex);
    for l in ["$1=25", "$2=5", "$21=1", "$30=24000", "$31=100", "$32=1"] {
        assert!(lines.contains(&l.into()), "{l} in {lines:?}");
    }
}

/// Grbl's errors (settings.c, system.c): 2 for a value that is no number
/// (`read_float` fails), 4 for a negative one, 3 for a number Grbl has no
/// setting of; taut's own refusals are 3 with the reason.
#[test]
fn refused_writes_say_why_and_change_nothing() {
    let (mut cfg, mut ex) = (MachineConfig::STRING_ART, Extras::DEFAULT);
    let error = |cfg: &mut MachineConfig, ex: &mut Extras, k, v| {
        let e = set(cfg, ex, k, v).unwrap_err();
        (e.code as u8, e.at, e.why.map(|w| show(&w)))
    };
    let why = |s: &str| Some(String::from(s));
    assert_eq!(
        error(&mut cfg, &mut ex, "110", " 1x"),
        (2, 2, why("expected a number"))
    );
    assert_eq!(error(&mut cfg, &mut ex, "110", "-5"), (4, 0, None));
    assert_eq!(
        error(&mut cfg, &mut ex, "110", "0"),
        (3, 0, why("expected 1 to 200000"))
    );
    assert_eq!(
        error(&mut cfg, &mut ex, "3", "8"),
        (3, 0, why("expected 0 to 7"))
    );
    assert_eq!(
        error(&mut cfg, &mut ex, "1", "256"),
        (3, 0, why("expected 0 to 255"))
    );
    assert_eq!(
        error(&mut cfg, &mut ex, "10", "4"),
        (3, 0, why("expected 0 to 3"))
    );
    // Homing needs the channels named: the string-art machine has none.
    assert_eq!(
        error(&mut cfg, &mut ex, "22", "1"),
        (3, 0, why("invalid homing_axes"))
    );
    // A pulse too long for the rate, as by name.
    assert_eq!(
        error(&mut cfg, &mut ex, "0", "255"),
        (
            3,
            0,
            why("pulse over half a step at base_max_rate: 250 us at most")
        )
    );
    // Steps per unit that make a rate out of range: nothing changes.
    assert_eq!(
        error(&mut cfg, &mut ex, "100", "1000000"),
        (3, 0, why("expected 1 to 200000"))
    );
    assert_eq!(cfg, MachineConfig::STRING_ART);
    assert_eq!(ex, Extras::DEFAULT);
    // Homing off and on where the machine has switches: its channels kept.
    let mut flatbed = MachineConfig::defaults(Machine::Flatbed);
    set(&mut flatbed, &mut ex, "22", "0").unwrap();
    assert_eq!(flatbed.homing.axes, 1);
    assert!(!ex.homing_enabled(&flatbed));
    set(&mut flatbed, &mut ex, "22", "1").unwrap();
    assert!(ex.homing_enabled(&flatbed));
}

/// A sender writes back what `$$` showed (UGS's settings editor): the
/// listing stays as it was, on every machine.
#[test]
fn every_listed_number_reads_back() {
    for machine in Machine::ALL {
        let cfg = MachineConfig::defaults(machine);
        let mut ex = Extras::DEFAULT;
        let before = listing(&cfg, &ex);
        let mut copy = cfg;
        for line in &before[..COUNT] {
            let (key, value) = line[1..].split_once('=').unwrap();
            set(&mut copy, &mut ex, key, value).unwrap_or_else(|e| panic!("{line}: {e:?}"));
        }
        assert_eq!(copy, cfg, "{machine:?}");
        assert_eq!(listing(&copy, &ex), before, "{machine:?}");
    }
}

#[test]
fn extras_read_back_from_their_bytes() {
    let mut ex = Extras::DEFAULT;
    ex.bytes[BYTE_FLAGS] = 0x1F;
    ex.spindle[0] = 123_456;
    ex.typed[TYPED_ACCEL + 2] = 7;
    ex.typed[TYPED_HOMING_SEEK] = 99;
    let bytes: Vec<u8> = (0..)
        .map_while(|k| ex.part(k))
        .flat_map(|(b, n)| b.into_iter().take(n as usize))
        .collect();
    assert_eq!(bytes.len(), EXTRAS_BYTES as usize);
    assert_eq!(Extras::decode(|i| bytes[i as usize]), ex);
}

#[test]
fn reset_is_the_default() {
    let mut ex = Extras::DEFAULT;
    ex.bytes = [1; BYTES];
    ex.spindle = [7, 7];
    ex.typed = [9; TYPED];
    ex.reset();
    assert_eq!(ex, Extras::DEFAULT);
}

/// `$flow` (XON/XOFF flow control) is off unless set, kept in a flag bit
/// of the extras: a record from before it reads back with it off.
#[test]
fn flow_control_is_a_flag_of_the_extras() {
    let mut ex = Extras::DEFAULT;
    assert!(!ex.xonxoff());
    ex.set_flow(b"XonXoff").unwrap();
    assert!(ex.xonxoff());
    let cfg = MachineConfig::STRING_ART;
    assert!(listing(&cfg, &ex).contains(&"$flow=xonxoff".into()));
    assert_eq!(ex.flags(), FLAG_XONXOFF, "the other flags untouched");
    assert!(ex.set_flow(b"rtscts").is_err());
    assert!(ex.xonxoff(), "a refused value changes nothing");
    ex.set_flow(b"off").unwrap();
    assert_eq!(ex, Extras::DEFAULT);
    ex.set_flow(b"xonxoff").unwrap();
    // Through the stored bytes and back.
    let mut bytes = std::vec::Vec::new();
    for k in 0..Extras::PARTS as u8 {
        let (b, n) = ex.part(k).unwrap();
        bytes.extend_from_slice(&b[..n as usize]);
    }
    assert!(Extras::decode(|i| bytes[i as usize]).xonxoff());
}

/// `$uart1_baud` (the second console's rate) is 9600 unless set, kept in
/// two flag bits of the extras: a record from before it reads back 9600.
#[test]
fn uart1_baud_is_a_code_in_the_flags() {
    let mut ex = Extras::DEFAULT;
    assert_eq!(ex.uart1_baud(), Uart1Baud::B9600);
    let flatbed = MachineConfig::defaults(crate::settings::Machine::Flatbed);
    assert_eq!(listing(&flatbed, &ex).last().unwrap(), "$uart1_baud=9600");
    ex.set_flow(b"xonxoff").unwrap();
    ex.set_uart1_baud(b"115200").unwrap();
    assert_eq!(ex.uart1_baud(), Uart1Baud::B115200);
    assert!(ex.xonxoff(), "the other flags untouched");
    assert_eq!(listing(&flatbed, &ex).last().unwrap(), "$uart1_baud=115200");
    for bad in [&b"4800"[..], b"", b"fast", b"-9600"] {
        assert!(ex.set_uart1_baud(bad).is_err());
    }
    assert_eq!(
        ex.uart1_baud(),
        Uart1Baud::B115200,
        "a refused value changes nothing"
    );
    ex.set_uart1_baud(b"0").unwrap();
    assert_eq!(ex.uart1_baud(), Uart1Baud::Off);
    let mut bytes = std::vec::Vec::new();
    for k in 0..Extras::PARTS as u8 {
        let (b, n) = ex.part(k).unwrap();
        bytes.extend_from_slice(&b[..n as usize]);
    }
    assert_eq!(
        Extras::decode(|i| bytes[i as usize]).uart1_baud(),
        Uart1Baud::Off
    );
    ex.set_uart1_baud(b"9600").unwrap();
    ex.set_flow(b"off").unwrap();
    assert_eq!(ex, Extras::DEFAULT);
}
