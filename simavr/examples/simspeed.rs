//! `simspeed FIRMWARE_ELF BUSY_ELF`: the bench's `sim_mhz_idle` (the
//! firmware, no card, 20 simulated seconds) and `sim_mhz_busy` (`busy.elf`,
//! 2 s), measured alone: simulated MHz per wall second.
use std::path::Path;
use std::time::{Duration, Instant};
use taut_simavr::Sim;

fn sim_mhz(elf: &Path, seconds: u64) -> f64 {
    let mut sim = Sim::load(elf).expect("image loads");
    let wall = Instant::now();
    sim.run_for(Duration::from_secs(seconds));
    sim.cycles() as f64 / wall.elapsed().as_secs_f64() / 1e6
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [fw, busy] = &args[..] else {
        eprintln!("usage: simspeed FIRMWARE_ELF BUSY_ELF");
        std::process::exit(2);
    };
    println!("sim_mhz_idle {:.1}", sim_mhz(Path::new(fw), 20));
    println!("sim_mhz_busy {:.1}", sim_mhz(Path::new(busy), 2));
}
