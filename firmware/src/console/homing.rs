//! Homing (`$H`, and at power-on where `homing_at_start` says): the
//! logic crate's homing legs (`taut_logic::homing`) driven against the
//! planner, segment preparation and the switches, one leg at a time.

use super::Console;
use crate::endstop;
use crate::info;
use crate::motion::Motion;
use crate::queues::Signal;
use crate::reply;
use crate::rt::Poll;
use taut_logic::config::MachineConfig;
use taut_logic::homing::{self, Homing, HomingError, Leg, Next};
use taut_logic::planner::Feed;
use taut_logic::units::Milli;

/// Homing under way: its legs' state, whether a leg moves, and whether a
/// line asked (answered `ok` at the end).
pub struct HomingRun {
    homing: Homing,
    moving: bool,
    reply: bool,
}

/// How often homing looks whether a leg has ended, ms.
const LEG_POLL_MS: u16 = 10;

impl Console {
    /// Home `axes` (bits), their drivers on; `reply`: answer the line
    /// that asked at the end.
    pub fn start_homing(&mut self, axes: u8, m: &mut Motion, reply: bool) {
        m.drivers.wake(axes);
        self.homing = Some(HomingRun {
            homing: Homing::new(axes),
            moving: false,
            reply,
        });
    }

    /// The safety door while homing: stop at once, not homed (Grbl's alarm
    /// 7); the line that asked is answered `ok`, as Grbl's.
    pub fn abort_homing(&mut self, m: &mut Motion) {
        let Some(run) = self.homing.take() else {
            return;
        };
        endstop::disarm();
        m.stop_now();
        m.lose_position();
        self.resync_next_run(m);
        reply::alarm(7);
        if run.reply {
            self.ok();
        }
    }

    /// One step of homing: wait for the leg to end (done, or stopped at
    /// its switch), then the next leg, the zero, or the end. Out of line:
    /// the console's frame stays small.
    #[inline(never)]
    pub(super) fn home(&mut self, m: &mut Motion, cfg: &MachineConfig) -> Poll<Signal> {
        let Some(HomingRun {
            homing,
            moving,
            reply,
        }) = self.homing.as_mut()
        else {
            return Poll::Again;
        };
        // Looked at every 10 ms while a leg moves (the tick wakes it at
        // once when the switch stops the steps).
        if *moving && !endstop::hit() && !m.is_idle() {
            return Poll::After(LEG_POLL_MS);
        }
        let hit = endstop::disarm();
        if hit {
            // The steps stopped at the switch: drop the rest of the leg
            // (a stop of our own: homing goes on).
            m.stop_now();
            self.epoch = m.epoch();
        }
        *moving = false;
        match homing.next(cfg, hit, endstop::closed(homing.axis())) {
            Next::Move(leg) => {
                if leg.until_closed {
                    endstop::watch(leg.axis);
                }
                let to = homing::target(m.target(), &leg);
                // The machine stands: the planner has room.
                let _ = m.push(to, leg_feed(cfg, &leg));
                *moving = true;
                return Poll::After(LEG_POLL_MS);
            }
            Next::Zero { axis, steps } => {
                let mut at = m.target();
                at[axis] = steps;
                m.set_position(at);
            }
            Next::Done => {
                let reply = *reply;
                self.homing = None;
                self.resync_next_run(m);
                // Grbl runs the startup lines after a homing cycle.
                self.startup = super::system::STARTUP;
                match reply {
                    true => self.ok(),
                    false => info!("homed"),
                }
            }
            // Grbl's alarms 8 (the switch stayed closed after the pull-off)
            // and 9 (no switch within the travel); the line that asked is
            // then answered `ok`, as Grbl's. G-code waits for `$H` or `$X`.
            Next::Failed(e) => {
                let reply = *reply;
                self.homing = None;
                self.resync_next_run(m);
                m.lose_position();
                reply::alarm(match e {
                    HomingError::Stuck => 8,
                    HomingError::NotFound => 9,
                });
                if reply {
                    self.ok();
                }
            }
        }
        Poll::Again
    }
}

/// The feed that moves `leg`'s axis at its rate: units per minute.
fn leg_feed(cfg: &MachineConfig, leg: &Leg) -> Feed {
    let spu = cfg.axes[leg.axis].steps_per_unit;
    let milli_per_min =
        u64::from(leg.rate) * 60_000 * u64::from(spu.den) / u64::from(spu.num.max(1));
    Feed::PerMinute(Milli(milli_per_min.min(i32::MAX as u64) as i32))
}
