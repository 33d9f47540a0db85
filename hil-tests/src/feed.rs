//! Feed along the pen on the machines whose kinematics are not linear
//! (the whiteboard, the SCARA arm): a straight line's ideal time worked
//! out on the host, independently of the firmware's planner, and the
//! line's time and joint rates measured from the pulses alone.
//!
//! The ideal is the fastest motion along the line from rest to rest with
//! the pen's speed at most the feed (and `pen_max_feed`), its
//! acceleration at most `pen_accel`, and every joint within its own
//! limits: its speed `max_rate` and its acceleration `accel`, both for
//! the speed's change along the line and for the change of the joint's
//! share of it (the line's curvature in joint space). Joints are worked
//! out here in `f64` from the machine's geometry, not with the
//! firmware's kinematics; the profile is integrated on a 0.02 mm grid
//! (forward and backward passes, as a look-ahead planner of infinite
//! depth would).

use crate::sim::Sim;
use crate::{send_ok, track};
use std::time::Duration;
use taut_logic::config::MachineConfig;
use taut_logic::kinematics::{AnyKinematics, Kinematics, Segmenter};
use taut_logic::machine::Machine;
use taut_logic::units::Milli;

/// Grid of the ideal profile, mm.
const DS: f64 = 0.02;

/// A machine's joints as functions of the pen's place, in steps, exact.
pub struct Joints {
    cfg: MachineConfig,
}

impl Joints {
    pub fn new(cfg: &MachineConfig) -> Joints {
        assert!(matches!(cfg.machine, Machine::Whiteboard | Machine::Scara));
        Joints { cfg: *cfg }
    }

    fn mm(m: Milli) -> f64 {
        m.0 as f64 / 1000.0
    }

    fn spu(&self, i: usize) -> f64 {
        let s = self.cfg.axes[i].steps_per_unit;
        s.num as f64 / s.den as f64
    }

    /// Both joints' positions at the pen's `p` (mm), steps.
    pub fn at(&self, p: [f64; 2]) -> [f64; 2] {
        let g = &self.cfg.geometry;
        match self.cfg.machine {
            Machine::Whiteboard => {
                let d = Self::mm(g.lengths[0]);
                let o = [Self::mm(g.origin[0]), Self::mm(g.origin[1])];
                let len = |x: f64, y: f64| [x.hypot(y), (d - x).hypot(y)];
                let home = len(o[0], o[1]);
                let now = len(o[0] + p[0], o[1] + p[1]);
                [0, 1].map(|i| (now[i] - home[i]) * self.spu(i))
            }
            _ => {
                let (l1, l2) = (Self::mm(g.lengths[0]), Self::mm(g.lengths[1]));
                let x = -(p[0] - Self::mm(g.origin[0]));
                let y = p[1] - Self::mm(g.origin[1]);
                let h2 = x * x + y * y;
                let h = h2.sqrt();
                let acos = |c: f64| c.clamp(-1.0, 1.0).acos();
                let shoulder = x.atan2(y) - acos((h2 + l1 * l1 - l2 * l2) / (2.0 * l1 * h));
                let ecr = g.crosstalk;
                let crosstalk = match ecr.num {
                    0 => 0.0,
                    n => ecr.den as f64 / n as f64,
                };
                let elbow = shoulder * crosstalk + acos((h2 - l1 * l1 - l2 * l2) / (2.0 * l1 * l2));
                [
                    shoulder.to_degrees() * self.spu(0),
                    elbow.to_degrees() * self.spu(1),
                ]
            }
        }
    }
}

/// The ideal motion along a line: speed and time at every grid point.
pub struct Profile {
    /// Grid step, mm (the line's length over a whole number of steps).
    ds: f64,
    /// Seconds from the start at each grid point.
    t: Vec<f64>,
}

impl Profile {
    /// Seconds from rest at the start to the pen at `s` mm along.
    pub fn time_at(&self, s: f64) -> f64 {
        let k = (s / self.ds).clamp(0.0, (self.t.len() - 1) as f64);
        let i = (k.floor() as usize).min(self.t.len() - 2);
        let f = k - i as f64;
        self.t[i] + f * (self.t[i + 1] - self.t[i])
    }

    pub fn total(&self) -> f64 {
        *self.t.last().unwrap()
    }
}

/// The ideal profile of the straight line `from → to` (mm) at `feed`
/// mm/min on the machine `cfg`, from rest to rest.
pub fn ideal(cfg: &MachineConfig, from: [f64; 2], to: [f64; 2], feed: f64) -> Profile {
    profile(cfg, from, to, feed, true)
}

/// The pen's trapezoid alone along the line (its feed, `pen_max_feed`
/// and `pen_accel`; the joints' limits left out), as [`ideal`]'s profile.
pub fn cartesian(cfg: &MachineConfig, from: [f64; 2], to: [f64; 2], feed: f64) -> Profile {
    profile(cfg, from, to, feed, false)
}

fn profile(
    cfg: &MachineConfig,
    from: [f64; 2],
    to: [f64; 2],
    feed: f64,
    with_joints: bool,
) -> Profile {
    let joints = Joints::new(cfg);
    let length = (to[0] - from[0]).hypot(to[1] - from[1]);
    let n = (length / DS).ceil().max(1.0) as usize;
    let ds = length / n as f64;
    let u = [(to[0] - from[0]) / length, (to[1] - from[1]) / length];
    let at = |s: f64| [from[0] + s * u[0], from[1] + s * u[1]];
    let vmax = feed.min(cfg.pen_max_feed as f64) / 60.0;
    let accel = cfg.pen_accel as f64;
    let rate = [0, 1].map(|i| cfg.axes[i].max_rate as f64);
    let joint_accel = [0, 1].map(|i| cfg.axes[i].accel as f64);
    // Each joint's steps per mm along the line and their change per mm.
    let e = 0.01;
    let (mut cap, mut acc) = (vec![0.0; n + 1], vec![0.0; n + 1]);
    for k in 0..=n {
        let s = k as f64 * ds;
        let (q0, q1, q2) = (joints.at(at(s - e)), joints.at(at(s)), joints.at(at(s + e)));
        let (mut v, mut a) = (vmax, accel);
        for j in (0..2).filter(|_| with_joints) {
            let r = ((q2[j] - q0[j]) / (2.0 * e)).abs();
            let r2 = ((q2[j] - 2.0 * q1[j] + q0[j]) / (e * e)).abs();
            if r > 0.0 {
                v = v.min(rate[j] / r);
                a = a.min(joint_accel[j] / r);
            }
            if r2 > 0.0 {
                v = v.min((joint_accel[j] / r2).sqrt());
            }
        }
        (cap[k], acc[k]) = (v, a);
    }
    // v² along the grid: forward from rest, backward to rest.
    let mut v2 = vec![0.0f64; n + 1];
    for k in 1..=n {
        let a = acc[k - 1].min(acc[k]);
        v2[k] = (v2[k - 1] + 2.0 * a * ds).min(cap[k] * cap[k]);
    }
    v2[n] = 0.0;
    for k in (0..n).rev() {
        let a = acc[k].min(acc[k + 1]);
        v2[k] = v2[k].min(v2[k + 1] + 2.0 * a * ds);
    }
    let mut t = vec![0.0; n + 1];
    for k in 1..=n {
        let (v0, v1) = (v2[k - 1].sqrt(), v2[k].sqrt());
        t[k] = t[k - 1] + 2.0 * ds / (v0 + v1);
    }
    Profile { ds, t }
}

/// The closed-form trapezoid of a line `length` mm long at `feed` mm/min
/// with the acceleration `accel` mm/s², from rest to rest: seconds.
pub fn trapezoid_s(length: f64, feed: f64, accel: f64) -> f64 {
    let v = feed / 60.0;
    let ramp = v * v / accel;
    if ramp >= length {
        2.0 * (length / accel).sqrt()
    } else {
        2.0 * v / accel + (length - ramp) / v
    }
}

/// Where along the line (mm from the start) the firmware's first and
/// last step fall: its first piece with a step, at that piece's first
/// step event (each piece's events are spread evenly along it), and the
/// end of the last piece with a step. The pieces are the logic crate's
/// (`Segmenter`, the kinematics' inverse): where the steps are, not when.
pub fn step_span(cfg: &MachineConfig, from: [f64; 2], to: [f64; 2]) -> (f64, f64) {
    let kin = AnyKinematics::of(cfg).unwrap();
    let pos = |p: [f64; 2]| {
        [
            Milli((p[0] * 1000.0).round() as i32),
            Milli((p[1] * 1000.0).round() as i32),
            Milli(0),
        ]
    };
    let (a, b) = (pos(from), pos(to));
    let mut last = kin.inverse(&a).unwrap();
    let mut at = a;
    let mut s = 0.0;
    let (mut first, mut end) = (None, 0.0);
    for p in Segmenter::new(&kin, a, &b, kin.piece_um()) {
        let steps = kin.inverse(&p).unwrap();
        let len = ((p[0].0 - at[0].0) as f64).hypot((p[1].0 - at[1].0) as f64) / 1000.0;
        let events = (0..3).map(|i| (steps[i] - last[i]).abs()).max().unwrap();
        if events > 0 {
            first.get_or_insert(s + len / events as f64);
            end = s + len;
        }
        s += len;
        (last, at) = (steps, p);
    }
    (first.expect("the line makes steps"), end)
}

/// One line drawn and measured.
#[derive(Debug)]
pub struct Measured {
    /// First to last step, s.
    pub seconds: f64,
    /// The ideal time of the same span, s.
    pub ideal: f64,
    /// The pen's trapezoid over the same span (the joints' limits left
    /// out: [`cartesian`]), s; the ideal where no joint's limit binds.
    pub cartesian: f64,
    /// The closed-form trapezoid of the whole line (feed and `pen_accel`
    /// alone), s.
    pub trapezoid: f64,
    /// Each joint's highest step rate, steps/s, over windows of
    /// [`RATE_WINDOW`] steps.
    pub rate: [f64; 2],
}

/// Steps a joint's rate is measured over: Bresenham spreads a joint's
/// steps over the events unevenly (an interval is ⌊e/s⌋ or ⌈e/s⌉ events)
/// and each piece starts its counters afresh, so a window of `k` steps
/// may read up to `k / (k − 4)` of the joint's rate over a few pieces.
pub const RATE_WINDOW: usize = 50;

/// The highest rate the windows may read for a joint at `max_rate`.
pub fn rate_bound(max_rate: f64) -> f64 {
    max_rate * RATE_WINDOW as f64 / (RATE_WINDOW - 4) as f64
}

/// Moves the pen up to `from`, then draws the line to `to` at `feed`
/// mm/min and measures it from the pulses.
pub fn draw_line(
    sim: &mut Sim,
    cfg: &MachineConfig,
    from: [f64; 2],
    to: [f64; 2],
    feed: f64,
) -> Measured {
    let t = Duration::from_secs(120);
    send_ok(sim, &format!("G0 X{:.3} Y{:.3}", from[0], from[1]), t);
    send_ok(sim, "M400", t);
    let before = track(sim).len();
    send_ok(sim, &format!("G1 X{:.3} Y{:.3} F{feed}", to[0], to[1]), t);
    send_ok(sim, "M400", t);
    let path = track(sim);
    let line = &path[before..];
    assert!(line.len() > 1, "the line made no steps");
    let seconds = (line.last().unwrap().0 - line[0].0) as f64 / 16e6;
    let profile = ideal(cfg, from, to, feed);
    let (first, last) = step_span(cfg, from, to);
    let ideal = profile.time_at(last) - profile.time_at(first);
    let pen = cartesian(cfg, from, to, feed);
    let cartesian = pen.time_at(last) - pen.time_at(first);
    let rate = [0, 1].map(|j| {
        let mut at = line[0].1[j];
        let mut rises = Vec::new();
        for (cycle, s) in line {
            if s[j] != at {
                rises.push(*cycle);
                at = s[j];
            }
        }
        rises
            .windows(RATE_WINDOW + 1)
            .map(|w| RATE_WINDOW as f64 * 16e6 / (w[RATE_WINDOW] - w[0]) as f64)
            .fold(0.0, f64::max)
    });
    let length = (to[0] - from[0]).hypot(to[1] - from[1]);
    let trapezoid = trapezoid_s(
        length,
        feed.min(cfg.pen_max_feed as f64),
        cfg.pen_accel as f64,
    );
    Measured {
        seconds,
        ideal,
        cartesian,
        trapezoid,
        rate,
    }
}
