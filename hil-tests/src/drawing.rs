//! A plotter's test drawing: the G-code lines that draw it, the toolpath
//! they define, and its check against the machine's step, direction and
//! pen pulses alone, rebuilt through the machine's forward kinematics.

use crate::{assert_ram_budget, log_tail, pen_deg_at, sim::Sim, track};
use taut_logic::config::MachineConfig;
use taut_logic::kinematics::{AnyKinematics, Kinematics};
use taut_logic::machine::Machine;

/// The toolpath as a polyline, mm: straight moves as they are, arcs
/// sampled far finer than the chord tolerance.
pub struct Toolpath(pub Vec<[f64; 2]>);

impl Toolpath {
    pub fn line_to(&mut self, p: [f64; 2]) {
        self.0.push(p);
    }

    /// From the last point round `c` to `to` (on the same circle),
    /// counter-clockwise or not, a full turn when `to` is the start.
    pub fn arc_to(&mut self, c: [f64; 2], to: [f64; 2], ccw: bool) {
        let p = *self.0.last().unwrap();
        let r = (p[0] - c[0]).hypot(p[1] - c[1]);
        let a0 = (p[1] - c[1]).atan2(p[0] - c[0]);
        let a1 = (to[1] - c[1]).atan2(to[0] - c[0]);
        let tau = std::f64::consts::TAU;
        let mut sweep = if ccw { a1 - a0 } else { a0 - a1 }.rem_euclid(tau);
        if sweep < 1e-9 {
            sweep = tau;
        }
        let n = ((sweep * r / 0.01).ceil() as usize).max(8);
        for k in 1..n {
            let a = a0 + if ccw { 1.0 } else { -1.0 } * sweep * k as f64 / n as f64;
            self.0.push([c[0] + r * a.cos(), c[1] + r * a.sin()]);
        }
        self.0.push(to);
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

    pub fn distance(&self, p: [f64; 2]) -> f64 {
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

/// How a machine's G-code lifts and lowers its pen.
#[derive(Clone, Copy)]
pub enum PenWords {
    /// `M3` / `M5` (Grbl's servo forks).
    Spindle,
    /// `M300 S30` / `M300 S50` (the Inkscape "unicorn" extension).
    Unicorn,
    /// `G1 Z0` / `G0 Z1` (seed 002, gcodetools).
    Z,
}

impl PenWords {
    pub fn line(self, down: bool) -> &'static str {
        match (self, down) {
            (PenWords::Spindle, true) => "M3",
            (PenWords::Spindle, false) => "M5",
            (PenWords::Unicorn, true) => "M300 S30",
            (PenWords::Unicorn, false) => "M300 S50",
            (PenWords::Z, true) => "G1 Z0 F300",
            (PenWords::Z, false) => "G0 Z1",
        }
    }
}

/// The drawing: its lines, what the pen draws, where it travels up, and
/// where it ends.
pub struct Drawing {
    pub lines: Vec<String>,
    pub drawn: Toolpath,
    pub travel: Toolpath,
    pub end: [f64; 2],
}

/// From `from`, with the pen up, to `(x, y)` mm; with it down, a square, a
/// half circle on its top and lines out from its centre in all eight
/// octants (they catch a sign or octant slip); with it up, back to
/// `(x, y)`; then `M400`.
pub fn drawing(pen: PenWords, from: [f64; 2], x: f64, y: f64) -> Drawing {
    let mut lines = vec![
        pen.line(false).to_string(),
        format!("G0 X{x} Y{y}"),
        pen.line(true).to_string(),
    ];
    let mut drawn = Toolpath(vec![[x, y]]);
    let mut go = |lines: &mut Vec<String>, to: [f64; 2]| {
        lines.push(format!("G1 X{} Y{} F1200", to[0], to[1]));
        drawn.line_to(to);
    };
    go(&mut lines, [x + 20.0, y]);
    go(&mut lines, [x + 20.0, y + 20.0]);
    lines.push(format!("G3 X{x} Y{} I-10 J0", y + 20.0));
    drawn.half_turn_ccw([x + 10.0, y + 20.0]);
    let c = [x + 10.0, y + 10.0];
    let mut go = |lines: &mut Vec<String>, to: [f64; 2]| {
        lines.push(format!("G1 X{} Y{}", to[0], to[1]));
        drawn.line_to(to);
    };
    go(&mut lines, c);
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
        go(&mut lines, [c[0] + dx as f64, c[1] + dy as f64]);
        go(&mut lines, c);
    }
    lines.push(pen.line(false).to_string());
    lines.push(format!("G0 X{x} Y{y}"));
    lines.push("M400".to_string());
    Drawing {
        lines,
        drawn,
        travel: Toolpath(vec![from, [x, y], c, [x, y]]),
        end: [x, y],
    }
}

/// Where `machine` stands at zero steps, mm.
pub fn home(machine: Machine) -> [f64; 2] {
    position(machine, [0; 3])
}

fn position(machine: Machine, steps: [i64; 3]) -> [f64; 2] {
    let kin = AnyKinematics::of(&MachineConfig::defaults(machine)).unwrap();
    let p = kin.forward(&[steps[0] as i32, steps[1] as i32, steps[2] as i32]);
    [p[0].0 as f64 / 1000.0, p[1].0 as f64 / 1000.0]
}

/// Checks every pulse against the drawing, within `within` mm (about a
/// step of the coarsest motor): while the pen PWM says down, on what the
/// G-code draws; while it says up, on the travel. Every corner and tip is
/// reached and the drawing ends on its target; the RAM budget holds.
pub fn assert_drawn_from_the_pulses(sim: &Sim, machine: Machine, d: &Drawing, within: f64) {
    let cfg = MachineConfig::defaults(machine);
    let points = track(sim);
    let (mut worst, mut down) = (0.0f64, 0);
    for (cycle, s) in &points {
        let p = position(machine, *s);
        let deg = pen_deg_at(sim, *cycle).expect("no pen pulses");
        let is_down = (deg - f64::from(cfg.pen.down_deg)).abs() < 1.0;
        let is_up = (deg - f64::from(cfg.pen.up_deg)).abs() < 1.0;
        assert!(
            is_down || is_up,
            "{machine:?}: pen at {deg:.1}° while moving"
        );
        let path = if is_down { &d.drawn } else { &d.travel };
        down += is_down as usize;
        let dist = path.distance(p);
        worst = worst.max(dist);
        assert!(
            dist <= within,
            "{machine:?}: ({:.3}, {:.3}) is {dist:.3} mm off the toolpath, pen {}",
            p[0],
            p[1],
            if is_down { "down" } else { "up" }
        );
    }
    let drawn = &d.drawn.0;
    for v in [drawn[1], drawn[2], drawn[drawn.len() - 2]] {
        let near = points.iter().map(|(_, s)| {
            let p = position(machine, *s);
            (p[0] - v[0]).hypot(p[1] - v[1])
        });
        assert!(
            near.fold(f64::MAX, f64::min) <= within,
            "{machine:?}: never at {v:?}"
        );
    }
    let end = position(machine, points.last().unwrap().1);
    assert!(
        (end[0] - d.end[0]).hypot(end[1] - d.end[1]) <= within,
        "{machine:?} ended at {end:?}\n{}",
        log_tail(sim)
    );
    eprintln!(
        "{machine:?}: {} pulses ({down} with the pen down), worst {worst:.3} mm off; stack {} B at {:#x}",
        points.len(),
        sim.peak_stack_bytes(),
        sim.peak_stack_pc()
    );
    assert_ram_budget(sim);
}
