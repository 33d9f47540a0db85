//! End to end: what the host tools (`taut-studio`) make, run by
//! the release firmware in simavr and judged from the pulses alone.
//!
//! - `taut stringart` → its card → the string-art job (drilling, winding,
//!   green pressed at each prompt) → the nails wrapped, rebuilt from the
//!   step pulses, are the card's pattern, and the picture drawn from them
//!   is `preview.png` byte for byte (the same chords on the same nails).
//! - `taut vectorize` → the flatbed, streamed line by line as `cargo xtask
//!   sim --send` does → every step of the rebuilt drawing lies on the
//!   toolpath the G-code defines (pen down on the strokes, up on the
//!   travel) and every corner of the strokes is reached.
//!
//! - `taut vectorize` of an Inkscape SVG (layers, a hatched fill, text
//!   converted to paths) → the flatbed and the whiteboard → likewise, the
//!   drawing rebuilt from the pulses lies on the toolpath and reaches
//!   every corner.
//!
//! Small on purpose: the job winds a few wraps (a wrap is seconds of
//! machine time), the drawings are 12 to 30 mm across.

use hil_tests::sim::operator::Operator;
use hil_tests::sim::{picture, Outcome};
use hil_tests::{assert_ram_budget, boot_machine, card, log_tail, pen_deg_at, send_ok, track};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use taut_logic::config::MachineConfig;
use taut_logic::kinematics::{AnyKinematics, Kinematics};
use taut_logic::machine::Machine;
use taut_studio::gray::Gray;
use taut_studio::stringart::{self, card::Spec, Options};
use taut_studio::toolpath::Toolpath;
use taut_studio::vectorize::{self, simplify::distance};
use taut_studio::{preview, progress};

fn example(name: &str) -> Gray {
    Gray::open(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../examples/images")
            .join(name),
    )
    .unwrap()
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("taut-hil-studio-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn a_generated_card_is_wound_as_its_preview_shows() {
    let wall = Instant::now();
    // 8 nails on a circle of R 8 cm, 6 chords.
    let mut o = Options::new(
        Spec {
            shape: 0,
            nails: 8,
            radius_um: 80_000,
        },
        6,
    );
    o.resolution = 64;
    let w = stringart::generate(&example("horse.png"), &o, &progress::quiet()).unwrap();
    let dir = scratch("card");
    stringart::write_card(&dir, &o, &w.pattern, 240).unwrap();
    let read = |f: &str| std::fs::read(dir.join(f)).unwrap();
    let (param, poradi) = (read("param.txt"), read("poradi.txt"));

    // The card's machine.txt lets the axes run 4 times as fast and
    // accelerate 16 times as hard: a minute of machine time instead of
    // over three (the steps, and so the replay, are the same).
    let mut fast = String::new();
    for axis in ["base", "radial", "drill"] {
        fast += &format!("{axis}_max_rate = 8000\n{axis}_accel = 8000\n");
    }
    let mut sim = boot_machine();
    sim.insert_sd(card(&[
        ("param.txt", &param),
        ("poradi.txt", &poradi),
        ("machine.txt", fast.as_bytes()),
    ]));
    let mut op = Operator::confirming();
    while !op.finished {
        let end = sim.run_for(Duration::from_millis(100));
        assert_eq!(end, Outcome::Running, "{}", log_tail(&sim));
        op.step(&mut sim);
        assert!(sim.time_s() < 600.0, "not finished:\n{}", log_tail(&sim));
    }
    let signals = sim.vcd_signals();
    let (board, wrapped) = preview::wrapped_nails(&signals, &param).unwrap();
    assert_eq!(wrapped, w.pattern, "the nails wrapped, from the pulses");

    // The picture of what was wound is the card's preview.
    let replayed = dir.join("replayed.png");
    stringart::picture::png(&board, &wrapped, f64::from(o.thread_mm), 240)
        .save_png(&replayed)
        .unwrap();
    assert!(
        read("replayed.png") == read("preview.png"),
        "the pictures differ"
    );
    // And simavr's own picture of the job, to be looked at.
    let job = hil_tests::sim::replay::JobReplay::from_signals(
        &signals,
        board,
        &MachineConfig::STRING_ART,
    )
    .unwrap();
    let png = Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/hil-studio-job.png");
    let summary = picture::render(&job, &png).unwrap();
    assert_eq!((summary.holes, summary.wrapped), (8, w.pattern.clone()));
    assert_eq!(summary.crossings_outside_gaps, 0);
    eprintln!(
        "card {:?}: {:.0} s of machine time in {:.1} s; {}",
        w.pattern,
        sim.time_s(),
        wall.elapsed().as_secs_f64(),
        png.display()
    );
    assert_ram_budget(&sim);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The pen's point at `steps` on `machine`, mm.
fn at(kin: &AnyKinematics, steps: [i64; 3]) -> [f64; 2] {
    let p = kin.forward(&[steps[0] as i32, steps[1] as i32, steps[2] as i32]);
    [f64::from(p[0].0) / 1000.0, f64::from(p[1].0) / 1000.0]
}

/// The least distance from `p` to the moves of `path` with the pen `down`.
fn off_path(path: &Toolpath, p: [f64; 2], down: bool) -> f64 {
    path.moves
        .iter()
        .filter(|m| m.down == down)
        .map(|m| distance(p, m.from, m.to))
        .fold(f64::MAX, f64::min)
}

#[test]
fn a_vectorized_drawing_is_drawn_on_its_toolpath() {
    let wall = Instant::now();
    let mut o = vectorize::Options::new(Machine::Flatbed, 12.0);
    o.tolerance_mm = Some(0.05);
    o.mode = vectorize::Mode::Edges;
    // The flatbed's top speed (2000 steps/s, 40 a mm).
    o.feed = 3000.0;
    let v = vectorize::vectorize(
        &vectorize::Source::Picture(example("horse.png")),
        &o,
        "horse",
    )
    .unwrap();
    // 0.025 mm a step: a step of each axis off, or the chord between two
    // points of a curve the G-code cut.
    let (down_steps, machine_s) = drawn_as_planned(&v, Machine::Flatbed, 0.046);
    let (drawn, _) = v.toolpath.lengths();
    assert!(
        down_steps as f64 > 0.9 * drawn * 40.0,
        "{down_steps} steps down for {drawn:.1} mm"
    );
    eprintln!(
        "horse: {} strokes, {} G-code lines, {down_steps} pen-down steps, {machine_s:.0} s machine time in {:.1} s",
        v.strokes.len(),
        v.gcode.lines().count(),
        wall.elapsed().as_secs_f64()
    );
}

/// Streams `v`'s G-code to `machine` and checks the pulses drew it: every
/// step on the toolpath (pen down on the strokes, up on the travel),
/// every vertex of every stroke reached with the pen down.
fn drawn_as_planned(v: &vectorize::Vectorized, machine: Machine, within: f64) -> (usize, f64) {
    let mut sim = boot_machine();
    send_ok(
        &mut sim,
        &format!("$machine={}", machine.name()),
        Duration::from_secs(5),
    );
    for line in v.gcode.lines() {
        send_ok(&mut sim, line, Duration::from_secs(60));
    }
    send_ok(&mut sim, "M400", Duration::from_secs(60));
    let cfg = MachineConfig::defaults(machine);
    let kin = AnyKinematics::of(&cfg).unwrap();
    let down_deg = f64::from(cfg.pen.down_deg);
    let points = track(&sim);
    let mut down_steps = 0;
    for (cycle, steps) in &points {
        let p = at(&kin, *steps);
        let down = (pen_deg_at(&sim, *cycle).expect("pen pulses") - down_deg).abs() < 1.0;
        down_steps += usize::from(down);
        let off = off_path(&v.toolpath, p, down);
        assert!(
            off <= within,
            "{machine:?}: ({:.3}, {:.3}) is {off:.3} mm off, pen down: {down}",
            p[0],
            p[1]
        );
    }
    for s in &v.strokes {
        for q in s {
            let near = points.iter().map(|(_, st)| {
                let p = at(&kin, *st);
                (p[0] - q[0]).hypot(p[1] - q[1])
            });
            assert!(
                near.fold(f64::MAX, f64::min) <= within,
                "{machine:?}: never at {q:?}"
            );
        }
    }
    assert_ram_budget(&sim);
    (down_steps, sim.time_s())
}

#[test]
fn an_inkscape_drawing_is_drawn_on_the_flatbed_and_the_whiteboard() {
    let svg = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/svg/inkscape-layers.svg");
    let source = vectorize::Source::open(&svg).unwrap();
    // A step of each motor off (a move's ends rounded to steps, the DDA's
    // minor axis within a step between them), or the chord a curve was cut
    // into: the flatbed 0.025 mm a step; the whiteboard's chain 1143/20000
    // mm a step, the two chains meeting near a right angle across the
    // drawing, so √2 steps (0.081 mm) and 5 % for the angle.
    let chain = 1143.0 / 20000.0 * 2f64.sqrt() * 1.05;
    for (machine, within) in [(Machine::Flatbed, 0.046), (Machine::Whiteboard, chain)] {
        let wall = Instant::now();
        let mut o = vectorize::Options::new(machine, 30.0);
        // One pass: the pen changes (M0) would wait for a cycle start.
        o.one_pen = true;
        o.hatch_mm = 1.0;
        o.feed = 3000.0;
        let v = vectorize::vectorize(&source, &o, "layers").unwrap();
        let (down_steps, machine_s) = drawn_as_planned(&v, machine, within);
        let (drawn, _) = v.toolpath.lengths();
        assert!(down_steps > 0 && drawn > 100.0, "{machine:?}: {drawn} mm");
        eprintln!(
            "inkscape-layers.svg at 30 mm on the {machine:?}: {} strokes, {:.0} mm pen down, {down_steps} pen-down steps, \
             {machine_s:.0} s machine time (planner: {:.0} s) in {:.1} s",
            v.strokes.len(),
            drawn,
            v.seconds,
            wall.elapsed().as_secs_f64()
        );
    }
}
