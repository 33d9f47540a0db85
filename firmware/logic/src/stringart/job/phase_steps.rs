//! The steps of the running phase, handed out in batches: one batch per
//! hole (its retract ends it) or per wrap, so each `MotionDone` finds the
//! machine in a safe pose (drill raised, needle inside the ring) with a
//! whole number of units done, and a pause stops there at the latest.

use super::phase::Phase;
use super::progress::Reporter;
use crate::stringart::{Drilling, MachineStep, Winder, Wrap};

/// Nail indices buffered ahead of the winder: the card is read while the
/// machine moves.
pub const FEED: usize = 8;

// One phase at a time and no heap: the winding variant's size is the
// price of not boxing.
#[allow(clippy::large_enum_variant)]
enum Work {
    Drill {
        drilling: Drilling,
        /// The last step handed out was the dwell: the next is the retract
        /// that ends the hole.
        after_dwell: bool,
    },
    Wind {
        winder: Winder,
        /// The entry move, until it has been handed out.
        entry: Option<core::array::IntoIter<MachineStep, 4>>,
        wrap: Option<Wrap>,
        feed: heapless::Deque<u16, FEED>,
        /// Indices received so far (the buffered ones included).
        fed: u32,
    },
}

/// The steps of drilling or winding, with the count of units done.
pub(super) struct PhaseSteps {
    work: Work,
    /// Units (holes, wraps) whose last step has been handed out.
    pub done: u32,
    pub total: u32,
    /// The batch is complete: no more steps until the next `MotionDone`.
    hold: bool,
    /// A step of the current batch has been handed out.
    started: bool,
    /// Every step has been handed out.
    pub exhausted: bool,
    pub reporter: Reporter,
}

impl PhaseSteps {
    pub fn drill(drilling: Drilling, nails: u16, now_ms: u32) -> Self {
        Self::new(
            Work::Drill {
                drilling,
                after_dwell: false,
            },
            Phase::Drilling,
            nails as u32,
            now_ms,
        )
    }

    pub fn wind(mut winder: Winder, count: u32, now_ms: u32) -> Self {
        let entry = Some(winder.entry().into_iter());
        let work = Work::Wind {
            winder,
            entry,
            wrap: None,
            feed: heapless::Deque::new(),
            fed: 0,
        };
        Self::new(work, Phase::Winding, count, now_ms)
    }

    fn new(work: Work, phase: Phase, total: u32, now_ms: u32) -> Self {
        PhaseSteps {
            work,
            done: 0,
            total,
            hold: false,
            started: false,
            exhausted: false,
            reporter: Reporter::start(phase, total, now_ms),
        }
    }

    /// The motion of the last batch has finished.
    pub fn release(&mut self) {
        self.hold = false;
        self.started = false;
    }

    /// Some of the current batch's steps have been handed out, not all.
    pub fn mid_batch(&self) -> bool {
        self.started && !self.hold && !self.exhausted
    }

    pub fn next(&mut self) -> Option<MachineStep> {
        let step = self.step();
        self.started |= step.is_some();
        step
    }

    fn step(&mut self) -> Option<MachineStep> {
        if self.hold || self.exhausted {
            return None;
        }
        match &mut self.work {
            Work::Drill {
                drilling,
                after_dwell,
            } => {
                let Some(step) = drilling.next() else {
                    self.exhausted = true;
                    return None;
                };
                if *after_dwell {
                    self.done += 1;
                    self.hold = true;
                }
                *after_dwell = matches!(step, MachineStep::Dwell(_));
                Some(step)
            }
            Work::Wind {
                winder,
                entry,
                wrap,
                feed,
                ..
            } => {
                if let Some(steps) = entry {
                    if let Some(step) = steps.next() {
                        return Some(step);
                    }
                    *entry = None;
                    self.hold = true;
                    return None;
                }
                if let Some(w) = wrap {
                    if let Some(step) = w.next() {
                        return Some(step);
                    }
                    *wrap = None;
                    self.done += 1;
                    self.hold = true;
                    return None;
                }
                if self.done == self.total {
                    self.exhausted = true;
                    return Some(winder.finish());
                }
                // Indices are range-checked when fed, so `wrap` succeeds.
                let j = feed.pop_front()?;
                *wrap = winder.wrap(j).ok();
                wrap.as_mut().and_then(Iterator::next)
            }
        }
    }

    /// Winding, with room in the buffer for another index of the pattern.
    pub fn wants_nail(&self) -> bool {
        match &self.work {
            Work::Wind { feed, fed, .. } => !feed.is_full() && *fed < self.total,
            Work::Drill { .. } => false,
        }
    }

    /// Buffers the next index; false if none was wanted.
    pub fn feed(&mut self, j: u16) -> bool {
        if !self.wants_nail() {
            return false;
        }
        match &mut self.work {
            Work::Wind { feed, fed, .. } => {
                *fed += 1;
                feed.push_back(j).is_ok()
            }
            Work::Drill { .. } => false,
        }
    }

    /// Indices received so far.
    pub fn fed(&self) -> u32 {
        match &self.work {
            Work::Wind { fed, .. } => *fed,
            Work::Drill { .. } => 0,
        }
    }

    /// Nothing to hand out until another index is fed.
    pub fn starved(&self) -> bool {
        match &self.work {
            Work::Wind {
                entry, wrap, feed, ..
            } => {
                !self.exhausted
                    && entry.is_none()
                    && wrap.is_none()
                    && feed.is_empty()
                    && self.done < self.total
            }
            Work::Drill { .. } => false,
        }
    }
}
