//! Homing (`G28`, `$H`, the flatbed's start-up), Grbl's cycle, one axis
//! after the other: seek the MIN switch fast, pull off, locate it slowly,
//! pull off again; the axis then stands at its travel's start plus the
//! pull-off. The firmware carries out each [`Leg`]: a move of one axis
//! that stops at once when its switch closes, if asked to.

use crate::axis::{PerAxis, AXES};
use crate::config::MachineConfig;

/// A move of one axis, `steps` from where it stands, at `rate` steps/s;
/// with `until_closed` it stops at once when its switch closes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Leg {
    pub axis: usize,
    pub steps: i32,
    pub rate: u16,
    pub until_closed: bool,
}

/// Why homing stopped short: the axis is then not homed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HomingError {
    /// The switch never closed over the whole travel and more.
    NotFound,
    /// The switch stayed closed after the pull-off.
    Stuck,
}

/// What to do next.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Next {
    Move(Leg),
    /// Take `steps` as this axis's position (it stands pulled off).
    Zero {
        axis: usize,
        steps: i32,
    },
    Done,
    Failed(HomingError),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage {
    Seek,
    Release,
    Locate,
    PullOff,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Homing {
    /// Axes still to home (bits).
    left: u8,
    axis: usize,
    stage: Option<Stage>,
}

impl Homing {
    pub fn new(axes: u8) -> Homing {
        Homing {
            left: axes & ((1 << AXES) - 1),
            axis: 0,
            stage: None,
        }
    }

    /// The axis being homed.
    pub fn axis(&self) -> usize {
        self.axis
    }

    /// The next step, once the last leg ended: `hit` says whether its
    /// switch closed and stopped it, `closed` whether the switch is closed
    /// now.
    pub fn next(&mut self, cfg: &MachineConfig, hit: bool, closed: bool) -> Next {
        let h = &cfg.homing;
        let a = &cfg.axes[self.axis];
        let mm = |um: i32| a.steps_per_unit.steps(crate::units::Milli(um));
        let pull_off = mm(i32::from(h.pull_off_um)).max(1);
        let leg = |steps, rate, until_closed| {
            Next::Move(Leg {
                axis: self.axis,
                steps,
                rate,
                until_closed,
            })
        };
        match self.stage {
            None => {
                if self.left == 0 {
                    return Next::Done;
                }
                self.axis = self.left.trailing_zeros() as usize;
                self.stage = Some(Stage::Seek);
                let a = &cfg.axes[self.axis];
                // Past the whole travel (or 200 units when it has none).
                let span = match a.travel.1 .0 - a.travel.0 .0 {
                    0 => 200_000,
                    span => span,
                };
                let far = a.steps_per_unit.steps(crate::units::Milli(span));
                Next::Move(Leg {
                    axis: self.axis,
                    steps: -(far / 2 * 3),
                    rate: h.seek,
                    until_closed: true,
                })
            }
            Some(Stage::Seek) if !hit => self.fail(HomingError::NotFound),
            Some(Stage::Seek) => {
                self.stage = Some(Stage::Release);
                leg(pull_off, h.locate, false)
            }
            Some(Stage::Release) if closed => self.fail(HomingError::Stuck),
            Some(Stage::Release) => {
                self.stage = Some(Stage::Locate);
                leg(-2 * pull_off, h.locate, true)
            }
            Some(Stage::Locate) if !hit => self.fail(HomingError::NotFound),
            Some(Stage::Locate) => {
                self.stage = Some(Stage::PullOff);
                leg(pull_off, h.locate, false)
            }
            Some(Stage::PullOff) if closed => self.fail(HomingError::Stuck),
            Some(Stage::PullOff) => {
                let steps = mm(a.travel.0 .0.saturating_add(i32::from(h.pull_off_um)));
                self.left &= !(1 << self.axis);
                self.stage = None;
                Next::Zero {
                    axis: self.axis,
                    steps,
                }
            }
        }
    }

    fn fail(&mut self, e: HomingError) -> Next {
        self.left = 0;
        self.stage = None;
        Next::Failed(e)
    }
}

/// `steps` from `from` on `leg`'s axis only.
pub fn target(from: PerAxis<i32>, leg: &Leg) -> PerAxis<i32> {
    let mut to = from;
    to[leg.axis] = to[leg.axis].saturating_add(leg.steps);
    to
}

#[cfg(test)]
mod tests;
