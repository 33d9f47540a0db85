//! `stack_trace ELF (--card DIR [SECONDS [FROM]] | --send FILE)`: the call
//! chain of a run's deepest stack, innermost first, with each frame's
//! bytes. With a card, an operator presses green whenever the job asks,
//! for SECONDS (default 60) of machine time, the deepest stack kept from
//! second FROM on (default 0: a later phase's own peak, past the card's
//! checks); with a G-code file, its lines are
//! sent one by one, each after the last one's `ok`. For RAM work (static
//! RAM + deepest stack within 5.5 KiB), after `cargo xtask build`:
//! `cargo run --release -p taut-simavr --example stack_trace -- \
//!    firmware/target/avr-none/release/taut.elf --card examples/card 120`.
//! How the chain is read: `taut_simavr::stack_chain`. A whole HIL run's
//! chains: `TAUT_STACK_CHAINS=1 cargo xtask test` writes each test's to
//! `target/hil-stack-chains.txt`.
use std::path::Path;
use std::time::Duration;
use taut_simavr::operator::Operator;
use taut_simavr::sdcard::SdImage;
use taut_simavr::{stack_chain, Sim};

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
    println!("deepest stack {} B", sim.peak_stack_bytes());
    println!("{:>6} {:>6}  where (innermost first)", "depth", "frame");
    for f in stack_chain::deepest(&sim, elf) {
        println!("{:>6} {:>6}  {}", f.depth, f.bytes, f.at);
    }
}
