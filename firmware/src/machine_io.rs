//! The executor's machine (`taut_logic::interp::MachineIo`) on the board:
//! moves into segment preparation's planner, the pen servo, the drivers, the
//! clock, and the work coordinate data (the store's, kept in EEPROM).
//!
//! A print resumed after a power cut goes over the blocks its checkpoint
//! says were drawn with the pen up, as rapids along the same path
//! ([`Trace`]), on along the block that was moving to where the motors
//! stood, and puts the pen down there.

use crate::board::clock;
use crate::motion::Motion;
use crate::store::Store;
use crate::{flash_str, reply};
use taut_logic::axis::AXES;
use taut_logic::config::PenConfig;
use taut_logic::coords::Slot;
use taut_logic::interp::{coords, Exact, MachineIo, Wait};
use taut_logic::kinematics::{Kinematics, Piece, Steps};
use taut_logic::planner::Feed;
use taut_logic::units::Decimal;
use ufmt::uwrite;

pub struct Io<'a, K: Kinematics> {
    pub m: &'a mut Motion,
    pub kin: &'a K,
    pub store: &'a mut Store,
    /// `M114` is answered (not from the card).
    pub replies: bool,
    /// A resumed print going over what it drew before the cut.
    pub trace: Option<Trace<'a>>,
}

/// Going over drawn blocks: `left - 2` more to queue (the pen stays up;
/// pen words until drawing again are passed over, the executor keeps the
/// pen's state); at 2, once the machine stands at the end of the
/// last, a rapid to where the checkpoint's motors stood (on the next
/// block's way); at 1, there, the pen to `pen_deg`; 0: drawing again,
/// the next block from that point.
pub struct Trace<'a> {
    pub left: &'a mut u16,
    pub pen_deg: u8,
    pub settle_ms: u16,
}

impl Trace<'_> {
    /// Blocks still to go over with the pen up.
    fn going_over(&self) -> bool {
        *self.left > 2
    }
}

/// Not drawing again yet: the pen is the trace's.
fn tracing(trace: &Option<Trace>) -> bool {
    trace.as_ref().is_some_and(|t| *t.left > 0)
}

/// A drawn block queued again with the pen up: a rapid along the same
/// path (the planner makes the same blocks, a move of no step none). Out
/// of line: off the path of a print that is not resuming.
#[inline(never)]
fn stage_over(m: &mut Motion, t: &mut Trace, steps: &Steps) -> bool {
    let queued = m.stage(*steps, Feed::Rapid).is_ok();
    *t.left -= (queued && m.staging()) as u16;
    queued
}

/// The drawn blocks are gone over: once the machine stands, a rapid to
/// where the checkpoint's motors stood, then the pen as the lines left
/// it, and its settle time. The checkpoint is the one resumed from: no
/// line read meanwhile is followed for records (`Print::line_ready`).
#[inline(never)]
fn pen_after_trace(m: &mut Motion, store: &Store, trace: &mut Option<Trace>) -> Option<Wait> {
    let t = trace.as_mut().filter(|t| *t.left <= 2 && *t.left > 0)?;
    if !m.is_idle() {
        return Some(Wait::PlannerRoom);
    }
    *t.left -= 1;
    if *t.left == 1 {
        if let Some(r) = store.plot_saved().and_then(|s| s.last) {
            let mut to = m.target();
            (to[0], to[1]) = (r.at[0], r.at[1]);
            let _ = m.stage(to, Feed::Rapid);
        }
        return Some(Wait::Again);
    }
    m.pen.set_pulse_us(PenConfig::pulse_us(t.pen_deg));
    Some(Wait::Ms(t.settle_ms))
}

impl<K: Kinematics> MachineIo for Io<'_, K> {
    fn coord(&self, index: u8) -> Exact {
        coords::stored(self.store.coords(), index)
    }

    /// In force at once, in EEPROM soon (two copies, cut-safe).
    fn set_coord(&mut self, index: u8, value: &Exact) {
        if let Some(slot) = Slot::at(index as usize) {
            self.store.set_coords(slot, coords::milli(value));
        }
    }

    fn room(&mut self, piece: bool) -> Option<Wait> {
        if let Some(wait) = pen_after_trace(self.m, self.store, &mut self.trace) {
            return Some(wait);
        }
        if !self.m.has_room() {
            return Some(Wait::PlannerRoom);
        }
        // A piece is not cut while the refill is filling the step queue
        // with pieces planned ahead: planning one takes a few ms, which
        // the refill needs first (with none ahead the planner would run
        // dry instead). It looks again once the queue is refilled.
        if piece && self.m.planned() >= 2 && self.m.refilling() {
            return Some(Wait::Refill);
        }
        None
    }

    fn steps(&self) -> Steps {
        self.m.target()
    }

    fn queue(&mut self, steps: &Steps, feed: Feed) -> bool {
        match self.trace.as_mut().filter(|t| t.going_over()) {
            Some(t) => stage_over(self.m, t, steps),
            None => self.m.stage(*steps, feed).is_ok(),
        }
    }

    fn queue_piece(&mut self, piece: &Piece, feed: Feed) -> bool {
        match self.trace.as_mut().filter(|t| t.going_over()) {
            Some(t) => stage_over(self.m, t, &piece.steps),
            None => self.m.stage_piece(piece, feed).is_ok(),
        }
    }

    fn idle(&mut self) -> bool {
        self.m.is_idle()
    }

    fn pen(&mut self, deg: u8) -> bool {
        if tracing(&self.trace) {
            return false;
        }
        let us = PenConfig::pulse_us(deg);
        let moves = self.m.pen.pulse_us() != us;
        self.m.pen.set_pulse_us(us);
        moves
    }

    fn drivers(&mut self, on: bool) {
        self.m.drivers.set(0xFF, on);
    }

    fn idle_delay(&mut self, ms: u32) {
        self.m.drivers.set_delay(ms);
    }

    fn pause(&mut self) {
        self.m.hold();
    }

    fn report_position(&mut self) {
        if self.replies {
            report_position(self.m, self.kin);
        }
    }

    fn program_end(&mut self) {
        let mut r = reply::line();
        let _ = uwrite!(r, "{}", flash_str!("[MSG:Pgm End]"));
        r.send();
    }

    fn millis(&self) -> u32 {
        clock::millis()
    }
}

/// `M114`: `C:1.000 X:0.000 Z:0.000 Count C:27 X:0 Z:0` (the executed
/// position, machine coordinates).
#[inline(never)]
pub fn report_position(m: &Motion, kin: &impl Kinematics) {
    let steps = m.stepper.position();
    let pos = kin.forward(&steps);
    let words = kin.words();
    let mut r = reply::line();
    for i in 0..AXES {
        let _ = uwrite!(r, "{}:{} ", words[i] as char, Decimal(pos[i].0, 3));
    }
    let _ = uwrite!(r, "{}", flash_str!("Count"));
    for i in 0..AXES {
        let _ = uwrite!(r, " {}:{}", words[i] as char, steps[i]);
    }
    r.send();
}
