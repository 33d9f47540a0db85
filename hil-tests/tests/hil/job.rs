//! The whole string-art job of the sample card (`examples/card`: hexagon,
//! 24 nails, 30 connections) on the release image, with an operator who
//! presses green at each prompt, judged from its VCD trace alone: the
//! machine's motion is rebuilt from the STEP/DIR/ENABLE pulses
//! (`taut_simavr::replay`), not taken from the firmware's word.
//!
//! About 700 s of machine time: the job runs once, and every check reads
//! that one trace. It also draws `target/hil-job.png` to be looked at.

use hil_tests::sim::operator::Operator;
use hil_tests::sim::replay::{board_from_param, JobReplay};
use hil_tests::sim::sdcard::SdImage;
use hil_tests::sim::{picture, vcd, Outcome};
use hil_tests::{
    assert_ram_budget, assert_step_interrupt_never_masked_long, boot_machine, sample_card_dir,
};
use std::f64::consts::TAU;
use std::path::Path;
use std::time::{Duration, Instant};
use taut_logic::config::MachineConfig;
use taut_logic::geometry::StepScale;

/// The job must be over by then (it takes about 700 s).
const TIMEOUT_S: f64 = 1500.0;

/// `poradi.txt`: the count C, then C nail indices.
fn pattern(text: &str) -> Vec<u16> {
    let numbers: Vec<u16> = text
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().expect("a number"))
        .collect();
    let (count, nails) = numbers.split_first().expect("a count");
    assert_eq!(usize::from(*count), nails.len(), "poradi.txt's count");
    nails.to_vec()
}

#[test]
fn the_sample_job_drills_and_winds_as_its_pulses_show() {
    let wall = Instant::now();
    let config = MachineConfig::STRING_ART;
    let card = sample_card_dir();
    let mut sim = boot_machine();
    sim.insert_sd(SdImage::from_path(&card).unwrap());
    let mut op = Operator::confirming();
    while !op.finished {
        let end = sim.run_for(Duration::from_millis(10));
        assert_eq!(end, Outcome::Running, "{}", sim.uart_text());
        op.step(&mut sim);
        assert!(
            sim.time_s() < TIMEOUT_S,
            "not finished after {TIMEOUT_S} s:\n{}",
            sim.uart_text()
        );
    }
    let finished_ns = (sim.time_s() * 1e9) as u64;
    // A moment at the end, to see the machine stay still.
    sim.run_for(Duration::from_millis(500));
    assert_eq!(op.presses, 2, "green: drill, wind\n{}", sim.uart_text());
    let simulated = wall.elapsed();

    // Back from the VCD text, as any viewer would read it.
    let path = std::env::temp_dir().join(format!("taut-hil-job-{}.vcd", std::process::id()));
    sim.write_vcd(&path).unwrap();
    let signals = vcd::parse(&std::fs::read_to_string(&path).unwrap()).unwrap();
    std::fs::remove_file(&path).unwrap();
    let board = board_from_param(&std::fs::read(card.join("param.txt")).unwrap()).unwrap();
    let job = JobReplay::from_signals(&signals, board, &config).unwrap();
    // Read back from the VCD as well as at the simulation's end: no STEP
    // edge reached a driver held off.
    let off = job.trace.steps_while_off();
    assert!(
        off.is_empty(),
        "stepped while off: {:?}",
        &off[..off.len().min(5)]
    );
    let scale = StepScale::from_config(&config);
    let turn = i64::from(scale.steps_per_turn);
    let radial_per_mm = f64::from(scale.radial.as_f32());

    // A hole at every nail, in order, where the geometry puts it.
    let plunges = job.plunges();
    assert_eq!(plunges.len(), usize::from(board.nails()), "{plunges:#?}");
    for (i, p) in plunges.iter().enumerate() {
        let nail = board.nail(i as u16);
        let want = f64::from(nail.angle) / TAU * turn as f64;
        let off = (p.base.rem_euclid(turn) as f64 - want).rem_euclid(turn as f64);
        assert!(
            off.min(turn as f64 - off) <= 1.0,
            "hole {i}: base at {} steps, nail at {want:.2} ({p:?})",
            p.base
        );
        let want = f64::from(nail.radius - board.radius()) * radial_per_mm;
        assert!(
            (p.radial as f64 - want).abs() <= 1.0,
            "hole {i}: radial at {} steps, nail at {want:.2} ({p:?})",
            p.radial
        );
    }
    let stray = job.moves_while_plunged();
    assert!(
        stray.is_empty(),
        "moved with the drill below: {:?}",
        &stray[..stray.len().min(10)]
    );

    // Winding: every nail of the pattern, the last one included.
    let pattern = pattern(&std::fs::read_to_string(card.join("poradi.txt")).unwrap());
    let wraps = job.wraps();
    assert!(wraps.iter().all(|w| w.nails.len() == 1), "{wraps:#?}");
    assert_eq!(job.wrapped_nails(), pattern);
    let crossings = job.crossings();
    // The entry, then out and in for each wrap.
    assert_eq!(crossings.len(), 1 + 2 * pattern.len(), "{crossings:#?}");
    let bad = job.crossings_outside_gaps();
    assert!(bad.is_empty(), "crossed the ring at a nail: {bad:#?}");
    // At every step, not only at the ends of moves: the blended paths
    // cross the ring mid-move. Within a micrometre of the clearance (the
    // replay's floats against the firmware's).
    let (closest, at_ns, nail) = job.closest_to_nails();
    let clearance = taut_logic::stringart::Clearance::of(&MachineConfig::STRING_ART).mm;
    assert!(
        closest >= f64::from(clearance) - 1e-3,
        "{closest:.3} mm from nail {nail} at {at_ns} ns"
    );
    // The drill's driver is off while winding, the others hold: checked
    // at every crossing of the ring.
    for c in &crossings {
        assert_eq!(
            job.trace.drivers_on(c.at_ns),
            [true, true, false],
            "drivers at {c:?}"
        );
    }

    // Drivers off while waiting for nails (green pressed to wind) and at
    // the end.
    let wind = job.trace.presses("confirm")[1];
    assert_eq!(job.winding().0, wind);
    assert_eq!(job.trace.drivers_on(wind), [false; 3], "at {wind} ns");
    assert_eq!(job.trace.drivers_on(finished_ns), [false; 3]);
    assert_eq!(job.trace.drivers_on(u64::MAX), [false; 3]);

    let png = Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/hil-job.png");
    let summary = picture::render(&job, &png).unwrap();
    assert_eq!((summary.holes, summary.wraps), (24, 30));
    eprintln!(
        "job: {:.1} s machine time, simulated in {:.1} s, checked in {:.1} s; {}",
        sim.time_s(),
        simulated.as_secs_f64(),
        (wall.elapsed() - simulated).as_secs_f64(),
        png.display()
    );
    // Reading the card while the machine moves never held the step
    // interrupt off.
    assert_step_interrupt_never_masked_long(&sim);
    assert_ram_budget(&sim);
    machine_time_is_the_estimate(&sim, &card);
}

/// The firmware's log stamp (ms) of `state: <name>`.
fn entered(sim: &hil_tests::sim::Sim, state: &str) -> f64 {
    let needle = format!("job: state: {state}]");
    let line = sim
        .uart_text()
        .lines()
        .find(|l| l.ends_with(&needle))
        .map(str::to_string);
    let line = line.unwrap_or_else(|| panic!("{needle} in the log"));
    line.split(' ')
        .nth(1)
        .and_then(|ms| ms.parse().ok())
        .expect("[MSG:I ms …]")
}

/// Each phase lasts what `cargo xtask estimate` works out on the host from
/// the same files (`taut_logic::stringart::estimate`), within 1 %.
fn machine_time_is_the_estimate(sim: &hil_tests::sim::Sim, card: &Path) {
    use taut_logic::files::FileName;
    let read = |f: FileName| std::fs::read(card.join(f.name().to_string())).ok();
    let files = [FileName::Param, FileName::Machine, FileName::Poradi].map(|f| (f, read(f)));
    let file = |name| {
        files
            .iter()
            .find(|(f, _)| *f == name)
            .and_then(|(_, b)| b.as_deref())
    };
    let estimate = taut_logic::stringart::estimate::card(file).unwrap();
    let simulated = [
        (
            "drilling",
            (entered(sim, "waiting for nails") - entered(sim, "drilling")) / 1000.0,
        ),
        (
            "winding",
            (entered(sim, "end") - entered(sim, "winding")) / 1000.0,
        ),
    ];
    let estimated = [estimate.firmware.drilling_s, estimate.firmware.winding_s];
    for ((phase, sim_s), est_s) in simulated.into_iter().zip(estimated) {
        eprintln!("{phase}: {sim_s:.2} s simulated, {est_s:.2} s estimated");
        assert!(
            (sim_s - est_s).abs() <= sim_s / 100.0,
            "{phase}: {sim_s:.2} s simulated, {est_s:.2} s estimated"
        );
    }
}

/// A thicker needle (`needle_diameter` in the card's `machine.txt`): the
/// firmware takes it with the card, and the needle, replayed from the
/// pulses, keeps the larger clearance at every step of the winding.
#[test]
fn a_thicker_needle_from_machine_txt_keeps_its_clearance() {
    let param = b"tvar = 0\npocet_hrebiku = 8\npolomer_matrice = 10.0\n";
    let poradi = b"6,0,3,6,1,4,7\n";
    let card = hil_tests::card(&[
        ("param.txt", param),
        ("machine.txt", b"needle_diameter = 4.0\n"),
        ("poradi.txt", poradi),
    ]);
    let mut sim = boot_machine();
    sim.insert_sd(card);
    let mut op = Operator::confirming();
    while !op.finished {
        assert_eq!(sim.run_for(Duration::from_millis(10)), Outcome::Running);
        op.step(&mut sim);
        assert!(sim.time_s() < 600.0, "not finished:\n{}", sim.uart_text());
    }
    let path = std::env::temp_dir().join(format!("taut-hil-needle-{}.vcd", std::process::id()));
    sim.write_vcd(&path).unwrap();
    let signals = vcd::parse(&std::fs::read_to_string(&path).unwrap()).unwrap();
    std::fs::remove_file(&path).unwrap();
    let mut config = MachineConfig::STRING_ART;
    config.winding.needle_um = 4000;
    let board = board_from_param(param).unwrap();
    let job = JobReplay::from_signals(&signals, board, &config).unwrap();
    assert_eq!(job.wrapped_nails(), [0, 3, 6, 1, 4, 7]);
    assert!(job.crossings_outside_gaps().is_empty());
    let (closest, at_ns, nail) = job.closest_to_nails();
    let thick = taut_logic::stringart::Clearance::of(&config).mm;
    let default = taut_logic::stringart::Clearance::of(&MachineConfig::STRING_ART).mm;
    assert!(thick > default + 1.0, "{thick} mm");
    assert!(
        closest >= f64::from(thick) - 1e-3,
        "{closest:.3} mm from nail {nail} at {at_ns} ns, clearance {thick} mm"
    );
    assert_ram_budget(&sim);
}

/// A job ends with its card left in the slot: green starts the next job
/// from it (read and checked again, `>>> insert card` never said), and
/// that job runs to its end too: no pulling the card and putting it back.
#[test]
fn green_at_the_end_starts_the_next_job_from_the_card_left_in() {
    let card = hil_tests::card(&[
        ("param.txt", b"shape = 0\nnails = 6\nradius_cm = 20\n"),
        ("machine.txt", hil_tests::QUICK_MACHINE_TXT.as_bytes()),
        ("poradi.txt", b"3,0,3,1"),
    ]);
    let mut sim = boot_machine();
    sim.insert_sd(card);
    let mut holes = Vec::new();
    let mut op = Operator::confirming();
    for job in 0..2 {
        let from = sim.uart_bytes().len();
        if job > 0 {
            // `>>> done: press green`, answered.
            op.finished = false;
            hil_tests::press(&mut sim, taut_logic::pinmap::Button::Confirm, 150);
        }
        while !op.finished {
            assert_eq!(sim.run_for(Duration::from_millis(10)), Outcome::Running);
            op.step(&mut sim);
            assert!(sim.time_s() < 600.0, "job {job}:\n{}", sim.uart_text());
        }
        let log = sim.uart_text_from(from);
        assert!(
            log.contains("files ok: shape 0 nails 6"),
            "job {job}:\n{log}"
        );
        assert!(log.contains("wind 3/3"), "job {job}:\n{log}");
        // (Before the first, the power-on prompt.)
        assert!(
            job == 0 || !log.contains("insert card"),
            "job {job}:\n{log}"
        );
        assert!(!log.contains("card out"), "job {job}:\n{log}");
        holes.push(hil_tests::pulses(&sim, taut_logic::axis::Axis::Drill));
    }
    // The second job moved the drill as the first did.
    let second = holes[1] - holes[0];
    assert!(
        holes[0] > 0 && second.abs_diff(holes[0]) * 10 <= holes[0],
        "{holes:?}"
    );
    assert_ram_budget(&sim);
}
