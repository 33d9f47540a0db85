//! `job_busy ELF`: the bench's busy figures of the demo job alone, with
//! the winding window's cycles by function and segment preparation's longest
//! runs (what is inside them). After `cargo xtask build`:
//! `cargo run --release -p taut-simavr --example job_busy -- \
//!    firmware/target/avr-none/release/taut.elf`. With `PCS=FROM-TO` (hex
//! addresses, from `llvm-nm -S`), the cycles by instruction in that range.
use std::path::Path;
use std::time::Duration;
use taut_simavr::sdcard::SdImage;
use taut_simavr::Sim;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let elf = Path::new(&args[1]);
    let card = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/card");
    let motion = taut_simavr::elf::function_address(elf, "4taut16prepare_segments")
        .unwrap()
        .unwrap();
    let mut sim = Sim::boot(elf);
    sim.insert_sd(SdImage::from_path(&card).unwrap());
    sim.watch_calls(motion);
    let names = [
        "Trapezoid5timed",
        "4taut3job",
        "4taut5store",
        "4taut6timers",
        "Preparer11begin_block",
        "Preparer8ramp_run",
        "Preparer7segment",
        "Preparer3fit",
        "trapezoid7isqrt32",
        "trapezoid5isqrt",
        "10div_to_u32",
        "__muldi3",
        "11round_div32",
        "memcpy",
        "12scaled_speed",
        "Preparer5ahead",
    ];
    let pcs: Vec<Option<u32>> = names
        .iter()
        .map(|n| taut_simavr::elf::function_address(elf, n).unwrap())
        .collect();
    for pc in pcs.iter().flatten() {
        sim.watch_calls(*pc);
    }
    let mut marks = taut_simavr::operator::Operator::confirming().job_phases(&mut sim);
    sim.enable_profile();
    sim.run_for(Duration::from_secs(30));
    if let Some(prof) = sim.profile() {
        let by = prof.by_function(elf).unwrap();
        let total: u64 = by.iter().map(|x| x.0).sum();
        for (c, n) in by.iter().take(45) {
            println!("{:6.2} % {:>12} {}", 100.0 * *c as f64 / total as f64, c, n);
        }
        // `PCS=0x2cf6-0x2fae`: cycles by instruction in that range.
        if let Some((from, to)) = std::env::var("PCS").ok().and_then(|r| {
            let (a, b) = r.split_once('-')?;
            let hex = |x: &str| u32::from_str_radix(x.trim_start_matches("0x"), 16).ok();
            Some((hex(a)?, hex(b)?))
        }) {
            let mut h = prof.hottest(100000);
            h.sort();
            for (pc, c) in h {
                if (from..to).contains(&pc) {
                    println!("{pc:#07x} {c}");
                }
            }
        }
    }
    marks.push(taut_simavr::operator::awake_and_all(&sim));
    let busy = |a: usize| {
        let ((w0, t0), (w1, t1)) = (marks[a], marks[a + 1]);
        100.0 * (w1 - w0) as f64 / (t1 - t0) as f64
    };
    let t_wind = (marks[3].1 - marks[2].1) as f64 / 16e6;
    for (n, pc) in names.iter().zip(&pcs) {
        if let Some(pc) = pc {
            let r: Vec<(u64, u64)> = sim
                .call_runs(*pc)
                .iter()
                .copied()
                .filter(|x| x.0 >= marks[2].1 && x.0 < marks[3].1)
                .collect();
            let (c, cyc): (usize, u64) = (r.len(), r.iter().map(|x| x.1).sum());
            println!(
                "{n}: {c} calls in winding, mean {} cycles (winding {t_wind:.1}s)",
                if c > 0 { cyc / c as u64 } else { 0 }
            );
        } else {
            println!("{n}: not found");
        }
    }
    let runs = sim.call_runs(motion);
    let w: Vec<&(u64, u64)> = runs
        .iter()
        .filter(|x| x.0 >= marks[2].1 && x.0 < marks[3].1)
        .collect();
    let tot: u64 = w.iter().map(|x| x.1).sum();
    println!(
        "segment preparation in winding: {} runs, {} cycles/s ({:.2} %), mean {}",
        w.len(),
        tot as f64 / t_wind,
        tot as f64 / t_wind / 16e4,
        tot / w.len().max(1) as u64
    );
    let mut top: Vec<(u64, u64)> = runs.to_vec();
    top.sort_by_key(|r| std::cmp::Reverse(r.1));
    for &(st, len) in top.iter().take(4) {
        print!("run {len} @{st}:");
        for (n, pc) in names.iter().zip(&pcs) {
            if let Some(pc) = pc {
                for &(s2, l2) in sim.call_runs(*pc) {
                    if s2 >= st && s2 < st + len {
                        print!(" {n}={l2}");
                    }
                }
            }
        }
        println!();
    }
    let longest = runs.iter().map(|r| r.1).max().unwrap_or(0);
    println!(
        "drilling {:.2} winding {:.2} longest {} runs {}",
        busy(0),
        busy(2),
        longest,
        runs.len()
    );
}
