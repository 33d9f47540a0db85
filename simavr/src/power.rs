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

use crate::Sim;
use simavr_ffi as ffi;
use std::os::raw::c_void;

/// EECR's data address, and EEAR's.
const EECR: u16 = 0x3F;
const EEARL: usize = 0x41;
const EEARH: usize = 0x42;
/// EECR: EEMPE and EEPE together start a byte's write.
const START_WRITE: u8 = 0b110;
/// Cycles an EEPROM byte takes to erase and write (3.4 ms at 16 MHz).
pub const WRITE_CYCLES: u64 = 54_400;

/// What the EECR hook saw.
#[derive(Default)]
pub(crate) struct EepromWatch {
    /// Byte writes started.
    pub writes: u64,
    /// The last one: address, and simavr's cycle counter then.
    pub last: Option<(u16, u64)>,
}

/// Called after simavr's own EEPROM module for every write to EECR.
///
/// # Safety
/// `param` is the `EepromWatch` boxed in the `Sim` that owns `avr`, which
/// outlives the avr_t's callbacks; `avr` is that live avr_t.
unsafe extern "C" fn on_eecr(avr: *mut ffi::avr_t, _addr: u16, v: u8, param: *mut c_void) {
    if v & START_WRITE != START_WRITE {
        return;
    }
    // SAFETY: see the function's contract; `data` spans the I/O space.
    unsafe {
        let w = &mut *(param as *mut EepromWatch);
        let data = (*avr).data;
        let at = u16::from_le_bytes([*data.add(EEARL), *data.add(EEARH)]) & 0x0FFF;
        w.writes += 1;
        w.last = Some((at, (*avr).cycle));
    }
}

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
