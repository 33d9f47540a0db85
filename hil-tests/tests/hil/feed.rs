//! Feed is the pen's speed on every machine: on the whiteboard and the
//! SCARA arm, whose straight lines are cut into pieces and planned in
//! joint space, `F` is the pen's speed along the line, `pen_accel` its
//! acceleration, and every joint stays within its own `max_rate` and
//! `accel`. Seeded random lines of 10–100 mm at F300–F3000 in several
//! places of each machine's work area are drawn on the release image;
//! each takes, from its first step to its last, within 3 % of the ideal
//! time worked out on the host (`hil_tests::feed::ideal`: the pen's
//! trapezoid along the line, slowed only where a joint's own limit binds;
//! where none does, and that is most lines, within 3 % of the pen's
//! trapezoid itself), and no joint steps faster than its limit (read from
//! the pulses). The status report's `FS:` is the pen's speed.
//! `TAUT_SOAK=1` draws more lines per place.

use hil_tests::feed::{draw_line, ideal, rate_bound, trapezoid_s, Measured};
use hil_tests::sim::{Reply, Sim};
use hil_tests::{assert_ram_budget, boot_machine, log_tail, send_ok, soak_or, track, Rng};
use std::time::Duration;
use taut_logic::config::MachineConfig;
use taut_logic::kinematics::{AnyKinematics, Kinematics};
use taut_logic::machine::Machine;
use taut_logic::units::Milli;

/// Within this share of the ideal time.
const TOLERANCE: f64 = 0.03;

fn machine(m: Machine, settings: &[&str]) -> (Sim, MachineConfig) {
    let mut sim = boot_machine();
    let mut cfg = MachineConfig::defaults(m);
    let t = Duration::from_secs(2);
    send_ok(&mut sim, &format!("$machine={}", m.name()), t);
    for s in settings {
        send_ok(&mut sim, s, t);
        let (key, value) = s[1..].split_once('=').unwrap();
        taut_logic::settings::set(&mut cfg, key, value).unwrap();
    }
    send_ok(&mut sim, "M17", t);
    (sim, cfg)
}

fn at(p: [f64; 2]) -> [Milli; 3] {
    [
        Milli((p[0] * 1000.0).round() as i32),
        Milli((p[1] * 1000.0).round() as i32),
        Milli(0),
    ]
}

/// Seeded lines centred on `places`, `per_place` each: a random
/// direction, 10–100 mm (shortened while the machine cannot draw it
/// whole), F300–F3000. Each line's feed is a whole number.
fn lines(
    cfg: &MachineConfig,
    places: &[[f64; 2]],
    per_place: usize,
    seed: u64,
) -> Vec<([f64; 2], [f64; 2], f64)> {
    let kin = AnyKinematics::of(cfg).unwrap();
    let mut rng = Rng::new(seed);
    let mut out = Vec::new();
    for c in places {
        for _ in 0..per_place {
            let angle = rng.between(0.0, std::f64::consts::TAU);
            let mut length = rng.between(10.0, 100.0);
            let feed = rng.between(300.0, 3000.0).round();
            let ends = |l: f64| {
                let (dx, dy) = (l / 2.0 * angle.cos(), l / 2.0 * angle.sin());
                ([c[0] - dx, c[1] - dy], [c[0] + dx, c[1] + dy])
            };
            while !kin.reaches_line(&at(ends(length).0), &at(ends(length).1)) {
                length *= 0.8;
                assert!(length >= 10.0, "no line of 10 mm at {c:?}");
            }
            let (a, b) = ends(length);
            let round = |p: [f64; 2]| p.map(|v| (v * 1000.0).round() / 1000.0);
            out.push((round(a), round(b), feed));
        }
    }
    out
}

/// Draws every line; each takes its ideal time within the tolerance and
/// no joint steps faster than its limit.
fn every_line_at_its_feed(
    m: Machine,
    settings: &[&str],
    places: &[[f64; 2]],
    seed: u64,
) -> Vec<Measured> {
    let (mut sim, cfg) = machine(m, settings);
    let per_place = soak_or(12, 2);
    let mut out = Vec::new();
    for (a, b, feed) in lines(&cfg, places, per_place, seed) {
        let got = draw_line(&mut sim, &cfg, a, b, feed);
        let length = (b[0] - a[0]).hypot(b[1] - a[1]);
        eprintln!(
            "{m:?} {a:?} → {b:?} ({length:.1} mm) F{feed}: {:.4} s, ideal {:.4} s ({:+.2} %), \
             the pen's trapezoid {:.4} s ({:+.2} %; whole line {:.4} s); joint rates {:.0} / {:.0} steps/s",
            got.seconds,
            got.ideal,
            100.0 * (got.seconds / got.ideal - 1.0),
            got.cartesian,
            100.0 * (got.seconds / got.cartesian - 1.0),
            got.trapezoid,
            got.rate[0],
            got.rate[1],
        );
        assert!(
            (got.seconds / got.ideal - 1.0).abs() <= TOLERANCE,
            "{m:?} {a:?} → {b:?} F{feed}: {:.4} s, ideal {:.4} s\n{}",
            got.seconds,
            got.ideal,
            log_tail(&sim)
        );
        for j in 0..2 {
            let limit = cfg.axes[j].max_rate as f64;
            assert!(
                got.rate[j] <= rate_bound(limit),
                "{m:?} {a:?} → {b:?} F{feed}: joint {j} at {:.0} steps/s, its limit {limit}",
                got.rate[j]
            );
        }
        out.push(got);
    }
    assert_ram_budget(&sim);
    out
}

/// Where no joint's limit binds (the ideal within 0.5 % of the pen's own
/// trapezoid), a line is within the tolerance of the pen's trapezoid
/// itself; with a machine's default figures most lines are such.
fn mostly_the_pens_trapezoid(m: Machine, lines: &[Measured]) {
    let free: Vec<&Measured> = lines
        .iter()
        .filter(|l| (l.ideal / l.cartesian - 1.0).abs() < 0.005)
        .collect();
    for l in &free {
        assert!(
            (l.seconds / l.cartesian - 1.0).abs() <= TOLERANCE,
            "{m:?}: {l:?}"
        );
    }
    assert!(
        3 * free.len() >= 2 * lines.len(),
        "{m:?}: {} of {} lines free of the joints' limits",
        free.len(),
        lines.len()
    );
}

/// The whiteboard's board, 1.2 m between the motors: its middle, its four
/// quarters and its bottom, each line the pen's own speed.
#[test]
fn whiteboard_lines_take_the_time_of_the_pens_path() {
    let places = [
        [0.0, 0.0],
        [-350.0, -250.0],
        [350.0, -250.0],
        [-350.0, 200.0],
        [350.0, 200.0],
        [0.0, -400.0],
    ];
    let lines = every_line_at_its_feed(Machine::Whiteboard, &[], &places, 3);
    mostly_the_pens_trapezoid(Machine::Whiteboard, &lines);
}

/// The whiteboard with slow chains (800 steps/s, 46 mm/s of chain, and
/// 400 steps/s²): near the board's edges a chain carries most of the
/// pen's speed, and the line slows there, the chain at its limit.
#[test]
fn whiteboard_lines_slow_where_a_chain_would_exceed_its_limits() {
    let places = [
        [-450.0, 250.0],
        [450.0, 250.0],
        [-450.0, -450.0],
        [450.0, -450.0],
        [0.0, 300.0],
    ];
    let slow = [
        "$left_max_rate=800",
        "$right_max_rate=800",
        "$left_accel=400",
        "$right_accel=400",
    ];
    let lines = every_line_at_its_feed(Machine::Whiteboard, &slow, &places, 4);
    // At least one line was held back by a chain: slower than its
    // trapezoid along the pen's path.
    assert!(lines.iter().any(|l| l.seconds > 1.1 * l.trapezoid));
}

/// The arm in front of its base (the shoulder at 100, −56; arms of 150
/// mm): near the shoulder, in the middle, to either side and near the
/// arms' full reach, where the elbow's rate and acceleration bind.
#[test]
fn scara_lines_take_the_time_of_the_pens_path() {
    let places = [
        [100.0, 100.0],
        [20.0, 150.0],
        [180.0, 150.0],
        [30.0, 40.0],
        [170.0, 40.0],
        [100.0, 215.0],
    ];
    let lines = every_line_at_its_feed(Machine::Scara, &[], &places, 5);
    mostly_the_pens_trapezoid(Machine::Scara, &lines);
}

/// `FS:` and `MPos:` of the status report after a `?`, whole.
fn feed_and_place(sim: &mut Sim) -> (f64, [f64; 2], u64) {
    let from = sim.uart_bytes().len();
    sim.uart_send(b"?");
    let report = |s: &Sim| {
        let text = s.uart_text_from(from);
        let line = text
            .lines()
            .find(|l| l.starts_with('<') && l.ends_with('>'))?;
        let field = |name: &str| {
            let f = line.split(['|', '>']).find_map(|f| f.strip_prefix(name))?;
            Some(
                f.split(',')
                    .map(|v| v.parse::<f64>().unwrap())
                    .collect::<Vec<_>>(),
            )
        };
        Some((field("FS:")?[0], field("MPos:")?))
    };
    sim.run_until(|s| report(s).is_some(), Duration::from_millis(50));
    let (feed, pos) = report(sim).unwrap_or_else(|| panic!("no report\n{}", log_tail(sim)));
    (feed, [pos[0], pos[1]], sim.cycles())
}

/// The status report's `FS:` is the pen's speed: in the middle of a line
/// at F1200 where no joint's limit binds (the ideal worked out on the host
/// is the pen's trapezoid), it reports 1200 on both machines, and the pen
/// covers 1200 mm/min between reports, while the joints turn at rates of
/// their own.
#[test]
fn status_reports_the_pens_feed() {
    let lines: [(Machine, [f64; 2], [f64; 2]); 2] = [
        (Machine::Whiteboard, [-150.0, -100.0], [150.0, -100.0]),
        (Machine::Scara, [40.0, 150.0], [160.0, 150.0]),
    ];
    for (m, a, b) in lines {
        let (mut sim, cfg) = machine(m, &[]);
        let length = (b[0] - a[0]).hypot(b[1] - a[1]);
        let trapezoid = trapezoid_s(length, 1200.0, cfg.pen_accel as f64);
        let free = ideal(&cfg, a, b, 1200.0).total();
        assert!(
            (free / trapezoid - 1.0).abs() < 0.005,
            "{m:?}: {free} s, trapezoid {trapezoid} s"
        );
        let t = Duration::from_secs(60);
        send_ok(&mut sim, &format!("G0 X{} Y{}", a[0], a[1]), t);
        send_ok(&mut sim, "M400", t);
        // Not waiting for its `ok`: that comes once its last pieces are
        // queued, near its end.
        let sent = sim.uart_bytes().len();
        sim.uart_send(format!("G1 X{} Y{} F1200\n", b[0], b[1]).as_bytes());
        sim.run_for(Duration::from_secs(1));
        let mut last = feed_and_place(&mut sim);
        for _ in 0..3 {
            sim.run_for(Duration::from_secs(1));
            let now = feed_and_place(&mut sim);
            let (feed, pos, cycle) = now;
            let moved = (pos[0] - last.1[0]).hypot(pos[1] - last.1[1]);
            let speed = moved / ((cycle - last.2) as f64 / 16e6) * 60.0;
            eprintln!("{m:?} at {pos:?}: FS {feed}, the pen at {speed:.1} mm/min");
            assert!(
                (feed / 1200.0 - 1.0).abs() < 0.01,
                "{m:?} at {pos:?}: FS:{feed}"
            );
            assert!(
                (speed / 1200.0 - 1.0).abs() < 0.02,
                "{m:?} at {pos:?}: {speed} mm/min"
            );
            last = now;
        }
        sim.run_until(|s| s.uart_text_from(sent).contains("ok\n"), t);
        send_ok(&mut sim, "M400", t);
        assert_eq!(feed_and_place(&mut sim).0, 0.0, "{m:?} standing");
    }
}

/// A straight move that would cross the ray behind the arm's shoulder
/// (its shoulder turning the long way round, pen down) is refused with
/// `error:33` before anything moves, and so is an arc across it; the
/// same ends joined by an arc round the front of the shoulder are drawn,
/// the shoulder turning once from one to the other.
#[test]
fn scara_refuses_a_move_behind_its_base_before_anything_moves() {
    let (mut sim, cfg) = machine(Machine::Scara, &[]);
    let t = Duration::from_secs(60);
    // Behind the base, 102 mm left and right of the shoulder (100, −56).
    send_ok(&mut sim, "G0 X60 Y-150", t);
    send_ok(&mut sim, "M400", t);
    let before = track(&sim).len();
    for line in [
        "G1 X140 Y-150 F600",
        "G3 X140 Y-150 I40 J94 F600",
        "G0 X140 Y-150",
    ] {
        match sim.send_line(line, t) {
            Ok(Reply::Error(e)) => assert!(e.starts_with("error:33"), "{line}: {e}"),
            other => panic!("{line}: {other:?}\n{}", log_tail(&sim)),
        }
    }
    sim.run_for(Duration::from_millis(500));
    assert_eq!(track(&sim).len(), before, "a refused move stepped");
    // Clockwise round the front: 314° of the pen's bearing.
    send_ok(&mut sim, "G2 X140 Y-150 I40 J94 F3000", t);
    send_ok(&mut sim, "M400", t);
    let path = &track(&sim)[before..];
    let kin = AnyKinematics::of(&cfg).unwrap();
    let (from, to) = (
        kin.inverse(&at([60.0, -150.0])).unwrap(),
        kin.inverse(&at([140.0, -150.0])).unwrap(),
    );
    let end = path.last().unwrap().1;
    assert!(
        (end[0] - to[0] as i64).abs() <= 1 && (end[1] - to[1] as i64).abs() <= 1,
        "ended at {end:?}, not {to:?}"
    );
    // Every shoulder pulse on the way there: none spent going round.
    let expected = (to[0] - from[0]).unsigned_abs() as usize;
    let pulses = path.windows(2).filter(|w| w[0].1[0] != w[1].1[0]).count() + 1;
    assert!(
        expected > 8000 && pulses <= expected + 4,
        "{pulses} shoulder pulses for {expected} steps"
    );
    assert_ram_budget(&sim);
}
