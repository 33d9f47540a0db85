//! Power cuts during a plotter's print from the card, on the release
//! image: the flatbed (its X homed against a switch at each power-on)
//! prints `examples/plotter/star.gcode`, the power goes at a seeded moment
//! (on some seeds in the middle of a checkpoint's EEPROM write), and the
//! next power-on, with only the EEPROM kept, offers the print (`>>>
//! resume`); `M1000` goes on. The drawing is rebuilt from the STEP, DIR
//! and pen pulses of both runs: every piece of the toolpath is drawn with
//! the pen down, nothing off it, and only the lines from the checkpoint's
//! to the one cut short are drawn twice.

use hil_tests::drawing::Toolpath;
use hil_tests::sim::Sim;
use hil_tests::{card, log_tail, pen_deg_at, soak_or, track, wait_for, Rng};
use std::time::Duration;
use taut_logic::checkpoint::{self, Found};
use taut_logic::config::MachineConfig;
use taut_logic::kinematics::{AnyKinematics, Kinematics};
use taut_logic::machine::Machine;
use taut_logic::settings::eeprom::host;

const STAR: &str = include_str!("../../../examples/plotter/star.gcode");
/// A step of the flatbed's 40 steps/mm, diagonally, and a little.
const WITHIN: f64 = 0.05;
/// Samples along the toolpath, mm apart.
const SAMPLE_MM: f64 = 0.2;

/// The file's drawing lines: the byte each starts at, and what it draws
/// with the pen down (its own polyline from where the line before left
/// the pen).
struct Line {
    start: usize,
    path: Toolpath,
}

/// The star's toolpath, line by line, as its G-code says (`G0`/`G1`
/// `X Y`, `G3 X Y I J`, `M3` down, `M5` up; absolute mm).
fn drawing_lines(text: &str) -> Vec<Line> {
    let mut lines = Vec::new();
    let (mut at, mut down, mut start) = ([0.0f64; 2], false, 0usize);
    for raw in text.split_inclusive('\n') {
        let line_start = start;
        start += raw.len();
        let code = raw.split(';').next().unwrap().trim();
        let word = |w: char| {
            code.split_whitespace()
                .find(|t| t.starts_with(w))
                .map(|t| t[1..].parse::<f64>().unwrap())
        };
        if code.starts_with("M3") {
            down = true;
            continue;
        }
        if code.starts_with("M5") {
            down = false;
            continue;
        }
        let (Some(x), Some(y)) = (word('X'), word('Y')) else {
            continue;
        };
        let mut path = Toolpath(vec![at]);
        if code.starts_with("G3") {
            let c = [at[0] + word('I').unwrap(), at[1] + word('J').unwrap()];
            path.arc_to(c, [x, y], true);
        } else {
            path.line_to([x, y]);
        }
        at = [x, y];
        if down {
            lines.push(Line {
                start: line_start,
                path,
            });
        }
    }
    lines
}

/// The flatbed as it powers on with `eeprom`, the star on its card, a
/// switch 3 mm below its X; run until it has homed and mounted the card.
fn power_on(eeprom: &[u8]) -> (Sim, [i32; 2]) {
    let cfg = MachineConfig::defaults(Machine::Flatbed);
    // Probed under the string-art names `track` reads (X, Y are its
    // base and radial channels).
    let mut sim = hil_tests::machine();
    sim.set_eeprom(eeprom);
    let endstops = sim.fit_machine_endstops(&cfg, 3.0);
    sim.watch_eeprom();
    sim.insert_sd(card(&[("STAR.GCO", STAR.as_bytes())]));
    wait_for(&mut sim, "homed", Duration::from_secs(20));
    wait_for(&mut sim, "MiB FAT", Duration::from_secs(3));
    let origin = endstops.power_on_origin(&sim, &cfg);
    (sim, origin)
}

fn send(sim: &mut Sim, line: &str) {
    hil_tests::send_ok(sim, line, Duration::from_secs(10));
}

/// Where the pen stood at each step with it down, machine mm (the steps
/// counted from power-on, `origin` where the machine stood then).
fn pen_down_points(sim: &Sim, origin: [i32; 2]) -> Vec<[f64; 2]> {
    let cfg = MachineConfig::defaults(Machine::Flatbed);
    let kin = AnyKinematics::of(&cfg).unwrap();
    track(sim)
        .into_iter()
        .filter(|(cycle, _)| {
            let deg = pen_deg_at(sim, *cycle).expect("no pen pulses");
            (deg - f64::from(cfg.pen.down_deg)).abs() < 1.0
        })
        .map(|(_, s)| {
            let p = kin.forward(&[s[0] as i32 + origin[0], s[1] as i32 + origin[1], 0]);
            [p[0].0 as f64 / 1000.0, p[1].0 as f64 / 1000.0]
        })
        .collect()
}

/// Points along each line's path, `SAMPLE_MM` of its length apart, and
/// its end: (line, point).
fn samples(lines: &[Line]) -> Vec<(usize, [f64; 2])> {
    let mut out = Vec::new();
    for (i, l) in lines.iter().enumerate() {
        let mut to_next = 0.0;
        for w in l.path.0.windows(2) {
            let (a, b) = (w[0], w[1]);
            let len = (b[0] - a[0]).hypot(b[1] - a[1]);
            let mut at = to_next;
            while at < len {
                let t = at / len;
                out.push((i, [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]));
                at += SAMPLE_MM;
            }
            to_next = at - len;
        }
        out.push((i, *l.path.0.last().unwrap()));
    }
    out
}

/// Whether any of `points` is within `WITHIN` of `p`.
fn covered(points: &[[f64; 2]], p: [f64; 2]) -> bool {
    points
        .iter()
        .any(|q| (q[0] - p[0]).abs() <= WITHIN && (q[1] - p[1]).hypot(q[0] - p[0]) <= WITHIN)
}

#[test]
fn a_print_cut_at_seeded_moments_resumes_with_no_gap_and_redraws_only_the_cut_lines() {
    let cfg = MachineConfig::defaults(Machine::Flatbed);
    let fresh = host::eeprom(&cfg, &Default::default(), &Default::default());
    let lines = drawing_lines(STAR);
    let all = samples(&lines);
    // Samples where another line of the drawing passes (the star's
    // crossings, the centre's rays): drawn there twice by the file itself.
    let crossing: Vec<bool> = all
        .iter()
        .map(|&(i, p)| {
            lines
                .iter()
                .enumerate()
                .any(|(j, l)| j != i && l.path.distance(p) < 0.3)
        })
        .collect();
    for seed in soak_or(vec![1u64, 2, 3, 4, 5, 6, 7, 8], vec![11, 12, 13]) {
        let mut rng = Rng::new(seed);
        let (mut sim, origin) = power_on(&fresh);
        send(&mut sim, "M17");
        send(&mut sim, "M23 star.gco");
        send(&mut sim, "M24");
        // The print takes ~30 s: cut within it, on some seeds once a
        // checkpoint byte is being written (a record torn).
        sim.run_for(Duration::from_secs_f64(rng.between(1.0, 22.0)));
        let torn_record = rng.below(2) == 0;
        if torn_record {
            let armed = sim.eeprom_writes();
            let started = sim.run_until(
                |s| {
                    s.eeprom_writes() > armed
                        && s.eeprom_writing().is_some_and(|a| a >= checkpoint::START)
                },
                Duration::from_secs(5),
            );
            assert_eq!(started, hil_tests::sim::Outcome::Done, "{}", log_tail(&sim));
            sim.run_for(Duration::from_secs_f64(rng.between(0.0, 0.03)));
        }
        let uart = sim.uart_text();
        assert!(
            uart.contains("File selected") && !uart.contains("Done printing file"),
            "seed {seed}: the cut must fall mid-print\n{}",
            log_tail(&sim)
        );
        let (eeprom, torn) = sim.eeprom_after_cut(0xFF);
        let first = pen_down_points(&sim, origin);
        assert!(
            !first.is_empty(),
            "seed {seed}: nothing drawn before the cut"
        );
        assert!(
            all.iter().any(|&(_, p)| !covered(&first, p)),
            "seed {seed}: all drawn before the cut"
        );
        let Found::Plot(saved) = checkpoint::scan(|a| eeprom[a as usize]) else {
            panic!("seed {seed}: no print checkpoint after the cut")
        };
        drop(sim);

        let (mut sim, origin) = power_on(&eeprom);
        wait_for(
            &mut sim,
            ">>> resume STAR.GCO from byte ",
            Duration::from_secs(2),
        );
        send(&mut sim, "M1000");
        wait_for(&mut sim, "Done printing file", Duration::from_secs(120));
        send(&mut sim, "M400");
        let second = pen_down_points(&sim, origin);
        eprintln!(
            "seed {seed}: resumed run's stack peak {} B at {:#x}",
            sim.peak_stack_bytes(),
            sim.peak_stack_pc()
        );
        hil_tests::assert_ram_budget(&sim);
        // The checkpoint is cleared once the print is done.
        sim.run_for(Duration::from_millis(300));
        let left = checkpoint::scan(|a| sim.eeprom()[a as usize]);
        assert!(matches!(left, Found::Idle { .. }), "seed {seed}: {left:?}");

        // Nothing off the toolpath with the pen down, in either run.
        for p in first.iter().chain(&second) {
            let d = lines
                .iter()
                .map(|l| l.path.distance(*p))
                .fold(f64::MAX, f64::min);
            assert!(d <= WITHIN, "seed {seed}: pen down at {p:?}, {d:.3} mm off");
        }
        // The checkpoint's line: the first drawing line at or after it;
        // the line cut short: the last one run 1 drew on.
        let from = lines
            .iter()
            .position(|l| l.start >= saved.pos() as usize)
            .unwrap_or(lines.len());
        let mut cut_line = 0;
        let mut doubled = Vec::new();
        for (k, &(i, p)) in all.iter().enumerate() {
            let (a, b) = (covered(&first, p), covered(&second, p));
            assert!(a || b, "seed {seed}: a gap at {p:?} (line {i})");
            if a && !crossing[k] {
                cut_line = cut_line.max(i);
            }
            if a && b && !crossing[k] {
                doubled.push(i);
            }
        }
        // Run 2 starts drawing where the checkpoint's line starts.
        let start = lines.get(from).map(|l| l.path.0[0]);
        if let Some(s) = start {
            let d = (second[0][0] - s[0]).hypot(second[0][1] - s[1]);
            assert!(
                d <= WITHIN,
                "seed {seed}: resumed at {:?}, not {s:?}",
                second[0]
            );
        }
        for &i in &doubled {
            assert!(
                (from..=cut_line).contains(&i),
                "seed {seed}: line {i} drawn twice, outside lines {from}..={cut_line}"
            );
        }
        let twice_mm = doubled.len() as f64 * SAMPLE_MM;
        doubled.dedup();
        eprintln!(
            "seed {seed}: cut {} (byte {torn:?} torn), checkpoint byte {} (drawing line \
             {from}), cut in drawing line {cut_line}; drawn twice: lines {doubled:?}, \
             {twice_mm:.1} mm",
            if torn_record {
                "mid-record"
            } else {
                "between writes"
            },
            saved.pos(),
        );
        // At most the line cut short and the lines since the last record
        // (one record every 0.5 s, or the one before a torn record).
        assert!(cut_line <= from + 3, "seed {seed}: {from}..={cut_line}");
    }
}

/// The offer on the buttons and the console: green held 2 s or `M524`
/// discards it (nothing moves but the power-on homing, and the next
/// power-on offers nothing), a short green press resumes it, and `M524`
/// stopping the resumed print clears the checkpoint.
#[test]
fn green_resumes_and_held_green_or_m524_discards_the_offer() {
    use hil_tests::press;
    use taut_logic::pinmap::Button;
    let cfg = MachineConfig::defaults(Machine::Flatbed);
    let fresh = host::eeprom(&cfg, &Default::default(), &Default::default());
    let (mut sim, _) = power_on(&fresh);
    send(&mut sim, "M17");
    send(&mut sim, "M23 star.gco");
    send(&mut sim, "M24");
    sim.run_for(Duration::from_secs(6));
    assert!(!sim.uart_text().contains("Done printing file"));
    let (cut, _) = sim.eeprom_after_cut(0xFF);
    let Found::Plot(saved) = checkpoint::scan(|a| cut[a as usize]) else {
        panic!("no checkpoint:\n{}", log_tail(&sim))
    };
    assert!(saved.pos() > 0, "six seconds in, a line is recorded");
    drop(sim);
    let offered = |eeprom: &[u8]| {
        let (mut sim, _) = power_on(eeprom);
        wait_for(
            &mut sim,
            ">>> resume STAR.GCO from byte ",
            Duration::from_secs(2),
        );
        sim
    };
    let idle_after = |sim: &mut Sim| {
        sim.run_for(Duration::from_millis(300));
        let e = sim.eeprom();
        checkpoint::scan(|a| e[a as usize])
    };
    // Held green: discarded, nothing drawn.
    let mut sim = offered(&cut);
    press(&mut sim, Button::Confirm, 2500);
    wait_for(&mut sim, "checkpoint discarded", Duration::from_secs(1));
    assert!(matches!(idle_after(&mut sim), Found::Idle { .. }));
    assert!(pen_down_points(&sim, [0, 0]).is_empty());
    let after = sim.eeprom();
    drop(sim);
    let (mut sim, _) = power_on(&after);
    sim.run_for(Duration::from_secs(1));
    assert!(
        !sim.uart_text().contains(">>> resume"),
        "{}",
        log_tail(&sim)
    );
    drop(sim);
    // `M524`: discarded.
    let mut sim = offered(&cut);
    send(&mut sim, "M524");
    assert!(sim.uart_text().contains("checkpoint discarded"));
    assert!(matches!(idle_after(&mut sim), Found::Idle { .. }));
    drop(sim);
    // Green: resumed, drawing again; `M524` stops it and clears it.
    let mut sim = offered(&cut);
    press(&mut sim, Button::Confirm, 200);
    wait_for(
        &mut sim,
        "resuming: STAR.GCO from byte",
        Duration::from_secs(1),
    );
    sim.run_for(Duration::from_secs(6));
    assert!(
        !pen_down_points(&sim, [0, 0]).is_empty(),
        "{}",
        log_tail(&sim)
    );
    send(&mut sim, "M524");
    wait_for(&mut sim, "print aborted", Duration::from_secs(1));
    assert!(matches!(idle_after(&mut sim), Found::Idle { .. }));
}
