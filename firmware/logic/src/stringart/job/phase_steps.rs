//! The steps of the running phase, handed out in batches: one batch per
//! hole (its retract ends it) or per wrap, so each `MotionDone` finds the
//! machine in a safe pose (drill raised, needle inside the ring) with a
//! whole number of units done, and a pause stops there at the latest.

use super::progress::Reporter;
use crate::checkpoint::Record;
use crate::stringart::Phase;
use crate::stringart::{BlendWinder, BlendWrap, Drilling, MachineStep, Save};

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
        /// The retract, held back behind the hole's record.
        retract: Option<MachineStep>,
    },
    /// Winding with the plan's winder, lent to each call
    /// ([`PhaseSteps::next`]): one winder in RAM, not two.
    Wind {
        /// The entry's next step, until it has been handed out.
        entry: Option<u8>,
        /// The entry after a power cut goes in through the gap after
        /// this nail.
        resume_gap: Option<u16>,
        wrap: Option<BlendWrap>,
        /// The wrap's checkpoint steps handed out, by the vertices handed
        /// before them: 1 the outward record made durable (after A, before
        /// the crossing out), 2 the inward one marked (after B), 3 made
        /// durable (after C, before the crossing in); 0 only the outward
        /// one marked (before the rotation to A).
        saved_at: u8,
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
    /// A step to hand out before anything else: a new phase's header, or
    /// the first half of the rotation to a wrap.
    then: Option<MachineStep>,
    /// Winding: the gap the needle last went in through (its record's).
    gap: u16,
}

fn save(n: u32, gap: u16) -> MachineStep {
    MachineStep::Save(Save::Record(Record { n, gap }))
}

fn mark(n: u32, gap: u16) -> MachineStep {
    MachineStep::Mark(Record { n, gap })
}

impl PhaseSteps {
    /// Drilling a new job (`resume: None`: its header comes first) or on
    /// from hole `resume` after a power cut.
    pub fn drill(drilling: Drilling, nails: u16, resume: Option<u32>, now_ms: u32) -> Self {
        let from = resume.unwrap_or(0);
        let mut steps = Self::new(
            Work::Drill {
                drilling,
                after_dwell: false,
                retract: None,
            },
            Phase::Drilling,
            (nails as u32, from),
            now_ms,
        );
        if resume.is_none() {
            steps.then = Some(MachineStep::Save(Save::Begin(Phase::Drilling)));
        }
        steps
    }

    /// Winding a new job's pattern (`resume: None`), or on from a
    /// checkpoint's record (`Some(None)`: none written yet).
    pub fn wind(count: u32, resume: Option<Option<Record>>, now_ms: u32) -> Self {
        let last = resume.flatten();
        let done = last.map_or(0, |r| r.n / 2);
        let work = Work::Wind {
            entry: Some(0),
            resume_gap: last.map(|r| r.gap),
            wrap: None,
            saved_at: 0,
            feed: heapless::Deque::new(),
            fed: done,
        };
        let mut steps = Self::new(work, Phase::Winding, (count, done), now_ms);
        steps.gap = last.map_or(0, |r| r.gap);
        if resume.is_none() {
            steps.then = Some(MachineStep::Save(Save::Begin(Phase::Winding)));
        }
        steps
    }

    fn new(work: Work, phase: Phase, (total, done): (u32, u32), now_ms: u32) -> Self {
        PhaseSteps {
            work,
            done,
            total,
            hold: false,
            started: false,
            exhausted: false,
            reporter: Reporter::start_at(phase, total, done, now_ms),
            then: None,
            gap: 0,
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

    /// The next step; `winder` is the plan's (only winding uses it).
    pub fn next(&mut self, winder: &mut BlendWinder) -> Option<MachineStep> {
        let step = self.step(winder);
        self.started |= step.is_some();
        step
    }

    fn step(&mut self, winder: &mut BlendWinder) -> Option<MachineStep> {
        if self.hold || self.exhausted {
            return None;
        }
        if let Some(step) = self.then.take() {
            return Some(step);
        }
        match &mut self.work {
            Work::Drill {
                drilling,
                after_dwell,
                retract,
            } => {
                if let Some(step) = retract.take() {
                    self.hold = true;
                    return Some(step);
                }
                let Some(step) = drilling.next() else {
                    self.exhausted = true;
                    return None;
                };
                if *after_dwell {
                    // The hole is drilled: its record, then the retract.
                    *after_dwell = false;
                    self.done += 1;
                    *retract = Some(step);
                    return Some(save(self.done, 0));
                }
                *after_dwell = matches!(step, MachineStep::Dwell(_));
                Some(step)
            }
            Work::Wind {
                entry,
                resume_gap,
                wrap,
                feed,
                saved_at,
                ..
            } => {
                if let Some(i) = entry {
                    if let Some(step) = winder.entry_step(*resume_gap, *i) {
                        *i += 1;
                        return Some(step);
                    }
                    *entry = None;
                    self.hold = true;
                    return None;
                }
                if let Some(w) = wrap {
                    // Each record is durable before the crossing it is
                    // about; the inward one is started once the needle is
                    // out (past B), the outward one once inside (past the
                    // last wrap's D).
                    let due = w.handed();
                    if due > *saved_at && due < 4 {
                        *saved_at = due;
                        if due != 2 {
                            return Some(MachineStep::Durable);
                        }
                        self.gap = w.gaps()[1];
                        return Some(mark(2 * self.done + 2, self.gap));
                    }
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
                let from = winder.base();
                let w = wrap.insert(winder.wrap(j).ok()?);
                self.then = w.half_turn(from);
                // The gap the needle will go out through, written while
                // it turns there.
                *saved_at = 0;
                self.gap = w.gaps()[0];
                Some(mark(2 * self.done + 1, self.gap))
            }
        }
    }

    /// The record of the last [`MachineStep::Mark`] handed out, while its
    /// wrap's crossing waits for it: the outward one until B is out, then
    /// the inward one.
    pub fn marked(&self) -> Option<Record> {
        let Work::Wind { wrap: Some(w), .. } = &self.work else {
            return None;
        };
        let inward = w.handed() >= 2;
        Some(Record {
            n: 2 * self.done + 1 + inward as u32,
            gap: self.gap,
        })
    }

    /// The base's position after the steps handed out (0 while drilling).
    pub fn base(&self, winder: &BlendWinder) -> i32 {
        match &self.work {
            Work::Wind { .. } => winder.base(),
            Work::Drill { .. } => 0,
        }
    }

    /// Paused between wraps, winding goes on at wrap `k + 1` (`k` counted
    /// done, the pattern to be read on from there): the record that says
    /// so, the needle inside the ring at its last gap.
    pub fn jump(&mut self, k: u32) -> Option<Record> {
        let Work::Wind {
            wrap,
            feed,
            fed,
            saved_at,
            ..
        } = &mut self.work
        else {
            return None;
        };
        *wrap = None;
        *saved_at = 0;
        feed.clear();
        *fed = k;
        self.done = k;
        self.exhausted = false;
        Some(Record {
            n: 2 * k,
            gap: self.gap,
        })
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
