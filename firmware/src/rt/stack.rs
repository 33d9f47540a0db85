//! Stack high-water mark: the free RAM between the end of static data and
//! the stack is painted with a pattern at boot; the lowest address still
//! changed tells how deep the stack ever went.

use core::ptr::{addr_of, read_volatile, write_volatile};

const PAINT: u8 = 0xC5;
/// Top of SRAM on the ATmega2560.
const RAMEND: usize = 0x21FF;

extern "C" {
    /// End of `.bss` (avr-libc's linker script): the lowest stack address.
    static __heap_start: u8;
}

fn bottom() -> usize {
    // SAFETY: only the address of the linker symbol is taken.
    addr_of!(__heap_start) as usize
}

fn sp() -> usize {
    // SAFETY: reading the stack pointer register (SPL/SPH at 0x5D/0x5E).
    unsafe { read_volatile(0x5D as *const u16) as usize }
}

/// Paint from the end of static data up to a little below the current
/// stack pointer. Call first thing in `main`.
pub fn paint() {
    let top = sp() - 16;
    for a in bottom()..top {
        // SAFETY: [bottom, sp-16) is unused RAM between statics and stack.
        unsafe { write_volatile(a as *mut u8, PAINT) };
    }
}

/// Deepest stack use since boot, in bytes.
pub fn peak() -> usize {
    let mut a = bottom();
    // SAFETY: reading RAM below the stack pointer.
    while a < sp() && unsafe { read_volatile(a as *const u8) } == PAINT {
        a += 1;
    }
    RAMEND - a + 1
}

/// Bytes of stack still never touched.
pub fn headroom() -> usize {
    RAMEND + 1 - bottom() - peak()
}
