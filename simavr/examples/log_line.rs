//! What a log line costs: a board powers on with a blank EEPROM, and the
//! store task prints the boot's warning line (`[MSG:W … store: settings:
//! EEPROM blank: defaults]`) in one run of its own. Prints that run's
//! cycles (`settings_cut` bounds it), then powers on again and
//! profiles that run alone: each function's cycles with its callees.
//! Run from the workspace root after `cargo xtask build`:
//! `cargo run -p taut-simavr --example log_line [N]` (the top N
//! functions, 25 unless given; `TAUT_ELF=path` for another image).
use std::path::Path;
use std::time::Duration;
use taut_simavr::Sim;

fn main() {
    let elf = std::env::var_os("TAUT_ELF").map(std::path::PathBuf::from);
    let elf = elf
        .as_deref()
        .unwrap_or(Path::new("firmware/target/avr-none/release/taut.elf"));
    let n: usize = std::env::args()
        .nth(1)
        .map_or(25, |a| a.parse().expect("N: a number"));
    let store = taut_simavr::elf::function_address(elf, "4taut5store")
        .unwrap()
        .expect("the store task's symbol");
    // The store's warning, in a run of the store task of its own.
    let say = taut_simavr::elf::function_address(elf, "5Store3say")
        .unwrap()
        .expect("Store::say's symbol");
    let boot = || {
        let mut sim = Sim::load(elf).unwrap();
        sim.watch_calls(store);
        sim.watch_calls(say);
        sim
    };
    let mut sim = boot();
    sim.run_for(Duration::from_millis(300));
    let said = sim.call_runs(say).first().expect("a warning").0;
    let (at, cycles) = *(sim.call_runs(store).iter())
        .find(|r| r.0 <= said && said < r.0 + r.1)
        .expect("the store run that warns");
    let longest = sim.call_runs(store).iter().map(|r| r.1).max().unwrap();
    let line = sim
        .uart_text()
        .lines()
        .find(|l| l.starts_with("[MSG:W"))
        .map(String::from);
    println!(
        "the warning's store run: {cycles} cycles at {:.3} ms",
        at as f64 / 16e3
    );
    println!("longest store run: {longest} cycles");
    println!("its line: {}", line.as_deref().unwrap_or("(none)"));
    // The same boot again, the profile taken over that run only.
    let mut sim = boot();
    sim.run_to(at - 1);
    sim.enable_call_profile(elf).unwrap();
    sim.run_to(at + cycles + 1);
    let again = sim.call_runs(store).iter().find(|r| r.0 == at);
    assert_eq!(again.map(|r| r.1), Some(cycles), "the second boot differs");
    println!("with callees (calls):");
    for (c, calls, name) in sim.profile().unwrap().inclusive().iter().take(n) {
        println!("  {c:>7} {calls:>5} {name}");
    }
}
