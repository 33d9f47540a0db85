//! The ATmega2560's 4 KiB EEPROM: byte reads, and byte writes that start
//! and return at once (a write takes 3.4 ms; the caller comes back when
//! [`Eeprom::busy`] is false instead of waiting). Cells are rated for
//! ~100 000 writes: callers write only the bytes that change.

use core::arch::asm;
use core::ptr::{read_volatile, write_volatile};

/// EEPROM size, bytes.
pub const BYTES: u16 = 4096;

/// I/O address of EECR (for `sbi`/`sbic`); data addresses of the rest.
const EECR_IO: u8 = 0x1F;
const EECR: *mut u8 = 0x3F as *mut u8;
const EEDR: *mut u8 = 0x40 as *mut u8;
const EEARL: *mut u8 = 0x41 as *mut u8;
const EEARH: *mut u8 = 0x42 as *mut u8;
/// EECR: write in progress.
const EEPE: u8 = 1 << 1;

/// Owner of the EEPROM: constructing it takes the peripheral.
pub struct Eeprom(());

impl Eeprom {
    pub fn new(_eeprom: avr_device::atmega2560::EEPROM) -> Eeprom {
        Eeprom(())
    }

    /// A write is still in progress.
    pub fn busy(&self) -> bool {
        // SAFETY: reading EECR has no side effect.
        unsafe { read_volatile(EECR) & EEPE != 0 }
    }

    /// Byte `addr`; waits for a write in progress to end (callers check
    /// [`Eeprom::busy`] first where that matters).
    /// Inlined: the settings image is read a byte at a time.
    #[inline(always)]
    pub fn read(&self, addr: u16) -> u8 {
        while self.busy() {}
        // SAFETY: the EEPROM registers belong to this owner; setting EERE
        // (bit 0) reads the byte at EEAR into EEDR, halting the CPU 4 cycles.
        unsafe {
            write_volatile(EEARH, (addr >> 8) as u8);
            write_volatile(EEARL, addr as u8);
            asm!("sbi {eecr}, 0", eecr = const EECR_IO, options(nostack));
            read_volatile(EEDR)
        }
    }

    /// Start writing `byte` at `addr` (erase and write, 3.4 ms); returns at
    /// once. Waits for a write in progress first.
    pub fn start_write(&mut self, addr: u16, byte: u8) {
        while self.busy() {}
        avr_device::interrupt::free(|_| {
            // SAFETY: the EEPROM registers belong to this owner. EEMPE, then
            // EEPE within four cycles: two consecutive `sbi`, masked so no
            // interrupt falls between them; EEPM is 0 (erase and write).
            unsafe {
                write_volatile(EEARH, (addr >> 8) as u8);
                write_volatile(EEARL, addr as u8);
                write_volatile(EEDR, byte);
                asm!(
                    "sbi {eecr}, 2",
                    "sbi {eecr}, 1",
                    eecr = const EECR_IO,
                    options(nostack)
                );
            }
        });
    }
}

/// Byte `addr`, for a reader that is not the owner (the console printing
/// a kept text): a read never disturbs a write; it waits for it.
pub fn peek(addr: u16) -> u8 {
    Eeprom(()).read(addr)
}
