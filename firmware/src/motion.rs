//! Segment preparation's state (the app's `Refill` and `Prepare` tasks):
//! planner → segment preparer → the step interrupt's queues. Grbl's `planner` and `st_prep_buffer` in one place,
//! with its feed hold (`!`/`~`), its stop at once (Ctrl-X) and a stop that
//! abandons the rest of the queued motion (a pulled card).

use crate::board::servo::PenServo;
use crate::drivers::Drivers;
use crate::queues::{BLOCKS, SEGMENTS, SEGMENTS_CAPACITY};
use crate::rt::byte;
use crate::rt::TaskCell;
use crate::stepper::{blocks_begun, every_event, fast_segment, Stepper, FAST};
use core::sync::atomic::AtomicU8;
use taut_logic::axis::PerAxis;
use taut_logic::config::MachineConfig;
use taut_logic::kinematics::Piece;
use taut_logic::planner::{Feed, Full, Overrides, Planner};
use taut_logic::prep::{Cut, Hold, Prep};
use taut_logic::segment::{Buffered, Later};
use taut_logic::units::Milli;

/// Preparing segments is urgent (the app runs it at the highest software
/// priority) while the queue holds less motion than this; otherwise it is
/// background work. Longer than any other task's run (a card block, a
/// wrap's planning: under 10 ms), so they never starve the queue, and
/// shorter than [`QUEUED_MAX_US`], so a filled queue is not urgent.
const URGENT_BUDGET_US: u32 = 30_000;
/// Fewer segments than this are always urgent.
const URGENT_MIN: u8 = 2;
/// The queue holds no more motion than this (plus one segment, 50 ms at
/// most): a feed hold brakes from the last segment queued, so this bounds
/// how long a hold waits to begin (≤ 90 ms). 25 ms starved a SCARA arm's
/// stream of tiny moves (`plotter_stress`).
const QUEUED_MAX_US: u32 = 40_000;

/// Below this much queued motion, with more to cut, the step queue is
/// about to run dry inside a planned move: the console waits for the
/// refill ([`Motion::starving`]), and a standing stepper does not start
/// on less (unless that is all there is to cut). Above the longest a
/// segment's cut takes with a console run and the interrupts between
/// (~3 ms): a stream of 0.2 mm moves on the flatbed, stopping and starting
/// at every line, ran dry with the refill behind a console's line.
const STARVING_US: u32 = 8_000;

/// The queued segments under which the refill is urgent, as many of the
/// newest as last less than [`URGENT_BUDGET_US`]: written by segment
/// preparation, read by the step interrupt and the tick (which spawn the
/// urgent `Refill` at or below it). One byte: atomic on the AVR.
static SHORT_AT: AtomicU8 = AtomicU8::new(SEGMENTS_CAPACITY as u8);

/// The step queue holds less than the urgent budget of motion.
#[inline(always)]
pub fn urgent() -> bool {
    SEGMENTS.len() <= byte::load(&SHORT_AT) as usize
}

/// The look-ahead ring (1 KiB): its own static, built in place.
static PLANNER: TaskCell<Planner> = TaskCell::new(Planner::EMPTY);

/// What the machine is doing, for status reports.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum State {
    Idle,
    Run,
    /// A feed hold braking (`Hold:1` in Grbl's words) or standing (`Hold:0`).
    Hold {
        standing: bool,
    },
}

pub struct Motion {
    prep: Prep,
    /// How long the queued segments last.
    buffered: Buffered<SEGMENTS_CAPACITY>,
    /// The block the preparer is cutting steps every axis at every event
    /// (its segments may take the fast path).
    every_event: bool,
    /// Blocks in `BLOCKS` after the last refill: fewer now, the step
    /// interrupt has begun one since (what the job waits for to start a
    /// checkpoint's record).
    blocks: u8,
    /// Drop the queued motion once a hold has brought the machine to rest.
    cancel: bool,
    /// Bumped by every stop that drops queued moves: whoever queued them
    /// reads the position back.
    epoch: u8,
    /// Stopped at once while moving: steps may have been lost, so motion
    /// waits for the position to be set again (Grbl's alarm lock).
    lost: bool,
    /// Axes (bit = index) that moves queued since the machine last stood
    /// have moved or will move.
    busy: u8,
    pub stepper: Stepper,
    pub drivers: Drivers,
    /// The plotters' pen on SERVO0.
    pub pen: PenServo,
}

/// The planner's figures at boot, before [`Motion::new`]: out of the frame
/// the motion's state is built in (the stack peak at boot).
pub fn configure_planner(config: &MachineConfig) {
    PLANNER.with(|p| p.configure(config));
}

impl Motion {
    /// After [`configure_planner`].
    pub fn new(stepper: Stepper, drivers: Drivers, pen: PenServo) -> Motion {
        Motion {
            prep: Prep::new(),
            buffered: Buffered::new(),
            every_event: false,
            blocks: 0,
            cancel: false,
            epoch: 0,
            lost: false,
            busy: 0,
            stepper,
            drivers,
            pen,
        }
    }

    /// A segment's part ends early when `others` says another task waits
    /// (`Preparer::yield_to`).
    pub fn yield_to(&mut self, others: fn() -> bool) {
        self.prep.yield_to(others);
    }

    /// Queue a move to the absolute step `target`; `Full` is back-pressure.
    #[optimize(speed)]
    pub fn push(&mut self, target: PerAxis<i32>, feed: Feed) -> Result<(), Full> {
        self.stage(target, feed)?;
        while self.plan_part() {}
        Ok(())
    }

    /// [`Motion::push`] in bounded parts: records the move, which
    /// [`Motion::plan_part`] then plans a part a run (each ≤ ~1 ms), so
    /// that a ready task never waits for a whole move's planning.
    pub fn stage(&mut self, target: PerAxis<i32>, feed: Feed) -> Result<(), Full> {
        let from = self.target();
        PLANNER.with(|p| p.stage(target, feed))?;
        self.moving(&from, &target);
        Ok(())
    }

    /// [`Motion::stage`] of a piece of a path: on the whiteboard and the
    /// arm its speeds are the pen's along it.
    #[inline(never)]
    pub fn stage_piece(&mut self, piece: &Piece, feed: Feed) -> Result<(), Full> {
        let from = self.target();
        PLANNER.with(|p| p.stage_piece(piece, feed))?;
        self.moving(&from, &piece.steps);
        Ok(())
    }

    /// The axes a move from `from` to `to` turns are busy.
    fn moving(&mut self, from: &PerAxis<i32>, to: &PerAxis<i32>) {
        for (i, (a, b)) in from.iter().zip(to).enumerate() {
            self.busy |= ((a != b) as u8) << i;
        }
    }

    /// One part of planning the staged move; false when none is left.
    #[optimize(speed)]
    pub fn plan_part(&mut self) -> bool {
        PLANNER.with(|p| p.plan_part())
    }

    /// A move staged is being planned (a move of no step is not).
    pub fn staging(&self) -> bool {
        PLANNER.with(|p| p.is_planning())
    }

    /// Moves queued in the planner, not yet taken to be cut.
    pub fn planned(&self) -> usize {
        PLANNER.with(|p| p.queued())
    }

    /// Planner blocks free for new moves (`Bf:`).
    pub fn free_blocks(&self) -> usize {
        PLANNER.with(|p| p.free())
    }

    /// Blocks queued whose first step has not been made: in the planner,
    /// in the preparer, or waiting for the step interrupt (which takes a
    /// block from `BLOCKS` as it begins it). The interrupt only lowers
    /// the count meanwhile, and the tasks do not preempt each other.
    pub fn unbegun(&self) -> u8 {
        let planned = PLANNER.with(|p| p.queued()) as u8;
        planned + self.prep.holds_block() as u8 + BLOCKS.len() as u8
    }

    /// The number the next block queued will have when the step
    /// interrupt begins it ([`blocks_begun`] counts them, wrapping). Read
    /// after [`Motion::unbegun`]: a block begun between the reads makes it
    /// one too high, never too low.
    pub fn next_block(&self) -> u8 {
        let unbegun = self.unbegun();
        blocks_begun().wrapping_add(unbegun)
    }

    /// Whether the planner has room for a move.
    pub fn has_room(&self) -> bool {
        !PLANNER.with(|p| p.is_full())
    }

    /// Axes (bit = index) moving now or queued to: switching one of their
    /// drivers must wait until the machine stands.
    pub fn busy_axes(&mut self) -> u8 {
        if self.is_idle() {
            self.busy = 0;
        }
        self.busy
    }

    /// Move planned blocks into the interrupt's queues, `max` pieces of
    /// work (taking a block, a part of its profile or of a segment: ≤ ~1
    /// ms each, so other tasks interleave), up to `most` while `others`
    /// says no other task waits, and start the interrupt.
    /// Returns (a planner slot was freed or a block begun, more can be
    /// prepared).
    pub fn refill(&mut self, max: usize, most: usize, others: fn() -> bool) -> (bool, bool) {
        let mut freed = BLOCKS.len() < self.blocks as usize;
        let mut made = 0;
        let mut pushed = false;
        let mut room = SEGMENTS.free() > 0 && BLOCKS.free() > 0;
        while room
            && (made < max || made < most && !others())
            && self.buffered.queued_us(SEGMENTS.len()) < QUEUED_MAX_US
        {
            // Taking a block, a part of its profile and a part of a
            // segment each count as one piece of work (each ≤ ~1 ms).
            let (loaded, took) = PLANNER.with(|p| {
                let queued = p.queued();
                (self.prep.load(p), p.queued() < queued)
            });
            freed |= took;
            if loaded {
                made += 1;
                continue;
            }
            let cut = match PLANNER.with(|p| self.prep.next_part(p)) {
                Ok(Some(cut)) => cut,
                Ok(None) => break,
                // Part of a segment worked out: the rest next run.
                Err(Later) => {
                    made += 1;
                    continue;
                }
            };
            freed |= self.queue(&cut);
            pushed = true;
            made += 1;
            room = SEGMENTS.free() > 0 && BLOCKS.free() > 0;
        }
        // Only a new segment moves where the queue counts as short.
        if pushed {
            let short = self
                .buffered
                .short_at(URGENT_BUDGET_US)
                .max(URGENT_MIN as usize);
            byte::store(&SHORT_AT, short as u8);
        }
        self.blocks = BLOCKS.len() as u8;
        // A standing stepper starts on enough motion to keep ahead of.
        if (!self.cuts() || !self.short()) && self.stepper.kick() {
            self.drivers.moving();
        }
        if self.cancel && self.prep.hold_state() == Hold::Stopped && !self.stepper.is_running() {
            self.abort();
            freed = true;
        }
        let work = !self.prep.is_idle() || !PLANNER.with(|p| p.is_idle());
        let held = self.prep.hold_state() == Hold::Stopped;
        (freed, made >= max && work && !held && room)
    }

    /// The step queue runs inside planned motion on less than
    /// [`STARVING_US`] while the preparer has more to cut: cutting it
    /// comes before anything else (an underrun is a fault).
    pub fn starving(&self) -> bool {
        self.stepper.is_running() && self.short() && self.cuts()
    }

    /// A console that waits for the refill while the queue starves waits
    /// on until it holds twice [`STARVING_US`] of motion, or the preparer
    /// has nothing more to cut now: fewer switches between the two.
    pub fn refilling(&self) -> bool {
        self.stepper.is_running()
            && !self.buffered.lasts(SEGMENTS.len(), 2 * STARVING_US)
            && self.cuts()
    }

    /// The queue holds less than [`STARVING_US`] of motion.
    fn short(&self) -> bool {
        !self.buffered.lasts(SEGMENTS.len(), STARVING_US)
    }

    /// The preparer can cut a segment now: a block taken or planned, no
    /// hold's stop, room in the step queue.
    fn cuts(&self) -> bool {
        let work = !self.prep.is_idle() || PLANNER.with(|p| p.queued()) > 0;
        work && self.prep.hold_state() != Hold::Stopped && SEGMENTS.free() > 0 && BLOCKS.free() > 0
    }

    /// Hand `cut` to the step interrupt; true if it begins a block. Out of
    /// line: its copies stay off the frame under the preparer's calls.
    #[inline(never)]
    fn queue(&mut self, cut: &Cut) -> bool {
        let mut seg = cut.segment;
        if let Some(block) = &cut.block {
            // Its drivers on before the step interrupt can reach it.
            let mut moving = 0;
            for (i, &steps) in block.steps.iter().enumerate() {
                moving |= ((steps != 0) as u8) << i;
            }
            self.drivers.wake(moving);
            // The block goes first: its first segment refers to it.
            let _ = BLOCKS.push(*block);
            // Coils step in the interrupt's general path only.
            self.every_event = every_event(block) && moving & self.stepper.coil_axes() == 0;
        }
        if self.every_event && fast_segment(&seg) {
            seg.flags |= FAST;
        }
        let _ = SEGMENTS.push(seg);
        self.buffered.push(&seg);
        cut.block.is_some()
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

    pub fn state(&self) -> State {
        match self.prep.hold_state() {
            Hold::Off if self.is_idle() => State::Idle,
            Hold::Off => State::Run,
            Hold::Braking => State::Hold { standing: false },
            Hold::Stopped => State::Hold {
                standing: !self.stepper.is_running(),
            },
        }
    }

    /// The feed and rapid overrides, for the moves not yet cut.
    pub fn set_overrides(&mut self, overrides: Overrides) {
        PLANNER.with(|p| p.set_overrides(overrides));
    }

    /// The speed along the path, milli-units per minute (0 standing).
    pub fn feed(&self) -> Milli {
        if self.is_idle() || matches!(self.state(), State::Hold { standing: true }) {
            return Milli::ZERO;
        }
        Milli((taut_logic::fmath::sqrt(self.prep.path_speed_sqr()) * 60.0) as i32)
    }

    /// Feed hold: brake to a stop on the path (after the queued motion).
    pub fn hold(&mut self) {
        self.prep.hold();
    }

    /// Go on after a feed hold; false when none is on.
    pub fn resume(&mut self) -> bool {
        !self.cancel && PLANNER.with(|p| self.prep.resume(p))
    }

    /// Brake to a stop and drop the rest of the queued motion: the machine
    /// then stands, idle, where it stopped (a jog cancelled, a card pulled).
    pub fn cancel(&mut self) {
        if !self.is_idle() {
            self.hold();
            self.cancel = true;
        }
    }

    /// A cancel is braking (the queued motion goes once it stands).
    pub fn is_cancelling(&self) -> bool {
        self.cancel
    }

    /// Stop at once (Ctrl-X): no more steps, the queued motion dropped, the
    /// position as the pulses left it. If the motors were moving, steps
    /// may have been lost: the position is unknown until set again (true).
    pub fn stop_now(&mut self) -> bool {
        let moving = self.stepper.is_running();
        self.lost |= moving;
        self.abort();
        moving
    }

    /// Drop the queued motion with the machine at rest (or stopped at once).
    fn abort(&mut self) {
        self.epoch = self.epoch.wrapping_add(1);
        let at = self.stepper.abort();
        SEGMENTS.clear();
        BLOCKS.clear();
        PLANNER.with(|p| p.clear(at));
        self.prep.clear();
        self.buffered = Buffered::new();
        self.cancel = false;
    }

    /// Take new machine figures (a `$` setting); only when idle.
    pub fn configure(&mut self, config: &MachineConfig) {
        PLANNER.with(|p| p.configure(config));
        self.stepper.configure(config);
        self.drivers.configure(config);
    }

    /// Redefine where the machine is (`G92`, zeroing). Only when idle.
    pub fn set_position(&mut self, steps: PerAxis<i32>) {
        PLANNER.with(|p| p.set_position(steps));
        self.stepper.set_position(steps);
        self.lost = false;
    }

    /// The position is trusted (not lost by a stop at once during motion).
    pub fn position_known(&self) -> bool {
        !self.lost
    }

    /// `$X`: trust the position again without setting it.
    pub fn unlock(&mut self) {
        self.lost = false;
    }

    /// The position can no longer be trusted (homing failed).
    pub fn lose_position(&mut self) {
        self.lost = true;
    }

    /// Another machine took over where it stands: whoever keeps a
    /// position reads it back (a new epoch, as after a stop).
    pub fn renew(&mut self) {
        self.epoch = self.epoch.wrapping_add(1);
    }

    /// See the `epoch` field.
    pub fn epoch(&self) -> u8 {
        self.epoch
    }
}
