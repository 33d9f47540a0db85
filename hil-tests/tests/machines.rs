//! Issue 11: one image, five machines. Each plotter and the arm is chosen
//! with `$machine=`, draws over the serial port, and its drawing is rebuilt
//! from the step and direction pulses alone through its own forward
//! kinematics, point by point against the toolpath the G-code defines.

use hil_tests::sim::Sim;
use hil_tests::{assert_ram_budget, boot_machine, log_tail, send_ok, track};
use std::time::Duration;
use taut_logic::config::MachineConfig;
use taut_logic::kinematics::{AnyKinematics, Kinematics};
use taut_logic::machine::Machine;

fn send(sim: &mut Sim, line: &str) {
    send_ok(sim, line, Duration::from_secs(60));
}

/// The toolpath as a polyline, mm: straight moves as they are, arcs
/// sampled far finer than the chord tolerance.
struct Toolpath(Vec<[f64; 2]>);

impl Toolpath {
    fn line_to(&mut self, p: [f64; 2]) {
        self.0.push(p);
    }

    /// Counter-clockwise half turn round `c` from the last point.
    fn half_turn_ccw(&mut self, c: [f64; 2]) {
        let p = *self.0.last().unwrap();
        let (r, a0) = (
            (p[0] - c[0]).hypot(p[1] - c[1]),
            (p[1] - c[1]).atan2(p[0] - c[0]),
        );
        for k in 1..=2000 {
            let a = a0 + std::f64::consts::PI * k as f64 / 2000.0;
            self.0.push([c[0] + r * a.cos(), c[1] + r * a.sin()]);
        }
    }

    fn distance(&self, p: [f64; 2]) -> f64 {
        self.0
            .windows(2)
            .map(|w| {
                let (a, b) = (w[0], w[1]);
                let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
                let len2 = dx * dx + dy * dy;
                let t = match len2 {
                    0.0 => 0.0,
                    _ => (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0),
                };
                (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dy)
            })
            .fold(f64::MAX, f64::min)
    }
}

/// A square, a half circle on its top and lines out from its centre in
/// all eight octants (they catch a sign or octant slip), at `(x, y)` mm.
fn draw(sim: &mut Sim, x: f64, y: f64) -> Toolpath {
    let mut path = Toolpath(Vec::new());
    let mut go = |sim: &mut Sim, line: String, to: [f64; 2]| {
        send(sim, &line);
        path.line_to(to);
    };
    go(sim, format!("G0 X{x} Y{y}"), [x, y]);
    go(sim, format!("G1 X{} Y{y} F1200", x + 20.0), [x + 20.0, y]);
    go(
        sim,
        format!("G1 X{} Y{}", x + 20.0, y + 20.0),
        [x + 20.0, y + 20.0],
    );
    send(sim, &format!("G3 X{x} Y{} I-10 J0", y + 20.0));
    path.half_turn_ccw([x + 10.0, y + 20.0]);
    let c = [x + 10.0, y + 10.0];
    let mut go = |sim: &mut Sim, line: String, to: [f64; 2]| {
        send(sim, &line);
        path.line_to(to);
    };
    go(sim, format!("G1 X{} Y{}", c[0], c[1]), c);
    for (dx, dy) in [
        (6, 2),
        (2, 6),
        (-2, 6),
        (-6, 2),
        (-6, -2),
        (-2, -6),
        (2, -6),
        (6, -2),
    ] {
        let to = [c[0] + dx as f64, c[1] + dy as f64];
        go(sim, format!("G1 X{} Y{}", to[0], to[1]), to);
        go(sim, format!("G1 X{} Y{}", c[0], c[1]), c);
    }
    send(sim, "M400");
    path
}

/// Draws on `machine` and checks every pulse of the drawing against the
/// toolpath, within `within` mm (about a step of its coarsest motor).
fn drawn_from_the_pulses(machine: Machine, at: [f64; 2], within: f64) {
    let mut sim = boot_machine();
    send(&mut sim, &format!("$machine={}", machine.name()));
    send(&mut sim, "M17");
    let cfg = MachineConfig::defaults(machine);
    let kin = AnyKinematics::of(&cfg).unwrap();
    let path = draw(&mut sim, at[0], at[1]);
    let pos = |steps: [i64; 3]| {
        let p = kin.forward(&[steps[0] as i32, steps[1] as i32, steps[2] as i32, 0]);
        [p[0].0 as f64 / 1000.0, p[1].0 as f64 / 1000.0]
    };
    let points = track(&sim);
    // The first move comes from wherever the machine stood: checked from
    // the first pulse at the drawing's start.
    let start = points
        .iter()
        .position(|(_, s)| {
            let p = pos(*s);
            (p[0] - at[0]).hypot(p[1] - at[1]) < within
        })
        .expect("never reached the drawing's start");
    let mut worst: f64 = 0.0;
    for (_, s) in &points[start..] {
        let p = pos(*s);
        let d = path.distance(p);
        worst = worst.max(d);
        assert!(
            d <= within,
            "{machine:?}: ({:.3}, {:.3}) is {d:.3} mm off the toolpath",
            p[0],
            p[1]
        );
    }
    // Every corner and tip is reached, and the drawing ends on its target.
    for v in [path.0[1], path.0[2], path.0[path.0.len() - 2]] {
        let near = points[start..].iter().map(|(_, s)| {
            let p = pos(*s);
            (p[0] - v[0]).hypot(p[1] - v[1])
        });
        assert!(
            near.fold(f64::MAX, f64::min) <= within,
            "{machine:?}: never at {v:?}"
        );
    }
    let end = pos(points.last().unwrap().1);
    let target = path.0.last().unwrap();
    assert!(
        (end[0] - target[0]).hypot(end[1] - target[1]) <= within,
        "{machine:?} ended at {end:?}\n{}",
        log_tail(&sim)
    );
    eprintln!(
        "{machine:?}: {} pulses, worst {worst:.3} mm off",
        points.len() - start
    );
    assert_ram_budget(&sim);
}

#[test]
fn the_drum_plotter_draws_its_toolpath() {
    // Y: 7.24 steps/mm of paper (a step is 0.14 mm).
    drawn_from_the_pulses(Machine::Drum, [5.0, 5.0], 0.15);
}

#[test]
fn the_flatbed_plotter_draws_its_toolpath() {
    // 0.025 mm a step: a step of each axis off, or the chord tolerance.
    drawn_from_the_pulses(Machine::Flatbed, [5.0, 5.0], 0.046);
}

#[test]
fn the_whiteboard_machine_draws_its_toolpath() {
    // 17.5 steps per mm of chain: a step of both moves the pen ~0.08 mm.
    drawn_from_the_pulses(Machine::Whiteboard, [-10.0, -10.0], 0.1);
}

#[test]
fn the_scara_arm_draws_its_toolpath() {
    // 26.7 steps a degree: at 220 mm from the shoulder a shoulder step is
    // 0.14 mm, an elbow step 0.1 mm at the 150 mm forearm.
    drawn_from_the_pulses(Machine::Scara, [90.0, 140.0], 0.25);
}
