//! Carrying out the job's steps ([`Job::next_step`]) on a machine: the
//! same code on the AVR (`firmware/src/job.rs`) and in the host's estimate
//! ([`crate::stringart::estimate`]), so both time a job alike.
//!
//! - A move names only the axes it moves: its other targets are where the
//!   last move handed over ends, so every target stays absolute.
//! - Moves go to the planner while it has room, so those of a batch blend.
//! - A dwell, a driver switch and a checkpoint wait until the machine
//!   stands; nothing follows a checkpoint until it is written.
//! - A [`MachineStep::Mark`]'s record is written while the machine moves:
//!   started once the machine has begun a move handed out after the mark
//!   (or stands), so the motion before the mark is done; the moves up to
//!   the next [`MachineStep::Durable`] go out meanwhile, the ones after it
//!   only once the record is durable. Until then the planner ends its
//!   queue at rest there: a record late for its vertex stops the machine
//!   there, one in time lets the next move blend in.
//! - Once the batch's last step is out and the machine stands,
//!   [`Feeding::Done`]: the caller sends [`super::Event::MotionDone`].
//!   While winding runs on ([`Job::chains`]) it is sent at once, the
//!   machine still moving: the next wrap blends into this one.

use super::Job;
use crate::axis::PerAxis;
use crate::checkpoint::Record;
use crate::files::check::CardId;
use crate::planner::Full;
use crate::stringart::{MachineStep, Save};

/// What the job's steps need of the machine's hardware: the planner,
/// the drivers, the checkpoint's EEPROM.
pub trait Hardware {
    /// Where the last move handed over ends (the position if none), steps.
    fn target(&self) -> PerAxis<i32>;
    /// Plans a move to `to` at the axes' own speeds.
    fn push(&mut self, to: PerAxis<i32>) -> Result<(), Full>;
    /// Nothing planned, nothing moving.
    fn is_idle(&self) -> bool;
    /// Moves handed over (of at least one step) whose first step has
    /// not been made yet.
    fn unbegun(&self) -> u8;
    fn drivers(&mut self, mask: u8, on: bool);
    /// Starts writing a checkpoint (after the last one is written). `card`
    /// is the job's ([`Job::card`]): a phase's header names it.
    fn save(&mut self, save: Save, card: (u16, u32, CardId));
    /// Starts writing a record (after the last checkpoint is written).
    fn record(&mut self, r: Record);
    /// A checkpoint is still being written.
    fn saving(&self) -> bool;
}

/// What the feeder waits for before its next run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Feeding {
    /// Nothing: its budget of steps is used and more are waiting.
    Again,
    /// The planner to take a block, the machine to begin one, or to stand
    /// (the app's `Signal::PlannerRoom`).
    PlannerRoom,
    /// This many ms: a dwell, or a checkpoint being written.
    After(u16),
    /// The batch is done and the machine stands (or winding runs on):
    /// `MotionDone` is due.
    Done,
    /// No batch: nothing until the next [`Feeder::pull`].
    Idle,
}

/// How often a checkpoint being written is looked at, ms (the store
/// writes one differing EEPROM byte per run, one run per 4 ms).
pub const SAVE_POLL_MS: u16 = 4;

/// Where a batch stands.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum Stage {
    #[default]
    Idle,
    /// Its steps being handed out.
    Pulling,
    /// Handed out up to a checkpoint: nothing more until the one marked
    /// or being written is durable.
    Held,
    /// All out: waiting for the machine to stand.
    Settling,
    /// All out, `Done` said with the machine still moving: winding runs
    /// on into the next batch.
    Chained,
}

/// What the steps wait for, besides the machine.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum Wait {
    #[default]
    None,
    /// The end of a dwell, ms.
    Dwell(u32),
    /// The record of the last [`MachineStep::Mark`] ([`Job::marked`]) is
    /// not started yet: the moves handed over since the mark.
    Marked(u8),
}

/// Where a batch stands: its steps being handed out, then the wait for
/// the machine to stand.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Feeder {
    stage: Stage,
    /// A step the machine had no room or time for yet.
    pending: Option<MachineStep>,
    wait: Wait,
}

impl Feeder {
    pub const fn new() -> Self {
        Feeder {
            stage: Stage::Idle,
            pending: None,
            wait: Wait::None,
        }
    }

    /// [`super::Action::NextMoves`]: the next batch's steps are due.
    pub fn pull(&mut self) {
        self.stage = Stage::Pulling;
    }

    /// The motion still running is the last batch's, which said `Done`
    /// early: the next batch follows it without waiting for a stand.
    pub fn chained(&self) -> bool {
        self.stage == Stage::Chained
    }

    /// The machine was stopped and its queues emptied: the steps in hand
    /// and the wait for them are gone too.
    pub fn abort(&mut self) {
        *self = Feeder::new();
    }

    /// Hands over at most `budget` steps of the batch (`now_ms`: the
    /// millisecond clock, which may wrap); what to wait for next.
    pub fn run(
        &mut self,
        job: &mut Job,
        m: &mut impl Hardware,
        now_ms: u32,
        mut budget: u8,
    ) -> Feeding {
        if self.record_due(job, m) {
            return self.held(m);
        }
        if let Wait::Dwell(until) = self.wait {
            let left = until.wrapping_sub(now_ms) as i32;
            if left > 0 {
                return Feeding::After(left as u16);
            }
            self.wait = Wait::None;
        }
        while self.stage == Stage::Pulling {
            if budget == 0 {
                return Feeding::Again;
            }
            budget -= 1;
            let Some(step) = self.pending.take().or_else(|| job.next_step()) else {
                if job.chains() {
                    self.stage = Stage::Chained;
                    return Feeding::Done;
                }
                self.stage = Stage::Settling;
                break;
            };
            match step {
                MachineStep::Move(targets) => {
                    let mut at = m.target();
                    let mut moves = false;
                    for (a, t) in at.iter_mut().zip(targets) {
                        let t = t.unwrap_or(*a);
                        moves |= t != *a;
                        *a = t;
                    }
                    if m.push(at).is_err() {
                        self.pending = Some(step);
                        return Feeding::PlannerRoom;
                    }
                    // A move of no step is no block: it never begins.
                    if let (Wait::Marked(after), true) = (&mut self.wait, moves) {
                        *after = after.saturating_add(1);
                    }
                }
                // Without a job's card (a tool's steps) there is nothing
                // to name in a checkpoint.
                MachineStep::Mark(_) => {
                    debug_assert!(self.wait == Wait::None, "a Durable between marks");
                    if job.card().is_some() {
                        self.wait = Wait::Marked(0);
                    }
                }
                MachineStep::Durable => {
                    self.stage = Stage::Held;
                    if self.record_due(job, m) {
                        return self.held(m);
                    }
                }
                _ if !m.is_idle() => {
                    self.pending = Some(step);
                    return Feeding::PlannerRoom;
                }
                MachineStep::Dwell(ms) => {
                    self.wait = Wait::Dwell(now_ms.wrapping_add(ms as u32));
                    return Feeding::After(ms);
                }
                MachineStep::Drivers { mask, on } => m.drivers(mask, on),
                MachineStep::Save(save) => {
                    if let Some(card) = job.card() {
                        // One write at a time.
                        self.stage = Stage::Held;
                        if !m.saving() {
                            m.save(save, card);
                        } else {
                            self.pending = Some(step);
                        }
                        return Feeding::After(SAVE_POLL_MS);
                    }
                }
            }
        }
        if self.stage == Stage::Settling {
            if !m.is_idle() {
                return Feeding::PlannerRoom;
            }
            self.stage = Stage::Idle;
            return Feeding::Done;
        }
        Feeding::Idle
    }

    /// While held: a record waits for the machine to pass its mark (it
    /// wakes the job as it begins a block, not a poll through a long
    /// rotation), or for the last checkpoint to be written.
    fn held(&self, m: &impl Hardware) -> Feeding {
        match self.wait {
            Wait::Marked(after) if !passed(after, m) => Feeding::PlannerRoom,
            _ => Feeding::After(SAVE_POLL_MS),
        }
    }

    /// Starts the marked record once the machine has passed its mark (a
    /// move handed over since has begun, so every one before it is done,
    /// or the machine stands) and the last checkpoint is written. True
    /// while the steps must wait for a record to be durable.
    fn record_due(&mut self, job: &Job, m: &mut impl Hardware) -> bool {
        if let Wait::Marked(after) = self.wait {
            if passed(after, m) && !m.saving() {
                self.wait = Wait::None;
                if let Some(r) = job.marked() {
                    m.record(r);
                }
            }
        }
        let held = self.stage == Stage::Held;
        if held && !m.saving() && self.wait == Wait::None {
            self.stage = Stage::Pulling;
        }
        self.stage == Stage::Held
    }
}

/// The machine has passed a mark with `after` moves handed over since: one
/// of them has begun, so every one before it is done, or it stands.
fn passed(after: u8, m: &impl Hardware) -> bool {
    after > m.unbegun() || m.is_idle()
}
