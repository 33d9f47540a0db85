//! The drivers' ENABLE inputs (TB6600 ENA): switching a motor's holding
//! current on and off, with the ENABLE-to-DIR set-up time kept.
#![deny(unsafe_code)]

use crate::board::delay::Delay;
use crate::board::gpio::{Output, Pin};
use embedded_hal::delay::DelayNs;
use embedded_hal::digital::OutputPin;
use taut_logic::axis::{PerAxis, AXES};
use taut_logic::config::MachineConfig;
use taut_logic::pinmap::DRIVERS;

/// RAMPS X/Y/Z ENABLE pins (see `taut_logic::pinmap::DRIVERS`).
pub struct EnablePins {
    pub base: Pin<38, Output>,
    pub radial: Pin<56, Output>,
    pub drill: Pin<62, Output>,
}

const _: () = {
    assert!(DRIVERS[0].enable == 38 && DRIVERS[1].enable == 56);
    assert!(DRIVERS[2].enable == 62);
};

pub struct Drivers {
    pins: EnablePins,
    active_high: PerAxis<bool>,
    setup_us: u32,
    /// Drivers on (bit = axis): the set-up wait is only for one coming on.
    on: u8,
}

impl Drivers {
    /// All drivers start off.
    pub fn new(pins: EnablePins, config: &MachineConfig) -> Drivers {
        let mut d = Drivers {
            pins,
            active_high: [true; AXES],
            setup_us: config.pulse.enable_setup_us as u32,
            on: 0xFF,
        };
        d.configure(config);
        d.set(0xFF, false);
        d
    }

    pub fn configure(&mut self, config: &MachineConfig) {
        for i in 0..AXES {
            self.active_high[i] = config.axes[i].enable_active_high;
        }
        self.setup_us = config.pulse.enable_setup_us as u32;
    }

    /// Switch the drivers in `mask` on or off. After switching one on, wait
    /// the set-up time so a DIR change right after is seen.
    pub fn set(&mut self, mask: u8, on: bool) {
        let before = self.on;
        for i in 0..AXES {
            if mask >> i & 1 == 0 {
                continue;
            }
            let level = on == self.active_high[i];
            let _ = match i {
                0 => self.pins.base.set_state(level.into()),
                1 => self.pins.radial.set_state(level.into()),
                _ => self.pins.drill.set_state(level.into()),
            };
            if on {
                self.on |= 1 << i;
            } else {
                self.on &= !(1 << i);
            }
        }
        if self.on & !before != 0 {
            Delay.delay_us(self.setup_us);
        }
    }
}
