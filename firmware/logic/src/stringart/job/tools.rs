//! The operator's tools (serial `$` lines), refused while the
//! job moves:
//!
//! | line | when | what |
//! | --- | --- | --- |
//! | `$wrap_test=<nail>` | waiting for nails, zeroed | the four-move wrap around one nail from the zero pose and back (in through the gap before it, out through the gap after it): clearances checked before a job |
//! | `$wrap_step=1` | paused while winding | one wrap more, then paused again |
//! | `$wrap_step=-1` | paused while winding | one wrap back: the last wrap counted undone, wound again on green (a `$wrap_jump` to it) |
//! | `$wrap_jump=<k>` | paused while winding | go on at wrap k+1 (k wraps counted done): the pattern is read on from there, the needle goes there from inside the ring (the safe path), the checkpoint says so |
//! | `$drift=<nail>` | paused while winding, waiting for nails | the base to that nail's angle, the count of base steps said against the nail's, and back |

use super::{Action, Job, Msg, Out, State};
use crate::axis::Axis;
use crate::checkpoint::Record;
use crate::stringart::Phase;
use crate::stringart::{bit, BlendWrap, MachineStep, Save};

/// A tool asked for on the console.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tool {
    WrapTest(u16),
    Step,
    /// One wrap back: a jump to the wrap before the next.
    Back,
    Jump(u32),
    Drift(u16),
}

/// A tool line that cannot be taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ToolError {
    /// The value is not a number this tool takes.
    BadValue,
}

/// The tool a `$key=value` line names; `None`: not a tool (a setting).
pub fn parse(key: &str, value: &str) -> Option<Result<Tool, ToolError>> {
    let number = || {
        value
            .trim_start_matches('+')
            .parse::<u32>()
            .map_err(|_| ToolError::BadValue)
    };
    let nail = || number().and_then(|n| u16::try_from(n).map_err(|_| ToolError::BadValue));
    // The names in flash: string constants would sit in the AVR's SRAM.
    let is = |name: taut_progmem::Text| name.eq_ignore_ascii_case(key.as_bytes());
    use taut_progmem::text;
    Some(if is(text!("wrap_test")) {
        nail().map(Tool::WrapTest)
    } else if is(text!("wrap_step")) {
        match value.trim_start_matches('+').as_bytes() {
            [b'1'] => Ok(Tool::Step),
            [b'-', b'1'] => Ok(Tool::Back),
            _ => Err(ToolError::BadValue),
        }
    } else if is(text!("wrap_jump")) {
        number().map(Tool::Jump)
    } else if is(text!("drift")) {
        nail().map(Tool::Drift)
    } else {
        return None;
    })
}

/// A tool under way: its steps are handed out by [`Job::next_step`].
#[derive(Clone, Debug)]
pub(super) enum Run {
    /// Step `i` of the wrap test on nail `k`.
    WrapTest {
        k: u16,
        i: u8,
        wrap: Option<BlendWrap>,
    },
    /// To the nail's angle (`there`), said, then back (`back`).
    Drift {
        nail: u16,
        there: i32,
        back: i32,
        i: u8,
    },
    /// The jump's record.
    Jump(Option<Record>),
}

impl Job {
    pub(in crate::stringart::job) fn tool(&mut self, t: Tool, o: &mut Out, now_ms: u32) {
        if self.state.is_running() || self.moving || self.run.is_some() {
            return o.log(Msg::ToolMoving);
        }
        let Some(plan) = &self.plan else {
            return o.log(Msg::ToolNotNow);
        };
        let (nails, count) = (plan.board().nails(), plan.count);
        let winding_paused = self.state == State::Paused(Phase::Winding) && !self.lost;
        let waiting = self.state == State::WaitingForNails && self.loose == 0;
        let t = match t {
            Tool::Back if winding_paused => match self.steps.as_ref().map_or(0, |s| s.done) {
                0 => return o.log(Msg::ToolRange),
                done => Tool::Jump(done - 1),
            },
            t => t,
        };
        let run = match t {
            Tool::WrapTest(k) | Tool::Drift(k) if k >= nails => {
                return o.log(Msg::ToolRange);
            }
            Tool::Jump(k) if k > count => return o.log(Msg::ToolRange),
            Tool::WrapTest(k) if waiting => Run::WrapTest {
                k,
                i: 0,
                wrap: None,
            },
            Tool::Drift(nail) if waiting || winding_paused => {
                let back = self.steps.as_ref().map_or(0, |s| s.base(&plan.winder));
                let scale = plan.scale();
                let there = scale.shorter_rotation(back, plan.board().nail(nail).angle);
                Run::Drift {
                    nail,
                    there,
                    back,
                    i: 0,
                }
            }
            Tool::Step if winding_paused => {
                self.step_once = 1;
                return self.confirm(o, now_ms);
            }
            Tool::Jump(k) if winding_paused => {
                let Some(steps) = &mut self.steps else { return };
                let record = steps.jump(k);
                self.open_pattern(k, o);
                Run::Jump(record)
            }
            _ => return o.log(Msg::ToolNotNow),
        };
        self.run = Some(run);
        if matches!(t, Tool::WrapTest(_)) {
            o.drivers(bit(Axis::Base) | bit(Axis::Radial), true);
        }
        self.next_moves(o);
    }

    /// The tool's next step; `None` at the end of its batch.
    pub(in crate::stringart::job) fn tool_step(&mut self) -> Option<MachineStep> {
        let plan = self.plan.as_mut()?;
        match self.run.as_mut()? {
            Run::WrapTest { k, i, wrap } => {
                let nails = plan.board().nails();
                let winder = &mut plan.winder;
                let step = match *i {
                    // In through the gap before nail k, from the zero pose.
                    0..=2 => winder.entry_step(Some((*k + nails - 1) % nails), *i),
                    3 => {
                        let w = wrap.get_or_insert_with(|| winder.wrap(*k).expect("in range"));
                        if let Some(step) = w.next() {
                            return Some(step);
                        }
                        Some(MachineStep::to(Axis::Radial, 0))
                    }
                    // Out at the board's edge (above), and back to nail 0.
                    4 => {
                        let at = wrap.as_ref().map_or(0, |w| w.end_base());
                        let (scale, board) = (winder.scale(), winder.board());
                        let home = scale.shorter_rotation(at, board.nail(0).angle);
                        Some(MachineStep::to(Axis::Base, home))
                    }
                    _ => None,
                };
                *i += 1;
                step
            }
            Run::Drift { there, back, i, .. } => {
                let target = match *i {
                    0 => *there,
                    2 => *back,
                    _ => return None,
                };
                *i += 1;
                Some(MachineStep::to(Axis::Base, target))
            }
            Run::Jump(record) => record.take().map(|r| MachineStep::Save(Save::Record(r))),
        }
    }

    /// The tool's batch is done: its report, its next batch or its end.
    pub(in crate::stringart::job) fn tool_done(&mut self, o: &mut Out) {
        match &mut self.run {
            Some(Run::Drift { nail, there, i, .. }) if *i == 1 => {
                o.push(Action::Drift {
                    nail: *nail,
                    expected: *there,
                });
                *i = 2;
                self.next_moves(o);
            }
            Some(run) => {
                let msg = match run {
                    Run::WrapTest { .. } => Msg::WrapTested,
                    Run::Drift { .. } => Msg::DriftChecked,
                    Run::Jump(_) => Msg::Jumped,
                };
                self.run = None;
                o.log(msg);
                let state = self.state;
                self.enter(state, o);
            }
            None => {}
        }
    }
}
