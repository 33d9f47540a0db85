//! A Mega 2560 as it comes from the shop: its flash holds the stock
//! bootloader (an Intel hex file) in the boot section, the fuses make every
//! reset start there (BOOTRST), the lock bits keep the boot section out of
//! reach of SPM, and the RESET pin is pulsed when a host opens the USB
//! serial port (the auto-reset capacitor on DTR: [`Sim::reset_external`]).
//!
//! simavr runs SPM itself (its `avr_flash` module: temporary page buffer,
//! page erase, page write, RWW re-enable, signature and fuse reads); what
//! it lacks is the part's rules about *who* may write *where*. A small I/O
//! module put at the head of simavr's module list sees every SPM first and
//! refuses, as the silicon does, an SPM executed outside the boot section
//! and a page erase or write of the boot section (lock bits BLB1 mode 3,
//! as the Arduino Mega ships). Not modelled: the lock bits' read side (LPM
//! from the application into the boot section) and the 3.7–4.5 ms a page
//! erase or write takes (simavr finishes it at once: the bootloader's busy
//! wait ends at once). Erased flash (0xFFFF) decodes as `sbrs r31, 7` in
//! simavr as on the part, so execution runs through it to the next
//! programmed word: a board without an application is back in its
//! bootloader a few milliseconds after the bootloader gives up waiting.

use crate::hooks::SpmGuard;
use crate::sim::Sim;
use crate::{Error, Result};
use simavr_ffi as ffi;
use std::path::Path;

/// Bytes of flash of the ATmega2560.
pub const FLASH_BYTES: u32 = 0x4_0000;

/// MCUSR in data space, and its external reset flag.
const MCUSR: usize = 0x54;
const EXTRF: u8 = 1 << 1;

/// The fuse and lock bytes (as avrdude names them).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fuses {
    pub low: u8,
    pub high: u8,
    pub extended: u8,
    pub lock: u8,
}

impl Fuses {
    /// The Arduino Mega 2560's (its `boards.txt`): external crystal, boot
    /// section 4096 words with reset into it (high 0xD8), brown-out at
    /// 2.7 V (extended 0xFD), SPM kept out of the boot section (lock 0x0F).
    pub const MEGA2560: Fuses = Fuses {
        low: 0xFF,
        high: 0xD8,
        extended: 0xFD,
        lock: 0x0F,
    };

    /// First byte of the boot section: BOOTSZ (high fuse bits 2:1, 00 =
    /// 4096 words) counts down from the end of flash.
    pub fn boot_start(self) -> u32 {
        let bootsz = u32::from(self.high >> 1) & 3;
        let words = 512 << (3 - bootsz);
        FLASH_BYTES - 2 * words
    }

    /// BOOTRST programmed (0): a reset starts at the boot section.
    pub fn reset_into_boot(self) -> bool {
        self.high & 1 == 0
    }

    /// BLB1 mode 2 or 3 (lock bits 5:4 = 10 or 00): SPM may not write the
    /// boot section.
    pub fn boot_section_locked(self) -> bool {
        self.lock & 0x10 == 0
    }
}

/// The bytes an Intel hex file puts in flash, as (address, bytes) runs.
pub fn read_hex(path: &Path) -> Result<Vec<(u32, Vec<u8>)>> {
    use ihex::Record;
    let text = std::fs::read_to_string(path).map_err(|e| Error::Io(path.to_owned(), e))?;
    let bad = |e: String| Error::Elf(format!("{}: {e}", path.display()));
    let mut base = 0u32;
    let mut runs = Vec::new();
    for record in ihex::Reader::new(&text) {
        match record.map_err(|e| bad(e.to_string()))? {
            Record::Data { offset, value } => runs.push((base + u32::from(offset), value)),
            Record::ExtendedSegmentAddress(s) => base = u32::from(s) << 4,
            Record::ExtendedLinearAddress(a) => base = u32::from(a) << 16,
            Record::EndOfFile => break,
            Record::StartSegmentAddress { .. } | Record::StartLinearAddress(_) => {}
        }
    }
    if let Some((at, bytes)) = runs
        .iter()
        .find(|(at, bytes)| at + bytes.len() as u32 > FLASH_BYTES)
    {
        return Err(bad(format!(
            "{} bytes at {at:#x} run past the end of flash",
            bytes.len()
        )));
    }
    Ok(runs)
}

impl Sim {
    /// A Mega 2560 with the stock fuses and lock bits ([`Fuses::MEGA2560`]):
    /// `bootloader` (an Intel hex file, e.g. Debian's
    /// `stk500boot_v2_mega2560.hex`) in the boot section, and in the
    /// application section the firmware ELF `app` (as `avrdude -U flash:w`
    /// left it) or nothing (erased, as a new board from the factory with
    /// only its bootloader). Power-on starts the bootloader.
    ///
    /// The harness's instruction traps (`traps`) are left out: the code
    /// changes under SPM and is read back by avrdude, so flash holds
    /// exactly what was written. The interrupts-masked figures and the
    /// crash at address 0 are therefore not watched on such a board.
    pub fn with_bootloader(bootloader: &Path, app: Option<&Path>) -> Result<Sim> {
        let fuses = Fuses::MEGA2560;
        let runs = read_hex(bootloader)?;
        let boot_start = fuses.boot_start();
        if let Some((at, _)) = runs.iter().find(|(at, _)| *at < boot_start) {
            return Err(Error::Elf(format!(
                "{}: bytes at {at:#x}, below the boot section ({boot_start:#x})",
                bootloader.display()
            )));
        }
        let mut sim = match app {
            Some(elf) => Sim::load_plain(elf)?,
            None => Sim::blank()?,
        };
        for (at, mut bytes) in runs {
            sim.load_flash(at, &mut bytes);
        }
        let mut guard = SpmGuard::new(boot_start, fuses.boot_section_locked());
        let avr = sim.avr_raw();
        // SAFETY: `avr` is live; the guard is boxed (stable address) and
        // kept in the Sim until it drops, after avr_terminate has unlinked
        // every module (it frees nothing of ours: no IRQs, no dealloc).
        // Put first in the list, its ioctl sees each SPM before simavr's
        // flash module.
        unsafe {
            guard.io.avr = avr;
            guard.io.next = (*avr).io_port;
            (*avr).io_port = &mut guard.io;
            (*avr).fuse[0] = fuses.low;
            (*avr).fuse[1] = fuses.high;
            (*avr).fuse[2] = fuses.extended;
            (*avr).lockbits = fuses.lock;
            if fuses.reset_into_boot() {
                (*avr).reset_pc = boot_start;
                (*avr).pc = boot_start;
            }
            (*avr).codeend = (*avr).flashend;
        }
        sim.spm_guard = Some(guard);
        Ok(sim)
    }

    /// SPMs the part refused so far: executed outside the boot section, or
    /// erasing or writing the (locked) boot section.
    pub fn spm_refused(&self) -> u32 {
        self.shared().spm_refused
    }

    /// The RESET pin pulsed (the reset button; on a Mega, a host opening
    /// the USB serial port: DTR through the auto-reset capacitor): EXTRF
    /// set in MCUSR, the I/O registers and the core reset, execution from
    /// the reset vector (the boot section with BOOTRST). SRAM, EEPROM and
    /// flash keep their contents, as on the part.
    pub fn reset_external(&mut self) {
        let avr = self.avr_raw();
        // SAFETY: `avr` is live; `data` spans the I/O space; no reference
        // into `Shared` is held across `avr_reset`.
        unsafe {
            *(*avr).data.add(MCUSR) |= EXTRF;
            let before = (*avr).cycle;
            ffi::avr_reset(avr);
            self.after_reset(before);
        }
        self.external_resets += 1;
    }

    /// External resets so far ([`Sim::reset_external`]).
    pub fn external_resets(&self) -> u32 {
        self.external_resets
    }

    /// A fault: execution goes on at byte address `pc`, as a stray jump,
    /// or a panic's endless loop (`abort`), would take it there. For tests
    /// of what follows (the watchdog, the bootloader).
    pub fn jump_to(&mut self, pc: u32) {
        let avr = self.avr_raw();
        // SAFETY: `avr` is live; simavr reads `pc` at the next instruction.
        unsafe { (*avr).pc = pc };
    }

    /// `len` bytes of flash from byte address `at` (as avrdude would read
    /// them back).
    pub fn flash(&self, at: u32, len: usize) -> Vec<u8> {
        assert!(
            at as usize + len <= FLASH_BYTES as usize,
            "past the end of flash"
        );
        let avr = self.avr_raw();
        // SAFETY: `flash` holds `flashend + 1` = FLASH_BYTES bytes.
        unsafe { std::slice::from_raw_parts((*avr).flash.add(at as usize), len).to_vec() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mega_fuses_put_8_kib_of_boot_section_at_the_top() {
        let f = Fuses::MEGA2560;
        assert_eq!(f.boot_start(), 0x3_E000);
        assert!(f.reset_into_boot());
        assert!(f.boot_section_locked());
        let unlocked = Fuses {
            lock: 0x3F,
            high: 0xD9,
            ..f
        };
        assert!(!unlocked.reset_into_boot() && !unlocked.boot_section_locked());
        assert_eq!(Fuses { high: 0xDE, ..f }.boot_start(), 0x3_FC00);
    }

    #[test]
    fn hex_records_land_at_their_addresses() {
        let path = std::env::temp_dir().join(format!("taut-hex-{}.hex", std::process::id()));
        // Extended segment 0x3000 (base 0x30000), 2 bytes at 0xE000.
        std::fs::write(&path, ":020000023000CC\n:02E00000AABBB9\n:00000001FF\n").unwrap();
        assert_eq!(read_hex(&path).unwrap(), vec![(0x3_E000, vec![0xAA, 0xBB])]);
        std::fs::write(&path, ":02E00000AABBBA\n:00000001FF\n").unwrap();
        assert!(read_hex(&path).is_err(), "bad checksum");
        std::fs::remove_file(&path).unwrap();
    }
}
