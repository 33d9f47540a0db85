//! The flash map of a linked image, checked: it ends below the budget
//! (the stock bootloader owns the top 8 KiB, and 16 KiB are kept free
//! below it), byte 0x20000 holds the watchdog entry the bootloader
//! reaches after a watchdog reset, the image ends with its build's mark,
//! and every function reached through a pointer is reachable by a 16-bit
//! word pointer: directly below 128 KiB, or through one of the linker's
//! trampolines (`.trampolines`, a `jmp` each, below 128 KiB); and no
//! function reads arguments from the stack (`stackargs`).
//!
//! LLVM's AVR backend calls through pointers with `eicall`/`eijmp`, and
//! the start-up sets EIND to 0 (avr-libc's crt for the ATmega2560), so a
//! pointer is a 16-bit word address within the first 128 KiB. Function
//! addresses taken as `gs()` (R_AVR_16_PM, R_AVR_LO8/HI8_LDI_GS) get a
//! trampoline from the linker when their function lies higher; `pm()`
//! ones (R_AVR_LO8/HI8_LDI_PM) do not, and would be cut to 16 bits: the
//! check reads every such relocation of the image (linked with
//! `--emit-relocs`, avr-link.sh) and the value the linker put there.

use crate::run::Result;
use object::{Object, ObjectSection, ObjectSymbol, RelocationFlags, RelocationTarget};
use std::path::Path;

/// Flash the image may use: 224 KiB.
pub const BUDGET: u64 = 229_376;
/// The stock bootloader's section.
pub const BOOT_START: u64 = 0x3_E000;
/// Where the bootloader's watchdog path lands (word 0x10000).
pub const WATCHDOG_ENTRY: u64 = 0x2_0000;
/// Data addresses in the ELF.
const DATA: u64 = 0x80_0000;

pub struct FlashMap {
    /// First byte past everything written to flash.
    pub end: u64,
    /// End of the code below the watchdog entry.
    pub low_end: u64,
    pub trampolines: usize,
    /// Function pointers checked, and those reached through a trampoline.
    pub pointers: usize,
    pub through_trampolines: usize,
}

impl FlashMap {
    pub fn print(&self) {
        let kib = |b: u64| b as f64 / 1024.0;
        println!(
            "flash map: code below the watchdog entry to {:#07x} ({} B filled before it), \
             watchdog entry at {WATCHDOG_ENTRY:#07x}; image ends at {:#07x} = {} B, \
             {} B ({:.1} KiB) under the {} B budget, bootloader at {BOOT_START:#07x}; \
             {} function pointers, {} through the {} trampolines",
            self.low_end,
            WATCHDOG_ENTRY.saturating_sub(self.low_end),
            self.end,
            self.end,
            BUDGET.saturating_sub(self.end),
            kib(BUDGET.saturating_sub(self.end)),
            BUDGET,
            self.pointers,
            self.through_trampolines,
            self.trampolines,
        );
    }
}

/// Reads and checks the flash map of `elf`.
pub fn check(elf: &Path) -> Result<FlashMap> {
    let bytes = std::fs::read(elf)?;
    let file = object::File::parse(&*bytes)?;
    let name = elf.display();
    // Flash bytes by address, from the sections placed in flash.
    let mut flash = vec![0xFFu8; BOOT_START as usize];
    let mut end = 0;
    for seg in file.segments() {
        use object::ObjectSegment;
        let (addr, data) = (seg.address(), seg.data()?);
        // `.data`'s values sit in flash at their load address.
        let load = match addr >= DATA {
            true => continue,
            false => addr,
        };
        if data.is_empty() {
            continue;
        }
        let stop = load + data.len() as u64;
        if stop > BOOT_START {
            return Err(format!("{name}: flash bytes up to {stop:#x} reach the bootloader").into());
        }
        flash[load as usize..stop as usize].copy_from_slice(data);
        end = end.max(stop);
    }
    // `.data`'s values: the program headers' physical addresses.
    let data_load = file
        .symbols()
        .find(|s| s.name() == Ok("__data_load_end"))
        .map(|s| s.address())
        .unwrap_or(0);
    end = end.max(data_load);
    let symbol = |want: &str| {
        file.symbols()
            .find(|s| s.name() == Ok(want))
            .map(|s| s.address())
    };
    // The code's end below the entry (a small image: all of it).
    let low_end = file
        .symbols()
        .filter(|s| s.kind() == object::SymbolKind::Text && s.address() < WATCHDOG_ENTRY)
        .map(|s| s.address() + s.size())
        .max()
        .unwrap_or(0);
    let mut problems = Vec::new();
    if end > BUDGET {
        problems.push(format!(
            "the image ends at {end} B, past the {BUDGET} B budget (the bootloader owns {BOOT_START:#x} on)"
        ));
    }
    if symbol("taut_watchdog_entry") != Some(WATCHDOG_ENTRY) {
        problems.push(format!(
            "the watchdog entry is at {:?}, not {WATCHDOG_ENTRY:#x} (firmware/avr-link.sh)",
            symbol("taut_watchdog_entry")
        ));
    }
    match symbol("TAUT_END_MARK") {
        Some(at) if at + 4 == end => {}
        other => problems.push(format!(
            "the build's end mark is at {other:?}, not the image's last 4 bytes (end {end:#x})"
        )),
    }
    let (t0, t1) = (
        symbol("__trampolines_start").unwrap_or(0),
        symbol("__trampolines_end").unwrap_or(0),
    );
    let word = |at: u64| u16::from_le_bytes([flash[at as usize], flash[at as usize + 1]]);
    // A trampoline: `jmp k` (0x940C | k bits, then k's low 16 bits).
    let jmp_target = |at: u64| {
        let (op, lo) = (word(at), word(at + 2));
        (op & 0xFE0E == 0x940C).then(|| {
            let hi = u64::from(((op >> 3) & 0x3E) | (op & 1));
            2 * ((hi << 16) | u64::from(lo))
        })
    };
    let trampolines: Vec<(u64, u64)> = (t0..t1)
        .step_by(4)
        .filter_map(|at| jmp_target(at).map(|to| (at, to)))
        .collect();
    // `ldi` immediate: 1110 KKKK dddd KKKK.
    let ldi = |at: u64| {
        let w = word(at);
        (w & 0xF000 == 0xE000).then_some(((w >> 4) & 0xF0) as u8 | (w & 0x0F) as u8)
    };
    let (mut pointers, mut through) = (0, 0);
    // Relocations of any kind: their absence means the link dropped them
    // (no `--emit-relocs`), not that the image takes no function's address.
    let mut relocations = 0;
    for section in file.sections() {
        for (offset, reloc) in section.relocations() {
            relocations += 1;
            let RelocationFlags::Elf { r_type } = reloc.flags() else {
                continue;
            };
            // R_AVR_16_PM 5, LO8/HI8_LDI_PM 12/13, LO8/HI8_LDI_GS 24/25.
            if ![5, 12, 13, 24, 25].contains(&r_type) {
                continue;
            }
            let RelocationTarget::Symbol(index) = reloc.target() else {
                continue;
            };
            let sym = file.symbol_by_index(index)?;
            let target = (sym.address() as i64 + reloc.addend()) as u64;
            let at = match offset < section.address() {
                true => section.address() + offset,
                false => offset,
            };
            if at >= BOOT_START {
                continue;
            }
            pointers += 1;
            // The word address the code or data holds.
            let held = match r_type {
                5 => Some(u64::from(word(at)) * 2),
                12 | 24 => ldi(at).map(|lo| u64::from(lo) << 1),
                _ => ldi(at).map(|hi| u64::from(hi) << 9),
            };
            let fits = |held: u64, to: u64| match r_type {
                5 => held == to,
                12 | 24 => held == (to & 0x1FE),
                _ => held == (to & 0x1_FE00),
            };
            let direct = target < WATCHDOG_ENTRY;
            let via = trampolines.iter().find(|t| t.1 == target);
            let ok = match (direct, via, held) {
                (true, _, Some(h)) => fits(h, target) || via.is_some_and(|t| fits(h, t.0)),
                (false, Some(t), Some(h)) => fits(h, t.0),
                _ => false,
            };
            if !ok {
                problems.push(format!(
                    "a pointer to {target:#x} ({}) at {at:#x} (relocation type {r_type}) is not \
                     reachable with a 16-bit word pointer",
                    sym.name().unwrap_or("?")
                ));
            } else if !direct {
                through += 1;
            }
        }
    }
    // Functions reading stack arguments, which the AVR back end misreads.
    let code = file
        .symbols()
        .filter(|s| s.kind() == object::SymbolKind::Text && s.size() > 0)
        .filter(|s| s.address() + s.size() <= BOOT_START)
        .map(|s| {
            let (at, end) = (s.address() as usize, (s.address() + s.size()) as usize);
            (s.name().unwrap_or("?"), &flash[at..end])
        });
    for (function, q) in crate::stackargs::readers(code) {
        problems.push(format!(
            "{function} reads arguments from the stack (ldd Y+{q}), which LLVM's AVR back end \
             reads a byte off on the ATmega2560: keep its arguments within 18 bytes, or \
             #[inline(always)] (xtask/src/stackargs.rs)"
        ));
    }
    if relocations == 0 {
        problems.push(format!(
            "{name} has no relocations: link it with --emit-relocs (firmware/avr-link.sh)"
        ));
    }
    if !problems.is_empty() {
        return Err(format!("{name}:\n  {}", problems.join("\n  ")).into());
    }
    Ok(FlashMap {
        end,
        low_end,
        trampolines: trampolines.len(),
        pointers,
        through_trampolines: through,
    })
}
