//! `stack_trace ELF [CARD] [SECONDS]`: where the deepest stack of a run
//! comes from. Runs the firmware (an operator pressing green whenever the
//! job asks) and notes the millisecond in which the stack went deepest; a
//! second, identical run stops there instruction by instruction and reads
//! the return addresses off the stack: the call chain, outermost first,
//! with each frame's size. For RAM work (issue #13's budget):
//! `cargo run --release -p taut-simavr --example stack_trace -- \
//!    firmware/target/avr-none/release/taut.elf examples/card 120`.
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;
use std::time::Duration;
use taut_simavr::operator::Operator;
use taut_simavr::sdcard::SdImage;
use taut_simavr::Sim;

const RAM_END: u16 = 0x21FF;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let elf = Path::new(&a[1]);
    let card = a.get(2).filter(|c| *c != "-");
    let seconds: u64 = a.get(3).map_or(60, |s| s.parse().unwrap());
    let start = |card: Option<&String>| {
        let mut s = Sim::load(elf).unwrap();
        if let Some(c) = card {
            s.insert_sd(SdImage::from_path(Path::new(c)).unwrap());
        }
        (s, Operator::confirming())
    };
    // Pass 1: the millisecond of the deepest stack.
    let (mut sim, mut op) = start(card);
    let (mut lowest, mut at_ms) = (RAM_END, 0);
    for ms in 0..seconds * 1000 {
        sim.run_for(Duration::from_millis(1));
        op.step(&mut sim);
        if sim.lowest_sp() < lowest {
            (lowest, at_ms) = (sim.lowest_sp(), ms);
        }
    }
    println!("deepest stack {} B, in ms {at_ms}", RAM_END - lowest);
    // Pass 2: the same run up to the millisecond before (an interrupt may
    // enter at its end), then one instruction at a time until the stack
    // pointer gets there.
    let (mut sim, mut op) = start(card);
    for _ in 0..at_ms.saturating_sub(1) {
        sim.run_for(Duration::from_millis(1));
        op.step(&mut sim);
    }
    sim.watch_pc(0x3FFFE); // one instruction per step
                           // An interrupt's return address is not after a call: note where the
                           // stack stood when the last one entered its vector.
    let names = symbols(elf);
    let is_isr = |n: &str| n.contains("_compa") || n.contains("__vector_");
    let isrs: Vec<u32> = (names.iter())
        .filter(|(_, n)| is_isr(n))
        .map(|(a, _)| *a)
        .collect();
    let mut vector_sp = None;
    while sim.sp() > lowest {
        sim.run_cycles(1);
        if isrs.contains(&sim.pc()) {
            vector_sp = Some(sim.sp());
        }
    }
    let stack = sim.ram(lowest + 1, (RAM_END - lowest) as usize);
    let code = calls(elf);
    let name = |pc: u32| {
        let f = names.range(..=pc).next_back();
        f.map_or("?".to_string(), |(at, n)| format!("{n}+{:#x}", pc - at))
    };
    // A return address is 3 bytes, big-endian word address, right after
    // a call. Stale ones lie in frames too: a frame counts only if its
    // call goes to the function of the frame inside it (or is indirect).
    let start_of = |pc: u32| names.range(..=pc).next_back().map_or(0, |(at, _)| *at);
    let mut frames = vec![(0, sim.pc())];
    let mut inner = start_of(sim.pc());
    let word = |i: usize| 2 * u32::from_be_bytes([0, stack[i], stack[i + 1], stack[i + 2]]);
    let mut from = 0;
    if let Some(sp) = vector_sp.filter(|_| is_isr(&name(sim.pc()))) {
        // The interrupted code's address, pushed by the interrupt.
        from = (sp - lowest) as usize;
        frames.push((from, word(from)));
        inner = start_of(word(from));
        from += 3;
    }
    for i in from..stack.len().saturating_sub(2) {
        let ret = word(i);
        match code.get(&ret) {
            // (libgcc's float helpers fall through into the next symbol)
            Some(target) if target.is_none_or(|t| t <= inner && inner - t < 64) => {
                frames.push((i + 1, ret));
                inner = start_of(ret);
            }
            _ => {}
        }
    }
    println!("{:>6} {:>6}  where (innermost first)", "depth", "frame");
    for (k, (offset, pc)) in frames.iter().enumerate() {
        let depth = RAM_END as usize - lowest as usize - offset;
        let next = frames.get(k + 1).map_or(stack.len(), |f| f.0);
        println!("{depth:>6} {:>6}  {}", next - offset, name(*pc));
    }
}

/// Return addresses (the byte after a call) and the call's target, `None`
/// for an indirect call.
fn calls(elf: &Path) -> BTreeMap<u32, Option<u32>> {
    let out = Command::new("avr-objdump")
        .arg("-d")
        .arg(elf)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    let mut after = BTreeMap::new();
    let mut pending: Option<Option<u32>> = None;
    for line in text.lines() {
        let Some((addr, rest)) = line.trim_start().split_once(':') else {
            continue;
        };
        let Ok(addr) = u32::from_str_radix(addr, 16) else {
            continue;
        };
        if let Some(target) = pending.take() {
            after.insert(addr, target);
        }
        let mut fields = rest.split('\t').skip(2);
        let (op, arg) = (
            fields.next().unwrap_or("").trim(),
            fields.next().unwrap_or(""),
        );
        let target = || {
            let hex = arg.trim().split(|c: char| c == ' ' || c == ';').next()?;
            u32::from_str_radix(hex.trim_start_matches(".+").trim_start_matches("0x"), 16).ok()
        };
        pending = match op {
            "call" => Some(target()),
            "rcall" => Some(
                arg.split("; 0x")
                    .nth(1)
                    .and_then(|h| u32::from_str_radix(h.split_whitespace().next()?, 16).ok()),
            ),
            "icall" | "eicall" => Some(None),
            _ => None,
        };
    }
    after
}

/// Function symbols by address, demangled.
fn symbols(elf: &Path) -> BTreeMap<u32, String> {
    let out = Command::new("avr-nm")
        .args(["-C", "--defined-only"])
        .arg(elf)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    let mut map = BTreeMap::new();
    for line in text.lines() {
        let mut it = line.splitn(3, ' ');
        let (Some(addr), Some(kind), Some(name)) = (it.next(), it.next(), it.next()) else {
            continue;
        };
        if kind.eq_ignore_ascii_case("t") {
            if let Ok(addr) = u32::from_str_radix(addr, 16) {
                map.insert(addr, name.to_string());
            }
        }
    }
    map
}
