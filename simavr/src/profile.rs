//! Where the MCU spends its cycles: a count per program word, folded into
//! the ELF's functions. For size/speed trade-offs (which function a lower
//! inlining threshold made hot); `taut-sim --profile N` prints the top N.

use crate::error::Error;
use std::path::Path;

/// Cycles spent per program word (flash byte address / 2).
#[derive(Default)]
pub struct Profile {
    cycles: Vec<u64>,
}

impl Profile {
    pub(crate) fn add(&mut self, pc: u32, cycles: u64) {
        let word = (pc / 2) as usize;
        if word >= self.cycles.len() {
            self.cycles.resize(word + 1, 0);
        }
        self.cycles[word] += cycles;
    }

    /// The `n` program words (byte addresses) with the most cycles.
    pub fn hottest(&self, n: usize) -> Vec<(u32, u64)> {
        let mut words: Vec<(u32, u64)> = (self.cycles.iter().enumerate())
            .filter(|(_, c)| **c > 0)
            .map(|(w, c)| (w as u32 * 2, *c))
            .collect();
        words.sort_by_key(|w| std::cmp::Reverse(w.1));
        words.truncate(n);
        words
    }

    /// Cycles counted so far.
    pub fn total(&self) -> u64 {
        self.cycles.iter().sum()
    }

    /// Cycles per function of `elf`, most first: (cycles, demangled name).
    pub fn by_function(&self, elf: &Path) -> Result<Vec<(u64, String)>, Error> {
        use object::{Object, ObjectSymbol};
        let bytes = std::fs::read(elf).map_err(|e| Error::Io(elf.to_owned(), e))?;
        let file = object::File::parse(&*bytes)
            .map_err(|e| Error::Elf(format!("{}: {e}", elf.display())))?;
        let mut funcs: Vec<(u64, u64, String)> = file
            .symbols()
            .filter(|s| s.kind() == object::SymbolKind::Text && s.size() > 0)
            .filter_map(|s| Some((s.address(), s.size(), s.name().ok()?.to_string())))
            .collect();
        funcs.sort();
        let mut out: Vec<(u64, String)> = funcs
            .iter()
            .map(|(addr, size, name)| {
                let words = (addr / 2) as usize..((addr + size) / 2) as usize;
                let sum = self.cycles.get(words).map_or(0, |c| c.iter().sum());
                (sum, short_name(name))
            })
            .filter(|(c, _)| *c > 0)
            .collect();
        out.sort_by(|a, b| b.cmp(a));
        Ok(out)
    }
}

/// A mangled Rust name demangled without its crate hashes.
fn short_name(mangled: &str) -> String {
    format!("{:#}", rustc_demangle::demangle(mangled))
}
