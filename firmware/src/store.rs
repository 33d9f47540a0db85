//! The machine's settings kept in EEPROM (`taut_logic::settings::image`):
//! read at power-on, and written back after a `$` change by the `Store`
//! task, one changed byte per run (a byte takes 3.4 ms to write: the task
//! comes back rather than wait). Only bytes that differ are written.
#![deny(unsafe_code)]

use crate::board::eeprom::Eeprom;
use crate::queues::{Signal, TX};
use crate::rt::Poll;
use crate::{flash_str, warn};
use taut_logic::config::MachineConfig;
use taut_logic::settings::image::{self, Unusable};

pub struct Store {
    eeprom: Eeprom,
    /// Why the stored settings were not used, to say once there is room
    /// for the line (it must not be dropped, and the boot fills the TX
    /// ring).
    unusable: Option<Unusable>,
}

impl Store {
    pub fn new(eeprom: Eeprom) -> Store {
        Store {
            eeprom,
            unusable: None,
        }
    }

    /// The settings in EEPROM, or `defaults` when they cannot be used: the
    /// task's first run then says why in one warning line and writes the
    /// defaults. True when the task must run.
    pub fn load(&mut self, defaults: &MachineConfig) -> (MachineConfig, bool) {
        match image::decode(|i| self.eeprom.read(i as u16), defaults) {
            Ok(cfg) => (cfg, false),
            Err(why) => {
                self.unusable = Some(why);
                (*defaults, true)
            }
        }
    }

    fn warn(why: Unusable) {
        let text = match why {
            Unusable::Blank => flash_str!("blank"),
            Unusable::OtherVersion(_) => flash_str!("from another firmware version"),
            Unusable::Checksum => flash_str!("corrupt (checksum)"),
            Unusable::Refused(_) | Unusable::Inconsistent => {
                flash_str!("holding values this firmware refuses")
            }
        };
        warn!("settings: EEPROM ", text, ": defaults");
    }

    /// Write the next byte of `cfg`'s image that differs from the EEPROM;
    /// `Wait(Settings)` once they all agree.
    pub fn poll(&mut self, cfg: &MachineConfig) -> Poll<Signal> {
        if let Some(why) = self.unusable {
            if TX.free() < crate::log::LINE {
                return Poll::After(5);
            }
            self.unusable = None;
            Self::warn(why);
        }
        if self.eeprom.busy() {
            return Poll::After(4);
        }
        match image::first_difference(cfg, |i| self.eeprom.read(i as u16)) {
            Some((i, b)) => {
                self.eeprom.start_write(i as u16, b);
                Poll::After(4)
            }
            None => Poll::Wait(Signal::Settings),
        }
    }
}
