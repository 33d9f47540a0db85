//! Carrying out an accepted line's actions (Grbl's step 4 in order):
//! each waits where Grbl's `protocol_buffer_synchronize` or a full
//! planner would, and goes on at the next call.

use super::{
    motor_channels, motor_milli, motor_only, motor_steps, todo, Env, Exact, Interpreter, MachineIo,
    Path, Progress, Wait,
};
use crate::axis::AXES;
use crate::kinematics::{Kinematics, Piece, Position, Segmenter};
use crate::planner::Feed;
use crate::units::Milli;

impl Interpreter {
    /// Carry out what is left of the accepted line, as far as the
    /// machine lets it now. Never inlined: a path's piece is worked out
    /// in its frame, off the caller's.
    #[inline(never)]
    pub fn run<K: Kinematics>(&mut self, env: &Env<K>, io: &mut impl MachineIo) -> Progress {
        loop {
            let todo = self.run.todo;
            // The first action left, lowest bit first.
            let next = todo & todo.wrapping_neg();
            if next == 0 {
                return Progress::Done;
            }
            let waits = match next {
                todo::FLUSH => self.flush(env, io),
                todo::PEN => self.pen(self.run.pen, env, io),
                todo::PEN_Z => self.pen(self.run.pen_z, env, io),
                todo::DRIVERS_ON => {
                    io.drivers(true);
                    None
                }
                todo::DWELL => self
                    .after_motion(io)
                    .or_else(|| self.wait_ms(self.run.dwell_ms, io)),
                todo::LEG_0 | todo::LEG_1 => self.leg(next == todo::LEG_1, env, io),
                todo::PATH => self.piece(env, io),
                todo::PAUSE => self.after_motion(io).or_else(|| {
                    io.pause();
                    None
                }),
                todo::END => self.after_motion(io).or_else(|| {
                    // M5: a plotter's pen goes up; then Grbl's message.
                    let up = env.cfg.pen.up_deg;
                    let pen = match env.cfg.machine.is_string_art() {
                        true => None,
                        false => self.pen(up, env, io),
                    };
                    if pen.is_none() {
                        io.program_end();
                    }
                    pen
                }),
                todo::DRIVERS_OFF => self.after_motion(io).or_else(|| {
                    io.drivers(false);
                    None
                }),
                todo::WAIT => self.after_motion(io),
                todo::IDLE_DELAY => {
                    io.idle_delay(self.run.idle_delay_ms);
                    None
                }
                _ => {
                    io.report_position();
                    None
                }
            };
            if let Some(wait) = waits {
                return Progress::Wait(wait);
            }
            // Done: an action that takes its own bit off (a leg that became
            // a path) has already.
            self.run.todo &= !next;
        }
    }

    /// Waits for the motion before to end.
    fn after_motion(&self, io: &mut impl MachineIo) -> Option<Wait> {
        match io.idle() {
            true => None,
            false => Some(Wait::PlannerRoom),
        }
    }

    /// Waits `ms` from the first call.
    fn wait_ms(&mut self, ms: u32, io: &mut impl MachineIo) -> Option<Wait> {
        let now = io.millis();
        let until = *self.dwell_until.get_or_insert(now.wrapping_add(ms));
        let left = until.wrapping_sub(now) as i32;
        if left > 0 {
            return Some(Wait::Ms(left.min(u16::MAX as i32) as u16));
        }
        self.dwell_until = None;
        None
    }

    /// The pen to `deg` once the motion before is done, then its settle
    /// time if it moved.
    fn pen<K: Kinematics>(
        &mut self,
        deg: u8,
        env: &Env<K>,
        io: &mut impl MachineIo,
    ) -> Option<Wait> {
        if self.dwell_until.is_none() {
            if let Some(wait) = self.after_motion(io) {
                return Some(wait);
            }
            if !io.pen(deg) {
                return None;
            }
        }
        self.wait_ms(u32::from(env.cfg.pen.settle_ms), io)
    }

    /// A straight leg: one move on a linear machine, from the exact
    /// target; on the others, pieces no longer than the kinematics'
    /// `piece_um` (then the leg's bit is off and the path's on). A tiny
    /// one may join the moves around it instead ([`super::join`]).
    fn leg<K: Kinematics>(
        &mut self,
        second: bool,
        env: &Env<K>,
        io: &mut impl MachineIo,
    ) -> Option<Wait> {
        // A line that did not join the moves before: they are queued, it
        // may start a join of its own.
        if self.run.opens && self.open_join(env) {
            return None;
        }
        let to = self.run.legs[second as usize];
        if !env.kin.is_linear() {
            self.line_path(second, env);
            // Its pieces next, from this same call.
            return self.piece(env, io);
        }
        let waits = self.queue_move(&[Milli::ZERO; AXES], &to, self.run.feed, env, io);
        if waits.is_none() {
            self.run.from = to;
        }
        waits
    }

    /// One straight move to `to`: on a linear machine its steps, rounded
    /// once from the exact target; on the others one piece from `start`
    /// (µm), the pen's. Out of line: the piece is built in its frame.
    #[inline(never)]
    pub(super) fn queue_move<K: Kinematics>(
        &self,
        start: &Position,
        to: &Exact,
        feed: Feed,
        env: &Env<K>,
        io: &mut impl MachineIo,
    ) -> Option<Wait> {
        let motors = motor_channels(env.cfg);
        let linear = env.kin.is_linear();
        if let Some(wait) = io.room(!linear) {
            return Some(wait);
        }
        // Every target was checked when its line was accepted.
        let queued = match linear {
            true => {
                let steps = motor_steps(to, motors, env.kin, env.cfg).unwrap_or_default();
                io.queue(&steps, feed)
            }
            false => {
                let to = motor_milli(to, motors);
                match env.kin.inverse_fine(&to) {
                    Ok((steps, frac)) => io.queue_piece(
                        &Piece {
                            start: *start,
                            to,
                            steps,
                            frac,
                        },
                        feed,
                    ),
                    Err(_) => true,
                }
            }
        };
        (!queued).then_some(Wait::PlannerRoom)
    }

    /// A straight leg as a path of pieces: the leg's bit off, the path's
    /// on. Out of line: the path is built in this frame (~160 B), not in
    /// the one under which its pieces are worked out.
    #[inline(never)]
    fn line_path<K: Kinematics>(&mut self, second: bool, env: &Env<K>) {
        let to = self.run.legs[second as usize];
        let motors = motor_channels(env.cfg);
        let from = motor_milli(&self.run.from, motors);
        let end = motor_milli(&to, motors);
        let line = Segmenter::new(env.kin, from, &end, env.kin.piece_um());
        self.run.path = Some(Path::Line(line));
        self.run.from = to;
        let bit = if second { todo::LEG_1 } else { todo::LEG_0 };
        self.run.todo = self.run.todo & !bit | todo::PATH;
    }

    /// The path's next piece; `None` once its last is queued. On a
    /// machine whose kinematics are not linear the piece goes to the
    /// planner as the pen's ([`MachineIo::queue_piece`]): `F` is the
    /// pen's speed along the path.
    fn piece<K: Kinematics>(&mut self, env: &Env<K>, io: &mut impl MachineIo) -> Option<Wait> {
        let path = self.run.path.as_mut()?;
        if let Some(wait) = io.room(true) {
            return Some(wait);
        }
        let before = *path;
        if let Path::Steps(steps) = before {
            if !io.queue(&steps, self.run.feed) {
                return Some(Wait::PlannerRoom);
            }
            self.run.path = None;
            return None;
        }
        let motors = motor_channels(env.cfg);
        let queued = if env.kin.is_linear() {
            let Some(end) = path.next() else {
                self.run.path = None;
                return None;
            };
            // An arc's last chord ends on the exact target (the steps
            // from it, rounded once).
            let steps = match matches!(path, Path::Arc(a) if a.remaining() == 0) {
                true => motor_steps(&self.run.legs[0], motors, env.kin, env.cfg),
                false => env
                    .kin
                    .inverse(&motor_only(&end, motors))
                    .map_err(|_| crate::gcode::ErrorKind::InvalidTarget),
            };
            io.queue(&steps.unwrap_or_default(), self.run.feed)
        } else {
            match path.next_piece(env.kin, motors) {
                None => {
                    self.run.path = None;
                    return None;
                }
                Some(Ok(piece)) => io.queue_piece(&piece, self.run.feed),
                // Every piece was checked when the line was accepted.
                Some(Err(_)) => true,
            }
        };
        if !queued {
            self.run.path = Some(before);
            return Some(Wait::PlannerRoom);
        }
        // The next piece in a run of its own: working one out takes up
        // to ms on the arm.
        Some(Wait::Again)
    }
}
