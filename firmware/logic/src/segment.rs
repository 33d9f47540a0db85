//! Step segments: what the step interrupt executes.
//!
//! **Why DDA + Klipper-style intervals.** The interrupt must do constant,
//! tiny work per step. A move on several axes is run as one stream of
//! *events* (the dominant axis steps at every event) and a Bresenham/DDA
//! decides which other axes step at each event: one addition and one
//! compare per axis, no division, exact step totals by construction, and a
//! single timer for all axes. The event times follow Klipper's scheme: a
//! [`Segment`] is `(interval, count, add)` and the interrupt does
//! `time += interval; interval += add` per event. Event times are then a
//! quadratic in the event index, which fits the square-root step times of a
//! constant-acceleration ramp to within [`TOLERANCE_TICKS`] over runs of
//! dozens to hundreds of events, and a cruise exactly over thousands. So the
//! ramp maths (square roots, divisions) run once per segment in the
//! preparer, not once per step; per-axis timers would need one division or
//! table look-up per axis and step instead.
//!
//! Times are in *sub-ticks*: 1/256 of a step-timer (Timer3) tick (16 MHz,
//! clk/1). The interrupt keeps a 24.8 fixed-point time and programs the
//! compare register with its integer part (bytes 1–2: free on AVR). The fraction
//! keeps rounding from accumulating: with whole ticks a 5333.3-tick cruise
//! interval drifts a tick every three steps.

mod buffered;
mod expand;
mod prepare;
mod trapezoid;

#[cfg(test)]
mod tests;

pub use buffered::Buffered;
pub use expand::{expand, Event, Expand};
pub use prepare::{Later, Preparer};
pub use trapezoid::{cbrt_floor_approx, div_to_u32, isqrt, isqrt32, Speeds, Trapezoid, MAX_ACCEL};

use crate::axis::PerAxis;

/// Step-timer (Timer3) ticks per second (16 MHz, prescaler 1).
pub const TICK_HZ: u32 = 16_000_000;
/// Fraction bits of [`Segment::interval`] and [`Segment::add`].
pub const FRAC_BITS: u32 = 8;
/// Sub-ticks per second.
pub const SUBTICKS_PER_S: u64 = (TICK_HZ as u64) << FRAC_BITS;
/// Every event lands within this many ticks (4 µs) of its ideal time: under
/// 1 % of a step at the string-art machine's 2 000 steps/s. It was 1 µs,
/// for a third more ramp segments (preparing them is the MCU's main work
/// while a job moves); Klipper's default is 25 µs.
pub const TOLERANCE_TICKS: u32 = 64;

/// One planned move as the step interrupt needs it: the DDA's figures.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StepBlock {
    /// Steps per axis (absolute counts).
    pub steps: PerAxis<u32>,
    /// Number of step events: the largest of `steps`.
    pub events: u32,
    /// Bit `i` set: axis `i` moves in its positive direction.
    pub dir: u8,
}

/// `count` events; the first `interval` sub-ticks after the previous event
/// (of this or an earlier segment), then `interval += add` after each event.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Segment {
    /// Sub-ticks (1/256 tick) from the previous event to the first one.
    pub interval: u32,
    /// Sub-ticks added to the interval after each event.
    pub add: i32,
    /// Events in this segment, ≥ 1.
    pub count: u16,
    /// [`NEW_BLOCK`]: load the next [`StepBlock`] before the first event;
    /// [`STOP`]: a hold stands after the last.
    pub flags: u8,
}

/// [`Segment::flags`] bit: the segment starts the next block. The
/// interrupt pops a [`StepBlock`], sets the DIR pins and resets the DDA
/// counters to `events / 2`.
pub const NEW_BLOCK: u8 = 1;

/// [`Segment::flags`] bit: a hold's stop, short of the block's end. The
/// interrupt then runs out of segments mid-block on purpose (no underrun).
pub const STOP: u8 = 2;
