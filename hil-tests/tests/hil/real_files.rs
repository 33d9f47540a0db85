//! Real files as they come (`hil-tests/files/`, where each came from is in
//! its README): an Inkscape unicorn-extension file with its long header
//! comment, a gcodetools file with a `G92` offset and arcs, and a
//! LaserGRBL-style file with `M3 S1000`/`M5`. Each is drawn on the
//! simulated flatbed after `$H`, a move to the middle of the bed and a
//! work zero set with `G10 L20 P1 X0 Y0`, streamed line by line as a
//! sender sends it (every line, comments and all), and its drawing is
//! rebuilt from the step, direction and pen pulses alone: every pulse
//! within a step of the file's toolpath as an independent reading gives
//! it (`hil_tests::reference`), pen down on the strokes and up on the
//! travel, every corner reached.

use hil_tests::reference::{self, Strokes};
use hil_tests::sim::Sim;
use hil_tests::{assert_ram_budget, log_tail, machine, pen_deg_at, send_ok, track, wait_for};
use std::path::Path;
use std::time::Duration;
use taut_logic::config::MachineConfig;
use taut_logic::kinematics::{AnyKinematics, Kinematics};
use taut_logic::machine::Machine;

/// The flatbed's step is 0.025 mm: a step of each axis off the toolpath
/// (0.035 mm), or an arc's chord 0.010 mm inside its circle.
const WITHIN: f64 = 0.046;
/// Where the work zero is set, machine mm: the middle of the bed's X.
const ZERO: [f64; 2] = [70.0, 100.0];

fn fixture(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("files")
        .join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A flatbed, homed with `$H` against its simulated X switch, at the
/// middle of the bed with its work zero there; the cycle where the file
/// begins.
fn ready_flatbed() -> (Sim, u64) {
    use taut_logic::axis::Axis;
    use taut_logic::pinmap::{driver, Button};
    let eeprom = {
        let mut sim = hil_tests::boot_machine();
        send_ok(&mut sim, "$machine=flatbed", Duration::from_secs(2));
        send_ok(&mut sim, "$homing_at_start=0", Duration::from_secs(2));
        sim.run_for(Duration::from_secs(2));
        sim.eeprom()
    };
    let mut sim = machine();
    sim.set_eeprom(&eeprom);
    let x = driver(Axis::Base);
    sim.endstop(Button::ZeroBase.pin(), x.step, x.dir, true, -120);
    wait_for(&mut sim, "reset:", Duration::from_millis(100));
    for line in [
        "$H",
        "M17",
        &format!("G0 X{} Y{}", ZERO[0], ZERO[1]),
        "G10 L20 P1 X0 Y0",
        "M400",
    ] {
        send_ok(&mut sim, line, Duration::from_secs(30));
    }
    let begins = sim.cycles();
    (sim, begins)
}

/// Sends every line of `text` as a sender does, waiting for each answer:
/// `ok`, or Grbl's `error:1` for a `%` delimiter.
fn send_file(sim: &mut Sim, text: &str) {
    for line in text.lines() {
        match sim.send_line(line, Duration::from_secs(60)) {
            Ok(hil_tests::sim::Reply::Ok) => {}
            Ok(hil_tests::sim::Reply::Error(e))
                if line.trim() == "%" && e.starts_with("error:1 ") => {}
            other => panic!("{line:?}: {other:?}\n{}", log_tail(sim)),
        }
    }
    send_ok(sim, "M400", Duration::from_secs(120));
}

/// Every pulse since `begins` against `strokes`: on a stroke while the pen
/// is down, on the travel while up, within [`WITHIN`]; every corner of a
/// stroke reached; the end where the file ends.
fn assert_drawn(sim: &Sim, begins: u64, strokes: &Strokes) {
    let cfg = MachineConfig::defaults(Machine::Flatbed);
    let kin = AnyKinematics::of(&cfg).unwrap();
    let at = |s: [i64; 3]| {
        let p = kin.forward(&[s[0] as i32, s[1] as i32, s[2] as i32]);
        [p[0].0 as f64 / 1000.0, p[1].0 as f64 / 1000.0]
    };
    // Step counts are from power-on; homing put X's zero 3 mm below
    // where it stood (the switch at -120 steps, the pull-off 1 mm).
    let all = track(sim);
    let offset = {
        let homed_x = all
            .iter()
            .rev()
            .find(|(c, _)| *c <= begins)
            .map(|(_, s)| s[0])
            .unwrap_or(0);
        // At `begins` the machine stands at ZERO.
        (ZERO[0] * 40.0).round() as i64 - homed_x
    };
    let points: Vec<(u64, [f64; 2])> = all
        .iter()
        .filter(|(c, _)| *c > begins)
        .map(|(c, s)| (*c, at([s[0] + offset, s[1], s[2]])))
        .collect();
    assert!(!points.is_empty(), "nothing moved");
    let (mut worst, mut down) = (0.0f64, 0);
    for (cycle, p) in &points {
        let deg = pen_deg_at(sim, *cycle).expect("pen pulses");
        let is_down = (deg - f64::from(cfg.pen.down_deg)).abs() < 1.0;
        down += is_down as usize;
        let d = strokes.distance(*p, is_down);
        worst = worst.max(d);
        assert!(
            d <= WITHIN,
            "({:.3}, {:.3}) is {d:.3} mm off the {} path",
            p[0],
            p[1],
            if is_down { "drawn" } else { "travel" }
        );
    }
    for c in &strokes.corners {
        let near = points
            .iter()
            .map(|(_, p)| (p[0] - c[0]).hypot(p[1] - c[1]))
            .fold(f64::MAX, f64::min);
        assert!(near <= WITHIN, "never at the corner {c:?} ({near:.3} mm)");
    }
    let end = points.last().unwrap().1;
    let e = strokes.end;
    assert!(
        (end[0] - e[0]).hypot(end[1] - e[1]) <= WITHIN,
        "ended at {end:?}, not {e:?}"
    );
    eprintln!(
        "{} pulses ({down} with the pen down), worst {worst:.3} mm off; {} strokes, {} corners",
        points.len(),
        strokes.drawn.len(),
        strokes.corners.len()
    );
}

fn draws_as_it_reads(name: &str) {
    let text = fixture(name);
    let (mut sim, begins) = ready_flatbed();
    send_file(&mut sim, &text);
    let strokes = reference::read(&text, ZERO, &MachineConfig::defaults(Machine::Flatbed));
    assert!(!strokes.drawn.is_empty(), "{name} draws nothing");
    assert_drawn(&sim, begins, &strokes);
    assert_ram_budget(&sim);
}

/// The unicorn extension's file: a 400-character header comment, `G92`
/// where the pen stands, `M300 S30`/`S50` pen moves with `G4 P150`
/// between, `M18`/`M01`/`M17` around its registration test, `M300 S255`
/// at the end.
#[test]
fn an_inkscape_unicorn_file() {
    draws_as_it_reads("unicorn_hello.gcode");
}

/// gcodetools: `%`, a `G92` offset in its header, arcs (`G02`/`G03` with
/// `I J`), the pen from `Z` on the same line as the move.
#[test]
fn a_gcodetools_file_with_g92_and_arcs() {
    draws_as_it_reads("gcodetools_arcs.ngc");
}

/// A LaserGRBL-style file: `M3 S1000` before each stroke, `M5` after.
#[test]
fn a_lasergrbl_style_file() {
    draws_as_it_reads("lasergrbl_style.nc");
}
