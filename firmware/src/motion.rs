//! The motion task's state: planner → segment preparer → the step
//! interrupt's queues. Grbl's `planner` and `st_prep_buffer` in one place.

use crate::drivers::Drivers;
use crate::rt::TaskCell;
use crate::stepper::{fast_segment, Stepper, BLOCKS, FAST, SEGMENTS};
use taut_logic::axis::PerAxis;
use taut_logic::config::MachineConfig;
use taut_logic::planner::{Feed, Full, Planner};
use taut_logic::segment::{Preparer, StepBlock};

/// Below this many queued segments, preparing more is urgent (the app runs
/// it at the highest software priority); above, it is background work.
pub const URGENT: usize = 16;

/// The look-ahead ring (1 KiB): its own static, built in place.
static PLANNER: TaskCell<Planner> = TaskCell::new(Planner::EMPTY);

pub struct Motion {
    prep: Preparer,
    /// The block the preparer is cutting (for the fast-path flag).
    block: StepBlock,
    pub stepper: Stepper,
    pub drivers: Drivers,
}

impl Motion {
    pub fn new(config: &MachineConfig, stepper: Stepper, drivers: Drivers) -> Motion {
        PLANNER.with(|p| p.configure(config));
        Motion {
            prep: Preparer::new(),
            block: StepBlock::default(),
            stepper,
            drivers,
        }
    }

    /// Queue a move to the absolute step `target`; `Full` is back-pressure.
    pub fn push(&mut self, target: PerAxis<i32>, feed: Feed) -> Result<(), Full> {
        PLANNER.with(|p| p.push(target, feed))
    }

    /// Move planned blocks into the interrupt's queues, at most `max`
    /// segments (a ramp segment costs up to ~4 ms here: runs stay short so
    /// other tasks interleave), and start the interrupt. Returns (a planner
    /// slot was freed, more can be prepared).
    pub fn refill(&mut self, max: usize) -> (bool, bool) {
        let mut freed = false;
        let mut made = 0;
        while SEGMENTS.free() > 0 && made < max {
            if self.prep.is_idle() {
                if BLOCKS.free() == 0 {
                    break;
                }
                let Some(p) = PLANNER.with(|p| p.take()) else {
                    break;
                };
                // The block goes first: its first segment refers to it.
                let _ = BLOCKS.push(p.block);
                self.block = p.block;
                self.prep.start(p.profile);
                freed = true;
            }
            match self.prep.next() {
                Some(mut seg) => {
                    if fast_segment(&seg, &self.block) {
                        seg.flags |= FAST;
                    }
                    let _ = SEGMENTS.push(seg);
                    made += 1;
                }
                None => break,
            }
        }
        self.stepper.kick();
        let work = !self.prep.is_idle() || !PLANNER.with(|p| p.is_idle());
        (freed, made == max && work && SEGMENTS.free() > 0)
    }

    /// Where the last queued move ends, steps.
    pub fn target(&self) -> PerAxis<i32> {
        PLANNER.with(|p| p.position())
    }

    /// Every queued move has been executed.
    pub fn is_idle(&self) -> bool {
        PLANNER.with(|p| p.is_idle())
            && self.prep.is_idle()
            && SEGMENTS.is_empty()
            && !self.stepper.is_running()
    }

    /// Take new machine figures (a `$` setting); only when idle.
    pub fn configure(&mut self, config: &MachineConfig) {
        PLANNER.with(|p| p.configure(config));
        self.drivers.configure(config);
        self.stepper.set_timing(&config.pulse);
    }

    /// Redefine where the machine is (`G92`, zeroing). Only when idle.
    pub fn set_position(&mut self, steps: PerAxis<i32>) {
        PLANNER.with(|p| p.set_position(steps));
        self.stepper.set_position(steps);
    }
}
