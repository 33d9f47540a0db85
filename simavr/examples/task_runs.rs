//! Where the console's longest runs go (the wait a `?` or a line may have,
//! the bench's dispatch latency): the string-art machine streams 300
//! random 3-axis moves, a `?` every tenth, no card in the slot; prints the
//! three longest console runs with the calls inside them, then each
//! watched function's run count, longest and 99th percentile (cycles),
//! segment preparation's last. With `scara` or
//! `whiteboard` as its argument, that machine streams 100 random lines of
//! its work area instead (each cut into pieces, each piece converted and
//! planned along the pen).
//! Run from the workspace root after `cargo xtask build`:
//! `cargo run --release -p taut-simavr --example task_runs [scara|whiteboard]`
//! (`TAUT_ELF=path` for another image).
use std::path::Path;
use std::time::Duration;
use taut_simavr::Sim;
fn main() {
    // Another image (an older build, to compare) from `TAUT_ELF`.
    let elf = std::env::var_os("TAUT_ELF").map(std::path::PathBuf::from);
    let elf = elf
        .as_deref()
        .unwrap_or(Path::new("firmware/target/avr-none/release/taut.elf"));
    let f = |p: &str| taut_simavr::elf::function_address(elf, p).unwrap();
    let names = [
        "4taut7console",
        "Console8run_line",
        "Interpreter4plan",
        // A move's planning, a part a console run.
        "Planner9plan_path",
        "Planner11plan_limits",
        "Planner11recalculate",
        "Console4read",
        "Parser4feed",
        "Kinematics7inverse",
        // A piece of a line on the arm or the whiteboard.
        "Console10next_piece",
        "5ScaraNtB6_10Kinematics12inverse_fine",
        "10PolargraphNtB6_10Kinematics12inverse_fine",
        "Planner13plan_pen_path",
        "Planner15plan_pen_joints",
        "5ScaraNtB6_10Kinematics7inverse",
        "4taut8realtime",
        "realtime6status",
        // Segment preparation: a block's profile and segments cut in parts.
        "4taut16prepare_segments",
    ];
    let machine = std::env::args().nth(1);
    // Those the build has (inlined functions have no symbol).
    let (names, pcs): (Vec<&str>, Vec<u32>) =
        names.iter().filter_map(|n| Some((*n, f(n)?))).unzip();
    let mut sim = Sim::load(elf).unwrap();
    for &pc in &pcs {
        sim.watch_calls(pc);
    }
    sim.run_until_uart_contains("reset:", Duration::from_millis(50));
    if let Some(m) = &machine {
        sim.send_line(&format!("$machine={m}"), Duration::from_millis(100))
            .unwrap();
    }
    sim.send_line("M17", Duration::from_millis(100)).unwrap();
    let mut x: u64 = 1234;
    // The arm's and the whiteboard's work areas (x, y, width, height), mm.
    let area = match machine.as_deref() {
        Some("scara") => Some([20.0, 20.0, 160.0, 180.0]),
        Some("whiteboard") => Some([-400.0, -400.0, 800.0, 600.0]),
        Some(other) => panic!("{other}: scara or whiteboard"),
        None => None,
    };
    for k in 0..area.map_or(0, |_| 100) {
        let [x0, y0, w, h] = area.unwrap();
        let mut draw = |n: u64| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x % n) as f64
        };
        let (px, py) = (x0 + draw(1000) / 1000.0 * w, y0 + draw(1000) / 1000.0 * h);
        let feed = 300 + draw(2700) as u64;
        if k % 10 == 0 {
            sim.uart_send(b"?");
        }
        let _ = sim.send_line(
            &format!("G1 X{px:.3} Y{py:.3} F{feed}"),
            Duration::from_secs(60),
        );
    }
    let (mut c, mut r, mut z) = (0.0f64, -100.0f64, -10.0f64);
    for k in 0..if area.is_some() { 0 } else { 300 } {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        let d = ((x % 3000) as f64 + 10.0) / 1000.0 * if x & 8 == 0 { 1.0 } else { -1.0 };
        match (x >> 4) % 3 {
            0 => c += d,
            1 => r = (r + d).clamp(-400.0, 20.0),
            _ => z = (z + d).clamp(-25.0, 10.0),
        }
        let feed = 10 + (x >> 8) % 6000;
        if k % 10 == 0 {
            sim.uart_send(b"?");
        }
        let _ = sim.send_line(
            &format!("G1 C{c:.3} X{r:.3} Z{z:.3} F{feed}"),
            Duration::from_secs(30),
        );
    }
    let mut top: Vec<(u64, u64)> = sim.call_runs(pcs[0]).to_vec();
    top.sort_by_key(|r| std::cmp::Reverse(r.1));
    for &(start, len) in top.iter().take(3) {
        print!("console run {len}:");
        for (i, &pc) in pcs.iter().enumerate().skip(1) {
            let inside: Vec<u64> = sim
                .call_runs(pc)
                .iter()
                .filter(|r| r.0 >= start && r.0 < start + len)
                .map(|r| r.1)
                .collect();
            if !inside.is_empty() {
                print!(" {}={:?}", names[i], inside);
            }
        }
        println!();
    }
    for (i, &pc) in pcs.iter().enumerate() {
        if let Some((n, max, p99)) = sim.call_summary(pc) {
            println!("{:<16} runs {n:>6} max {max:>7} p99 {p99:>7}", names[i]);
        }
    }
}
