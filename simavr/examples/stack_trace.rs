//! `stack_trace ELF (--card DIR [SECONDS [FROM]] | --send FILE)`: the call
//! chain of a run's deepest stack, innermost first, with each frame's
//! bytes. With a card, an operator presses green whenever the job asks,
//! for SECONDS (default 60) of machine time, the deepest stack kept from
//! second FROM on (default 0: a later phase's own peak, past the card's
//! checks); with a G-code file, its lines are
//! sent one by one, each after the last one's `ok`. For RAM work (issue
//! #13's budget), after `cargo xtask build`:
//! `cargo run --release -p taut-simavr --example stack_trace -- \
//!    firmware/target/avr-none/release/taut.elf --card examples/card 120`.
//!
//! The chain is read from the stack as it stood at its deepest
//! ([`Sim::keep_peak_stack`]): a function's prologue (its pushes and the
//! frame it reserves, from `avr-objdump -d`) says how far up the stack its
//! return address lies, and so on outwards. An interrupt's return address
//! is the interrupted instruction's, not a call's.
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;
use std::time::Duration;
use taut_simavr::operator::Operator;
use taut_simavr::sdcard::SdImage;
use taut_simavr::Sim;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let elf = Path::new(&a[1]);
    let mut sim = Sim::load(elf).unwrap();
    sim.keep_peak_stack();
    match a[2].as_str() {
        "--card" => {
            sim.insert_sd(SdImage::from_path(Path::new(&a[3])).unwrap());
            let seconds: u64 = a.get(4).map_or(60, |s| s.parse().unwrap());
            let from: u64 = a.get(5).map_or(0, |s| s.parse().unwrap());
            let mut op = Operator::confirming();
            for tick in 0..seconds * 100 {
                if tick == from * 100 {
                    sim.reset_peak_stack();
                }
                sim.run_for(Duration::from_millis(10));
                op.step(&mut sim);
            }
        }
        "--send" => {
            sim.run_for(Duration::from_millis(500));
            for line in std::fs::read_to_string(&a[3]).unwrap().lines() {
                sim.send_line(line, Duration::from_secs(600)).unwrap();
            }
        }
        other => panic!("--card DIR or --send FILE, not {other}"),
    }
    let code = Code::read(elf);
    let stack = sim.peak_stack().unwrap();
    println!("deepest stack {} B", sim.peak_stack_bytes());
    println!("{:>6} {:>6}  where (innermost first)", "depth", "frame");
    let ret = |i: usize| 2 * u32::from_be_bytes([0, stack[i], stack[i + 1], stack[i + 2]]);
    let (mut at, mut pc) = (0, sim.peak_stack_pc());
    while at + 3 <= stack.len() {
        let (start, name) = code.function(pc);
        let prologue = at + code.prologue_bytes(start, pc);
        let isr = ["_compa", "__vector_", "usart0_"]
            .iter()
            .any(|v| name.contains(v));
        // An interrupt handler's frame ends at the interrupted code's
        // address (any instruction); a function's at a return site: where
        // its prologue says, or (code the prologue does not describe, e.g.
        // a helper's pushes in its body) the nearest one above.
        let next = match prologue + 3 <= stack.len() {
            true if isr || code.returns.contains_key(&ret(prologue)) => Some(prologue),
            _ => (at..stack.len() - 2).find(|&i| code.returns.contains_key(&ret(i))),
        };
        let depth = stack.len() - at;
        let size = next.map_or(stack.len(), |n| n + 3) - at;
        println!("{depth:>6} {size:>6}  {name}+{:#x}", pc - start);
        let Some(next) = next else { break };
        (at, pc) = (next + 3, ret(next));
    }
}

struct Code {
    /// Instructions by byte address: (mnemonic, operands).
    text: BTreeMap<u32, (String, String)>,
    /// Function symbols by address.
    functions: BTreeMap<u32, String>,
    /// Return sites: the byte after each call.
    returns: BTreeMap<u32, ()>,
}

impl Code {
    fn read(elf: &Path) -> Code {
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
