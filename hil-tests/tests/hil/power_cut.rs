//! Power cuts during a string-art job, on the release image.
//!
//! One job (12 nails, 30 wraps) is cut again and again at seeded moments —
//! some in the middle of a checkpoint's EEPROM write — each time keeping
//! only the EEPROM, as a cut does, and powered on again with it; the
//! operator takes the resume offer and zeroes the axes (at the zero pose:
//! each run's trace starts there). The union of the runs' traces must show
//! every hole drilled in order (only a hole cut mid-plunge drilled twice)
//! and the wraps of `poradi.txt`, each once: a wrap whose needle went out
//! before one cut and came back in after it counts once, through the gaps
//! it crossed. Also: another card after a cut discards the checkpoint; a
//! corrupt one is ignored with a warning.

use hil_tests::sim::operator::{Operator, Seen};
use hil_tests::sim::replay::{Crossing, Direction, JobReplay};
use hil_tests::sim::sdcard::SdImage;
use hil_tests::sim::vcd::Signal;
use hil_tests::sim::{Outcome, Sim};
use hil_tests::{
    assert_ram_budget, card, machine, quick_string_art, soak_or, Rng, QUICK_MACHINE_TXT,
};
use std::time::{Duration, Instant};
use taut_logic::checkpoint::{self, Found};
use taut_logic::geometry::{Board, StepScale};
use taut_logic::units::Milli;

const NAILS: u16 = 12;
/// The pattern: 40 wraps, no nail twice in a row (long enough for the
/// blended job to take more than twenty cuts).
const PATTERN: [u16; 40] = [
    9, 4, 11, 5, 11, 10, 8, 0, 7, 3, 10, 0, 2, 1, 5, 7, 3, 6, 8, 1, 9, 3, 0, 11, 3, 6, 4, 2, 6, 2,
    5, 8, 1, 10, 4, 9, 0, 7, 11, 2,
];
/// A run that has not finished (or been cut) by then has hung.
const RUN_TIMEOUT_S: f64 = 600.0;

fn poradi(pattern: &[u16]) -> String {
    let nails: Vec<String> = pattern.iter().map(u16::to_string).collect();
    format!("{},{}\n", pattern.len(), nails.join(","))
}

fn job_card(pattern: &[u16]) -> SdImage {
    card(&[
        (
            "param.txt",
            b"tvar = 0\npocet_hrebiku = 12\npolomer_matrice = 20.0\n",
        ),
        ("poradi.txt", poradi(pattern).as_bytes()),
        ("machine.txt", QUICK_MACHINE_TXT.as_bytes()),
    ])
}

fn board() -> Board {
    Board::new(0, NAILS, Milli(200_000)).unwrap()
}

/// When a run's power goes.
#[derive(Clone, Copy, Debug)]
struct Cut {
    /// Simulated seconds after power-on.
    at_s: f64,
    /// Then wait for the next checkpoint byte's write to start and cut
    /// this many seconds into it (a record's 8 bytes take ~32 ms).
    mid_write: Option<f64>,
    /// What a byte cut within its 3.4 ms write holds.
    torn: u8,
}

/// One power-on, until its cut or the job's end.
struct Run {
    signals: Vec<Signal>,
    /// When winding started, ns (its crossings are looked for after it).
    winding_ns: Option<u64>,
    /// The job's state when the power went (or at its end).
    state: Option<String>,
    cut_at_s: Option<f64>,
    /// The cut fell within a checkpoint write: record bytes still to come,
    /// or one torn.
    mid_record: bool,
    torn: Option<u16>,
    finished: bool,
    uart: String,
    /// The checkpoint the cut left.
    left: Found,
    sim: Sim,
}

/// Powers on with `eeprom`, runs until `cut` (or the job's end) with an
/// operator who answers every prompt; returns the run and the EEPROM the
/// cut leaves.
fn power_on(eeprom: Option<&[u8]>, image: SdImage, cut: Option<Cut>) -> (Run, Vec<u8>) {
    let mut sim = machine();
    if let Some(e) = eeprom {
        sim.set_eeprom(e);
    }
    sim.watch_eeprom();
    sim.insert_sd(image);
    let mut op = Operator::confirming();
    let mut winding_ns = None;
    let mut cut_at_s = None;
    let mut armed = cut.map(|c| c.at_s);
    let mut writes = 0;
    let mut mid_record = false;
    while !op.finished && sim.time_s() < RUN_TIMEOUT_S {
        let slice = match armed {
            Some(at) => (at - sim.time_s()).clamp(1e-6, 0.01),
            None if cut.is_some_and(|c| c.mid_write.is_some()) => 0.0005,
            None => 0.01,
        };
        let end = sim.run_for(Duration::from_secs_f64(slice));
        assert_eq!(end, Outcome::Running, "{}", sim.uart_text());
        for seen in op.step(&mut sim) {
            if seen == Seen::State("winding".into()) && winding_ns.is_none() {
                winding_ns = Some((sim.time_s() * 1e9) as u64);
            }
        }
        let c = match cut {
            Some(c) => c,
            None => continue,
        };
        match armed {
            Some(at) if sim.time_s() >= at - 1e-9 => {
                if let (Some(_), None) = (c.mid_write, cut_at_s) {
                    // Now wait for a checkpoint write to start.
                    armed = None;
                    writes = sim.eeprom_writes();
                    cut_at_s = Some(0.0);
                    continue;
                }
                cut_at_s = Some(sim.time_s());
                break;
            }
            None if sim.eeprom_writes() > writes
                && sim.eeprom_writing().is_some_and(|a| a >= checkpoint::START) =>
            {
                armed = Some(sim.time_s() + c.mid_write.unwrap());
                mid_record = true;
            }
            _ => {}
        }
        writes = sim.eeprom_writes();
    }
    let cut_at_s = cut_at_s.filter(|_| !op.finished);
    if op.finished {
        // The end's idle header takes 32 bytes × 3.4 ms to write.
        sim.run_for(Duration::from_millis(300));
    }
    let (eeprom, torn) = match (cut, cut_at_s) {
        (Some(c), Some(_)) => sim.eeprom_after_cut(c.torn),
        _ => (sim.eeprom(), None),
    };
    assert!(
        op.finished || cut_at_s.is_some(),
        "neither finished nor cut:\n{}",
        sim.uart_text()
    );
    let left = checkpoint::scan(|a| eeprom[a as usize]);
    let run = Run {
        left,
        signals: sim.vcd_signals(),
        winding_ns,
        state: op.state.clone(),
        cut_at_s,
        mid_record: mid_record && cut_at_s.is_some(),
        torn,
        finished: op.finished,
        uart: sim.uart_text(),
        sim,
    };
    (run, eeprom)
}

/// The shorter way round from base position `from` to `to` (steps), as the
/// operator's turning by hand between two runs is taken.
fn shorter(from: i64, to: i64, turn: i64) -> i64 {
    let d = (to - from).rem_euclid(turn);
    from + if d > turn / 2 { d - turn } else { d }
}

/// Checks the union of the runs' traces; returns (holes drilled twice,
/// wraps completed across a cut).
fn check_union(runs: &[Run], pattern: &[u16]) -> (usize, usize) {
    let cfg = quick_string_art();
    let board = board();
    let scale = StepScale::from_config(&cfg);
    let turn = i64::from(scale.steps_per_turn);
    let per_nail = turn as f64 / f64::from(NAILS);
    let mut holes: Vec<(usize, u16)> = Vec::new();
    let mut wrapped: Vec<u16> = Vec::new();
    let mut pending: Option<Crossing> = None;
    let mut across = 0;
    let mut log = String::new();
    for (r, run) in runs.iter().enumerate() {
        let mut job = JobReplay::from_signals(&run.signals, board, &cfg).unwrap();
        let stray = job.moves_while_plunged();
        assert!(
            stray.is_empty(),
            "run {r}: moved with the drill down: {stray:?}"
        );
        for p in job.plunges() {
            let at = p.base.rem_euclid(turn) as f64 / per_nail;
            let nail = at.round() as u16 % NAILS;
            assert!(
                (at - at.round()).abs() < 0.05,
                "run {r}: plunge off a nail: {p:?}"
            );
            holes.push((r, nail));
        }
        let Some(from) = run.winding_ns else { continue };
        job.set_winding(from, u64::MAX);
        let bad = job.crossings_outside_gaps();
        assert!(
            bad.is_empty(),
            "run {r}: crossed the ring at a nail: {bad:#?}"
        );
        let mut first = true;
        for c in job.crossings() {
            match (c.direction, pending.take()) {
                (Direction::Out, _) => pending = Some(c),
                (Direction::In, Some(o)) => {
                    let back = match first {
                        // Out before the cut, in after it: the base was
                        // turned back to the zero pose by hand between.
                        true => shorter(o.base, c.base, turn),
                        false => c.base,
                    };
                    let nails = job.ring.nails_between(o.base, back);
                    across += usize::from(first && !nails.is_empty());
                    log += &format!("run {r}: wrap {nails:?}\n");
                    wrapped.extend(nails);
                }
                (Direction::In, None) => {}
            }
            first = false;
        }
    }
    // Holes in order; a hole twice only across a cut (the one it stopped).
    let mut order = Vec::new();
    for (i, &(r, h)) in holes.iter().enumerate() {
        let again = i > 0 && holes[i - 1].1 == h && holes[i - 1].0 + 1 == r;
        let first_of_run = i == 0 || holes[i - 1].0 != r;
        if again && first_of_run {
            continue;
        }
        order.push(h);
    }
    assert_eq!(order, (0..NAILS).collect::<Vec<_>>(), "holes {holes:?}");
    assert_eq!(wrapped, pattern, "{log}");
    (holes.len() - order.len(), across)
}

/// The seeded cut of campaign `seed`: a few seconds into each run (the
/// offer and the zeroing take two), every third one in the middle of a
/// checkpoint write.
fn cut_of(seed: u64) -> Cut {
    let mut rng = Rng::new(seed);
    Cut {
        at_s: rng.between(2.2, 6.0),
        mid_write: seed.is_multiple_of(3).then(|| rng.between(0.0, 0.036)),
        torn: [0xFF, 0x00, rng.below(256) as u8][rng.below(3) as usize],
    }
}

#[test]
fn twenty_power_cuts_lose_no_hole_and_no_wrap() {
    let wall = Instant::now();
    let seeds: Vec<u64> = (1..=soak_or(60, 22)).collect();
    let mut runs: Vec<Run> = Vec::new();
    let mut eeprom: Option<Vec<u8>> = None;
    for &seed in &seeds {
        let cut = cut_of(seed);
        let (run, e) = power_on(eeprom.as_deref(), job_card(&PATTERN), Some(cut));
        eeprom = Some(e);
        let finished = run.finished;
        runs.push(run);
        if finished {
            break;
        }
    }
    // And the last one to the end.
    if !runs.last().unwrap().finished {
        let (run, e) = power_on(eeprom.as_deref(), job_card(&PATTERN), None);
        eeprom = Some(e);
        runs.push(run);
    }
    let last = runs.last().unwrap();
    assert!(last.finished, "{}", last.uart);
    // The job's end forgot the checkpoint.
    let e = eeprom.unwrap();
    assert!(matches!(
        checkpoint::scan(|a| e[a as usize]),
        Found::Idle { .. }
    ));

    let cuts: Vec<&Run> = runs.iter().filter(|r| r.cut_at_s.is_some()).collect();
    let in_state = |s: &str| {
        cuts.iter()
            .filter(|r| r.state.as_deref() == Some(s))
            .count()
    };
    let (drilling, winding) = (in_state("drilling"), in_state("winding"));
    let mid = cuts.iter().filter(|r| r.mid_record).count();
    let torn = cuts.iter().filter(|r| r.torn.is_some()).count();
    // Every run after a cut that left a checkpoint said why the job had
    // stopped, and offered it.
    for (r, run) in runs.iter().enumerate().skip(1) {
        if matches!(runs[r - 1].left, Found::Job(_)) {
            assert!(run.uart.contains("checkpoint: "), "run {r}:\n{}", run.uart);
            assert!(run.uart.contains(">>> resume "), "run {r}:\n{}", run.uart);
        }
    }
    let simulated = wall.elapsed();
    let (twice, across) = check_union(&runs, &PATTERN);
    eprintln!(
        "power cuts: {} ({drilling} drilling, {winding} winding, {mid} in a checkpoint write, \
         {torn} with a byte torn); {twice} hole(s) drilled again, {across} wrap(s) completed \
         across a cut; {:.0} s of machine time in {:.1} s, checked in {:.1} s",
        cuts.len(),
        runs.iter().map(|r| r.sim.time_s()).sum::<f64>(),
        simulated.as_secs_f64(),
        (wall.elapsed() - simulated).as_secs_f64()
    );
    assert!(cuts.len() >= 20, "only {} cuts", cuts.len());
    assert!(
        drilling >= 3 && winding >= 10,
        "{drilling} drilling, {winding} winding"
    );
    assert!(mid >= 5, "{mid} cuts in a checkpoint write");
    assert_ram_budget(&last.sim);
}

/// A cut while winding, then power-on with another card: the checkpoint
/// is discarded with a message and a new job starts; and the EEPROM's
/// checkpoint with a flipped bit is ignored with a warning.
#[test]
fn another_card_or_a_corrupt_checkpoint_is_never_resumed() {
    let cut = Cut {
        at_s: 0.0,
        mid_write: None,
        torn: 0xFF,
    };
    // Cut after a few wraps.
    let mut sim = machine();
    sim.insert_sd(job_card(&PATTERN));
    let mut op = Operator::confirming();
    // Progress is said every 5 %: every other wrap of 40.
    let fourth = format!("wind 4/{}", PATTERN.len());
    while !sim.uart_text().contains(&fourth) {
        assert_eq!(sim.run_for(Duration::from_millis(10)), Outcome::Running);
        op.step(&mut sim);
        assert!(sim.time_s() < RUN_TIMEOUT_S, "{}", sim.uart_text());
    }
    let eeprom = sim.eeprom();
    let Found::Job(saved) = checkpoint::scan(|a| eeprom[a as usize]) else {
        panic!("no checkpoint")
    };
    assert_eq!(saved.done(), 4);

    // Another pattern on the same board: not this job.
    let mut other = PATTERN;
    other.swap(3, 4);
    let (run, after) = power_on(
        Some(&eeprom),
        job_card(&other),
        Some(Cut { at_s: 3.0, ..cut }),
    );
    assert!(
        run.uart.contains("checkpoint: another card, discarded"),
        "{}",
        run.uart
    );
    assert!(!run.uart.contains(">>> resume "), "{}", run.uart);
    assert_eq!(run.state.as_deref(), Some("drilling"), "{}", run.uart);
    // It started a new job: its own checkpoint now.
    let Found::Job(new) = checkpoint::scan(|a| after[a as usize]) else {
        panic!("no checkpoint")
    };
    assert_ne!(new.header.id, saved.header.id);

    // Bit flips: in a header, in a record the ring still needs.
    for flip in [
        checkpoint::START as usize + 5,
        checkpoint::RING as usize + 8 + 3,
    ] {
        let mut bad = eeprom.clone();
        bad[flip] ^= 0x10;
        let (run, after) = power_on(
            Some(&bad),
            job_card(&PATTERN),
            Some(Cut { at_s: 2.0, ..cut }),
        );
        let ignored = run.uart.contains("checkpoint: corrupt, ignored")
            || run.uart.contains("checkpoint: another card, discarded");
        assert!(ignored, "flip at {flip}:\n{}", run.uart);
        assert!(
            !run.uart.contains(">>> resume "),
            "flip at {flip}:\n{}",
            run.uart
        );
        assert!(!matches!(
            checkpoint::scan(|a| after[a as usize]),
            Found::Corrupt { .. }
        ));
    }
}
