//! The per-segment costs `cargo xtask bench` reports, on the AVR: the
//! status LED (D13) is high while each batch of 64 runs, so the harness
//! reads the cycles from its edges. In turn: polargraph (whiteboard)
//! inverses, SCARA inverses, and chords of a 1 mm-radius circle cut,
//! converted and planned on the flatbed as the console does it.
#![no_std]
#![no_main]

use core::hint::black_box;
use panic_halt as _;
use taut_logic::arc::{Arc, Plane, Sweep};
use taut_logic::config::MachineConfig;
use taut_logic::kinematics::{AnyKinematics, Kinematics};
use taut_logic::machine::Machine;
use taut_logic::planner::{Feed, Planner};
use taut_logic::units::Milli;

/// Operations a batch.
const N: i32 = 64;

#[avr_device::entry]
fn main() -> ! {
    let dp = avr_device::atmega2560::Peripherals::take().unwrap();
    dp.PORTB.ddrb().write(|w| w.pb7().set_bit());
    let led = |on: bool| dp.PORTB.portb().write(|w| w.pb7().bit(on));
    for machine in [Machine::Whiteboard, Machine::Scara] {
        let cfg = MachineConfig::defaults(machine);
        let kin = AnyKinematics::of(&cfg).unwrap();
        led(true);
        for i in 0..N {
            let p = [Milli(50_000 + i * 100), Milli(120_000 - i * 50), Milli(0)];
            let _ = black_box(kin.inverse(black_box(&p)));
        }
        led(false);
    }
    let cfg = MachineConfig::defaults(Machine::Flatbed);
    let kin = AnyKinematics::of(&cfg).unwrap();
    let mut planner = Planner::new(&cfg);
    let start = [Milli(11_000), Milli(10_000), Milli(0)];
    let sweep = Sweep {
        start,
        end: start,
        plane: Plane {
            axis_0: 0,
            axis_1: 1,
            linear: Some(2),
        },
        clockwise: false,
        tolerance: Milli(cfg.arc_tolerance_um as i32),
    };
    let circle = Arc::from_centre(black_box(&sweep), [Milli(-1000), Milli(0)]).unwrap();
    let mut arc = circle;
    let feed = Feed::PerMinute(Milli(3_000_000));
    led(true);
    for _ in 0..N {
        // Round and round: 12 chords a turn.
        let p = match arc.next() {
            Some(p) => p,
            None => {
                arc = circle;
                arc.next().unwrap()
            }
        };
        if let Ok(steps) = kin.inverse(&p) {
            if planner.push(steps, feed).is_err() {
                let _ = black_box(planner.take());
                let _ = planner.push(steps, feed);
            }
        }
    }
    led(false);
    loop {
        avr_device::asm::sleep();
    }
}
