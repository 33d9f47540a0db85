//! Against Grbl 1.1's interface document (`doc/markdown/interface.md`,
//! "Real-time Status Reports"), whose lines are quoted.

use super::*;
use crate::text::error::tests::show;
use std::format;
use std::vec::Vec;

fn idle() -> Status {
    Status {
        state: State::Idle,
        position: [Milli::ZERO; 3],
        wco: [Milli::ZERO; 3],
        angles: 0,
        feed: Milli::ZERO,
        buffer: (15, 128),
        pins: 0,
        overrides: Overrides::NONE,
        extra: Extra::None,
        fields: 1,
        inches: false,
    }
}

/// "Valid states types: `Idle, Run, Hold, Jog, Alarm, Door, Check, Home,
/// Sleep`"; "`Hold:0` Hold complete. Ready to resume. `Hold:1` Hold
/// in-progress."; "`Door:0` Door closed. Ready to resume." "`Door:2` Door
/// opened. Hold (or parking retract) in-progress."
#[test]
fn every_state_in_grbl_s_words() {
    let words = [
        (State::Idle, "Idle"),
        (State::Run, "Run"),
        (State::Hold { standing: true }, "Hold:0"),
        (State::Hold { standing: false }, "Hold:1"),
        (State::Jog, "Jog"),
        (State::Alarm, "Alarm"),
        (State::Door { standing: true }, "Door:0"),
        (State::Door { standing: false }, "Door:2"),
        (State::Check, "Check"),
        (State::Home, "Home"),
        (State::Sleep, "Sleep"),
    ];
    for (state, word) in words {
        assert_eq!(show(&state), word);
        let report = show(&Status { state, ..idle() });
        assert_eq!(report, format!("<{word}|MPos:0.000,0.000,0.000|FS:0,0>"));
    }
}

/// "`<Idle|MPos:0.000,0.000,0.000|FS:0,0|WCO:0.000,0.000,0.000>`",
/// "`<Idle|MPos:0.000,0.000,0.000|FS:0,0|Ov:100,100,100>`": the work
/// offset and the overrides in separate reports; "Buffer State:
/// `Bf:15,128`", "Feed and Speed: `FS:500,8000`", "Input Pin State:
/// `Pn:XYZPDHRS`" (only the pins that are on, absent when none is).
#[test]
fn the_fields_in_grbl_s_order_and_format() {
    assert_eq!(
        show(&Status {
            extra: Extra::Wco,
            ..idle()
        }),
        "<Idle|MPos:0.000,0.000,0.000|FS:0,0|WCO:0.000,0.000,0.000>"
    );
    assert_eq!(
        show(&Status {
            extra: Extra::Ov,
            ..idle()
        }),
        "<Idle|MPos:0.000,0.000,0.000|FS:0,0|Ov:100,100,100>"
    );
    let run = Status {
        state: State::Run,
        position: [Milli(23_036), Milli(1_620), Milli(-450_000)],
        feed: Milli(499_600),
        buffer: (12, 100),
        pins: 0b101,
        overrides: Overrides {
            feed: 110,
            rapid: 50,
        },
        extra: Extra::Ov,
        fields: 3,
        ..idle()
    };
    assert_eq!(
        show(&run),
        "<Run|MPos:23.036,1.620,-450.000|Bf:12,100|FS:500,0|Pn:XZ|Ov:110,50,100>"
    );
}

/// `$10`: "`0` Enable `WPos:` Disable `MPos:`", "`1` Enable `MPos:`",
/// "`2` Enabled Buffer Data: `Bf:`"; `$13` reports in inches, four
/// decimals for positions ("`MPos:0.0000,…`" in inch mode) and one for
/// rates. An angle stays in degrees.
#[test]
fn dollar_10_chooses_the_fields_and_dollar_13_inches() {
    let s = Status {
        position: [Milli(25_400), Milli(-1_000), Milli(90_000)],
        feed: Milli(2_540_000),
        ..idle()
    };
    let with = |fields, inches| {
        show(&Status {
            fields,
            inches,
            ..s
        })
    };
    assert_eq!(with(0, false), "<Idle|WPos:25.400,-1.000,90.000|FS:2540,0>");
    assert_eq!(
        with(3, false),
        "<Idle|MPos:25.400,-1.000,90.000|Bf:15,128|FS:2540,0>"
    );
    assert_eq!(
        with(2, false),
        "<Idle|WPos:25.400,-1.000,90.000|Bf:15,128|FS:2540,0>"
    );
    assert_eq!(
        with(1, true),
        "<Idle|MPos:1.0000,-0.0394,3.5433|FS:100.0,0>"
    );
    // The string-art base in Y's place turns in degrees.
    let art = Status {
        angles: 0b010,
        inches: true,
        ..s
    };
    assert_eq!(show(&art), "<Idle|MPos:1.0000,-1.000,3.5433|FS:100.0,0>");
}

/// Grbl's refresh: `WCO:` every 10th report while idle (30th busy),
/// `Ov:` every 10th (20th), never both at once, and `Ov:` in the report
/// after the overrides change.
#[test]
fn the_work_offset_and_overrides_come_every_so_often() {
    let extras = |r: &mut Refresh, busy, n| (0..n).map(|_| r.next(busy)).collect::<Vec<_>>();
    let mut r = Refresh::new();
    let idle = extras(&mut r, false, 21);
    let at = |e: Extra| -> Vec<usize> {
        idle.iter()
            .enumerate()
            .filter(|(_, x)| **x == e)
            .map(|(i, _)| i)
            .collect()
    };
    assert_eq!(at(Extra::Wco), [0, 10, 20]);
    assert_eq!(at(Extra::Ov), [1, 11]);
    let mut r = Refresh::new();
    let busy = extras(&mut r, true, 50);
    let count = |e| busy.iter().filter(|x| **x == e).count();
    assert_eq!((count(Extra::Wco), count(Extra::Ov)), (2, 3));
    r.overrides_changed();
    assert_eq!(r.next(true), Extra::Ov);
}

/// "0x90 : Set 100% of programmed rate.", "0x91 : Increase 10%", "0x92 :
/// Decrease 10%", "0x93 : Increase 1%", "0x94 : Decrease 1%", "0x95 : Set
/// to 100% full rapid rate.", "0x96 : Set to 50% of rapid rate.", "0x97 :
/// Set to 25% of rapid rate."; "Feed override ... values ... 10% to 200%".
#[test]
fn override_bytes_step_and_clamp_as_grbl_s() {
    let bit = |byte: u8| 1 << (byte - OVERRIDE_BYTES);
    let mut o = Overrides::NONE;
    assert!(!o.apply(0));
    assert!(o.apply(bit(0x91)));
    assert_eq!(o.feed, 110);
    assert!(o.apply(bit(0x94)));
    assert_eq!(o.feed, 109);
    for _ in 0..20 {
        o.apply(bit(0x91));
    }
    assert_eq!(o.feed, 200);
    assert!(!o.apply(bit(0x91)), "already at 200 %");
    for _ in 0..30 {
        o.apply(bit(0x92));
    }
    assert_eq!(o.feed, 10);
    o.apply(bit(0x93));
    assert_eq!(o.feed, 11);
    // Reset, then the coarse and fine steps that came with it.
    o.apply(bit(0x90) | bit(0x91) | bit(0x93));
    assert_eq!(o.feed, 111);
    // Presses counted apart: five 0x92 that came before one report are
    // five steps down, not one.
    assert!(o.apply_counted(bit(0x92), -50));
    assert_eq!(o.feed, 61);
    o.apply_counted(bit(0x90) | bit(0x91), 20);
    assert_eq!(o.feed, 120, "reset, then the presses after it");
    o.apply(bit(0x96));
    assert_eq!(o.rapid, 50);
    o.apply(bit(0x97));
    assert_eq!(o.rapid, 25);
    o.apply(bit(0x95));
    assert_eq!(
        o,
        Overrides {
            feed: 120,
            rapid: 100
        }
    );
}

/// report.c line 510: `WPos` is the machine position less the work
/// offset (`WCO` = the work system's + `G92`'s + the tool length's); the
/// `WCO:` field carries the offset itself, in the report's units.
#[test]
fn the_work_position_is_the_machine_position_less_the_offset() {
    let s = Status {
        position: [Milli(70_000), Milli(100_000), Milli(0)],
        wco: [Milli(70_000), Milli(90_000), Milli(-1_500)],
        fields: 0,
        extra: Extra::Wco,
        ..idle()
    };
    assert_eq!(
        show(&s),
        "<Idle|WPos:0.000,10.000,1.500|FS:0,0|WCO:70.000,90.000,-1.500>"
    );
    assert_eq!(
        show(&Status { fields: 1, ..s }),
        "<Idle|MPos:70.000,100.000,0.000|FS:0,0|WCO:70.000,90.000,-1.500>"
    );
}

/// `Refresh::wco_changed`: the next report carries `WCO:` (Grbl's
/// `system_flag_wco_change` sets its counter to 0).
#[test]
fn a_changed_work_offset_is_in_the_next_report() {
    let mut r = Refresh::new();
    assert_eq!(r.next(false), Extra::Wco);
    for _ in 0..5 {
        assert_ne!(r.next(true), Extra::Wco);
    }
    r.wco_changed();
    assert_eq!(r.next(true), Extra::Wco);
}
