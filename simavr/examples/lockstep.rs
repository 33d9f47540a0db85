//! `lockstep ELF [CARD] [STEP_US] [TOTAL_MS]`: runs a firmware batched (the
//! harness's fast path) and one instruction at a time side by side, comparing
//! cycles, sleep, UART, stack and interrupts-masked figures after every step
//! (a simulated operator pressing green whenever the job asks, in both):
//! the batched run must see exactly what instruction-by-instruction watching does.
use std::time::Duration;
use taut_simavr::operator::Operator;
use taut_simavr::sdcard::SdImage;
use taut_simavr::Sim;
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let elf = std::path::Path::new(&a[1]);
    let card = a.get(2);
    let step_us: u64 = a.get(3).map_or(100, |s| s.parse().unwrap());
    let total_ms: u64 = a.get(4).map_or(2000, |s| s.parse().unwrap());
    let mk = |single: bool| {
        let mut s = Sim::load(elf).unwrap();
        if let Some(c) = card {
            s.insert_sd(SdImage::from_path(std::path::Path::new(c)).unwrap());
        }
        if single {
            s.watch_pc(0x3FFFE);
        }
        s
    };
    let (mut x, mut y) = (mk(false), mk(true));
    // The simulated operator presses green whenever the job asks.
    let (mut opx, mut opy) = (Operator::confirming(), Operator::confirming());
    let mut t = 0;
    while t < total_ms * 1000 {
        let ox = x.run_for(Duration::from_micros(step_us));
        let oy = y.run_for(Duration::from_micros(step_us));
        t += step_us;
        opx.step(&mut x);
        opy.step(&mut y);
        let fx = (
            ox,
            x.cycles(),
            x.asleep_cycles(),
            x.uart_bytes().len(),
            x.lowest_sp(),
            x.peak_stack_pc(),
            x.masked_spans(),
        );
        let fy = (
            oy,
            y.cycles(),
            y.asleep_cycles(),
            y.uart_bytes().len(),
            y.lowest_sp(),
            y.peak_stack_pc(),
            y.masked_spans(),
        );
        if fx != fy {
            println!("diverged by {t} us:\n batch  {:?}\n single {:?}", fx, fy);
            return;
        }
    }
    println!(
        "same for {total_ms} ms: cycles {} asleep {} sp {:#x} at {:#x}, masked {:?}",
        x.cycles(),
        x.asleep_cycles(),
        x.lowest_sp(),
        x.peak_stack_pc(),
        &x.masked_spans()[..3.min(x.masked_spans().len())]
    );
}
