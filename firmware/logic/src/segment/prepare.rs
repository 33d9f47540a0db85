//! Segment preparation: cut the executing block's profile into the fewest
//! [`Segment`]s that keep every event within [`TOLERANCE_TICKS`] of its
//! ideal time.
//!
//! Error budget, sub-ticks (tolerance 64 ticks = 16 384):
//! - quadratic through the segment's start and end event, its `add` the
//!   change of pace (time per event) between them over the events: at
//!   most `0.024·d³/τ²` for a segment lasting `d` at a speed `τ` away
//!   from standstill (third derivative of the ramp's step times, the same
//!   bound as a fit through the middle event); kept ≤ 12 288;
//! - `add` rounded to a whole sub-tick: ≤ n²/16 ≤ 1024 for n ≤ 128;
//! - `interval` rounded: ≤ n/2 ≤ 2048 in a cruise (no other error there);
//! - lag carried from the previous segment ≤ 66; the interrupt's tick
//!   truncation < 256.

use super::trapezoid::{cbrt_floor_approx, div_to_u32, Slope, Speeds, Trapezoid};
use super::{Segment, NEW_BLOCK, STOP, SUBTICKS_PER_S as Q};
use crate::units::div_round;

/// Longest ramp segment: bounds the `add` rounding error.
const MAX_RAMP_EVENTS: u32 = 128;
/// Longest cruise segment: bounds the `interval` rounding error.
const MAX_CRUISE_EVENTS: u32 = 4096;
/// No segment lasts longer than this (1/20 s): a feed hold brakes from the
/// last segment queued, so this and the queue's own budget
/// (`firmware/src/motion.rs`) bound how long it waits to begin.
const MAX_SEGMENT_PER_S: u64 = 20;
/// `d ≤ 78·∛τ²` keeps the quadratic fit's error ≤ 12 288 sub-ticks
/// (`(12 288 / 0.024)^⅓ = 80`).
const FIT_GAIN: u64 = 78;
/// Budget units ([`Preparer::next_part`]): an event time and pace
/// (~7 000 cycles), a ramp segment's size (~4 000 an acceleration's, ~8 000 a
/// deceleration's), and what one call may spend: one of them.
const TIME_COST: u8 = 1;
const SIZE_COST: u8 = 1;
const PART_BUDGET: u8 = 1;

/// Turns one block's [`Trapezoid`] after another into segments.
///
/// A feed hold replaces the rest of the block's profile by the quickest
/// stop from the current speed ([`Preparer::stop`]), and a resume by a new
/// start from rest to the block's end ([`Preparer::restart`]): the block is
/// then cut in *legs*, each its own profile, joined at equal speed, so the
/// events (and the DDA's step totals) stay those of the block.
#[derive(Clone, Debug)]
pub struct Preparer {
    /// The leg being cut.
    profile: Trapezoid,
    /// Events of the leg already cut into segments.
    done: u32,
    /// Time of event `done` as the segments place it, sub-ticks after the
    /// leg's ideal start (negative when the previous leg ended early).
    now: i64,
    /// The next segment is the block's first.
    fresh: bool,
    /// Events of the block in the legs before this one.
    before: u32,
    /// The block's events.
    events: u32,
    /// The block's figures, for the legs after a hold: events/s², and
    /// cruise and planned exit speeds², events²/s².
    accel: u32,
    cruise_sqr: u64,
    exit_sqr: u64,
    /// The last event time worked out on this leg: (event, sub-ticks,
    /// sub-ticks per event there). A bounded call
    /// ([`Preparer::next_part`]) that ran out of budget finds it there
    /// when called again, and a ramp segment its start's pace in it.
    memo: (u32, u64, u32),
    /// (event, sub-ticks per event) at a ramp segment's start, when it
    /// was not the last segment's end.
    start: (u32, u32),
    /// (first event, events): a fit too long for a segment's figures
    /// goes on from the shorter run next call.
    shorter: (u32, u32),
    /// What the current call may still work out: [`TIME_COST`] an event
    /// time, [`SIZE_COST`] a ramp segment's size.
    budget: u8,
    /// Whether another task waits ([`Preparer::yield_to`]).
    yield_to: fn() -> bool,
}

/// A bounded call ran out of budget: call again to go on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Later;

impl Default for Preparer {
    fn default() -> Self {
        Self::new()
    }
}

impl Preparer {
    pub fn new() -> Self {
        Preparer {
            profile: Trapezoid::idle(),
            done: 0,
            now: 0,
            fresh: false,
            before: 0,
            events: 0,
            accel: 1,
            cruise_sqr: 0,
            exit_sqr: 0,
            memo: (u32::MAX, 0, 0),
            start: (u32::MAX, 0),
            shorter: (u32::MAX, 0),
            budget: u8::MAX,
            yield_to: || false,
        }
    }

    /// A bounded call ([`Preparer::next_part`]) that worked out an event
    /// time ends before the fit when `others` says another task waits:
    /// the app's way to keep a ready console's wait within one part.
    pub fn yield_to(&mut self, others: fn() -> bool) {
        self.yield_to = others;
    }

    /// What [`Preparer::yield_to`] set (kept over a clear).
    pub(crate) fn yields_to(&self) -> fn() -> bool {
        self.yield_to
    }

    /// Every event of the current block has been cut into segments.
    pub fn is_idle(&self) -> bool {
        self.before + self.done >= self.events
    }

    /// A hold stopped the block short of its end: [`Preparer::next_segment`] has
    /// nothing until [`Preparer::restart`].
    pub fn is_stopped(&self) -> bool {
        self.done >= self.profile.events() && !self.is_idle()
    }

    /// Starts the next block. Its ideal start is the previous block's ideal
    /// end, so timing errors never accumulate across blocks.
    pub fn start(&mut self, profile: Trapezoid) {
        self.switch(profile);
        self.adopt();
    }

    /// [`Preparer::start`] in parts: the block's profile is begun here and
    /// made by [`Preparer::advance_block`], one bounded part per call (the
    /// preparer stays idle until then). Only once the last block is cut.
    pub fn begin_block(&mut self, events: u32, accel: u32, speeds: &Speeds) {
        debug_assert!(self.is_idle());
        self.leave_leg();
        self.profile.begin_in_place(events, accel, speeds);
    }

    /// A block begun by [`Preparer::begin_block`] made whole at once.
    pub fn finish_block(&mut self) {
        while !self.advance_block() {}
    }

    /// Starts the block just made braking from `entry_sqr` (at most its
    /// planned entry): a hold that did not stop inside the previous
    /// block; returns the speed² left at its end.
    pub fn brake_from(&mut self, entry_sqr: u64) -> u64 {
        self.brake(entry_sqr.min(self.speed_sqr()))
    }

    /// The next part of the profile begun by [`Preparer::begin_block`];
    /// true once it is whole and the block started (at once when no
    /// profile is being made).
    pub fn advance_block(&mut self) -> bool {
        if !self.is_loading() {
            return true;
        }
        if !self.profile.advance() {
            return false;
        }
        self.adopt();
        true
    }

    /// A block's profile is being made ([`Preparer::begin_block`]).
    pub fn is_loading(&self) -> bool {
        !self.profile.is_whole()
    }

    /// The profile in place is the new block's.
    fn adopt(&mut self) {
        let profile = &self.profile;
        self.before = 0;
        self.events = profile.events();
        self.accel = profile.accel();
        self.cruise_sqr = profile.cruise_sqr();
        self.exit_sqr = profile.exit_sqr();
        self.fresh = true;
    }

    /// Speed² at the last event cut, events²/s² (at the end of the block
    /// when it is all cut).
    pub fn speed_sqr(&self) -> u64 {
        self.profile.speed_sqr(self.done)
    }

    /// Feed hold: the rest of the block becomes the quickest stop from the
    /// current speed at the block's acceleration. Returns the speed² left
    /// at the end of the block when it is too short to stop in (the next
    /// block must go on braking: [`Preparer::brake_from`]), else 0.
    pub fn stop(&mut self) -> u64 {
        if self.is_idle() {
            return self.speed_sqr();
        }
        self.brake(self.speed_sqr())
    }

    /// After a hold stopped the block: the rest of it from rest, to the
    /// block's exit speed if it can still be reached. Returns the exit
    /// speed² it will have (the next block must enter no faster).
    pub fn restart(&mut self) -> u64 {
        let left = self.events - self.before - self.done;
        let speeds = Speeds {
            entry_sqr: 0,
            cruise_sqr: self.cruise_sqr,
            exit_sqr: self.exit_sqr,
        };
        self.switch_to(left, &speeds);
        self.profile.exit_sqr()
    }

    /// The rest of the block: braking from `v_sqr` to a stop, or to its end.
    fn brake(&mut self, v_sqr: u64) -> u64 {
        let two_a = 2 * self.accel as u64;
        let left = (self.events - self.before - self.done) as u64;
        let (n, end_sqr) = match v_sqr.div_ceil(two_a) {
            stop if stop <= left => (stop, 0),
            _ => (left, v_sqr - two_a * left),
        };
        // Standing already: an empty leg (a profile needs an event).
        match n {
            0 => {
                // In place: a profile on the stack is 137 B, deep under a
                // hold (a feed hold inside a card print's line).
                self.leave_leg();
                self.profile.make_idle();
            }
            n => {
                let speeds = Speeds {
                    entry_sqr: v_sqr,
                    cruise_sqr: v_sqr,
                    exit_sqr: end_sqr,
                };
                self.switch_to(n as u32, &speeds);
            }
        }
        end_sqr
    }

    /// [`Preparer::switch`] to a leg of `events` at the block's
    /// acceleration, made in place: a hold's legs come deep in the stack
    /// (a feed hold inside a card print's line), where a profile's copy
    /// would cost its size again.
    fn switch_to(&mut self, events: u32, speeds: &Speeds) {
        self.leave_leg();
        self.profile.begin_in_place(events, self.accel, speeds);
        while !self.profile.advance() {}
    }

    /// Make `leg` the profile from the last event cut on. Its ideal start
    /// is that event's ideal time on the leg before.
    fn switch(&mut self, leg: Trapezoid) {
        self.leave_leg();
        self.profile = leg;
    }

    /// The last event cut becomes the next leg's start.
    fn leave_leg(&mut self) {
        self.now = if self.done > 0 {
            self.now - self.profile.time(self.done) as i64
        } else {
            self.now
        };
        self.before += self.done;
        self.done = 0;
        self.memo = (u32::MAX, 0, 0);
        self.start = (u32::MAX, 0);
        self.shorter = (u32::MAX, 0);
    }

    /// The next segment of the current leg, `None` when it is done.
    pub fn next_segment(&mut self) -> Option<Segment> {
        self.budget = u8::MAX;
        self.segment().unwrap_or(None)
    }

    /// [`Preparer::next_segment`] in bounded parts: one event time worked
    /// out afresh (a 64-bit root: ~7 000 cycles on the AVR) or one ramp
    /// segment's size; `Later` when the segment needs another
    /// call (what a call worked out is kept for the next). A cruise segment
    /// takes one call, a ramp's two (three for the first after a cruise or
    /// a leg's start, whose start pace is not known yet; one more when the
    /// fit yields, [`Preparer::yield_to`]).
    pub fn next_part(&mut self) -> Result<Option<Segment>, Later> {
        self.budget = PART_BUDGET;
        self.segment()
    }

    fn segment(&mut self) -> Result<Option<Segment>, Later> {
        if self.done >= self.profile.events() {
            return Ok(None);
        }
        let k0 = self.done;
        let mut seg = match self.profile.slope_after(k0) {
            None => self.fit(k0, 1)?,
            Some((Slope::Cruise, end)) => {
                let n = (end - k0).min(MAX_CRUISE_EVENTS).min(
                    self.profile
                        .cruise_events_in((Q / MAX_SEGMENT_PER_S) as u32),
                );
                self.cruise(k0, n.max(1))?
            }
            // A call that ran out of budget sized this segment already.
            Some((Slope::Accel | Slope::Decel, _)) if self.shorter.0 == k0 => {
                self.fit(k0, self.shorter.1)?
            }
            // One event left on the ramp (a tiny block's): a segment of
            // it, as the sizing below would make, without its cost.
            Some((Slope::Accel | Slope::Decel, end)) if end - k0 == 1 => self.fit(k0, 1)?,
            Some((Slope::Accel, end)) => {
                self.spend(SIZE_COST)?;
                let n = self.ramp_run(k0).min(end - k0);
                self.fit(k0, n)?
            }
            Some((Slope::Decel, end)) => {
                self.spend(SIZE_COST)?;
                // The slow end of a deceleration is the segment's end.
                let first = self.ramp_run(k0).min(end - k0);
                let n = self.ramp_run(k0 + first).min(first);
                self.fit(k0, n)?
            }
        };
        if self.fresh {
            seg.flags |= NEW_BLOCK;
            self.fresh = false;
        }
        let n = seg.count as u32;
        self.now += seg.interval as i64 * n as i64 + seg.add as i64 * (n * (n - 1) / 2) as i64;
        self.done += seg.count as u32;
        if self.is_stopped() {
            seg.flags |= STOP;
        }
        Ok(Some(seg))
    }

    /// Events a ramp segment may span from a speed at event `k`.
    fn ramp_run(&self, k: u32) -> u32 {
        let (to_stop, v) = self.profile.ramp_speed(k);
        if v == 0 {
            return 1;
        }
        // v / 20 from below (3276 / 2^16 < 1/20), without a division.
        const _: () = assert!(MAX_SEGMENT_PER_S == 20);
        let v = v.min(1 << 20);
        let most = ((v * 3276) >> 16).min(MAX_RAMP_EVENTS);
        // d ≤ 78·∛τ², in events: d·v / Q with Q = 125 000·2^15. A cube
        // root within 4.2 % below the true one: segments at most 8 %
        // shorter than the error budget allows, for a fraction of the
        // cost. Past 2^15 (τ over two hours) `most` is the bound anyway.
        let c = cbrt_floor_approx(to_stop).min(1 << 15);
        let duration = FIT_GAIN * c * c;
        // Below 2^37·2^20 / 2^15: a 32-bit quotient (a general u64
        // division is ~3 000 cycles).
        let n = div_to_u32((duration * v as u64) >> 15, 125_000);
        n.min(most).max(1)
    }

    /// Takes `units` of the call's budget, or `Later` when too few are left.
    fn spend(&mut self, units: u8) -> Result<(), Later> {
        self.budget = self.budget.checked_sub(units).ok_or(Later)?;
        Ok(())
    }

    /// Sub-ticks from the last placed event to the ideal time of `k`, and
    /// the ideal sub-ticks per event there; `Later` when they are not
    /// known yet and the budget is spent.
    fn ahead(&mut self, k: u32) -> Result<(i64, u32), Later> {
        if self.memo.0 != k {
            self.spend(TIME_COST)?;
            let (t, pace) = self.profile.time_and_pace(k);
            self.memo = (k, t, pace);
        }
        Ok((self.memo.1 as i64 - self.now, self.memo.2))
    }

    /// Sub-ticks per event at event `k0`, where the last segment ended
    /// (in the memo then) or, after a leg's start or a cruise, worked out.
    fn pace_at(&mut self, k0: u32) -> Result<u32, Later> {
        if self.memo.0 == k0 {
            self.start = (k0, self.memo.2);
        } else if self.start.0 != k0 {
            self.spend(TIME_COST)?;
            self.start = (k0, self.profile.time_and_pace(k0).1);
        }
        Ok(self.start.1)
    }

    /// Constant interval: the ideal times are equally spaced.
    fn cruise(&mut self, k0: u32, n: u32) -> Result<Segment, Later> {
        let ahead = self.ahead(k0 + n)?.0;
        let interval = round_div32(ahead, n).unwrap_or_else(|| div_round(ahead, n as i64));
        Ok(segment(interval, n, 0))
    }

    /// Quadratic through the last placed event and the ideal end, its
    /// `add` the mean second difference over the run: the change of pace
    /// from start to end over the events. One root a segment, where a
    /// fit through the middle event takes two, and as close (`t'''`
    /// times `n³/125` at most, either way). Shorter runs when `add` or
    /// the intervals do not fit.
    fn fit(&mut self, k0: u32, mut n: u32) -> Result<Segment, Later> {
        if self.shorter.0 == k0 {
            n = n.min(self.shorter.1);
        }
        loop {
            self.shorter = (k0, n);
            if n < 2 {
                return Ok(segment(self.ahead(k0 + 1)?.0, 1, 0));
            }
            let p0 = self.pace_at(k0)?;
            let (yn, p1) = self.ahead(k0 + n)?;
            // A call that worked out the time ends here if a task waits:
            // the fit (~3 000 cycles) next call, on the time kept.
            if self.budget == 0 && (self.yield_to)() {
                return Err(Later);
            }
            let fitted = round_div32(p1 as i64 - p0 as i64, n).and_then(|add| {
                let interval = round_div32(yn - add * (n * (n - 1) / 2) as i64, n)?;
                let last = interval + add * (n - 1) as i64;
                let fits = i32::try_from(add).is_ok()
                    && interval.min(last) >= 1
                    && interval.max(last) <= u32::MAX as i64;
                fits.then(|| segment(interval, n, add as i32))
            });
            if let Some(seg) = fitted {
                return Ok(seg);
            }
            n /= 2;
        }
    }
}

/// `n / d` rounded half away from zero, when its magnitude fits 32 bits
/// (a segment's `add` and `interval` must): one narrow division, a fifth
/// of a general `i64` one on the AVR. `None` when it does not fit.
fn round_div32(n: i64, d: u32) -> Option<i64> {
    let half = (d / 2) as u64;
    let m = n.unsigned_abs().checked_add(half)?;
    if m >> 32 >= d as u64 {
        return None;
    }
    let q = div_to_u32(m, d) as i64;
    Some(if n < 0 { -q } else { q })
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
