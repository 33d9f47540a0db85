//! From the planner's blocks to the step interrupt's segments, with feed
//! hold: Grbl's `st_prep_buffer`. The firmware's segment preparation calls
//! [`Prep::next`] while the step queue has room and queues what it returns.
//!
//! A hold ([`Prep::hold`]) brakes at the block's acceleration from the speed
//! of the last segment cut — the motion already queued runs first, so the
//! firmware keeps that short — along the planned path: inside the block
//! when it is long enough, else on through the next blocks, each entered
//! at the speed the last left with (never above its planned entry, which
//! the planned profile reaches no slower than the quickest stop). Every
//! event of every block is still executed after [`Prep::resume`], so the
//! position is kept exactly.

use crate::planner::Planner;
use crate::segment::{Later, Preparer, Segment, StepBlock};

/// Where a feed hold stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Hold {
    /// Running (or standing with nothing to do).
    Off,
    /// Braking: the segments to a stop are not all cut yet.
    Braking,
    /// Every segment up to the stop is cut: the machine stands once the
    /// step queue has run out.
    Stopped,
}

/// A segment for the step interrupt, with its block if it starts one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cut {
    pub block: Option<StepBlock>,
    pub segment: Segment,
}

pub struct Prep {
    cut: Preparer,
    hold: Hold,
    /// A resume asked for while braking: it takes effect at the stop.
    resume_at_stop: bool,
    /// The block being cut, until its first segment goes out with it.
    block: Option<StepBlock>,
    /// (events per path milli-unit)² of the block being cut.
    ev_per_milli_sqr: f32,
}

impl Default for Prep {
    fn default() -> Self {
        Self::new()
    }
}

impl Prep {
    pub fn new() -> Self {
        Prep {
            cut: Preparer::new(),
            hold: Hold::Off,
            resume_at_stop: false,
            block: None,
            ev_per_milli_sqr: 1.0,
        }
    }

    pub fn hold_state(&self) -> Hold {
        self.hold
    }

    /// Speed² along the path of the last segment cut, (milli-units/s)²:
    /// Grbl's real-time feed rate (`FS:`), a segment ahead of the steps.
    pub fn path_speed_sqr(&self) -> f32 {
        self.cut.speed_sqr() as f32 / self.ev_per_milli_sqr
    }

    /// Every block taken has been cut whole (no hold stopped one short),
    /// and none is half loaded.
    pub fn is_idle(&self) -> bool {
        self.cut.is_idle() && !self.cut.is_loading()
    }

    /// A block is taken whose first segment has not gone out yet.
    pub fn holds_block(&self) -> bool {
        self.block.is_some()
    }

    /// One bounded part of loading the next block, if the last is all
    /// cut: taking it from `planner`, or one part of its profile (a whole
    /// profile costs two segments; a caller keeping its runs short calls
    /// this in runs of its own until it returns false). True if it did
    /// any work. During a hold the block is taken and made at once.
    pub fn load(&mut self, planner: &mut Planner) -> bool {
        if self.cut.is_loading() {
            self.cut.advance_block();
            return true;
        }
        if !self.cut.is_idle() {
            return false;
        }
        if self.hold != Hold::Off {
            self.block = self.take(planner);
            return self.block.is_some();
        }
        let Some(t) = planner.take_speeds() else {
            return false;
        };
        self.cut.begin_block(t.block.events, t.accel, &t.speeds);
        self.ev_per_milli_sqr = t.ev_per_milli_sqr;
        self.block = Some(t.block);
        true
    }

    /// See [`Preparer::yield_to`].
    pub fn yield_to(&mut self, others: fn() -> bool) {
        self.cut.yield_to(others);
    }

    /// [`Prep::next`] bounded as [`Preparer::next_part`]: `Err(Later)`
    /// when the segment needs another call. Loads at once what
    /// [`Prep::load`] left unmade.
    pub fn next_part(&mut self, planner: &mut Planner) -> Result<Option<Cut>, Later> {
        if self.cut.is_idle() && !self.cut.is_loading() {
            return Ok(self.next(planner));
        }
        while !self.cut.advance_block() {}
        match self.cut.next_part()? {
            Some(segment) => {
                let block = self.block.take();
                Ok(Some(Cut { block, segment }))
            }
            // A leg ended short of the block's end, or the block is cut:
            // the unbounded path takes it from here.
            None => Ok(self.next(planner)),
        }
    }

    /// The next segment, taking the next block from `planner` when the last
    /// is cut; `None` when there is nothing to cut or a hold has stopped.
    pub fn next(&mut self, planner: &mut Planner) -> Option<Cut> {
        loop {
            if self.cut.is_idle() {
                self.block = Some(self.take(planner)?);
            }
            if let Some(segment) = self.cut.next_segment() {
                let block = self.block.take();
                return Some(Cut { block, segment });
            }
            if !self.cut.is_idle() {
                // A leg ended short of the block's end: a hold's stop.
                self.hold = Hold::Stopped;
                if !core::mem::take(&mut self.resume_at_stop) || !self.resume(planner) {
                    return None;
                }
            }
        }
    }

    /// The next block from the planner, braking into it during a hold.
    fn take(&mut self, planner: &mut Planner) -> Option<StepBlock> {
        let carried = self.cut.speed_sqr();
        match self.hold {
            Hold::Stopped => return None,
            Hold::Braking if carried == 0 => return self.stopped_at_block_end(planner),
            _ => {}
        }
        let Some(t) = planner.take_speeds() else {
            // The queue ends at rest: a hold's stop is there.
            return match self.hold {
                Hold::Braking => self.stopped_at_block_end(planner),
                _ => None,
            };
        };
        // Made in place, whole: this path is the hold's, or a caller's
        // that does not bound its runs.
        self.cut.begin_block(t.block.events, t.accel, &t.speeds);
        self.cut.finish_block();
        if self.hold == Hold::Braking {
            // The same path speed in the new block's events.
            let entry = (carried as f32 * (t.ev_per_milli_sqr / self.ev_per_milli_sqr)) as u64;
            self.cut.brake_from(entry);
        }
        self.ev_per_milli_sqr = t.ev_per_milli_sqr;
        Some(t.block)
    }

    /// A hold's stop fell on a block's end: nothing more until resumed.
    fn stopped_at_block_end(&mut self, planner: &mut Planner) -> Option<StepBlock> {
        self.hold = Hold::Stopped;
        if core::mem::take(&mut self.resume_at_stop) && self.resume(planner) {
            return self.take(planner);
        }
        None
    }

    /// Feed hold: brake to a stop from the speed of the last segment cut.
    pub fn hold(&mut self) {
        // A block half loaded is finished first: its entry is where the
        // braking starts.
        while !self.cut.advance_block() {}
        if self.hold == Hold::Off {
            self.hold = Hold::Braking;
            self.cut.stop();
        }
    }

    /// Go on after a hold: the rest of the held block from rest, and the
    /// planner's next block no faster than it can now enter. While still
    /// braking, it takes effect at the stop. False when not held.
    pub fn resume(&mut self, planner: &mut Planner) -> bool {
        match self.hold {
            Hold::Off => return false,
            Hold::Braking => {
                self.resume_at_stop = true;
                return true;
            }
            Hold::Stopped => {}
        }
        self.hold = Hold::Off;
        let exit_sqr = if self.cut.is_stopped() {
            self.cut.restart()
        } else {
            0
        };
        planner.limit_entry((exit_sqr as f32 / self.ev_per_milli_sqr) as u64);
        true
    }

    /// Drop the block being cut and any hold: a stop that abandons the
    /// queued motion (the planner is cleared by the caller).
    pub fn clear(&mut self) {
        let others = self.cut.yields_to();
        *self = Prep::new();
        self.cut.yield_to(others);
    }
}

#[cfg(test)]
mod tests;
