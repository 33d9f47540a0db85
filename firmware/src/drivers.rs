//! The drivers' ENABLE inputs (TB6600 ENA) and a coil axis's coils: a
//! motor's holding current on and off, with the ENABLE-to-DIR set-up time
//! kept.
//!
//! As Grbl's and Marlin's: motion switches the drivers of the axes it moves
//! on ([`Drivers::wake`], before the step interrupt gets the move), and
//! once the machine stands for the step idle delay (`$1`, ms; 255 keeps
//! them on; `M18 S`/`M84 S` seconds until the next reset) they go off
//! again. A driver switched on by `M17` or the string-art job stays on
//! through any wait (it holds); `M18`/`M84`, `$SLP` and the job switch
//! drivers off, and the job never moves an axis it holds off (the drill
//! while winding, an axis freed for zeroing by hand).

use crate::board::delay::Delay;
use crate::board::gpio::{Output, Pin};
use crate::stepper;
use embedded_hal::delay::DelayNs;
use embedded_hal::digital::OutputPin;
use taut_logic::axis::AXES;
use taut_logic::config::{Driver, MachineConfig, KEEP_DRIVERS_ON};
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

/// The idle delay that never comes.
const KEEP: u32 = u32::MAX;

pub struct Drivers {
    pins: EnablePins,
    /// ENABLE high switches the driver on (bit = axis).
    active_high: u8,
    /// Axes driven through their coils.
    coils: u8,
    setup_us: u32,
    /// Drivers on (bit = axis): the set-up wait is only for one coming on.
    on: u8,
    /// Drivers switched on by `M17` or the job: the idle delay leaves them.
    held: u8,
    /// ms from the machine standing to the drivers going off, or [`KEEP`].
    delay_ms: u32,
    /// The `$1` that `delay_ms` came from: `M18 S` overrides it until `$1`
    /// changes or the board resets.
    delay_setting: u8,
    /// When the machine was first seen standing with drivers to release.
    since: Option<u32>,
}

impl Drivers {
    /// All drivers start off.
    pub fn new(pins: EnablePins, config: &MachineConfig) -> Drivers {
        let mut d = Drivers {
            pins,
            active_high: 0,
            coils: 0,
            setup_us: 0,
            on: 0,
            held: 0,
            delay_ms: KEEP,
            delay_setting: KEEP_DRIVERS_ON,
            since: None,
        };
        // Every pin written: all off.
        d.configure(config);
        d
    }

    /// Take `config`'s polarity, drivers and idle delay (after the
    /// stepper's). Only while the machine stands.
    pub fn configure(&mut self, config: &MachineConfig) {
        self.active_high = 0;
        self.coils = 0;
        for i in 0..AXES {
            self.active_high |= (config.axes[i].enable_active_high as u8) << i;
            self.coils |= ((config.axes[i].driver == Driver::Uln2003) as u8) << i;
        }
        self.setup_us = config.pulse.enable_setup_us as u32;
        if config.idle_delay_ms != self.delay_setting {
            self.delay_setting = config.idle_delay_ms;
            self.delay_ms = match config.idle_delay_ms {
                KEEP_DRIVERS_ON => KEEP,
                ms => ms as u32,
            };
        }
        // Every pin again: the polarity or the drive may have changed
        // (an axis now on coils has them energised if its driver is on).
        let on = self.on;
        self.switch(!on, false);
        self.switch(on, true);
    }

    /// Switch the drivers in `mask` on or off, as `M17`/`M18` or the job
    /// asks: on, they hold through the idle delay; off, the next motion
    /// switches them on again.
    pub fn set(&mut self, mask: u8, on: bool) {
        self.switch(mask, on);
        match on {
            true => self.held |= mask,
            false => self.held &= !mask,
        }
    }

    /// The axes in `mask` are about to move: their drivers on. Called
    /// before a move's first step is queued for the step interrupt.
    #[inline(always)]
    pub fn wake(&mut self, mask: u8) {
        let off = mask & !self.on;
        if off != 0 {
            self.switch(off, true);
        }
    }

    /// `M18 S`/`M84 S`: the idle delay, ms (0: keep the drivers on).
    pub fn set_delay(&mut self, ms: u32) {
        self.delay_ms = match ms {
            0 => KEEP,
            ms => ms,
        };
    }

    /// The machine moves (or the step interrupt has just started).
    pub fn moving(&mut self) {
        self.since = None;
    }

    /// Called with the time whenever segment preparation finds the machine
    /// standing (nothing queued, no step running; [`Drivers::moving`]
    /// otherwise): once it has stood for the idle delay, the drivers that
    /// do not hold go off. Returns the ms until it should be called again,
    /// if drivers wait to go off.
    pub fn idle(&mut self, now_ms: u32) -> Option<u32> {
        let loose = self.on & !self.held;
        if loose == 0 || self.delay_ms == KEEP {
            self.since = None;
            return None;
        }
        let since = *self.since.get_or_insert(now_ms);
        let waited = now_ms.wrapping_sub(since);
        // The clock counts whole ms: a tick more, never less than the
        // delay (none for 0, Grbl's "at once").
        let due = self.delay_ms + (self.delay_ms != 0) as u32;
        if waited >= due {
            self.switch(loose, false);
            self.since = None;
            return None;
        }
        Some(due - waited)
    }

    /// Set the ENABLE pins (and coils) of `mask`. After switching one on,
    /// wait the set-up time so a DIR change right after is seen.
    #[inline(never)]
    fn switch(&mut self, mask: u8, on: bool) {
        let before = self.on;
        for i in 0..AXES {
            if mask >> i & 1 == 0 {
                continue;
            }
            let level = on == (self.active_high >> i & 1 != 0);
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
        stepper::coils(mask & self.coils, on);
        if self.on & !before != 0 {
            Delay.delay_us(self.setup_us);
        }
    }
}
