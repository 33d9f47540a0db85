//! Segment preparation: cut the executing block's profile into the fewest
//! [`Segment`]s that keep every event within [`TOLERANCE_TICKS`] of its
//! ideal time.
//!
//! Error budget, sub-ticks (tolerance 16 ticks = 4096):
//! - quadratic through the segment's start, middle and end event: at most
//!   `0.024·d³/τ²` for a segment lasting `d` at a speed `τ` away from
//!   standstill (third derivative of the ramp's step times); kept ≤ 2048;
//! - `add` rounded to a whole sub-tick: ≤ n²/16 ≤ 1024 for n ≤ 128;
//! - `interval` rounded: ≤ n/2 ≤ 2048 in a cruise (no other error there);
//! - lag carried from the previous segment ≤ 66; the interrupt's tick
//!   truncation < 256.

use super::trapezoid::{cbrt_floor_approx, Phase, Trapezoid};
use super::{Segment, NEW_BLOCK, SUBTICKS_PER_S as Q};
use crate::units::div_round;

/// Longest ramp segment: bounds the `add` rounding error.
const MAX_RAMP_EVENTS: u32 = 128;
/// Longest cruise segment: bounds the `interval` rounding error.
const MAX_CRUISE_EVENTS: u32 = 4096;
/// `d ≤ 43·∛τ²` keeps the quadratic fit's error ≤ 2048 sub-ticks.
const FIT_GAIN: u64 = 43;

/// Turns one block's [`Trapezoid`] after another into segments.
#[derive(Clone, Debug)]
pub struct Preparer {
    profile: Trapezoid,
    /// Events already cut into segments.
    done: u32,
    /// Time of event `done` as the segments place it, sub-ticks after the
    /// block's ideal start (negative when the previous block ended early).
    now: i64,
    /// The next segment is the block's first.
    fresh: bool,
}

impl Default for Preparer {
    fn default() -> Self {
        Self::new()
    }
}

impl Preparer {
    pub const fn new() -> Self {
        Preparer {
            profile: Trapezoid::ZERO,
            done: 0,
            now: 0,
            fresh: false,
        }
    }

    /// Every event of the current block has been cut into segments.
    pub fn is_idle(&self) -> bool {
        self.done >= self.profile.events()
    }

    /// Starts the next block. Its ideal start is the previous block's ideal
    /// end, so timing errors never accumulate across blocks.
    pub fn start(&mut self, profile: Trapezoid) {
        self.now = if self.done > 0 {
            self.now - self.profile.time(self.done) as i64
        } else {
            0
        };
        self.profile = profile;
        self.done = 0;
        self.fresh = true;
    }

    /// The next segment of the current block, `None` when it is done.
    pub fn next(&mut self) -> Option<Segment> {
        if self.is_idle() {
            return None;
        }
        let k0 = self.done;
        let mut seg = match self.profile.phase_after(k0) {
            None => self.fit(k0, 1),
            Some((Phase::Cruise, end)) => self.cruise(k0, (end - k0).min(MAX_CRUISE_EVENTS)),
            Some((Phase::Accel, end)) => {
                let n = self.ramp_run(k0).min(end - k0);
                self.fit(k0, n)
            }
            Some((Phase::Decel, end)) => {
                // The slow end of a deceleration is the segment's end.
                let first = self.ramp_run(k0).min(end - k0);
                let n = self.ramp_run(k0 + first).min(first);
                self.fit(k0, n)
            }
        };
        if self.fresh {
            seg.flags |= NEW_BLOCK;
            self.fresh = false;
        }
        let n = seg.count as i64;
        self.now += n * seg.interval as i64 + seg.add as i64 * n * (n - 1) / 2;
        self.done += seg.count as u32;
        Some(seg)
    }

    /// Events a ramp segment may span from a speed at event `k`.
    fn ramp_run(&self, k: u32) -> u32 {
        let (to_stop, v) = self.profile.ramp_speed(k);
        if v == 0 {
            return 1;
        }
        // A cube root within 26 % below the true one: segments at most that
        // much shorter than the error budget allows, for 1/20 of the cost.
        let c = cbrt_floor_approx(to_stop);
        let duration = FIT_GAIN * c * c;
        let n = duration / (Q / v);
        n.clamp(1, MAX_RAMP_EVENTS as u64) as u32
    }

    /// Sub-ticks from the last placed event to the ideal time of `k`.
    fn ahead(&self, k: u32) -> i64 {
        self.profile.time(k) as i64 - self.now
    }

    /// Constant interval: the ideal times are equally spaced.
    fn cruise(&self, k0: u32, n: u32) -> Segment {
        let interval = div_round(self.ahead(k0 + n), n as i64);
        segment(interval, n, 0)
    }

    /// Quadratic through the last placed event and the ideal middle and end
    /// events; shorter runs when `add` or the intervals do not fit.
    fn fit(&self, k0: u32, mut n: u32) -> Segment {
        loop {
            if n < 2 {
                return segment(self.ahead(k0 + 1), 1, 0);
            }
            n &= !1;
            let (m, ni) = (n / 2, n as i64);
            let (ym, yn) = (self.ahead(k0 + m), self.ahead(k0 + n));
            let add = div_round(4 * (yn - 2 * ym), ni * ni);
            let interval = div_round(yn - add * ni * (ni - 1) / 2, ni);
            let last = interval + add * (ni - 1);
            let fits = i32::try_from(add).is_ok()
                && interval.min(last) >= 1
                && interval.max(last) <= u32::MAX as i64;
            if fits {
                return segment(interval, n, add as i32);
            }
            n /= 2;
        }
    }
}

/// A segment with its interval clamped to what the interrupt can time (only
/// binding for absurd figures: below ~1 step/s or 2 steps/s²).
fn segment(interval: i64, count: u32, add: i32) -> Segment {
    Segment {
        interval: interval.clamp(1, u32::MAX as i64) as u32,
        count: count as u16,
        add,
        flags: 0,
    }
}
