//! Power cuts during a plotter's print from the card, on the release
//! image: each plotter prints `examples/plotter/star.gcode` (moved onto
//! its drawing area), the power goes at a seeded moment (on some seeds in
//! the middle of a checkpoint's EEPROM write), and the next power-on, with
//! only the EEPROM kept, offers the print (`>>> resume`); `M1000` goes on.
//! The flatbed homes its X against a switch at each power-on; the
//! whiteboard and the arm have no switches and take where they stand at
//! power-on as their zero, so the maker puts them back there before
//! powering on again (a fresh simulator stands at zero steps). The drawing
//! is rebuilt from the STEP, DIR and pen pulses of both runs through the
//! machine's forward kinematics: every piece of the toolpath is drawn with
//! the pen down, nothing off it, and drawn twice only what was drawn after
//! the checkpoint: run 2 goes over what its line drew before with the pen
//! up and puts it down where the motors stood at the last record.

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

/// The star moved by `by` mm: every `X` and `Y` word (the arcs' `I`,
/// `J` are relative and stay); unmoved, the example's bytes as they are.
fn star_at(by: [f64; 2]) -> String {
    if by == [0.0, 0.0] {
        return STAR.to_string();
    }
    let shift = |t: &str, axis: char, d: f64| match t.strip_prefix(axis) {
        Some(v) => format!("{axis}{:.3}", v.parse::<f64>().unwrap() + d),
        None => t.to_string(),
    };
    STAR.lines()
        .map(|l| match l.starts_with(';') {
            true => l.to_string(),
            false => l
                .split(' ')
                .map(|t| shift(&shift(t, 'X', by[0]), 'Y', by[1]))
                .collect::<Vec<_>>()
                .join(" "),
        })
        .map(|l| l + "\n")
        .collect()
}

/// `text` with each `G1 X Y` line cut into chords of `mm` from where the
/// line before ended, to the µm, the last on the line's target.
fn in_chords(text: &str, mm: f64) -> String {
    let mut at = [0.0f64; 2];
    let mut out = String::new();
    for raw in text.lines() {
        let code = raw.split(';').next().unwrap().trim();
        let word = |w: char| {
            code.split_whitespace()
                .find(|t| t.starts_with(w))
                .map(|t| t[1..].parse::<f64>().unwrap())
        };
        let (Some(x), Some(y)) = (word('X'), word('Y')) else {
            out += raw;
            out += "\n";
            continue;
        };
        if code.starts_with("G1 ") {
            let len = (x - at[0]).hypot(y - at[1]);
            let n = (len / mm).ceil().max(1.0) as usize;
            let feed = word('F').map(|f| format!(" F{f}")).unwrap_or_default();
            for k in 1..n {
                let t = k as f64 / n as f64;
                let p = [at[0] + t * (x - at[0]), at[1] + t * (y - at[1])];
                out += &format!("G1 X{:.3} Y{:.3}{feed}\n", p[0], p[1]);
            }
        }
        out += raw;
        out += "\n";
        at = [x, y];
    }
    out
}

/// A plotter under the test: where its star goes, how near the pulses
/// must come to the toolpath (about a step of its coarsest motor), and
/// between which seconds of the print it is cut (once the pen has gone
/// down, before the star is done).
struct Plotter {
    machine: Machine,
    by: [f64; 2],
    within: f64,
    cut_s: (f64, f64),
    /// The star's straight lines cut into chords this long (mm; 0: as
    /// the example has them): a stream of tiny lines, which the firmware
    /// joins into moves.
    chord_mm: f64,
}

const FLATBED: Plotter = Plotter {
    machine: Machine::Flatbed,
    by: [0.0, 0.0],
    within: 0.05,
    cut_s: (1.0, 22.0),
    chord_mm: 0.0,
};

const WHITEBOARD: Plotter = Plotter {
    machine: Machine::Whiteboard,
    by: [-40.0, -40.0],
    within: 0.1,
    cut_s: (3.0, 30.0),
    chord_mm: 0.0,
};

/// The star's feed, mm/s (`F1500`).
const FEED_MM_S: f64 = 25.0;

impl Plotter {
    fn cfg(&self) -> MachineConfig {
        MachineConfig::defaults(self.machine)
    }

    fn file(&self) -> String {
        match self.chord_mm > 0.0 {
            true => in_chords(&star_at(self.by), self.chord_mm),
            false => star_at(self.by),
        }
    }

    /// The machine as it powers on with `eeprom`, its star on the card
    /// (the flatbed with a switch 3 mm below its X); run until it has
    /// homed and mounted the card. Where it stood at power-on, in steps.
    fn power_on(&self, eeprom: &[u8]) -> (Sim, [i32; 2]) {
        self.power_on_with(eeprom, ("STAR.GCO", &self.file()))
    }

    /// [`Plotter::power_on`] with `file` (name, text) on the card.
    fn power_on_with(&self, eeprom: &[u8], file: (&str, &str)) -> (Sim, [i32; 2]) {
        let cfg = self.cfg();
        // Probed under the string-art names `track` reads (X, Y are its
        // base and radial channels).
        let mut sim = hil_tests::machine();
        sim.set_eeprom(eeprom);
        let endstops = (cfg.homing.axes != 0).then(|| sim.fit_machine_endstops(&cfg, 3.0));
        sim.watch_eeprom();
        sim.insert_sd(card(&[(file.0, file.1.as_bytes())]));
        if endstops.is_some() {
            wait_for(&mut sim, "homed", Duration::from_secs(20));
        }
        wait_for(&mut sim, "MiB FAT", Duration::from_secs(3));
        let origin = endstops.map_or([0, 0], |e| e.power_on_origin(&sim, &cfg));
        (sim, origin)
    }

    /// Where the pen stood at each step with it down, mm in the drawing's
    /// frame (the steps counted from power-on, `origin` where the machine
    /// stood then).
    fn pen_down_points(&self, sim: &Sim, origin: [i32; 2]) -> Vec<[f64; 2]> {
        let cfg = self.cfg();
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

    /// Whether any of `points` is within `within` of `p`.
    fn covered(&self, points: &[[f64; 2]], p: [f64; 2]) -> bool {
        let w = self.within;
        points
            .iter()
            .any(|q| (q[0] - p[0]).abs() <= w && (q[1] - p[1]).hypot(q[0] - p[0]) <= w)
    }
}

fn send(sim: &mut Sim, line: &str) {
    hil_tests::send_ok(sim, line, Duration::from_secs(10));
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

#[test]
fn a_flatbed_print_cut_at_seeded_moments_resumes_with_no_gap_and_redraws_only_the_cut_lines() {
    cut_and_resume(
        &FLATBED,
        soak_or(vec![1u64, 2, 3, 4, 5, 6, 7, 8], vec![11, 12, 13]),
    );
}

/// The star's lines as chords of 0.1 mm (thousands of lines, joined
/// into moves of about a millimetre): a cut anywhere resumes from the
/// line that starts the move it fell in, the same lines joined the same
/// way, with no gap.
#[test]
fn a_flatbed_print_of_tiny_chords_cut_at_seeded_moments_resumes_with_no_gap() {
    let chords = Plotter {
        chord_mm: 0.1,
        ..FLATBED
    };
    cut_and_resume(&chords, soak_or(vec![51u64, 52, 53, 54, 56], vec![55]));
}

#[test]
fn a_whiteboard_print_cut_at_seeded_moments_resumes_with_no_gap() {
    cut_and_resume(&WHITEBOARD, soak_or(vec![31u64, 32, 33], vec![34, 35, 36]));
}

#[test]
fn an_arm_print_cut_at_seeded_moments_resumes_with_no_gap() {
    let arm = Plotter {
        machine: Machine::Scara,
        by: [60.0, 110.0],
        within: 0.3,
        cut_s: (3.0, 30.0),
        chord_mm: 0.0,
    };
    cut_and_resume(&arm, soak_or(vec![41u64, 42, 43], vec![44, 45, 46]));
}

fn cut_and_resume(plotter: &Plotter, seeds: Vec<u64>) {
    let name = plotter.machine.name();
    let fresh = host::eeprom(&plotter.cfg(), &Default::default(), &Default::default());
    let file = plotter.file();
    let lines = drawing_lines(&file);
    let all = samples(&lines);
    // Samples where another line of the drawing passes (the star's
    // crossings, the centre's rays): drawn there twice by the file itself.
    let crossing: Vec<bool> = all
        .iter()
        .map(|&(i, p)| {
            lines.iter().enumerate().any(|(j, l)| {
                // A chord's neighbours are the same line of the star.
                let near = match plotter.chord_mm > 0.0 {
                    true => ((0.5 / plotter.chord_mm) as usize).max(1),
                    false => 0,
                };
                j.abs_diff(i) > near && l.path.distance(p) < plotter.within + 0.25
            })
        })
        .collect();
    for seed in seeds {
        let mut rng = Rng::new(seed);
        let (mut sim, origin) = plotter.power_on(&fresh);
        send(&mut sim, "M17");
        send(&mut sim, "M23 star.gco");
        send(&mut sim, "M24");
        // Cut within the print, on some seeds once a checkpoint byte is
        // being written (a record torn).
        let (from_s, to_s) = plotter.cut_s;
        sim.run_for(Duration::from_secs_f64(rng.between(from_s, to_s)));
        let torn_record = rng.below(2) == 0;
        if torn_record {
            // A record is written when the line drawing changes: the
            // star's circle is one line of some 10 s.
            let armed = sim.eeprom_writes();
            let started = sim.run_until(
                |s| {
                    s.eeprom_writes() > armed
                        && s.eeprom_writing().is_some_and(|a| a >= checkpoint::START)
                },
                Duration::from_secs(15),
            );
            assert_eq!(started, hil_tests::sim::Outcome::Done, "{}", log_tail(&sim));
            sim.run_for(Duration::from_secs_f64(rng.between(0.0, 0.03)));
        }
        let uart = sim.uart_text();
        assert!(
            uart.contains("File selected") && !uart.contains("Done printing file"),
            "{name} seed {seed}: the cut must fall mid-print\n{}",
            log_tail(&sim)
        );
        let (eeprom, torn) = sim.eeprom_after_cut(0xFF);
        let first = plotter.pen_down_points(&sim, origin);
        assert!(
            !first.is_empty(),
            "{name} seed {seed}: nothing drawn before the cut\n{}",
            log_tail(&sim)
        );
        assert!(
            all.iter().any(|&(_, p)| !plotter.covered(&first, p)),
            "{name} seed {seed}: all drawn before the cut"
        );
        let Found::Plot(saved) = checkpoint::scan(|a| eeprom[a as usize]) else {
            panic!("{name} seed {seed}: no print checkpoint after the cut")
        };
        drop(sim);

        let (mut sim, origin) = plotter.power_on(&eeprom);
        wait_for(
            &mut sim,
            ">>> resume STAR.GCO from byte ",
            Duration::from_secs(2),
        );
        send(&mut sim, "M1000");
        wait_for(&mut sim, "Done printing file", Duration::from_secs(120));
        send(&mut sim, "M400");
        let second = plotter.pen_down_points(&sim, origin);
        eprintln!(
            "{name} seed {seed}: resumed run's stack peak {} B at {:#x}",
            sim.peak_stack_bytes(),
            sim.peak_stack_pc()
        );
        hil_tests::assert_ram_budget(&sim);
        // The checkpoint is cleared once the print is done.
        sim.run_for(Duration::from_millis(300));
        let left = checkpoint::scan(|a| sim.eeprom()[a as usize]);
        assert!(
            matches!(left, Found::Idle { .. }),
            "{name} seed {seed}: {left:?}"
        );

        // Nothing off the toolpath with the pen down, in either run.
        for p in first.iter().chain(&second) {
            let d = lines
                .iter()
                .map(|l| l.path.distance(*p))
                .fold(f64::MAX, f64::min);
            assert!(
                d <= plotter.within,
                "{name} seed {seed}: pen down at {p:?}, {d:.3} mm off"
            );
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
            let (a, b) = (plotter.covered(&first, p), plotter.covered(&second, p));
            assert!(a || b, "{name} seed {seed}: a gap at {p:?} (line {i})");
            if a && !crossing[k] {
                cut_line = cut_line.max(i);
            }
            if a && b && !crossing[k] {
                doubled.push(i);
            }
        }
        // Run 2 starts drawing where the motors stood at the record, or,
        // if the pen was up there (a travel) or the line was drawn to its
        // end, where the next drawing line starts: the checkpoint's line
        // or one after it (blocks counted past a line that draws nothing).
        let last = saved.last.expect("a record");
        let kin = AnyKinematics::of(&plotter.cfg()).unwrap();
        let p = kin.forward(&[last.at[0], last.at[1], 0]);
        let at = [p[0].0 as f64 / 1000.0, p[1].0 as f64 / 1000.0];
        let near = |q: [f64; 2]| (second[0][0] - q[0]).hypot(second[0][1] - q[1]) <= plotter.within;
        let to = (cut_line.max(from) + 1).min(lines.len() - 1);
        assert!(
            near(at) || (from..=to).any(|i| near(lines[i].path.0[0])),
            "{name} seed {seed}: resumed at {:?}, the record at {at:?}, lines {from}..={to}",
            second[0]
        );
        for &i in &doubled {
            assert!(
                (from..=cut_line).contains(&i),
                "{name} seed {seed}: line {i} drawn twice, outside lines {from}..={cut_line}"
            );
        }
        let twice_mm = doubled.len() as f64 * SAMPLE_MM;
        doubled.dedup();
        eprintln!(
            "{name} seed {seed}: cut {} (byte {torn:?} torn), checkpoint byte {} block {} \
             (drawing line {from}), cut in drawing line {cut_line}; drawn twice: lines \
             {doubled:?}, {twice_mm:.1} mm",
            if torn_record {
                "mid-record"
            } else {
                "between writes"
            },
            saved.pos(),
            saved.done(),
        );
        // At most what was drawn since the last record: one every 0.5 s
        // (the one before a torn one: 0.5 s more), 61 ms to write.
        let bound = FEED_MM_S * 1.1;
        assert!(
            twice_mm <= bound,
            "{name} seed {seed}: {twice_mm:.1} mm drawn twice, over {bound:.1}"
        );
    }
}

/// A second cut while the resumed print draws the rest of the line it
/// went on in (the whiteboard's star circle is one `G3` line of some
/// 8 s): the rapid on to where the pen stood is a block the file does not
/// have, so the resumed run writes no record until a later line moves,
/// and the third run goes on from the first record again: no gap, nothing
/// off the toolpath.
#[test]
fn a_second_cut_in_the_line_a_resume_went_on_in_leaves_no_gap() {
    let wb = &WHITEBOARD;
    let fresh = host::eeprom(&wb.cfg(), &Default::default(), &Default::default());
    let lines = drawing_lines(&wb.file());
    let (mut sim, origin) = wb.power_on(&fresh);
    send(&mut sim, "M17");
    send(&mut sim, "M23 star.gco");
    send(&mut sim, "M24");
    sim.run_for(Duration::from_secs(4));
    let (eeprom, _) = sim.eeprom_after_cut(0xFF);
    let mut drawn = wb.pen_down_points(&sim, origin);
    let Found::Plot(cut1) = checkpoint::scan(|a| eeprom[a as usize]) else {
        panic!("no print checkpoint after the first cut")
    };
    assert!(
        cut1.done() > 0,
        "the first cut must fall inside the circle: {cut1:?}"
    );
    drop(sim);

    // Run 2: cut 1.5 s after the pen is down again.
    let (mut sim, origin) = wb.power_on(&eeprom);
    wait_for(&mut sim, ">>> resume STAR.GCO", Duration::from_secs(2));
    send(&mut sim, "M1000");
    let down = sim.run_until(
        |s| {
            pen_deg_at(s, s.cycles())
                .is_some_and(|d| (d - f64::from(wb.cfg().pen.down_deg)).abs() < 1.0)
        },
        Duration::from_secs(30),
    );
    assert_eq!(down, hil_tests::sim::Outcome::Done, "{}", log_tail(&sim));
    sim.run_for(Duration::from_millis(1500));
    let (eeprom, _) = sim.eeprom_after_cut(0xFF);
    let second = wb.pen_down_points(&sim, origin);
    assert!(!second.is_empty(), "run 2 drew nothing before its cut");
    drawn.extend(second);
    let Found::Plot(cut2) = checkpoint::scan(|a| eeprom[a as usize]) else {
        panic!("no print checkpoint after the second cut")
    };
    // Still in the circle: no record since the resume (one counting the
    // rapid as a chord would name the block after the one moving).
    assert_eq!(cut2.last, cut1.last);
    drop(sim);

    let (mut sim, origin) = wb.power_on(&eeprom);
    wait_for(&mut sim, ">>> resume STAR.GCO", Duration::from_secs(2));
    send(&mut sim, "M1000");
    wait_for(&mut sim, "Done printing file", Duration::from_secs(120));
    send(&mut sim, "M400");
    drawn.extend(wb.pen_down_points(&sim, origin));
    for p in &drawn {
        let d = lines
            .iter()
            .map(|l| l.path.distance(*p))
            .fold(f64::MAX, f64::min);
        assert!(d <= wb.within, "pen down at {p:?}, {d:.3} mm off");
    }
    for (i, p) in samples(&lines) {
        assert!(wb.covered(&drawn, p), "a gap at {p:?} (line {i})");
    }
    eprintln!(
        "first cut: byte {} block {}; second: byte {} block {}",
        cut1.pos(),
        cut1.done(),
        cut2.pos(),
        cut2.done()
    );
}

/// gcodetools' file as it comes (`G92 X40 Y-5` "the pen stands here",
/// arcs, the pen from `Z` on each move), printed from the card where the
/// maker put the pen, the middle of the bed, and cut at seeded moments.
/// The flatbed homes at the next power-on; the resume reads the file's
/// `G92` again from where the print began (the checkpoint's header keeps
/// it), so the rest lands on the first part: no gap, nothing off the
/// strokes, at most 1.1 s of drawing twice.
#[test]
fn a_gcodetools_file_begun_mid_bed_resumes_where_its_g92_put_it() {
    const FILE: &str = include_str!("../../files/gcodetools_arcs.ngc");
    const BEGIN: [f64; 2] = [70.0, 100.0];
    let cfg = FLATBED.cfg();
    let strokes = hil_tests::reference::read(FILE, BEGIN, &cfg);
    let lines: Vec<Line> = strokes
        .drawn
        .iter()
        .map(|path| Line {
            start: 0,
            path: Toolpath(path.0.clone()),
        })
        .collect();
    let all = samples(&lines);
    let fresh = host::eeprom(&cfg, &Default::default(), &Default::default());
    let file = ("ARCS.NGC", FILE);
    for seed in soak_or(vec![21u64, 22, 23, 24], vec![25, 26]) {
        let mut rng = Rng::new(seed);
        let (mut sim, origin) = FLATBED.power_on_with(&fresh, file);
        for line in ["M17", &format!("G0 X{} Y{}", BEGIN[0], BEGIN[1]), "M400"] {
            send(&mut sim, line);
        }
        send(&mut sim, "M23 arcs.ngc");
        send(&mut sim, "M24");
        sim.run_for(Duration::from_secs_f64(rng.between(4.0, 60.0)));
        assert!(
            !sim.uart_text().contains("Done printing file"),
            "seed {seed}: the cut must fall mid-print"
        );
        let (eeprom, _) = sim.eeprom_after_cut(0xFF);
        let first = FLATBED.pen_down_points(&sim, origin);
        let Found::Plot(saved) = checkpoint::scan(|a| eeprom[a as usize]) else {
            panic!("seed {seed}: no print checkpoint after the cut")
        };
        drop(sim);

        let (mut sim, origin) = FLATBED.power_on_with(&eeprom, file);
        wait_for(&mut sim, ">>> resume ARCS.NGC", Duration::from_secs(2));
        send(&mut sim, "M1000");
        wait_for(&mut sim, "Done printing file", Duration::from_secs(240));
        send(&mut sim, "M400");
        let second = FLATBED.pen_down_points(&sim, origin);
        hil_tests::assert_ram_budget(&sim);

        for p in first.iter().chain(&second) {
            let d = strokes.distance(*p, true);
            assert!(
                d <= FLATBED.within,
                "seed {seed}: pen down at {p:?}, {d:.3} mm off"
            );
        }
        let mut twice = 0;
        for &(i, p) in &all {
            let (a, b) = (FLATBED.covered(&first, p), FLATBED.covered(&second, p));
            assert!(
                a || b,
                "seed {seed}: a gap at {p:?} (stroke {i})\n{}",
                log_tail(&sim)
            );
            twice += (a && b) as usize;
        }
        let twice_mm = twice as f64 * SAMPLE_MM;
        eprintln!(
            "gcodetools seed {seed}: checkpoint byte {} block {}, {} points drawn before the \
             cut, {} after; drawn twice {twice_mm:.1} mm",
            saved.pos(),
            saved.done(),
            first.len(),
            second.len()
        );
        // F400: 6.7 mm/s for 1.1 s.
        assert!(
            twice_mm <= 400.0 / 60.0 * 1.1,
            "seed {seed}: {twice_mm:.1} mm twice"
        );
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
    let fresh = host::eeprom(&FLATBED.cfg(), &Default::default(), &Default::default());
    let (mut sim, _) = FLATBED.power_on(&fresh);
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
        let (mut sim, _) = FLATBED.power_on(eeprom);
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
    assert!(FLATBED.pen_down_points(&sim, [0, 0]).is_empty());
    let after = sim.eeprom();
    drop(sim);
    let (mut sim, _) = FLATBED.power_on(&after);
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
        !FLATBED.pen_down_points(&sim, [0, 0]).is_empty(),
        "{}",
        log_tail(&sim)
    );
    send(&mut sim, "M524");
    wait_for(&mut sim, "print aborted", Duration::from_secs(1));
    assert!(matches!(idle_after(&mut sim), Found::Idle { .. }));
}
