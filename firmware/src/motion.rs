//! The motion task's state: planner → segment preparer → the step
//! interrupt's queues. Grbl's `planner` and `st_prep_buffer` in one place.

use crate::drivers::Drivers;
use crate::stepper::{Stepper, BLOCKS, SEGMENTS};
use taut_logic::axis::PerAxis;
use taut_logic::config::MachineConfig;
use taut_logic::planner::{Feed, Full, Planner};
use taut_logic::segment::Preparer;

pub struct Motion {
    pub planner: Planner,
    prep: Preparer,
    pub stepper: Stepper,
    pub drivers: Drivers,
}

impl Motion {
    pub fn new(config: &MachineConfig, stepper: Stepper, drivers: Drivers) -> Motion {
        Motion {
            planner: Planner::new(config),
            prep: Preparer::new(),
            stepper,
            drivers,
        }
    }

    /// Queue a move to the absolute step `target`; `Full` is back-pressure.
    pub fn push(&mut self, target: PerAxis<i32>, feed: Feed) -> Result<(), Full> {
        self.planner.push(target, feed)
    }

    /// Move planned blocks into the interrupt's queues while they have room
    /// and start the interrupt. Returns true if a planner slot was freed.
    pub fn refill(&mut self) -> bool {
        let mut freed = false;
        while SEGMENTS.free() > 0 {
            if self.prep.is_idle() {
                if BLOCKS.free() == 0 {
                    break;
                }
                let Some(p) = self.planner.take() else { break };
                // The block goes first: its first segment refers to it.
                let _ = BLOCKS.push(p.block);
                self.prep.start(p.profile);
                freed = true;
            }
            match self.prep.next() {
                Some(seg) => {
                    let _ = SEGMENTS.push(seg);
                }
                None => break,
            }
        }
        self.stepper.kick();
        freed
    }

    /// Every queued move has been executed.
    pub fn is_idle(&self) -> bool {
        self.planner.is_idle()
            && self.prep.is_idle()
            && SEGMENTS.is_empty()
            && !self.stepper.is_running()
    }

    /// Redefine where the machine is (`G92`, zeroing). Only when idle.
    pub fn set_position(&mut self, steps: PerAxis<i32>) {
        self.planner.set_position(steps);
        self.stepper.set_position(steps);
    }
}
