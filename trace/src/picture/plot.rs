//! A plotter's drawing as its pulses made it: every STEP of the two
//! drawing motors through the machine's forward kinematics, drawn dark
//! while the pen servo's pulses (`pen_pwm`) put the pen at its down angle,
//! faint blue while it travels up.

use super::{write_png, Canvas, SIZE};
use crate::vcd::Signal;
use serde::Serialize;
use std::io;
use std::path::Path;
use taut_logic::axis::{Axis, AXES};
use taut_logic::config::MachineConfig;
use taut_logic::kinematics::{AnyKinematics, Kinematics};

/// What the picture shows, counted.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Plot {
    /// Motor steps replayed, and of those with the pen down.
    pub steps: usize,
    pub steps_down: usize,
    /// The drawing's extent, mm: least and greatest x and y with the pen
    /// down.
    pub min: [f64; 2],
    pub max: [f64; 2],
}

const INK: [u8; 3] = [20, 20, 40];
const TRAVEL: [u8; 3] = [80, 140, 230];

/// The pen angle, degrees, of a pulse `high_ns` long (1–2 ms for 0–180°).
fn degrees(high_ns: u64) -> f64 {
    (high_ns as f64 / 1000.0 - 1000.0) * 180.0 / 1000.0
}

/// Replays `signals` (named by `cfg`'s machine: `x_step`, `left_step`…,
/// and `pen_pwm`) and writes the drawing to `path` (PNG). `origin`: the
/// two drawing motors' step counts in the machine's own coordinates where
/// they stood at power-on (found by homing; zero when it did not home).
pub fn render_plot(
    signals: &[Signal],
    cfg: &MachineConfig,
    origin: [i32; 2],
    path: &Path,
) -> io::Result<Plot> {
    let points = plot_points(signals, cfg, origin)?;
    draw_plot(&points, path)
}

/// The pen's point (mm) after power-on and after every step of the two
/// drawing motors, in time order, each with whether the pen was down
/// (see [`render_plot`] for `origin`).
pub fn plot_points(
    signals: &[Signal],
    cfg: &MachineConfig,
    origin: [i32; 2],
) -> io::Result<Vec<((f64, f64), bool)>> {
    let kin = AnyKinematics::of(cfg).map_err(|e| io::Error::other(e.message()))?;
    let find = |name: &str| signals.iter().find(|s| s.name == name);
    let missing = |name: &str| io::Error::other(format!("no signal {name}"));
    // Every STEP rise of the two drawing motors, with its direction.
    let mut events: Vec<(u64, usize, i32)> = Vec::new();
    for (i, axis) in [Axis::Base, Axis::Radial].into_iter().enumerate() {
        let channel = cfg.machine.channel(axis).to_string();
        let step = find(&format!("{channel}_step")).ok_or_else(|| missing(&channel))?;
        let dir = find(&format!("{channel}_dir")).ok_or_else(|| missing(&channel))?;
        let positive = cfg.axes[axis.index()].dir_high_is_positive;
        for &(t, _) in step.changes.iter().filter(|c| c.1) {
            let i_dir = dir.changes.partition_point(|c| c.0 <= t);
            let dir_high = match i_dir {
                0 => dir.initial,
                n => dir.changes[n - 1].1,
            };
            events.push((t, i, if dir_high == positive { 1 } else { -1 }));
        }
    }
    events.sort_unstable();
    // The pen's pulse widths, each known from the end of its pulse.
    let pen = find("pen_pwm").ok_or_else(|| missing("pen_pwm"))?;
    let mut widths: Vec<(u64, f64)> = Vec::new();
    let mut rise = None;
    for &(t, high) in &pen.changes {
        match (high, rise) {
            (true, _) => rise = Some(t),
            (false, Some(r)) => widths.push((t, degrees(t - r))),
            _ => {}
        }
    }
    let down_at = |t: u64| {
        let i = widths.partition_point(|w| w.0 <= t);
        i > 0 && (widths[i - 1].1 - f64::from(cfg.pen.down_deg)).abs() < 1.0
    };
    let mut steps = [origin[0], origin[1], 0];
    let mut points = Vec::with_capacity(events.len() + 1);
    let at = |s: &[i32; AXES]| {
        let p = kin.forward(s);
        (p[0].0 as f64 / 1000.0, p[1].0 as f64 / 1000.0)
    };
    points.push((at(&steps), false));
    for &(t, i, d) in &events {
        steps[i] += d;
        points.push((at(&steps), down_at(t)));
    }
    Ok(points)
}

/// The drawing of [`plot_points`], written to `path` (PNG).
fn draw_plot(points: &[((f64, f64), bool)], path: &Path) -> io::Result<Plot> {
    let mut plot = Plot {
        steps: points.len() - 1,
        min: [f64::MAX; 2],
        max: [f64::MIN; 2],
        ..Plot::default()
    };
    for (p, down) in points {
        if *down {
            plot.steps_down += 1;
            plot.min = [plot.min[0].min(p.0), plot.min[1].min(p.1)];
            plot.max = [plot.max[0].max(p.0), plot.max[1].max(p.1)];
        }
    }
    // The whole path in view, with a margin; y up.
    let (lo, hi) = points.iter().fold(
        ((f64::MAX, f64::MAX), (f64::MIN, f64::MIN)),
        |(lo, hi), (p, _)| {
            (
                (lo.0.min(p.0), lo.1.min(p.1)),
                (hi.0.max(p.0), hi.1.max(p.1)),
            )
        },
    );
    let span = (hi.0 - lo.0).max(hi.1 - lo.1).max(1.0) * 1.1;
    let centre = ((lo.0 + hi.0) / 2.0, (lo.1 + hi.1) / 2.0);
    let mut canvas = Canvas::new(SIZE, f64::from(SIZE) / span);
    let shift = |p: (f64, f64)| (p.0 - centre.0, p.1 - centre.1);
    for w in points.windows(2) {
        let ((p, _), (q, down)) = (w[0], w[1]);
        match down {
            true => canvas.line(shift(p), shift(q), 2.0, INK, 1.0),
            false => canvas.line(shift(p), shift(q), 1.0, TRAVEL, 0.35),
        }
    }
    write_png(&canvas, path)?;
    Ok(plot)
}
