//! What runs before `main`, and the door the stock bootloader uses after a
//! watchdog reset.
//!
//! - `.init3` (after the stack pointer is set, before `.data` and `.bss`):
//!   MCUSR is kept for [`super::ResetCause`] and cleared, and the watchdog
//!   stopped. After a watchdog reset it runs on at its shortest period
//!   (16 ms) with WDRF forcing it on; the start-up before `main` must not
//!   depend on being shorter than that.
//! - Also in `.init3`: the image is whole. avrdude writes pages from the
//!   bottom up, so a write cut short leaves the new start before the old
//!   (or erased) end: this build's mark (`TAUT_BUILD_MARK`, a hash of the
//!   sources, from build.rs) must stand in the image's last bytes, where
//!   the linker puts it (`.endmark`, after `.data`'s values). If it does
//!   not, the start-up jumps back to the bootloader (byte 0x3E000), which
//!   waits for avrdude again, instead of running half an image.
//! - The watchdog entry, placed at byte 0x20000 by the linker
//!   (`scripts/avr-link.sh`): the Mega's stock STK500v2 bootloader, after a
//!   watchdog reset, clears MCUSR and the watchdog and then calls
//!   `app_start()`, a null function pointer, with `eicall` while EIND is
//!   still 1 from its own start-up: it lands on word 0x10000, not on 0. A
//!   firmware over 128 KiB has code there; this entry makes it a jump to
//!   the reset vector, and it keeps the MCUSR the bootloader read (still
//!   in r25) so the reset cause can be told.

/// MCUSR as it stood when this firmware started (`.init3`).
#[no_mangle]
#[link_section = ".noinit"]
static mut TAUT_MCUSR_AT_START: u8 = 0;

/// MCUSR as the bootloader read it, with a mark, when the watchdog entry
/// was taken: `[mcusr, 0xA5, 0x5A]`. Outside `.bss`: the start-up does not
/// clear it; [`take_bootloader_mcusr`] does, once read.
#[no_mangle]
#[link_section = ".noinit"]
static mut TAUT_BOOT_NOTE: [u8; 3] = [0; 3];

const MARK: [u8; 2] = [0xA5, 0x5A];

/// This build's mark, the image's last bytes (`.endmark`).
const BUILD_MARK: u32 = const_parse(env!("TAUT_BUILD_MARK"));

#[no_mangle]
#[used]
#[link_section = ".endmark"]
static TAUT_END_MARK: [u8; 4] = BUILD_MARK.to_le_bytes();

/// A decimal `u32` (build.rs writes the mark so).
const fn const_parse(s: &str) -> u32 {
    let b = s.as_bytes();
    let mut v = 0u32;
    let mut i = 0;
    while i < b.len() {
        v = v.wrapping_mul(10).wrapping_add((b[i] - b'0') as u32);
        i += 1;
    }
    v
}

/// `.init3`: MCUSR kept and cleared, the watchdog stopped (WDCE|WDE, then
/// 0, within 4 cycles; WDTCSR is at data 0x60), and the image checked
/// whole (RAMPZ is I/O 0x3B). r1 is 0 here; it falls through to `.init4`.
///
/// A naked function's assembly is assembled for the generic AVR core in a
/// library crate (no SRAM, no ELPM, no JMP), so those instructions are
/// spelled as words: `st Z, r24` 0x8380, `st Z, r1` 0x8210, `elpm r24, Z+`
/// 0x9187, `jmp 0x3E000` 0x940D 0xF000.
///
/// # Safety
/// Placed in `.init3` by the linker script and never called: the
/// start-up runs into it with interrupts off, the stack set, r1 = 0; it
/// touches r24, r30, r31 and RAMPZ, which the start-up sets again after.
#[unsafe(naked)]
#[unsafe(no_mangle)]
#[unsafe(link_section = ".init3")]
pub unsafe extern "C" fn taut_init3() {
    core::arch::naked_asm!(
        "in r24, 0x34",
        "ldi r30, lo8({start})",
        "ldi r31, hi8({start})",
        ".word 0x8380", // st Z, r24
        "out 0x34, r1",
        "wdr",
        "ldi r30, 0x60",
        "ldi r31, 0",
        "ldi r24, 0x18",
        ".word 0x8380", // st Z, r24
        ".word 0x8210", // st Z, r1
        "ldi r30, lo8({end})",
        "ldi r31, hi8({end})",
        "ldi r24, hh8({end})",
        "out 0x3b, r24",
        ".word 0x9187",
        "cpi r24, {m0}",
        "brne 1f",
        ".word 0x9187",
        "cpi r24, {m1}",
        "brne 1f",
        ".word 0x9187",
        "cpi r24, {m2}",
        "brne 1f",
        ".word 0x9187",
        "cpi r24, {m3}",
        "breq 2f",
        "1:",
        ".word 0x940D, 0xF000",
        "2:",
        start = sym TAUT_MCUSR_AT_START,
        end = sym TAUT_END_MARK,
        m0 = const BUILD_MARK & 0xFF,
        m1 = const (BUILD_MARK >> 8) & 0xFF,
        m2 = const (BUILD_MARK >> 16) & 0xFF,
        m3 = const BUILD_MARK >> 24,
    );
}

/// The watchdog entry (see the module's text), at byte 0x20000. The
/// bootloader's path has no interrupt source enabled since the reset, and
/// the reset vector's start-up sets SREG and the stack afresh. (`st Z+,
/// r25` is 0x9391, `st Z, r25` 0x8390, `jmp 0` 0x940C 0x0000.)
///
/// # Safety
/// Reached only from the bootloader's `eicall` (never from Rust):
/// it keeps r25 in a static and jumps to the reset vector.
#[unsafe(naked)]
#[unsafe(no_mangle)]
#[unsafe(link_section = ".watchdog_entry")]
pub unsafe extern "C" fn taut_watchdog_entry() {
    core::arch::naked_asm!(
        "ldi r30, lo8({note})",
        "ldi r31, hi8({note})",
        ".word 0x9391", // st Z+, r25
        "ldi r25, 0xA5",
        ".word 0x9391", // st Z+, r25
        "ldi r25, 0x5A",
        ".word 0x8390", // st Z, r25
        ".word 0x940C, 0x0000",
        note = sym TAUT_BOOT_NOTE,
    );
}

/// MCUSR as it stood when this firmware started.
pub fn mcusr_at_start() -> u8 {
    // SAFETY: written once by `.init3` before `main`, read-only since.
    unsafe { core::ptr::addr_of!(TAUT_MCUSR_AT_START).read_volatile() }
}

/// The MCUSR the stock bootloader read before it took the watchdog entry,
/// if this start came through it; the note is cleared.
pub fn take_bootloader_mcusr() -> Option<u8> {
    // SAFETY: only `main`'s start-up touches the note, with interrupts off
    // (no handler reads it); plain byte reads and writes of a static.
    unsafe {
        let note = core::ptr::addr_of_mut!(TAUT_BOOT_NOTE);
        let bytes = note.read_volatile();
        note.write_volatile([0; 3]);
        (bytes[1..] == MARK).then_some(bytes[0])
    }
}
