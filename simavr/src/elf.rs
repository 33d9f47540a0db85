//! What the harness needs from the firmware ELF besides its code: section
//! sizes (flash and static RAM) and where static RAM ends, below which the
//! stack must never grow.

use crate::Error;
use object::{Object, ObjectSection, ObjectSymbol};
use serde::Serialize;
use std::path::Path;

/// First SRAM address of the ATmega2560 (below are registers and I/O).
pub const RAM_START: u16 = 0x200;
/// Last SRAM address of the ATmega2560.
pub const RAM_END: u16 = 0x21FF;

/// avr-gcc places data addresses at this offset in the ELF address space.
const DATA_OFFSET: u64 = 0x80_0000;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct ElfInfo {
    /// Code and constants kept in flash (`.text`).
    pub text_bytes: u32,
    /// Initialised statics: in flash and copied to SRAM at start-up.
    pub data_bytes: u32,
    /// Zeroed statics (`.bss` and `.noinit`).
    pub bss_bytes: u32,
    /// First SRAM address past all statics (`__heap_start`).
    pub static_ram_end: u16,
}

impl ElfInfo {
    /// Flash used: code plus the initial values of `.data`.
    pub fn flash_bytes(&self) -> u32 {
        self.text_bytes + self.data_bytes
    }

    /// SRAM taken by statics before the stack gets any.
    pub fn ram_static_bytes(&self) -> u32 {
        self.data_bytes + self.bss_bytes
    }
}

pub fn read(path: &Path) -> Result<ElfInfo, Error> {
    let bytes = std::fs::read(path).map_err(|e| Error::Io(path.to_owned(), e))?;
    let bad = |e: object::Error| Error::Elf(format!("{}: {e}", path.display()));
    let file = object::File::parse(&*bytes).map_err(bad)?;
    let size = |name: &str| file.section_by_name(name).map_or(0, |s| s.size() as u32);
    // `.endmark`: the build's mark after `.data`'s values
    // (firmware/avr-link.sh).
    let text_bytes = size(".text") + size(".endmark");
    let data_bytes = size(".data");
    let bss_bytes = size(".bss") + size(".noinit");
    // The linker script marks the end of statics; prefer the most inclusive name.
    let symbol_end = ["__heap_start", "_end", "__bss_end"]
        .iter()
        .find_map(|want| {
            file.symbols()
                .find(|s| s.name() == Ok(want))
                .map(|s| (s.address() - DATA_OFFSET.min(s.address())) as u16)
        });
    let static_ram_end =
        symbol_end.unwrap_or(RAM_START + (data_bytes + bss_bytes).min(u16::MAX as u32) as u16);
    Ok(ElfInfo {
        text_bytes,
        data_bytes,
        bss_bytes,
        static_ram_end,
    })
}

/// The address of the function whose (mangled) name contains `part`: the
/// app's tasks are found by name, e.g. `4taut7console` for `console`.
pub fn function_address(path: &Path, part: &str) -> Result<Option<u32>, Error> {
    use object::ObjectSymbol;
    let bytes = std::fs::read(path).map_err(|e| Error::Io(path.to_owned(), e))?;
    let file =
        object::File::parse(&*bytes).map_err(|e| Error::Elf(format!("{}: {e}", path.display())))?;
    Ok(file
        .symbols()
        .filter(|s| s.kind() == object::SymbolKind::Text)
        .find(|s| s.name().is_ok_and(|n| n.contains(part)))
        .map(|s| s.address() as u32))
}

/// The address of the symbol named `name` exactly.
pub fn symbol_address(path: &Path, name: &str) -> Result<Option<u32>, Error> {
    use object::ObjectSymbol;
    let bytes = std::fs::read(path).map_err(|e| Error::Io(path.to_owned(), e))?;
    let file =
        object::File::parse(&*bytes).map_err(|e| Error::Elf(format!("{}: {e}", path.display())))?;
    Ok(file
        .symbols()
        .find(|s| s.name() == Ok(name))
        .map(|s| s.address() as u32))
}

/// The byte ranges of flash holding code (end exclusive): each code
/// symbol's, to the next symbol when it has no size (the C runtime's
/// labels). Constants in flash are data symbols and never inside one.
pub(crate) fn code_ranges(path: &Path) -> Result<Vec<(u32, u32)>, Error> {
    let bytes = std::fs::read(path).map_err(|e| Error::Io(path.to_owned(), e))?;
    let file =
        object::File::parse(&*bytes).map_err(|e| Error::Elf(format!("{}: {e}", path.display())))?;
    let mut ranges = Vec::new();
    if let Some(text) = file.section_by_name(".text") {
        let text_end = (text.address() + text.size()) as u32;
        let mut symbols: Vec<(u32, u32, bool)> = file
            .symbols()
            .filter(|s| s.section_index() == Some(text.index()))
            .map(|s| {
                // Functions, and the untyped labels of the C runtime's and
                // libgcc's assembly (`__prologue_saves__`, `_exit`…);
                // objects (constants in flash) only end the range before
                // them.
                let code = s.kind() != object::SymbolKind::Data;
                (s.address() as u32, s.size() as u32, code)
            })
            .collect();
        symbols.sort_unstable();
        for (i, &(at, size, code)) in symbols.iter().enumerate() {
            if !code {
                continue;
            }
            let end = if size > 0 {
                at + size
            } else {
                symbols[i + 1..]
                    .iter()
                    .map(|s| s.0)
                    .find(|&a| a > at)
                    .unwrap_or(text_end)
            };
            ranges.push((at, end.min(text_end)));
        }
    }
    ranges.sort_unstable();
    ranges.dedup();
    Ok(ranges)
}
