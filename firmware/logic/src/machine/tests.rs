use super::*;
use crate::config::MachineConfig;
use crate::kinematics::{AnyKinematics, Kinematics, Position};
use crate::units::Milli;
use std::string::ToString;

fn at(x: i32, y: i32) -> Position {
    [Milli(x), Milli(y), Milli(0)]
}

#[test]
fn names_round_trip_and_channels_are_named_by_the_machine() {
    for m in Machine::ALL {
        assert_eq!(Machine::parse(m.name().to_string().as_bytes()), Some(m));
        assert_eq!(Machine::from_index(m as u8), Some(m));
        assert_eq!(MachineConfig::defaults(m).machine, m);
        assert_eq!(MachineConfig::defaults(m).validate(), Ok(()), "{m:?}");
    }
    assert_eq!(Machine::parse(b"SCARA"), Some(Machine::Scara));
    assert_eq!(Machine::parse(b"polar"), None);
    assert_eq!(
        Machine::StringArt.channel(Axis::Radial).to_string(),
        "radial"
    );
    assert_eq!(Machine::Whiteboard.channel(Axis::Base).to_string(), "left");
    assert_eq!(Machine::Scara.channel(Axis::Radial).to_string(), "elbow");
    assert_eq!(Machine::Drum.words(), *b"XYZ");
}

#[test]
fn the_seeds_figures() {
    let drum = MachineConfig::defaults(Machine::Drum);
    let k = AnyKinematics::of(&drum).unwrap();
    // 40 mm of belt and a whole turn of the 90 mm drum are a 28BYJ-48's
    // turn each: 4096 half-steps on its coils, at most 1000 a second.
    assert_eq!(k.inverse(&at(40_000, 282_743)).unwrap()[..2], [4096, 4096]);
    assert_eq!(drum.axes[0].travel.1, Milli(200_000));
    for axis in &drum.axes[..2] {
        assert_eq!(axis.driver, crate::config::Driver::Uln2003);
        assert_eq!(axis.max_rate, crate::config::COIL_MAX_RATE);
    }
    assert_eq!(drum.axes[2].driver, crate::config::Driver::StepDir);
    assert_eq!(drum.idle_delay_ms, 250);
    assert_eq!(flatbed_idle(), crate::config::KEEP_DRIVERS_ON);
    let flatbed = MachineConfig::defaults(Machine::Flatbed);
    let k = AnyKinematics::of(&flatbed).unwrap();
    assert_eq!(k.inverse(&at(140_000, -1_000)).unwrap()[..2], [5600, -40]);
    assert!(flatbed.axes[0].soft_limits && !flatbed.axes[1].soft_limits);
    assert_eq!(flatbed.axes[0].travel, (Milli(0), Milli(140_000)));
}

/// Every point of a drawing area goes to steps and back within a step of
/// each motor (plus the f32 rounding of the non-linear machines).
#[test]
fn inverse_then_forward_round_trips_on_every_machine() {
    // The machine, its drawing area's x and y ranges (µm), the slack (µm).
    type Area = (Machine, (i32, i32), (i32, i32), i32);
    let areas: [Area; 5] = [
        (Machine::StringArt, (-90_000, 90_000), (-100_000, 0), 40),
        (Machine::Drum, (0, 200_000), (-300_000, 300_000), 150),
        (Machine::Flatbed, (0, 140_000), (-300_000, 300_000), 30),
        (
            Machine::Whiteboard,
            (-400_000, 400_000),
            (-400_000, 100_000),
            250,
        ),
        (Machine::Scara, (0, 200_000), (50_000, 150_000), 250),
    ];
    for (m, (x0, x1), (y0, y1), within) in areas {
        let k = AnyKinematics::of(&MachineConfig::defaults(m)).unwrap();
        for i in 0..=20 {
            for j in 0..=20 {
                let p = at(x0 + (x1 - x0) / 20 * i, y0 + (y1 - y0) / 20 * j);
                let steps = k
                    .inverse(&p)
                    .unwrap_or_else(|e| panic!("{m:?} {p:?}: {e:?}"));
                let back = k.forward(&steps);
                for a in 0..2 {
                    assert!(
                        (back[a].0 - p[a].0).abs() <= within,
                        "{m:?} {p:?} came back as {back:?}"
                    );
                }
            }
        }
    }
}

#[test]
fn bad_geometry_is_refused_not_used() {
    let mut cfg = MachineConfig::defaults(Machine::Scara);
    cfg.geometry.lengths[1] = Milli(0);
    assert!(AnyKinematics::of(&cfg).is_err());
    let mut cfg = MachineConfig::defaults(Machine::Whiteboard);
    cfg.geometry.origin[1] = Milli(10_000); // above the motors
    assert!(AnyKinematics::of(&cfg).is_err());
}

fn flatbed_idle() -> u8 {
    MachineConfig::defaults(Machine::Flatbed).idle_delay_ms
}
