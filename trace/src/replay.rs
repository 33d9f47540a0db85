//! The machine's motion rebuilt from its pulse trace alone: the parsed VCD
//! signals (`vcd::parse`) of the string-art machine, nothing else — not the
//! firmware's log, not its view of its own position.
//!
//! - [`Trace`]: per axis (base, radial, drill) the step position as a
//!   function of time (a step is a rising edge of `<axis>_step`, its sign the
//!   level of `<axis>_dir` at that moment), the drivers' enable state
//!   (`<axis>_en`, polarity from the [`MachineConfig`]) and the buttons'
//!   presses (`btn_<name>`, pressed = low). Times are ns, as in the VCD.
//! - [`JobReplay`]: the string-art job on a [`Board`] (from `param.txt`):
//!   where the drill plunged ([`JobReplay::plunges`]), base or radial steps
//!   with the drill below the surface ([`JobReplay::moves_while_plunged`]),
//!   the needle's crossings of the ring of nails while winding
//!   ([`JobReplay::crossings`]), whether each lay in a gap, and the nails
//!   wrapped ([`JobReplay::wrapped_nails`]).
//! - [`Ring`]: the ring of nails (a circle, or the polygon through the nails
//!   of a polygonal board) in the base's step units.
//!
//! Positions are counted from the first pulse: the axes' zero at power-on.
//! Zeroing by hand (white buttons) moves nothing electrically and is not
//! seen; the base angle is taken modulo one turn.

mod job;
mod ring;
#[cfg(test)]
mod tests;

pub use job::{Crossing, Direction, JobReplay, Plunge, StrayStep, Wrap};
pub use ring::Ring;

use crate::vcd::Signal;
use taut_logic::axis::Axis;
use taut_logic::config::MachineConfig;
use taut_logic::files::param::ParamFile;
use taut_logic::geometry::Board;

/// The axes of the string-art machine, in [`Trace`]'s order.
pub const MACHINE_AXES: [Axis; 3] = [Axis::Base, Axis::Radial, Axis::Drill];

/// A one-bit signal's level over time.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Level {
    pub initial: bool,
    /// Changes, in time order, ns.
    pub changes: Vec<(u64, bool)>,
}

impl Level {
    fn of(signal: &Signal) -> Level {
        Level {
            initial: signal.initial,
            changes: signal.changes.clone(),
        }
    }

    /// The level at `t`, changes at `t` included.
    pub fn at(&self, t: u64) -> bool {
        let n = self.changes.partition_point(|&(c, _)| c <= t);
        n.checked_sub(1).map_or(self.initial, |i| self.changes[i].1)
    }

    /// Times the signal went to `level`.
    pub fn edges_to(&self, level: bool) -> Vec<u64> {
        let mut prev = self.initial;
        let mut out = Vec::new();
        for &(t, v) in &self.changes {
            if v == level && prev != level {
                out.push(t);
            }
            prev = v;
        }
        out
    }
}

/// One axis's step position over time.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Track {
    /// `(time ns, position after the step)`, one entry per step.
    pub changes: Vec<(u64, i64)>,
}

impl Track {
    /// Steps from the STEP and DIR signals.
    pub fn from_pulses(step: &Signal, dir: &Signal, dir_high_is_positive: bool) -> Track {
        let dir = Level::of(dir);
        let mut pos = 0i64;
        let mut prev = step.initial;
        let mut changes = Vec::new();
        for &(t, high) in &step.changes {
            if high && !prev {
                pos += if dir.at(t) == dir_high_is_positive {
                    1
                } else {
                    -1
                };
                changes.push((t, pos));
            }
            prev = high;
        }
        Track { changes }
    }

    /// The position at `t`, steps at `t` included.
    pub fn at(&self, t: u64) -> i64 {
        let n = self.changes.partition_point(|&(c, _)| c <= t);
        n.checked_sub(1).map_or(0, |i| self.changes[i].1)
    }

    /// The position after the last step.
    pub fn last(&self) -> i64 {
        self.changes.last().map_or(0, |c| c.1)
    }
}

/// One step of one axis, in a merged time line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StepEvent {
    pub at_ns: u64,
    /// Index into [`MACHINE_AXES`].
    pub axis: usize,
    /// The axis's position after the step.
    pub pos: i64,
}

/// The string-art machine's pulse trace, read back.
#[derive(Clone, Debug)]
pub struct Trace {
    /// Base, radial, drill.
    pub tracks: [Track; 3],
    enables: [Level; 3],
    enable_active_high: [bool; 3],
    buttons: Vec<(String, Level)>,
    /// The last change of any signal, ns.
    pub end_ns: u64,
}

impl Trace {
    /// Needs `<axis>_step`, `<axis>_dir` and `<axis>_en` of base, radial and
    /// drill; keeps every `btn_*` signal.
    pub fn from_signals(signals: &[Signal], config: &MachineConfig) -> Result<Trace, String> {
        let find = |name: String| {
            signals
                .iter()
                .find(|s| s.name == name)
                .ok_or(format!("no signal {name} in the trace"))
        };
        let mut tracks: [Track; 3] = Default::default();
        let mut enables: [Level; 3] = Default::default();
        let mut enable_active_high = [true; 3];
        for (i, axis) in MACHINE_AXES.iter().enumerate() {
            let cfg = config.axes[axis.index()];
            let (step, dir) = (
                find(format!("{}_step", axis.name()))?,
                find(format!("{}_dir", axis.name()))?,
            );
            tracks[i] = Track::from_pulses(step, dir, cfg.dir_high_is_positive);
            enables[i] = Level::of(find(format!("{}_en", axis.name()))?);
            enable_active_high[i] = cfg.enable_active_high;
        }
        let buttons = signals
            .iter()
            .filter_map(|s| Some((s.name.strip_prefix("btn_")?.to_string(), Level::of(s))))
            .collect();
        let end_ns = signals
            .iter()
            .filter_map(|s| s.changes.last().map(|c| c.0))
            .max()
            .unwrap_or(0);
        Ok(Trace {
            tracks,
            enables,
            enable_active_high,
            buttons,
            end_ns,
        })
    }

    /// The track of `axis` (base, radial or drill).
    pub fn track(&self, axis: Axis) -> &Track {
        &self.tracks[Self::slot(axis)]
    }

    fn slot(axis: Axis) -> usize {
        MACHINE_AXES
            .iter()
            .position(|&a| a == axis)
            .expect("base, radial or drill")
    }

    /// Position of `axis` at `t`, steps.
    pub fn position(&self, axis: Axis, t: u64) -> i64 {
        self.track(axis).at(t)
    }

    /// Whether the driver of `axis` is on at `t`.
    pub fn driver_on(&self, axis: Axis, t: u64) -> bool {
        let i = Self::slot(axis);
        self.enables[i].at(t) == self.enable_active_high[i]
    }

    /// Base, radial and drill drivers on at `t`.
    pub fn drivers_on(&self, t: u64) -> [bool; 3] {
        MACHINE_AXES.map(|a| self.driver_on(a, t))
    }

    /// Times button `name` (`confirm`, `zero_base`, …) went down.
    pub fn presses(&self, name: &str) -> Vec<u64> {
        self.button(name).map_or(Vec::new(), |l| l.edges_to(false))
    }

    /// Times button `name` came back up.
    pub fn releases(&self, name: &str) -> Vec<u64> {
        self.button(name).map_or(Vec::new(), |l| l.edges_to(true))
    }

    fn button(&self, name: &str) -> Option<&Level> {
        self.buttons.iter().find(|(n, _)| n == name).map(|(_, l)| l)
    }

    /// Every step of every axis in time order (same time: base, radial,
    /// drill).
    pub fn events(&self) -> Vec<StepEvent> {
        let mut all: Vec<StepEvent> = self
            .tracks
            .iter()
            .enumerate()
            .flat_map(|(axis, t)| {
                t.changes
                    .iter()
                    .map(move |&(at_ns, pos)| StepEvent { at_ns, axis, pos })
            })
            .collect();
        all.sort_by_key(|e| (e.at_ns, e.axis));
        all
    }
}

/// The board described by a `param.txt`.
pub fn board_from_param(text: &[u8]) -> Result<Board, String> {
    let mut file = ParamFile::new();
    let params = file
        .push(text)
        .and_then(|()| file.finish())
        .map_err(|e| format!("param.txt: {e:?}"))?;
    let radius = i32::try_from(params.radius_um).map_err(|_| "param.txt: radius".to_string())?;
    Board::new(params.shape, params.nails, taut_logic::units::Milli(radius))
        .map_err(|e| format!("param.txt: {}", e.message()))
}
