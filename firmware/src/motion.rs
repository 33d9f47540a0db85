//! The motion task's state: planner → segment preparer → the step
//! interrupt's queues. Grbl's `planner` and `st_prep_buffer` in one place.

use crate::drivers::Drivers;
use crate::rt::TaskCell;
use crate::stepper::{fast_segment, Stepper, BLOCKS, FAST, SEGMENTS, SEGMENTS_CAPACITY};
use core::sync::atomic::{AtomicU8, Ordering::Relaxed};
use taut_logic::axis::PerAxis;
use taut_logic::config::MachineConfig;
use taut_logic::planner::{Feed, Full, Planner};
use taut_logic::segment::{Buffered, Preparer, StepBlock};

/// Preparing segments is urgent (the app runs it at the highest software
/// priority) while the queue holds less motion than this; otherwise it is
/// background work. Longer than any other task's run (a card block, a
/// wrap's planning: under 10 ms), so they never starve the queue.
const URGENT_BUDGET_US: u32 = 30_000;
/// Fewer segments than this are always urgent.
const URGENT_MIN: u8 = 2;

/// At or below this many queued segments the refill is urgent: as many of
/// the newest as last less than the budget. Set by the refill, read by the
/// interrupts that spawn it (one byte: atomic on the AVR).
static SHORT_AT: AtomicU8 = AtomicU8::new(SEGMENTS_CAPACITY as u8);

/// The step queue holds less than the urgent budget of motion.
#[inline(always)]
pub fn urgent() -> bool {
    SEGMENTS.len() <= SHORT_AT.load(Relaxed) as usize
}

/// The look-ahead ring (1 KiB): its own static, built in place.
static PLANNER: TaskCell<Planner> = TaskCell::new(Planner::EMPTY);

pub struct Motion {
    prep: Preparer,
    /// How long the queued segments last.
    buffered: Buffered<SEGMENTS_CAPACITY>,
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
            buffered: Buffered::new(),
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
                    self.buffered.push(&seg);
                    made += 1;
                }
                None => break,
            }
        }
        if made > 0 {
            let short = self
                .buffered
                .short_at(URGENT_BUDGET_US)
                .max(URGENT_MIN as usize);
            SHORT_AT.store(short as u8, Relaxed);
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
