//! The call chain at a run's deepest stack ([`Sim::keep_peak_stack`]),
//! innermost first, with each frame's bytes: for RAM work (static RAM +
//! deepest stack within 5.5 KiB). A function's prologue (its pushes and the frame it reserves,
//! from `avr-objdump -d`) says how far up the stack its return address
//! lies, and so on outwards. An interrupt's return address is the
//! interrupted instruction's, not a call's.
use crate::Sim;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

/// One frame of the chain.
pub struct Frame {
    /// Stack bytes in use where this frame ends (its return address).
    pub depth: usize,
    /// Bytes of this frame.
    pub bytes: usize,
    /// Function and offset, e.g. `taut::prepare_segments+0x30e`.
    pub at: String,
}

/// The deepest chain `sim` kept, innermost first; empty when
/// [`Sim::keep_peak_stack`] was not called before it.
pub fn deepest(sim: &Sim, elf: &Path) -> Vec<Frame> {
    let Some(stack) = sim.peak_stack() else {
        return Vec::new();
    };
    Code::read(elf).chain(stack, sim.peak_stack_pc())
}

/// A firmware image's code as `avr-objdump -d` lists it: what a chain is
/// read from (read once, then any number of chains).
pub struct Code {
    /// Instructions by byte address: (mnemonic, operands).
    text: BTreeMap<u32, (String, String)>,
    /// Function symbols by address.
    functions: BTreeMap<u32, String>,
    /// Return sites: the byte after each call.
    returns: BTreeMap<u32, ()>,
}

impl Code {
    /// The chain in `stack` (from the stack pointer + 1 up to RAMEND), the
    /// innermost function at `pc`.
    pub fn chain(&self, stack: &[u8], pc: u32) -> Vec<Frame> {
        let ret = |i: usize| 2 * u32::from_be_bytes([0, stack[i], stack[i + 1], stack[i + 2]]);
        let (mut at, mut pc) = (0, pc);
        let mut frames = Vec::new();
        while at + 3 <= stack.len() {
            let (start, name) = self.function(pc);
            let prologue = at + self.prologue_bytes(start, pc);
            let isr = ["_compa", "__vector_", "usart0_"]
                .iter()
                .any(|v| name.contains(v));
            // An interrupt handler's frame ends at the interrupted code's
            // address (any instruction); a function's at a return site:
            // where its prologue says, or (code the prologue does not
            // describe, e.g. a helper's pushes in its body) the nearest
            // one above.
            let next = match prologue + 3 <= stack.len() {
                true if isr || self.returns.contains_key(&ret(prologue)) => Some(prologue),
                _ => (at..stack.len() - 2).find(|&i| self.returns.contains_key(&ret(i))),
            };
            frames.push(Frame {
                depth: stack.len() - at,
                bytes: next.map_or(stack.len(), |n| n + 3) - at,
                at: format!("{name}+{:#x}", pc - start),
            });
            let Some(next) = next else { break };
            (at, pc) = (next + 3, ret(next));
        }
        frames
    }

    pub fn read(elf: &Path) -> Code {
        let out = Command::new("avr-objdump")
            .arg("-d")
            .arg(elf)
            .output()
            .unwrap();
        let (mut text, mut functions, mut returns) =
            (BTreeMap::new(), BTreeMap::new(), BTreeMap::new());
        let mut after_call = false;
        for line in String::from_utf8_lossy(&out.stdout).lines() {
            if let Some(name) = line.strip_suffix(">:") {
                if let Some((addr, name)) = name.split_once(" <") {
                    functions.insert(u32::from_str_radix(addr, 16).unwrap(), demangle(name));
                }
                continue;
            }
            let Some((addr, rest)) = line.trim_start().split_once(':') else {
                continue;
            };
            let Ok(addr) = u32::from_str_radix(addr, 16) else {
                continue;
            };
            if std::mem::take(&mut after_call) {
                returns.insert(addr, ());
            }
            let mut f = rest.split('\t').skip(2);
            let op = f.next().unwrap_or("").trim().to_string();
            let args = f.next().unwrap_or("").trim().to_string();
            after_call = ["call", "rcall", "icall", "eicall"].contains(&op.as_str());
            text.insert(addr, (op, args));
        }
        Code {
            text,
            functions,
            returns,
        }
    }

    fn function(&self, pc: u32) -> (u32, &str) {
        let (start, name) = self.functions.range(..=pc).next_back().unwrap();
        (*start, name)
    }

    /// Stack bytes the prologue of the function at `start` has taken by
    /// `pc`: its pushes and the frame it reserves (`sbiw`/`subi`+`sbci` on
    /// the Y pointer before `out` to SP).
    fn prologue_bytes(&self, start: u32, pc: u32) -> usize {
        let mut used = 0;
        for (_, (op, args)) in self.text.range(start..pc) {
            let number =
                |s: &str| usize::from_str_radix(s.trim().trim_start_matches("0x"), 16).unwrap_or(0);
            match op.as_str() {
                "push" => used += 1,
                "sbiw" | "subi" if args.starts_with("r28,") => used += number(&args[4..]),
                "sbci" if args.starts_with("r29,") => used += 256 * number(&args[4..]),
                // Saving SREG, RAMPZ, EIND; r1 cleared (an interrupt's).
                "in" | "out" | "cli" | "eor" | "clr" => {}
                _ => break,
            }
        }
        used
    }
}

fn demangle(name: &str) -> String {
    format!("{:#}", rustc_demangle::demangle(name))
}
