//! What plotter users send, at random. From a list of seeds,
//! streams of tiny moves, longer ones and arcs of random radius and sweep
//! at random feeds, on the two machines whose kinematics are not linear
//! (the whiteboard's strings, the SCARA arm: every straight move is cut
//! into 1 mm pieces, every arc into chords); each drawing is rebuilt from
//! the pulses alone and every pulse must lie on the toolpath. A reset at
//! a random moment stops everything at once.

use hil_tests::drawing::{assert_drawn_from_the_pulses, home, Drawing, PenWords, Toolpath};
use hil_tests::sim::{Reply, Sim};
use hil_tests::{boot_machine, log_tail, send_ok, soak_or, steps_on_pins, Rng};
use std::time::Duration;
use taut_logic::machine::Machine;

fn send(sim: &mut Sim, line: &str) {
    send_ok(sim, line, Duration::from_secs(60));
}

/// `n` random moves inside the square of half-side `half` round `centre`,
/// the pen down: tiny moves (0.05–0.5 mm) most often, longer ones, and
/// arcs (`G2`/`G3`, radius 1–6 mm, any sweep, full circles) at random
/// feeds of 300–3000 mm/min.
fn random_drawing(
    rng: &mut Rng,
    machine: Machine,
    centre: [f64; 2],
    half: f64,
    n: usize,
) -> Drawing {
    let round = |v: f64| (v * 1000.0).round() / 1000.0;
    let inside = |p: [f64; 2]| (p[0] - centre[0]).abs() < half && (p[1] - centre[1]).abs() < half;
    let pen = PenWords::Spindle;
    let mut lines = vec![
        pen.line(false).to_string(),
        format!("G0 X{} Y{}", centre[0], centre[1]),
        pen.line(true).to_string(),
    ];
    let mut drawn = Toolpath(vec![centre]);
    let mut at = centre;
    while lines.len() < n + 3 {
        let f = rng.below(2700) + 300;
        let kind = rng.below(10);
        if kind < 8 {
            let len = match kind {
                0..=5 => rng.between(0.05, 0.5),
                _ => rng.between(1.0, 8.0),
            };
            let a = rng.between(0.0, std::f64::consts::TAU);
            let to = [round(at[0] + len * a.cos()), round(at[1] + len * a.sin())];
            if !inside(to) {
                continue;
            }
            lines.push(format!("G1 X{} Y{} F{f}", to[0], to[1]));
            drawn.line_to(to);
            at = to;
        } else {
            // The centre at a rounded offset, the end on its circle.
            let r = rng.between(1.0, 6.0);
            let a = rng.between(0.0, std::f64::consts::TAU);
            let (i, j) = (round(r * a.cos()), round(r * a.sin()));
            let c = [at[0] + i, at[1] + j];
            let r = i.hypot(j);
            let b = rng.between(0.0, std::f64::consts::TAU);
            let full = rng.below(4) == 0;
            let to = match full {
                true => at,
                false => [round(c[0] + r * b.cos()), round(c[1] + r * b.sin())],
            };
            // Inside with its whole circle.
            if !inside([c[0] - r, c[1] - r]) || !inside([c[0] + r, c[1] + r]) {
                continue;
            }
            let ccw = rng.below(2) == 0;
            let g = if ccw { "G3" } else { "G2" };
            lines.push(format!("{g} X{} Y{} I{i} J{j} F{f}", to[0], to[1]));
            drawn.arc_to(c, to, ccw);
            at = to;
        }
    }
    lines.push(pen.line(false).to_string());
    lines.push("M400".to_string());
    Drawing {
        lines,
        drawn,
        travel: Toolpath(vec![home(machine), centre, at]),
        end: at,
    }
}

fn random_drawings_on(machine: Machine, centre: [f64; 2], half: f64, within: f64) {
    for seed in soak_or(vec![1u64, 2, 3, 4, 5, 6, 7, 8], vec![21, 22]) {
        let mut rng = Rng::new(seed);
        let d = random_drawing(&mut rng, machine, centre, half, soak_or(400, 60));
        let mut sim = boot_machine();
        send(&mut sim, &format!("$machine={}", machine.name()));
        send(&mut sim, "M17");
        for line in &d.lines {
            match sim.send_line(line, Duration::from_secs(60)) {
                Ok(Reply::Ok) => {}
                other => panic!("seed {seed}: {line}: {other:?}\n{}", log_tail(&sim)),
            }
        }
        eprintln!("seed {seed}: {} lines", d.lines.len());
        assert_drawn_from_the_pulses(&sim, machine, &d, within);
        sim.run_for(Duration::from_millis(1100));
        assert!(!sim.uart_text().contains("underruns"), "{}", log_tail(&sim));
    }
}

#[test]
fn seeded_tiny_moves_and_arcs_on_the_whiteboard_stay_on_their_toolpath() {
    random_drawings_on(Machine::Whiteboard, [0.0, 0.0], 20.0, 0.1);
}

#[test]
fn seeded_tiny_moves_and_arcs_on_the_scara_arm_stay_on_their_toolpath() {
    random_drawings_on(Machine::Scara, [100.0, 150.0], 15.0, 0.3);
}

/// Ctrl-X at a random moment of an arc being cut into pieces: the steps
/// stop at once and no piece of it follows.
#[test]
fn a_reset_at_a_seeded_moment_of_an_arc_stops_it_for_good() {
    for seed in soak_or(vec![1u64, 2, 3, 4, 5, 6, 7, 8], vec![31, 32, 33]) {
        let mut rng = Rng::new(seed);
        let mut sim = boot_machine();
        send(&mut sim, "$machine=scara");
        send(&mut sim, "M17");
        send(&mut sim, "G0 X100 Y140");
        send(&mut sim, "M400");
        sim.uart_send(b"G2 X100 Y140 I0 J10 F1500\n");
        sim.run_for(Duration::from_secs_f64(rng.between(0.05, 2.0)));
        sim.uart_send(&[0x18]);
        sim.run_for(Duration::from_millis(50));
        let stopped = steps_on_pins(&sim);
        sim.run_for(Duration::from_secs(2));
        assert_eq!(
            steps_on_pins(&sim),
            stopped,
            "seed {seed}: moved after the reset"
        );
        let log = sim.uart_text();
        assert!(
            log.contains("ALARM:3") && log.contains("position unknown until $H"),
            "seed {seed}: {}",
            log_tail(&sim)
        );
        // The machine answers and, once told where it is, moves again.
        send(&mut sim, "$X");
        send(&mut sim, "G0 X100 Y140");
        send(&mut sim, "M400");
    }
}
