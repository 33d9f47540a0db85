//! Look-ahead planner: a ring of moves in steps with Grbl's junction
//! deviation and trapezoidal speed profiles.
//!
//! Speeds are compared across blocks along the *path*. On a machine whose
//! kinematics are linear each axis's steps are divided by its steps per
//! unit, so the path is measured in thousandths of the axes' units (µm,
//! millidegrees) — the same scale as `junction_deviation_um`. A base turn
//! of 1° and a radial move of 1 mm are thus equally long; that is the only
//! way to compare degrees with mm. On the whiteboard and the arm a move
//! comes as [`Piece`]s of the pen's straight path, and the path is the
//! pen's, in µm: the feed, `pen_max_feed`, `pen_accel` and the junction
//! deviation are the pen's (Klipper's and Marlin's meaning of `F`), and
//! each piece is slowed where a joint would pass its own `max_rate` or
//! `accel` — along the piece, and where the joints' share of the pen's
//! speed changes from piece to piece (the path's curvature in joint space,
//! `Geometry::joints_sqr`).
//! Floats are used once per block when it is added (its length, the
//! junction cosine); the look-ahead passes are additions and comparisons of
//! squared speeds, `u32` (µm/s)² shifted right by [`Planner`]'s `shift`
//! (0 unless the machine's top speed needs more than 32 bits: 16 B a
//! block less than `u64`, and cheaper on the AVR). The block handed to the
//! segment preparer is converted to events (steps of its dominant axis).

mod axis_jump;
mod junction;

#[cfg(test)]
mod pen_tests;
#[cfg(test)]
mod tests;

use crate::axis::{PerAxis, AXES};
use crate::config::MachineConfig;
use crate::kinematics::{Frac, Piece, Position};
use crate::segment::{Speeds, StepBlock, Trapezoid};
use crate::units::Milli;
use axis_jump::AxisJumps;
use junction::{Geometry, PenLimits, PenMove, PenPath, Turn};

/// Number of moves the firmware's planner holds: as many as the RAM
/// budget allows (`docs/architecture.md`).
pub const PLANNER_BLOCKS: usize = 11;

/// The firmware's planner. The host may plan with other depths
/// ([`Lookahead`]`<N>`, say Grbl-Mega's 36) through the same code.
pub type Planner = Lookahead<PLANNER_BLOCKS>;

/// Requested speed of a move.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Feed {
    /// As fast as every axis allows (`G0`).
    Rapid,
    /// Thousandths of a unit per minute along the path (`G1 F`).
    PerMinute(Milli),
}

/// The planner is full; push again after the preparer took a block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Full;

/// A block taken by the segment preparer: what the step interrupt needs and
/// the profile to cut into segments. The planner no longer changes it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Planned {
    pub block: StepBlock,
    pub profile: Trapezoid,
    /// (events per path milli-unit)²: converts a speed² in events to the
    /// path's, to carry a speed from one block into the next.
    pub ev_per_milli_sqr: f32,
}

/// A block taken with its speeds, its profile not made yet: the segment
/// preparer makes it in parts ([`Trapezoid::begin`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Taken {
    pub block: StepBlock,
    /// Events/s².
    pub accel: u32,
    /// Events²/s².
    pub speeds: Speeds,
    pub ev_per_milli_sqr: f32,
}

/// A move's steps and directions, as a [`StepBlock`] without its events
/// (the most steps of an axis): 4 B a block less.
#[derive(Clone, Copy, Debug)]
struct Steps {
    steps: [u32; AXES],
    /// [`StepBlock::dir`], and [`PEN`].
    dir: u8,
}

/// Bit of [`Steps::dir`] past the channels': the block is a [`Piece`],
/// its path the pen's.
const PEN: u8 = 0x80;
const _: () = assert!(AXES < 8);

impl Steps {
    fn block(&self) -> StepBlock {
        StepBlock {
            steps: self.steps,
            events: self.steps.iter().copied().max().unwrap_or(0),
            dir: self.dir & !PEN,
        }
    }

    fn is_pen(&self) -> bool {
        self.dir & PEN != 0
    }
}

#[derive(Clone, Copy, Debug)]
struct Block {
    step: Steps,
    /// Events/s², the tightest of the axes' limits.
    accel: u32,
    /// The speed asked for, events/s, before the overrides and the axes'
    /// limits; 0: a rapid. Milli-units/min until `plan_limits`.
    feed_ev: f32,
    /// Cruise speed² along the path with the overrides, (milli-units/s)²
    /// (as all the speeds² here, shifted by `Planner::shift`): kept
    /// squared, as the look-ahead passes compare it (a multiply each time
    /// was a third of a pass on the AVR).
    nominal_sqr: u32,
    /// (events per path milli-unit)²: converts path speeds² to events²/s².
    ev_per_milli_sqr: f32,
    /// Path speeds²: what the junction with the block before allows, and
    /// the entry planned.
    junction_sqr: u32,
    entry_sqr: u32,
    /// Largest change of speed² over the block: 2·accel·length.
    delta_sqr: u32,
}

impl Block {
    const EMPTY: Block = Block {
        step: Steps {
            steps: [0; AXES],
            dir: 0,
        },
        accel: 0,
        feed_ev: 0.0,
        nominal_sqr: 0,
        ev_per_milli_sqr: 0.0,
        junction_sqr: 0,
        entry_sqr: 0,
        delta_sqr: 0,
    };
}

/// The feed and rapid overrides, percent (Grbl's 10–200 and 25/50/100).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Overrides {
    pub feed: u8,
    pub rapid: u8,
}

impl Overrides {
    pub const NONE: Overrides = Overrides {
        feed: 100,
        rapid: 100,
    };

    /// The cruise speed along the path of a move asking `feed_ev` events/s
    /// (0: rapid) whose axes allow `rate`, with `ev_per_milli` events per
    /// path milli-unit, squared: (milli-units/s)², from the speed in 24.8
    /// fixed point.
    fn nominal_sqr(self, feed_ev: f32, rate: u32, ev_per_milli: f32) -> u64 {
        let (asked, percent) = match feed_ev == 0.0 {
            true => (rate as f32, self.rapid),
            false => (feed_ev, self.feed),
        };
        let ev = (asked * percent as f32 / 100.0).clamp(1.0, rate as f32);
        let nominal = (ev * 256.0 / ev_per_milli) as u32 as u64;
        (nominal * nominal) >> 16
    }
}

/// How far the newest move has been planned: [`Planner::stage`] only
/// records it, [`Planner::plan_part`] works it out in bounded parts (on
/// the AVR ~0.9 ms at most each; a move planned whole is ~2.3 ms), so
/// that a caller may spread a move over several runs of its task. Its
/// block sits in the slot after the queue, counted in the queue once the
/// last part is done.
/// `repr(u8)`: `Done` is then a zero byte, and `Planner::EMPTY` all
/// zeros (a static of it needs no initial image, in flash or `.data`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(u8)]
enum Stage {
    /// No move is being planned.
    Done,
    /// Its steps are in the slot; the path comes next.
    Pushed(Feed),
    /// Direction, the axes' jumps and asked speed worked out; the
    /// junction's speed comes next.
    Turned { ev_per_milli: f32 },
    /// A piece's direction along the pen and its turn worked out, and
    /// the joints' shares of the pen's speed (`PenLast`); the joints'
    /// limits at the junction come next, then as `Turned`.
    PenTurned {
        ev_per_milli: f32,
        joint: [f32; AXES],
        len: f32,
    },
    /// Its junction too; the axes' limits come next.
    Path { ev_per_milli: f32 },
    /// Its figures are complete; the look-ahead passes come next.
    Limits,
}

/// The pen's last piece, for the junction with the next: each joint's
/// share of the pen's speed (joint milli-units per µm) and its length, µm.
#[derive(Clone, Copy, Debug)]
struct PenLast {
    joint: [f32; AXES],
    len: f32,
}

/// A planner of `N` blocks.
pub struct Lookahead<const N: usize> {
    blocks: [Block; N],
    /// Oldest block.
    head: usize,
    len: usize,
    /// Blocks from the oldest whose entry speeds are final: the look-ahead
    /// passes start after them (Grbl's "planned" pointer), so a push costs
    /// the blocks whose entries may still change, not the whole queue.
    /// 0: plan from the oldest.
    planned: usize,
    /// Entry speed² of the oldest block, fixed: the exit speed of the block
    /// the preparer took before it.
    carry_sqr: u32,
    /// Right shift of the speeds² kept: the fewest bits that hold the
    /// machine's top speed² in a `u32`.
    shift: u8,
    /// Target of the last move, steps.
    position: PerAxis<i32>,
    geometry: Geometry,
    jumps: AxisJumps,
    /// Direction of the last move, for the next junction: the pen's if
    /// `pen_last` is some, else in the axes' units.
    last: Option<[f32; AXES]>,
    /// The pen's limits where moves come as pieces; `None` on a machine
    /// whose kinematics are linear, whose path is the axes'.
    pen: Option<PenLimits>,
    pen_last: Option<PenLast>,
    /// Where the last piece with steps left the pen (a piece of no step
    /// is dropped: the next measures from here), and the joints' rounding
    /// at `position`.
    pen_at: Option<Position>,
    frac: Frac,
    /// The piece staged ([`Planner::stage_piece`]).
    pen_staged: PenMove,
    /// `None`: none (100 %). An `Option`, so that `EMPTY` is all zeros: a
    /// static of it then costs no initial image in flash.
    overrides: Option<Overrides>,
    stage: Stage,
}

impl<const N: usize> Lookahead<N> {
    /// A planner that moves nothing until [`Planner::configure`]: `const`, so
    /// the firmware's static holds it without building 1 KiB on the stack.
    pub const EMPTY: Self = Lookahead {
        blocks: [Block::EMPTY; N],
        head: 0,
        len: 0,
        planned: 0,
        carry_sqr: 0,
        shift: 0,
        position: [0; AXES],
        geometry: Geometry::EMPTY,
        jumps: AxisJumps::EMPTY,
        last: None,
        pen: None,
        pen_last: None,
        pen_at: None,
        frac: [0; AXES],
        pen_staged: PenMove::NONE,
        overrides: None,
        stage: Stage::Done,
    };

    /// Take the machine's figures, in place; drops queued moves and keeps
    /// the position. Only while idle.
    pub fn configure(&mut self, config: &MachineConfig) {
        self.head = 0;
        self.len = 0;
        self.planned = 0;
        self.carry_sqr = 0;
        self.geometry = Geometry::new(config);
        self.pen = PenLimits::of(config);
        let top = match &self.pen {
            Some(pen) => pen.max_speed_sqr().max(self.geometry.max_speed_sqr()),
            None => self.geometry.max_speed_sqr(),
        };
        self.shift = shift_for(top);
        self.jumps = AxisJumps::new(config);
        self.stage = Stage::Done;
        self.set_position(self.position);
    }

    pub fn new(config: &MachineConfig) -> Self {
        let mut p = Self::EMPTY;
        p.configure(config);
        p
    }

    /// Whether [`Planner::push`] would refuse for want of room.
    /// Moves queued, not yet taken.
    pub fn queued(&self) -> usize {
        self.len
    }

    /// Blocks a move may still be pushed into (`Bf:`): the queue's free
    /// slots, less the one a move being planned holds.
    pub fn free(&self) -> usize {
        N - self.len - (self.stage != Stage::Done) as usize
    }

    /// No room for a move: the queue is full, or a move is still being
    /// planned.
    pub fn is_full(&self) -> bool {
        self.len == N || self.stage != Stage::Done
    }

    /// Adds a move to the absolute step position `target`, planned whole.
    /// A move of no step is dropped.
    pub fn push(&mut self, target: PerAxis<i32>, feed: Feed) -> Result<(), Full> {
        self.stage(target, feed)?;
        while self.plan_part() {}
        Ok(())
    }

    /// [`Planner::push`] of a piece of a path ([`Planner::stage_piece`]).
    pub fn push_piece(&mut self, piece: &Piece, feed: Feed) -> Result<(), Full> {
        self.stage_piece(piece, feed)?;
        while self.plan_part() {}
        Ok(())
    }

    /// Records a piece of a path, its speeds along the pen where the
    /// machine's kinematics are not linear (else as [`Planner::stage`]):
    /// `feed` is then the pen's. The pen's path is measured from the last
    /// piece's end, or the path's start after the position was set; a
    /// piece of no step is dropped, and the next measures from where this
    /// one started.
    pub fn stage_piece(&mut self, piece: &Piece, feed: Feed) -> Result<(), Full> {
        if self.pen.is_none() {
            return self.stage(piece.steps, feed);
        }
        let from = self.pen_at.unwrap_or(piece.start);
        self.stage_steps(piece.steps, feed, PEN)?;
        if self.stage == Stage::Done {
            // No step: dropped.
            return Ok(());
        }
        self.pen_staged = PenMove {
            delta: core::array::from_fn(|i| piece.to[i].0.saturating_sub(from[i].0)),
            frac: [self.frac, piece.frac],
        };
        self.pen_at = Some(piece.to);
        self.frac = piece.frac;
        Ok(())
    }

    /// Records a move to the absolute step position `target`, to be
    /// planned by [`Planner::plan_part`]; the next move waits for it
    /// (`Full`). A move of no step is dropped.
    pub fn stage(&mut self, target: PerAxis<i32>, feed: Feed) -> Result<(), Full> {
        self.stage_steps(target, feed, 0)?;
        if self.stage != Stage::Done {
            // Moved off the pen's path: a piece after it starts afresh.
            self.pen_at = None;
            self.frac = [0; AXES];
        }
        Ok(())
    }

    /// [`Planner::stage`] with the flags `kind` ([`PEN`]).
    // Indexed: zipping the two arrays costs ~270 B of flash at `z`.
    #[allow(clippy::needless_range_loop)]
    fn stage_steps(&mut self, target: PerAxis<i32>, feed: Feed, kind: u8) -> Result<(), Full> {
        if self.is_full() {
            return Err(Full);
        }
        let mut step = Steps {
            steps: [0; AXES],
            dir: kind,
        };
        for i in 0..AXES {
            let delta = target[i] as i64 - self.position[i] as i64;
            step.steps[i] = delta.unsigned_abs() as u32;
            if delta > 0 {
                step.dir |= 1 << i;
            }
        }
        if step.steps.iter().all(|&n| n == 0) {
            return Ok(());
        }
        // Its other fields are all written by the parts before they are read.
        let slot = self.staged();
        self.blocks[slot].step = step;
        self.position = target;
        self.stage = Stage::Pushed(feed);
        Ok(())
    }

    /// A move staged is still being planned.
    pub fn is_planning(&self) -> bool {
        self.stage != Stage::Done
    }

    /// The slot of the move being planned: the one after the queue.
    fn staged(&self) -> usize {
        wrap::<N>(self.head + self.len)
    }

    /// One bounded part of planning the move [`Planner::stage`] recorded
    /// (each under ~0.9 ms on the AVR); false when there is none. Once
    /// the last is done the move is queued, and there is room again.
    pub fn plan_part(&mut self) -> bool {
        match self.stage {
            Stage::Done => return false,
            Stage::Pushed(feed) => self.plan_path(feed),
            Stage::Turned { ev_per_milli } => self.plan_junction(ev_per_milli),
            Stage::PenTurned {
                ev_per_milli,
                joint,
                len,
            } => self.plan_pen_joints(ev_per_milli, &PenLast { joint, len }),
            Stage::Path { ev_per_milli } => self.plan_limits(ev_per_milli),
            Stage::Limits => {
                self.len += 1;
                self.recalculate();
                self.stage = Stage::Done;
            }
        }
        true
    }

    /// The staged move's direction, the axes' jumps at the junction with
    /// the move before it and the speed asked (in events/s by
    /// `plan_limits`). Out of line, as each part: the parts are measured
    /// apart (`simavr/examples/task_runs.rs`).
    #[inline(never)]
    fn plan_path(&mut self, feed: Feed) {
        let b = &mut self.blocks[self.staged()];
        // Scaled to events/s by `plan_limits`: this part is the longer.
        b.feed_ev = match feed {
            Feed::Rapid => 0.0,
            // Never 0, which means a rapid.
            Feed::PerMinute(f) => f.0.max(1) as f32,
        };
        if b.step.is_pen() {
            return self.plan_pen_path();
        }
        let path = self.geometry.path(&b.step.block());
        // The axes' jumps now, the junction's roots in the next part: the
        // turn waits in `entry_sqr` and `delta_sqr`, which `plan_limits`
        // and `recalculate` write before anything reads them. After a
        // piece of the pen's path, whose direction is the pen's: from rest.
        let last = match self.pen_last.take() {
            None => self.last,
            Some(_) => None,
        };
        (b.junction_sqr, (b.entry_sqr, b.delta_sqr)) = match last {
            Some(prev) => (
                down(self.jumps.limit_sqr(&prev, &path.unit), self.shift),
                self.geometry.turn(&prev, &path.unit).pack(),
            ),
            None => (0, (0, 0)),
        };
        self.last = Some(path.unit);
        self.stage = Stage::Turned {
            ev_per_milli: path.ev_per_milli,
        };
    }

    /// [`Planner::plan_path`] of a piece: its direction and length along
    /// the pen, the joints' shares of the pen's speed, and the pen's turn
    /// at the junction with the piece before it.
    #[inline(never)]
    fn plan_pen_path(&mut self) {
        let slot = self.staged();
        let path: PenPath = self
            .geometry
            .pen_path(&self.blocks[slot].step.block(), &self.pen_staged);
        let b = &mut self.blocks[slot];
        // The turn waits in `entry_sqr` and `delta_sqr`, as a move's.
        (b.entry_sqr, b.delta_sqr) = match (self.last, self.pen_last, &self.pen) {
            (Some(prev), Some(_), Some(pen)) => {
                self.geometry.turn_pen(&prev, &path.unit, pen).pack()
            }
            _ => (0, 0),
        };
        self.last = Some(path.unit);
        self.stage = Stage::PenTurned {
            ev_per_milli: path.ev_per_milli,
            joint: path.joint,
            len: path.len,
        };
    }

    /// The joints' limits at a piece's junction with the piece before
    /// it: their jumps, and their acceleration where their shares of the
    /// pen's speed change (0: the first piece).
    #[inline(never)]
    fn plan_pen_joints(&mut self, ev_per_milli: f32, this: &PenLast) {
        let b = &mut self.blocks[self.staged()];
        b.junction_sqr = match (self.pen_last, &self.pen) {
            (Some(before), Some(pen)) => {
                // The junction low enough that the speed a piece reaches
                // between two junctions (at most (v₀² + v₁²)/2 + a·len)
                // stays within the joints' limits.
                let mean = 0.5 * (before.len + this.len);
                let joints =
                    self.geometry
                        .joints_sqr(&self.jumps, &before.joint, &this.joint, mean);
                // Shifted as the speeds² kept; saturating (∞: none, < 0: 0).
                let shift = f32::from_bits((127 - self.shift as u32) << 23);
                ((joints - pen.accel_len_sqr(this.len)) * shift) as u32
            }
            _ => 0,
        };
        self.pen_last = Some(*this);
        self.stage = Stage::Turned { ev_per_milli };
    }

    /// The staged move's junction speed: Grbl's, within the axes' jumps.
    /// Built for size: it is the shortest part.
    #[inline(never)]
    fn plan_junction(&mut self, ev_per_milli: f32) {
        let b = &mut self.blocks[self.staged()];
        // 0: the first move, or a jump that allows no speed.
        if b.junction_sqr != 0 {
            let turn = Turn::unpack((b.entry_sqr, b.delta_sqr));
            let speed_sqr = down(turn.speed_sqr(&self.geometry), self.shift);
            b.junction_sqr = b.junction_sqr.min(speed_sqr);
        }
        self.stage = Stage::Path { ev_per_milli };
    }

    /// The staged move's acceleration and cruise speed within the axes'
    /// limits, and how much its speed² can change over it.
    #[inline(never)]
    fn plan_limits(&mut self, ev_per_milli: f32) {
        let b = &mut self.blocks[self.staged()];
        let step = b.step.block();
        let (mut accel, mut rate) = self.geometry.limits(&step);
        if let (true, Some(pen)) = (b.step.is_pen(), &self.pen) {
            pen.cap(&mut accel, &mut rate, ev_per_milli);
        }
        let k2 = ev_per_milli * ev_per_milli;
        let overrides = self.overrides.unwrap_or(Overrides::NONE);
        b.feed_ev = b.feed_ev / 60.0 * ev_per_milli;
        b.accel = accel;
        b.nominal_sqr = down(
            overrides.nominal_sqr(b.feed_ev, rate, ev_per_milli),
            self.shift,
        );
        b.ev_per_milli_sqr = k2;
        let delta = ((2 * accel as u64 * step.events as u64) as f32 / k2) as u64;
        b.delta_sqr = down(delta, self.shift);
        self.stage = Stage::Limits;
    }

    /// No move is waiting for the preparer or being planned.
    pub fn is_idle(&self) -> bool {
        self.len == 0 && self.stage == Stage::Done
    }

    /// Target of the last move pushed, steps.
    pub fn position(&self) -> PerAxis<i32> {
        self.position
    }

    /// Redefines the position (`G92`, homing). Only when idle and stopped:
    /// the next move starts from standstill.
    pub fn set_position(&mut self, position: PerAxis<i32>) {
        self.position = position;
        self.last = None;
        self.pen_last = None;
        self.pen_at = None;
        self.frac = [0; AXES];
    }

    /// Hands the oldest block to the segment preparer. Its exit speed is
    /// what the look-ahead allows now; the next block's entry is fixed to it.
    pub fn take(&mut self) -> Option<Planned> {
        let t = self.take_speeds()?;
        Some(Planned {
            block: t.block,
            profile: Trapezoid::new(t.block.events, t.accel, &t.speeds),
            ev_per_milli_sqr: t.ev_per_milli_sqr,
        })
    }

    /// [`Planner::take`] without making the profile.
    pub fn take_speeds(&mut self) -> Option<Taken> {
        if self.len == 0 {
            return None;
        }
        let b = self.blocks[self.head];
        self.head = wrap::<N>(self.head + 1);
        self.len -= 1;
        // The next block's entry is fixed now: final, as those before it.
        self.planned = self.planned.saturating_sub(1);
        let exit_sqr = if self.len > 0 {
            self.blocks[self.head].entry_sqr
        } else {
            0
        };
        self.carry_sqr = exit_sqr;
        let k2 = times_pow2(b.ev_per_milli_sqr, self.shift);
        let to_events = |v: u32| (v as f32 * k2) as u64;
        Some(Taken {
            block: b.step.block(),
            accel: b.accel,
            speeds: Speeds {
                entry_sqr: to_events(b.entry_sqr),
                cruise_sqr: to_events(b.nominal_sqr),
                exit_sqr: to_events(exit_sqr),
            },
            ev_per_milli_sqr: b.ev_per_milli_sqr,
        })
    }

    /// The oldest block may enter at `path_sqr` at most, (milli-units/s)²:
    /// the block before it was held and can no longer leave faster.
    pub fn limit_entry(&mut self, path_sqr: u64) {
        self.carry_sqr = self.carry_sqr.min(down(path_sqr, self.shift));
        self.planned = 0;
        if self.len > 0 {
            self.recalculate();
        }
    }

    /// Drops every queued move (a stop that abandons them): the planner
    /// stands at `position`, the next move starts from rest.
    pub fn clear(&mut self, position: PerAxis<i32>) {
        self.head = 0;
        self.len = 0;
        self.planned = 0;
        self.carry_sqr = 0;
        self.stage = Stage::Done;
        self.set_position(position);
    }

    /// New overrides: the cruise speeds of the moves not yet taken, as
    /// Grbl's (the block being cut keeps its profile).
    /// Built for speed (also `recalculate`): the real-time task runs it for
    /// each override byte, and a move's planning waits for `recalculate`.
    #[cfg_attr(target_arch = "avr", optimize(speed))]
    pub fn set_overrides(&mut self, overrides: Overrides) {
        self.overrides = Some(overrides);
        for i in 0..self.len {
            let b = &mut self.blocks[wrap::<N>(self.head + i)];
            let (mut accel, mut rate) = self.geometry.limits(&b.step.block());
            let ev_per_milli = crate::fmath::sqrt(b.ev_per_milli_sqr);
            if let (true, Some(pen)) = (b.step.is_pen(), &self.pen) {
                pen.cap(&mut accel, &mut rate, ev_per_milli);
            }
            let nominal_sqr = overrides.nominal_sqr(b.feed_ev, rate, ev_per_milli);
            b.nominal_sqr = down(nominal_sqr, self.shift);
        }
        self.planned = 0;
        if self.len > 0 {
            self.recalculate();
        }
    }

    /// Grbl's passes over the blocks not yet final: backwards, each entry
    /// is at most what the junction and both cruise speeds allow and what
    /// still stops at the end of the queue; forwards, at most what the
    /// block before can reach from its entry. A block becomes final where
    /// it enters at its most, or at what the block before reaches: more
    /// blocks behind it only raise the backward pass's figures, so it
    /// keeps that entry, and so do those before it. Integer only; the ring
    /// stepped by hand (a `%` is a 16-bit division call on the AVR).
    fn recalculate(&mut self) {
        if self.len == 0 {
            return;
        }
        let mut i = wrap::<N>(self.head + self.len - 1);
        let mut nominal_sqr = self.blocks[i].nominal_sqr;
        let mut next_entry = 0u32;
        for _ in self.planned + 1..self.len {
            let prev = i.checked_sub(1).unwrap_or(N - 1);
            let prev_nominal_sqr = self.blocks[prev].nominal_sqr;
            let b = &mut self.blocks[i];
            let max_entry_sqr = b.junction_sqr.min(nominal_sqr).min(prev_nominal_sqr);
            b.entry_sqr = max_entry_sqr.min(next_entry.saturating_add(b.delta_sqr));
            next_entry = b.entry_sqr;
            nominal_sqr = prev_nominal_sqr;
            i = prev;
        }
        let mut i = wrap::<N>(self.head + self.planned);
        if self.planned == 0 {
            self.blocks[i].entry_sqr = self.carry_sqr;
        }
        let mut reach = self.blocks[i]
            .entry_sqr
            .saturating_add(self.blocks[i].delta_sqr);
        let mut nominal_sqr = self.blocks[i].nominal_sqr;
        for k in self.planned + 1..self.len {
            i = if i + 1 == N { 0 } else { i + 1 };
            let b = &mut self.blocks[i];
            if reach < b.entry_sqr {
                b.entry_sqr = reach;
                self.planned = k;
            } else if b.entry_sqr == b.junction_sqr.min(nominal_sqr).min(b.nominal_sqr) {
                self.planned = k;
            }
            reach = b.entry_sqr.saturating_add(b.delta_sqr);
            nominal_sqr = b.nominal_sqr;
        }
    }
}

/// The right shift that brings speeds² up to `max_sqr` into a `u32`.
fn shift_for(max_sqr: f32) -> u8 {
    let mut shift = 0;
    // `u32::MAX as f32` rounds up to 2³²: compare with 2³¹ and halve.
    let mut top = max_sqr * 0.5;
    while top >= (1u32 << 31) as f32 {
        top *= 0.5;
        shift += 1;
    }
    shift
}

/// `i` back in the ring of `N` slots, for `i` < 2·`N` (a slot plus a
/// count): a subtraction, where a `%` is a 16-bit division call on the
/// AVR (~200 cycles, several a move).
fn wrap<const N: usize>(i: usize) -> usize {
    if i >= N {
        i - N
    } else {
        i
    }
}

/// A speed² for the planner's fields: shifted, at most `u32::MAX` (a
/// straight junction's "no limit").
fn down(v: u64, shift: u8) -> u32 {
    (v >> shift).min(u32::MAX as u64) as u32
}

/// `x · 2^k` by its exponent (a multiply is ~1 000 cycles on the AVR); `x`
/// normal or zero, and no overflow: the events² of a planner speed².
fn times_pow2(x: f32, k: u8) -> f32 {
    match x == 0.0 {
        true => x,
        false => f32::from_bits(x.to_bits() + ((k as u32) << 23)),
    }
}
