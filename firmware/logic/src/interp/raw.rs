//! Seed 003's raw-step line ([`crate::seed`]) as the executor takes it:
//! the pen first, then one move of the first two motor channels by their
//! steps from where the moves before end, planned as a `G0` of those
//! motors (each channel's `max_rate` and `accel`, the one with more steps
//! setting the pace: both finish together).

use super::{
    check_travel, coords, motor_channels, motor_only, motor_steps, pick, todo, Env, Interpreter,
    MachineIo, Path, Run,
};
use crate::gcode::ErrorKind;
use crate::kinematics::Kinematics;
use crate::planner::Feed;
use crate::seed::SeedMove;

/// Steps a raw move's end may miss when read back through the
/// kinematics (their floats) and still be one the machine reaches.
const REACH_STEPS: i32 = 2;

impl Interpreter {
    /// Checks a raw-step move and, if it passes, takes its actions: the
    /// programmed position becomes the move's end read through the
    /// kinematics. Refused (nothing changes) while a job owns the motion
    /// (`JobOwnsMotion`), when its end is outside a channel's soft limits
    /// (`TravelExceeded`, as a move to that point would be) or out of the
    /// machine's reach (`InvalidTarget`: a chain longer than both
    /// together, an arm past its length). Out of line, as
    /// [`Interpreter::accept`].
    #[inline(never)]
    pub fn accept_steps<K: Kinematics>(
        &mut self,
        mv: &SeedMove,
        env: &Env<K>,
        io: &mut impl MachineIo,
    ) -> Result<(), ErrorKind> {
        let (kin, cfg) = (env.kin, env.cfg);
        if !env.allowed.motion {
            return Err(ErrorKind::JobOwnsMotion);
        }
        let motors = motor_channels(cfg);
        // From where the moves end: the tiny ones joined (queued first,
        // `todo::FLUSH`) end at `run.from`.
        let mut steps = match self.join.is_some() {
            true => motor_steps(&self.run.from, motors, kin, cfg).unwrap_or_else(|_| io.steps()),
            false => io.steps(),
        };
        for (s, d) in steps.iter_mut().zip(mv.steps) {
            *s = s.saturating_add(i32::from(d));
        }
        let at = motor_only(&kin.forward(&steps), motors);
        let reached = kin.inverse(&at).is_ok_and(|back| {
            back.iter()
                .zip(&steps)
                .all(|(b, s)| b.abs_diff(*s) <= REACH_STEPS as u32)
        });
        if !reached {
            return Err(ErrorKind::InvalidTarget);
        }
        let end = pick(&self.position, &coords::exact(&at), motors);
        check_travel(cfg, &end, &end, motors)?;
        self.position = end;
        let plotter = !cfg.machine.is_string_art();
        self.run = Run {
            todo: if plotter { todo::PEN } else { 0 }
                | todo::PATH
                | if self.join.is_some() { todo::FLUSH } else { 0 },
            pen: match mv.pen_up {
                true => cfg.pen.up_deg,
                false => cfg.pen.down_deg,
            },
            feed: Feed::Rapid,
            path: Some(Path::Steps(steps)),
            from: self.run.from,
            ..Run::new()
        };
        if env.allowed.checking {
            self.run.todo = 0;
        }
        self.dwell_until = None;
        Ok(())
    }
}
