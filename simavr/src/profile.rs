//! Where the MCU spends its cycles: a count per program word, folded into
//! the ELF's functions. For size/speed trade-offs (which function a lower
//! inlining threshold made hot); `taut-sim --profile N` prints the top N.

use crate::error::Error;
use std::path::Path;

/// Cycles spent per program word (flash byte address / 2), and, when
/// the ELF's functions are given, per function with its callees (a shadow
/// call stack).
#[derive(Default)]
pub struct Profile {
    cycles: Vec<u64>,
    calls: Option<Calls>,
}

/// Cycles per function, callees and interrupts inside included: a
/// function is entered when execution reaches its first word, and left
/// when the stack pointer rises above where it stood then (its `ret`).
struct Calls {
    /// Entry address → index into `names` and `inclusive`.
    entries: std::collections::HashMap<u32, usize>,
    names: Vec<String>,
    inclusive: Vec<u64>,
    entered: Vec<u64>,
    /// The functions under way: (index, stack pointer at entry).
    stack: Vec<(usize, u16)>,
    /// (caller, callee) → the callee's own cycles under that caller.
    edges: std::collections::HashMap<(usize, usize), u64>,
}

impl Profile {
    pub(crate) fn add(&mut self, pc: u32, cycles: u64) {
        let word = (pc / 2) as usize;
        if word >= self.cycles.len() {
            self.cycles.resize(word + 1, 0);
        }
        self.cycles[word] += cycles;
    }

    /// Counts from now on each function's cycles with its callees too.
    pub fn with_calls(&mut self, elf: &Path) -> Result<(), Error> {
        let funcs = functions(elf)?;
        self.calls = Some(Calls {
            entries: (funcs.iter().enumerate())
                .map(|(i, f)| (f.0 as u32, i))
                .collect(),
            inclusive: vec![0; funcs.len()],
            entered: vec![0; funcs.len()],
            names: funcs.into_iter().map(|f| f.2).collect(),
            stack: Vec::new(),
            edges: Default::default(),
        });
        Ok(())
    }

    /// After an instruction that took `cycles`: execution at `pc`, the
    /// stack pointer at `sp`.
    pub(crate) fn after(&mut self, cycles: u64, pc: u32, sp: u16) {
        let Some(c) = &mut self.calls else { return };
        for &(f, _) in &c.stack {
            c.inclusive[f] += cycles;
        }
        if let [.., (caller, _), (callee, _)] = c.stack[..] {
            *c.edges.entry((caller, callee)).or_default() += cycles;
        }
        while c.stack.last().is_some_and(|&(_, at)| sp > at) {
            c.stack.pop();
        }
        if let Some(&f) = c.entries.get(&pc) {
            c.stack.push((f, sp));
            c.entered[f] += 1;
        }
    }

    /// The callers of the function named `name` with the cycles it spent
    /// (its own) under each, most first.
    pub fn callers_of(&self, name: &str) -> Vec<(u64, String)> {
        let Some(c) = &self.calls else {
            return Vec::new();
        };
        let mut out: Vec<(u64, String)> = (c.edges.iter())
            .filter(|((_, callee), _)| c.names[*callee] == name)
            .map(|((caller, _), cycles)| (*cycles, c.names[*caller].clone()))
            .collect();
        out.sort_by(|a, b| b.cmp(a));
        out
    }

    /// What `name` called, with the cycles each took from its calls
    /// (callees included), most first.
    pub fn callees_of(&self, name: &str) -> Vec<(u64, String)> {
        let Some(c) = &self.calls else {
            return Vec::new();
        };
        let mut out: Vec<(u64, String)> = (c.edges.iter())
            .filter(|((caller, _), _)| c.names[*caller].contains(name))
            .map(|((_, callee), cycles)| (*cycles, c.names[*callee].clone()))
            .collect();
        out.sort_by(|a, b| b.cmp(a));
        out
    }

    /// Each function's cycles with its callees, most first: (cycles,
    /// entries, name). A recursive function counts its depth over.
    pub fn inclusive(&self) -> Vec<(u64, u64, String)> {
        let Some(c) = &self.calls else {
            return Vec::new();
        };
        let mut out: Vec<(u64, u64, String)> = (0..c.names.len())
            .filter(|&i| c.inclusive[i] > 0)
            .map(|i| (c.inclusive[i], c.entered[i], c.names[i].clone()))
            .collect();
        out.sort_by(|a, b| b.cmp(a));
        out
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
        let funcs = functions(elf)?;
        let mut out: Vec<(u64, String)> = funcs
            .iter()
            .map(|(addr, size, name)| {
                let words = (addr / 2) as usize..((addr + size) / 2) as usize;
                let sum = self.cycles.get(words).map_or(0, |c| c.iter().sum());
                (sum, name.clone())
            })
            .filter(|(c, _)| *c > 0)
            .collect();
        out.sort_by(|a, b| b.cmp(a));
        Ok(out)
    }
}

/// The ELF's functions by address: (address, size, demangled name).
fn functions(elf: &Path) -> Result<Vec<(u64, u64, String)>, Error> {
    use object::{Object, ObjectSymbol};
    let bytes = std::fs::read(elf).map_err(|e| Error::Io(elf.to_owned(), e))?;
    let file =
        object::File::parse(&*bytes).map_err(|e| Error::Elf(format!("{}: {e}", elf.display())))?;
    let mut funcs: Vec<(u64, u64, String)> = file
        .symbols()
        .filter(|s| s.kind() == object::SymbolKind::Text && s.size() > 0)
        .filter_map(|s| Some((s.address(), s.size(), short_name(s.name().ok()?))))
        .collect();
    funcs.sort();
    Ok(funcs)
}

/// A mangled Rust name demangled without its crate hashes.
fn short_name(mangled: &str) -> String {
    format!("{:#}", rustc_demangle::demangle(mangled))
}
