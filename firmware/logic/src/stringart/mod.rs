//! Move planning of the string-art job: pure iterators that turn the board's
//! geometry into the machine's sequence of absolute step targets and events.
//! `drilling` drills every nail's hole, `winding` wraps the pattern's nails,
//! `estimate` works out a job's machine time on the host with the
//! firmware's own job, planner and trapezoids; `timing` the same for the
//! original firmware's moves, one axis after another.

mod blend;
mod clearance;
mod drilling;
pub mod estimate;
pub mod job;
mod phase;
mod timing;
mod winding;

pub use blend::{BlendWinder, BlendWrap};
pub use clearance::Clearance;
pub use drilling::{Depths, Drilling};
pub use phase::Phase;
pub use timing::{machine_time, Overlap};
pub use winding::{WindError, Winder, Winding, Wrap, Wraps};

use crate::axis::{Axis, PerAxis, AXES};

/// Drill axis vs board surface: a depth d needs d / sin(74.333°) of travel.
pub const DRILL_ANGLE_DEG: f32 = 74.333;
/// Holes are drilled this deep, from this high above the surface, mm.
pub const HOLE_DEPTH_MM: f32 = 10.0;
pub const DRILL_CLEARANCE_MM: f32 = 10.0;
/// Blended drilling moves the tool sideways this far above the surface
/// (the original rose 1 cm): the board's flatness (±0.5 mm over its
/// radius) and the chips and raised rim a hole leaves (under 1 mm),
/// with margin, mm.
pub const SIDEWAYS_CLEARANCE_MM: f32 = 2.0;
/// The drill rests at the bottom of each hole this long.
pub const DWELL_MS: u16 = 250;
/// While winding, the needle turns this far inside the smallest nail
/// radius, and this far outside the radius of the nail being wrapped, mm.
pub const INNER_MARGIN_MM: f32 = 20.0;
pub const OUTER_MARGIN_MM: f32 = 29.0;

/// One thing the machine does, in order: a move, a dwell, a driver switch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MachineStep {
    /// Move the axes that have a target to it (absolute steps). They start
    /// together, each within its own speed and acceleration, and the next
    /// step waits until all have arrived.
    Move(PerAxis<Option<i32>>),
    /// Wait, ms.
    Dwell(u16),
    /// Switch the drivers of the axes in `mask` (bit = axis index) on or off.
    Drivers { mask: u8, on: bool },
    /// Make the job's progress durable (EEPROM) with the machine standing,
    /// before any later step: the checkpoint a power cut resumes from.
    Save(Save),
    /// A record written while the machine moves on: started once the
    /// machine has passed this point (begun a move handed out after it,
    /// or stands), the moves after it still going out.
    Mark(crate::checkpoint::Record),
    /// Nothing after this until the [`MachineStep::Mark`]'s record is
    /// durable: the motion it is about comes next.
    Durable,
}

/// What a [`MachineStep::Save`] writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Save {
    /// A phase starts: a new checkpoint header ([`job::Job::card`] names
    /// the job).
    Begin(Phase),
    Record(crate::checkpoint::Record),
}

impl MachineStep {
    /// A move of one axis.
    pub fn to(axis: Axis, target: i32) -> MachineStep {
        let mut t = [None; AXES];
        t[axis.index()] = Some(target);
        MachineStep::Move(t)
    }
}

/// The driver bit of an axis, for [`MachineStep::Drivers`].
pub const fn bit(axis: Axis) -> u8 {
    1 << axis as u8
}

/// Base, radial and drill.
pub const MACHINE_DRIVERS: u8 = bit(Axis::Base) | bit(Axis::Radial) | bit(Axis::Drill);

#[cfg(test)]
mod tests;
