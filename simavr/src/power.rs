//! Power cuts: the run stops where it is, and only the EEPROM survives,
//! as the cut leaves it.
//!
//! simavr commits an EEPROM byte the moment the firmware sets EEPE (and
//! clears EEPE at once); the real part erases and writes it for 3.4 ms.
//! So "a cut in the middle of an EEPROM write" here is: between two bytes
//! of a record the firmware writes byte by byte (the bytes before the cut
//! new, those after it old, as on the real part), or within 3.4 ms of a
//! byte's start, which leaves that byte torn: [`Sim::eeprom_after_cut`]
//! puts the value given (erased 0xFF, a half-written pattern) in its place.

use crate::hooks::{on_eecr, EepromWatch};
use crate::Sim;
use simavr_ffi as ffi;
use std::os::raw::c_void;

/// EECR's data address.
const EECR: u16 = 0x3F;
/// Cycles an EEPROM byte takes to erase and write (3.4 ms at 16 MHz).
pub const WRITE_CYCLES: u64 = 54_400;

impl Sim {
    /// Watch the EEPROM's byte writes from now on (for power cuts in the
    /// middle of one); idempotent.
    pub fn watch_eeprom(&mut self) {
        if self.eeprom_watch.is_some() {
            return;
        }
        let watch = Box::new(EepromWatch::default());
        let param = &*watch as *const EepromWatch as *mut c_void;
        self.eeprom_watch = Some(watch);
        // SAFETY: the box is kept in the Sim until it drops, after the
        // avr_t is terminated; the callback matches simavr's signature and
        // simavr chains it after the EEPROM module's own.
        unsafe { ffi::avr_register_io_write(self.avr_raw(), EECR, Some(on_eecr), param) };
    }

    /// EEPROM byte writes started since [`Sim::watch_eeprom`].
    pub fn eeprom_writes(&self) -> u64 {
        self.eeprom_watch.as_ref().map_or(0, |w| w.writes)
    }

    /// The byte being written now (within its 3.4 ms), if any.
    pub fn eeprom_writing(&self) -> Option<u16> {
        let (at, cycle) = self.eeprom_watch.as_ref()?.last?;
        let now = self.avr_cycle();
        (now >= cycle && now - cycle < WRITE_CYCLES).then_some(at)
    }

    /// The EEPROM as a power cut now leaves it: a byte still being written
    /// holds `torn`. Returns the image and the torn byte's address.
    pub fn eeprom_after_cut(&self, torn: u8) -> (Vec<u8>, Option<u16>) {
        let mut image = self.eeprom();
        let at = self.eeprom_writing();
        if let Some(at) = at {
            image[at as usize] = torn;
        }
        (image, at)
    }
}
