//! The G-code interpreter, Grbl's `gc_execute_line`: the modal state
//! (distance mode, motion mode, feed rate, the commanded position) and what
//! a parsed [`Line`] asks of the machine.
//!
//! Pure and two-step: [`Interpreter::plan`] checks a line against the modal
//! state, the machine's figures and what the machine allows now, and
//! returns the [`Order`] with the modal state it leaves; the caller carries
//! the order out and only then [`Interpreter::commit`]s. So a line that
//! fails — or waits for planner room and is planned again — changes no
//! modal state: `G91 G1 X1` without a feed rate is refused and leaves the
//! interpreter in `G90`/`G0` as it was.

use crate::config::MachineConfig;
use crate::gcode::{AxisWord, Command, Distance, ErrorKind, Line, MIN_FEED};
use crate::kinematics::{Kinematics, Position, Steps};
use crate::planner::Feed;
use crate::units::Milli;

/// What a line asks of the machine.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Order {
    /// Nothing but modal state (`G91`, `F100`, a blank line).
    None,
    /// Move to these absolute motor steps.
    Move {
        steps: Steps,
        feed: Feed,
    },
    /// Wait this long once motion is done.
    Dwell {
        ms: u32,
    },
    /// Take these steps as the position (once motion is done).
    SetPosition {
        steps: Steps,
    },
    /// Switch every driver on or off (off once motion is done).
    Drivers {
        on: bool,
    },
    /// Answer once motion is done.
    WaitIdle,
    ReportPosition,
}

/// What the machine allows the console now.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Allowed {
    /// No job owns the motion: moves, drivers and `G92` may run.
    pub motion: bool,
    /// The position is known (not lost by a stop at once during motion).
    pub position_known: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Modal {
    distance: Distance,
    /// `G0` (else `G1`).
    rapid: bool,
    feed: Option<Milli>,
    /// Commanded position in milli-units (G-code coordinates).
    target: Position,
}

/// A line checked and ready to carry out, with the modal state it leaves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Planned {
    pub order: Order,
    next: Modal,
}

pub struct Interpreter {
    modal: Modal,
}

impl Default for Interpreter {
    fn default() -> Self {
        Self::new()
    }
}

impl Interpreter {
    /// Grbl's power-on state: `G90 G0`, no feed rate, at zero.
    pub const fn new() -> Self {
        Interpreter {
            modal: Modal {
                distance: Distance::Absolute,
                rapid: true,
                feed: None,
                target: [Milli::ZERO; crate::axis::AXES],
            },
        }
    }

    /// The commanded position.
    pub fn target(&self) -> Position {
        self.modal.target
    }

    /// The machine was moved or stopped by someone else (a job, a stop
    /// that dropped queued moves): it is commanded where it is.
    pub fn resync(&mut self, target: Position) {
        self.modal.target = target;
    }

    /// Ctrl-X: the modal state back to its power-on values; the position
    /// stays.
    pub fn reset(&mut self) {
        let target = self.modal.target;
        *self = Interpreter::new();
        self.modal.target = target;
    }

    /// Check `line` and work out its order; the modal state is unchanged
    /// until [`Interpreter::commit`].
    pub fn plan(
        &self,
        line: &Line,
        kin: &impl Kinematics,
        cfg: &MachineConfig,
        allowed: Allowed,
    ) -> Result<Planned, ErrorKind> {
        let mut next = self.modal;
        let has_axes = line.axes.iter().any(Option::is_some);
        let moves = has_axes
            || matches!(
                line.command,
                Command::EnableDrivers | Command::DisableDrivers | Command::SetPosition
            );
        if moves && !allowed.motion {
            return Err(ErrorKind::JobOwnsMotion);
        }
        if line.f.is_some_and(|f| f.0 < MIN_FEED) {
            return Err(ErrorKind::FeedTooLow);
        }
        if let Some(d) = line.distance {
            next.distance = d;
        }
        if line.f.is_some() {
            next.feed = line.f;
        }
        let order = match line.command {
            Command::Rapid | Command::Linear | Command::Empty => {
                if line.command != Command::Empty {
                    next.rapid = line.command == Command::Rapid;
                }
                if !has_axes {
                    return Ok(Planned {
                        order: Order::None,
                        next,
                    });
                }
                let feed = match (next.rapid, next.feed) {
                    (true, _) => Feed::Rapid,
                    (false, Some(f)) => Feed::PerMinute(f),
                    (false, None) => return Err(ErrorKind::UndefinedFeedRate),
                };
                if !allowed.position_known {
                    return Err(ErrorKind::Locked);
                }
                next.target = self.destination(line, kin, next.distance);
                let outside = cfg.axes.iter().zip(&next.target).any(|(a, t)| {
                    let (min, max) = a.travel;
                    a.soft_limits && (*t < min || *t > max)
                });
                if outside {
                    return Err(ErrorKind::TravelExceeded);
                }
                // Converted once from the absolute target: relative moves
                // never drift.
                let steps = kin
                    .inverse(&next.target)
                    .map_err(|_| ErrorKind::InvalidTarget)?;
                Order::Move { steps, feed }
            }
            Command::Dwell => Order::Dwell {
                ms: line.p.map_or(0, |p| p.0.max(0) as u32),
            },
            Command::SetPosition => {
                for (i, w) in kin.words().iter().enumerate() {
                    if let Some(v) = value(line, *w) {
                        next.target[i] = v;
                    }
                }
                let steps = kin
                    .inverse(&next.target)
                    .map_err(|_| ErrorKind::InvalidTarget)?;
                Order::SetPosition { steps }
            }
            Command::EnableDrivers => Order::Drivers { on: true },
            Command::DisableDrivers => Order::Drivers { on: false },
            Command::WaitIdle => Order::WaitIdle,
            Command::ReportPosition => Order::ReportPosition,
        };
        Ok(Planned { order, next })
    }

    /// The order of `planned` was carried out: take the modal state it
    /// leaves.
    pub fn commit(&mut self, planned: Planned) {
        self.modal = planned.next;
    }

    /// Where the axis words of `line` take the commanded position.
    fn destination(&self, line: &Line, kin: &impl Kinematics, distance: Distance) -> Position {
        let mut target = self.modal.target;
        for (i, w) in kin.words().iter().enumerate() {
            if let Some(v) = value(line, *w) {
                target[i] = match distance {
                    Distance::Absolute => v,
                    Distance::Relative => Milli(target[i].0.saturating_add(v.0)),
                };
            }
        }
        target
    }
}

/// The value of the axis word named `letter`, if the line has one.
fn value(line: &Line, letter: u8) -> Option<Milli> {
    AxisWord::ALL
        .iter()
        .find(|w| w.letter() == letter)
        .and_then(|w| line.axis(*w))
}

#[cfg(test)]
mod tests;
