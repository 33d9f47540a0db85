//! Carrying out the job's steps ([`Job::next_step`]) on a machine: the
//! same code on the AVR (`firmware/src/job.rs`) and in the host's estimate
//! ([`crate::stringart::estimate`]), so both time a job alike.
//!
//! - A move names only the axes it moves: its other targets are where the
//!   last move handed over ends, so every target stays absolute.
//! - Moves go to the planner while it has room, so those of a batch blend.
//! - A dwell, a driver switch and a checkpoint wait until the machine
//!   stands; nothing follows a checkpoint until it is written.
//! - Once the batch's last step is out and the machine stands,
//!   [`Feeding::Done`]: the caller sends [`super::Event::MotionDone`].

use super::Job;
use crate::axis::PerAxis;
use crate::files::check::CardId;
use crate::planner::Full;
use crate::stringart::{MachineStep, Save};

/// What the job's steps need of the machine.
pub trait Machine {
    /// Where the last move handed over ends (the position if none), steps.
    fn target(&self) -> PerAxis<i32>;
    /// Plans a move to `to` at the axes' own speeds.
    fn push(&mut self, to: PerAxis<i32>) -> Result<(), Full>;
    /// Nothing planned, nothing moving.
    fn is_idle(&self) -> bool;
    fn drivers(&mut self, mask: u8, on: bool);
    /// Starts writing a checkpoint, the machine standing. `card` is the
    /// job's ([`Job::card`]): a phase's header names it.
    fn save(&mut self, save: Save, card: (u16, u32, CardId));
    /// A checkpoint is still being written.
    fn saving(&self) -> bool;
}

/// What the feeder waits for before its next run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Feeding {
    /// Nothing: its budget of steps is used and more are waiting.
    Again,
    /// The planner to take a block, or the machine to stand.
    Motion,
    /// This many ms: a dwell, or a checkpoint being written.
    After(u16),
    /// The batch is done and the machine stands: `MotionDone` is due.
    Done,
    /// No batch: nothing until the next [`Feeder::pull`].
    Idle,
}

/// How often a checkpoint being written is looked at, ms (the store
/// writes one differing EEPROM byte per run, one run per 4 ms).
pub const SAVE_POLL_MS: u16 = 4;

/// Where a batch stands: its steps being handed out, then the wait for
/// the machine to stand.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Feeder {
    pulling: bool,
    settling: bool,
    /// A step the machine had no room or time for yet.
    pending: Option<MachineStep>,
    dwell_until: Option<u32>,
}

impl Feeder {
    pub const fn new() -> Self {
        Feeder {
            pulling: false,
            settling: false,
            pending: None,
            dwell_until: None,
        }
    }

    /// [`super::Action::NextMoves`]: the next batch's steps are due.
    pub fn pull(&mut self) {
        self.pulling = true;
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
        m: &mut impl Machine,
        now_ms: u32,
        mut budget: u8,
    ) -> Feeding {
        if m.saving() {
            return Feeding::After(SAVE_POLL_MS);
        }
        if let Some(until) = self.dwell_until {
            let left = until.wrapping_sub(now_ms) as i32;
            if left > 0 {
                return Feeding::After(left as u16);
            }
            self.dwell_until = None;
        }
        while self.pulling {
            if budget == 0 {
                return Feeding::Again;
            }
            budget -= 1;
            let Some(step) = self.pending.take().or_else(|| job.next_step()) else {
                self.pulling = false;
                self.settling = true;
                break;
            };
            match step {
                MachineStep::Move(targets) => {
                    let mut at = m.target();
                    for (a, t) in at.iter_mut().zip(targets) {
                        *a = t.unwrap_or(*a);
                    }
                    if m.push(at).is_err() {
                        self.pending = Some(step);
                        return Feeding::Motion;
                    }
                }
                _ if !m.is_idle() => {
                    self.pending = Some(step);
                    return Feeding::Motion;
                }
                MachineStep::Dwell(ms) => {
                    self.dwell_until = Some(now_ms.wrapping_add(ms as u32));
                    return Feeding::After(ms);
                }
                MachineStep::Drivers { mask, on } => m.drivers(mask, on),
                // Without a job's card (a tool's steps) there is nothing
                // to name in a checkpoint.
                MachineStep::Save(save) => {
                    if let Some(card) = job.card() {
                        m.save(save, card);
                        return Feeding::After(SAVE_POLL_MS);
                    }
                }
            }
        }
        if self.settling {
            if !m.is_idle() {
                return Feeding::Motion;
            }
            self.settling = false;
            return Feeding::Done;
        }
        Feeding::Idle
    }
}
