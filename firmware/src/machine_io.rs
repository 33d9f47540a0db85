//! The executor's machine (`taut_logic::interp::MachineIo`) on the board:
//! moves into segment preparation's planner, the pen servo, the drivers, the
//! clock, and the work coordinate data (the store's, kept in EEPROM).

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
        self.m.stage(*steps, feed).is_ok()
    }

    fn queue_piece(&mut self, piece: &Piece, feed: Feed) -> bool {
        self.m.stage_piece(piece, feed).is_ok()
    }

    fn idle(&mut self) -> bool {
        self.m.is_idle()
    }

    fn pen(&mut self, deg: u8) -> bool {
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
