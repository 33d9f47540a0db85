//! Grbl-Mega side by side: `grbl_stream_<len>_serial_lines_per_s`. The
//! bench builds grbl-Mega 1.1 (its RAMPS/Mega map and defaults) with
//! `avr-gcc` as its Makefile does, from the checkout named by
//! `TAUT_GRBL_MEGA` (never a copy in this repository), runs it in the
//! same simulator, sets its steps, rates, accelerations and junction
//! deviation to the flatbed's with `$` lines, and streams the flatbed's
//! circles by the same character counting. Whether the flatbed's bars
//! are reachable on a 16 MHz AVR at all is then a measured fact. Grbl
//! reads no card and counts no underruns: serial only.

use crate::stream::{chords, lines, over_serial, FEED, MACHINES, SEGMENTS};
use serde_json::{json, Map, Value};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;
use taut_logic::config::MachineConfig;
use taut_logic::machine::Machine;
use taut_simavr::{Outcome, Reply, Sim};

/// Grbl-Mega's sources, in its Makefile's order.
const SOURCES: [&str; 19] = [
    "main",
    "motion_control",
    "gcode",
    "spindle_control",
    "coolant_control",
    "serial",
    "protocol",
    "stepper",
    "eeprom",
    "settings",
    "planner",
    "nuts_bolts",
    "limits",
    "print",
    "probe",
    "report",
    "system",
    "sleep",
    "jog",
];

/// Its Makefile's flags (avr-gcc ≥ 4.9).
const FLAGS: [&str; 7] = [
    "-Wall",
    "-Os",
    "-DF_CPU=16000000L",
    "-mmcu=atmega2560",
    "-ffunction-sections",
    "-flto",
    "-w",
];

/// Timer1's compare register A (data address).
const OCR1A: u16 = 0x88;

const NOT_MEASURED: &str = "not measured (set TAUT_GRBL_MEGA)";

/// grbl-Mega built from `checkout` into `dir`: the ELF.
fn build(checkout: &Path, dir: &Path) -> Result<PathBuf, String> {
    let src = checkout.join("grbl");
    std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
    let mut objects = Vec::new();
    for s in SOURCES {
        let o = dir.join(format!("{s}.o"));
        let st = Command::new("avr-gcc")
            .args(FLAGS)
            .arg(format!("-I{}", src.display()))
            .arg("-c")
            .arg(src.join(format!("{s}.c")))
            .arg("-o")
            .arg(&o)
            .status()
            .map_err(|e| format!("avr-gcc: {e}"))?;
        if !st.success() {
            return Err(format!("avr-gcc failed on {s}.c"));
        }
        objects.push(o);
    }
    let elf = dir.join("grbl.elf");
    let st = Command::new("avr-gcc")
        .args(FLAGS)
        .arg("-Wl,--gc-sections")
        .arg("-o")
        .arg(&elf)
        .args(&objects)
        .status()
        .map_err(|e| format!("avr-gcc: {e}"))?;
    match st.success() {
        true => Ok(elf),
        false => Err("avr-gcc failed to link grbl".into()),
    }
}

fn send(sim: &mut Sim, line: &str) {
    match sim.send_line(line, Duration::from_secs(10)) {
        Ok(Reply::Ok) => {}
        other => panic!("grbl: {line}: {other:?}\n{}", sim.uart_text()),
    }
}

/// Grbl's `$` lines for `machine`'s X and Y: steps/mm, mm/min, mm/s²,
/// junction deviation in mm.
fn settings(machine: Machine) -> Vec<String> {
    let cfg = MachineConfig::defaults(machine);
    let mut out = Vec::new();
    for (i, a) in cfg.axes[..2].iter().enumerate() {
        let per_mm = a.steps_per_unit.num as f64 / a.steps_per_unit.den as f64;
        out.push(format!("${}={}", 100 + i, per_mm));
        out.push(format!(
            "${}={}",
            110 + i,
            a.max_rate as f64 / per_mm * 60.0
        ));
        out.push(format!("${}={}", 120 + i, a.accel as f64 / per_mm));
    }
    out.push(format!("$11={}", cfg.junction_deviation_um as f64 / 1000.0));
    out
}

/// Grbl booted, set up as `machine`, at `start`, standing.
fn ready(elf: &Path, machine: Machine, start: [f64; 2]) -> Sim {
    let mut sim = Sim::load(elf).expect("grbl loads");
    // simavr runs no CTC timer whose TOP (OCR1A) is 0, where the real one
    // matches at every clock: Grbl's stepper interrupt, whose compare
    // value is 0 until its first run sets it, would never come. Its
    // first match at the top instead: the first move begins ≤ 4.1 ms
    // late, and none after it (OCR1A then holds a segment's rate).
    sim.poke_ram(OCR1A, &0xFFFFu16.to_le_bytes());
    let up = sim.run_until_uart_contains("Grbl 1.1", Duration::from_millis(500));
    assert_eq!(up, Outcome::Done, "grbl: {}", sim.uart_text());
    for s in settings(machine) {
        send(&mut sim, &s);
    }
    send(&mut sim, "G90 G21");
    send(&mut sim, &format!("G0 X{} Y{}", start[0], start[1]));
    // Grbl's wait for the motion before: a dwell.
    send(&mut sim, "G4 P0.01");
    sim
}

/// The Grbl rows: measured with `TAUT_GRBL_MEGA`, else said not to be.
pub fn grbl_figures(f: &mut Map<String, Value>, only: Option<&str>) {
    let key = |len: &str| format!("grbl_stream_{len}_serial_lines_per_s");
    let cases: Vec<_> = SEGMENTS
        .iter()
        .filter(|(_, len)| only.is_none_or(|o| key(len).contains(o)))
        .collect();
    if cases.is_empty() {
        return;
    }
    let checkout = std::env::var_os("TAUT_GRBL_MEGA").map(PathBuf::from);
    let dir = std::env::temp_dir().join(format!("taut-bench-grbl-{}", std::process::id()));
    let elf = checkout.as_ref().map(|c| build(c, &dir));
    let (machine, centre, r) = MACHINES[0];
    for &(segment, len) in cases {
        let key = key(len);
        let value = match &elf {
            None => json!(NOT_MEASURED),
            Some(Err(e)) => panic!("grbl-Mega from {:?}: {e}", checkout.as_ref().unwrap()),
            Some(Ok(elf)) => {
                let points = chords(centre, r, segment, crate::stream::line_count(segment));
                let lines = lines(&points, FEED);
                let mut sim = ready(elf, machine, points[0]);
                let rate = over_serial(&mut sim, &lines);
                println!("{key:<36} {rate:>7.1} lines/s");
                json!((rate * 10.0).round() / 10.0)
            }
        };
        f.insert(key, value);
    }
    let _ = std::fs::remove_dir_all(&dir);
}
