//! Winding the pattern: every nail of `poradi.txt`, the last one included.
//!
//! The needle starts outside nail 0 (zero pose). Entry: half a nail round
//! to the gap after nail 0, needle in, back to nail 0's angle. Each wrap of
//! nail j: with the needle inside the ring, turn the shorter way to the
//! nearer gap beside j; needle out beyond j; turn across j to the gap on its
//! other side; needle back in. The needle crosses the ring of nails only
//! inside a gap, and turns only well inside the ring or beyond the nail it
//! wraps. Every target is absolute, from the nail index: no drift.

use super::{bit, MachineStep, INNER_MARGIN_MM, OUTER_MARGIN_MM};
use crate::axis::Axis;
use crate::config::MachineConfig;
use crate::geometry::{Board, StepScale};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WindError {
    /// A nail index past the board's last nail.
    BadNail(u16),
    /// The inner winding radius would reach the board's centre.
    BoardTooSmall,
    /// The nails beside this gap (named by the nail before it) stand too
    /// close for the needle to pass between them (blended winding).
    GapTooNarrow(u16),
}

/// Plans the moves of a winding: today's four single-axis moves a wrap
/// ([`Winder`]) or the blended path ([`super::BlendWinder`]).
pub trait Wraps {
    type Wrap: Iterator<Item = MachineStep>;
    /// Step `i` of the entry from the zero pose; `None` after the last.
    fn entry_step(&mut self, resume: Option<u16>, i: u8) -> Option<MachineStep>;
    fn wrap(&mut self, j: u16) -> Result<Self::Wrap, WindError>;
    fn finish(&self) -> MachineStep;
    /// The base's position after the moves planned so far.
    fn base(&self) -> i32;
    /// A step before the wrap's own, from base `from`: the first half of
    /// the rotation to a blended wrap.
    fn lead_in(&self, _from: i32, _wrap: &Self::Wrap) -> Option<MachineStep> {
        None
    }
}

impl Wraps for Winder {
    type Wrap = Wrap;
    fn entry_step(&mut self, resume: Option<u16>, i: u8) -> Option<MachineStep> {
        Winder::entry_step(self, resume, i)
    }
    fn wrap(&mut self, j: u16) -> Result<Wrap, WindError> {
        Winder::wrap(self, j)
    }
    fn finish(&self) -> MachineStep {
        Winder::finish(self)
    }
    fn base(&self) -> i32 {
        Winder::base(self)
    }
}

/// Plans the wraps one nail at a time, so the pattern can be streamed from
/// the card.
pub struct Winder {
    board: Board,
    scale: StepScale,
    /// Needle inside the ring, radial steps.
    inner: i32,
    base: i32,
}

/// The four moves that wrap one nail: base, radial, base, radial.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Wrap {
    targets: [i32; 4],
    next: u8,
    /// The gaps the needle goes out and comes back in through, as the
    /// nail each follows (`gap_after`).
    gaps: [u16; 2],
}

impl Wrap {
    /// Moves handed out so far (0 to 4).
    pub fn handed(&self) -> u8 {
        self.next
    }

    /// The gap the needle goes out through, and the one it comes back
    /// in through, each named by the nail before it.
    pub fn gaps(&self) -> [u16; 2] {
        self.gaps
    }

    /// The base's position once the wrap is done.
    pub fn end_base(&self) -> i32 {
        self.targets[2]
    }
}

impl Iterator for Wrap {
    type Item = MachineStep;

    fn next(&mut self) -> Option<MachineStep> {
        let i = self.next as usize;
        let target = *self.targets.get(i)?;
        self.next += 1;
        const AXES: [Axis; 4] = [Axis::Base, Axis::Radial, Axis::Base, Axis::Radial];
        Some(MachineStep::to(AXES[i], target))
    }
}

impl Winder {
    /// From the winding zero pose: nail 0 under the needle, needle at the
    /// board's edge.
    pub fn new(board: Board, config: &MachineConfig) -> Result<Self, WindError> {
        let inner_mm = board.min_nail_radius() - INNER_MARGIN_MM;
        if inner_mm <= 0.0 {
            return Err(WindError::BoardTooSmall);
        }
        let scale = StepScale::from_config(config);
        Ok(Winder {
            inner: scale.radial_steps(&board, inner_mm),
            board,
            scale,
            base: 0,
        })
    }

    /// Step `i` of the entry from the zero pose (needle outside the ring
    /// at the board's edge), made when needed rather than kept: a new
    /// job's (`resume: None`: half a nail round to the gap after nail 0,
    /// needle in, back to nail 0's angle), or after a power cut (`Some(g)`:
    /// to the gap after nail `g`, needle in through it; the wraps go on
    /// from there as they would have). The drill's driver goes off first.
    pub fn entry_step(&mut self, resume: Option<u16>, i: u8) -> Option<MachineStep> {
        let s = &self.scale;
        let gap = s.shorter_rotation(0, self.board.gap_after(resume.unwrap_or(0)));
        let last = match resume {
            Some(_) => gap,
            None => s.shorter_rotation(gap, self.board.nail(0).angle),
        };
        self.base = last;
        Some(match (i, resume) {
            (0, _) => MachineStep::Drivers {
                mask: bit(Axis::Drill),
                on: false,
            },
            (1, _) => MachineStep::to(Axis::Base, gap),
            (2, _) => MachineStep::to(Axis::Radial, self.inner),
            (3, None) => MachineStep::to(Axis::Base, last),
            _ => return None,
        })
    }

    /// The moves that wrap nail `j`.
    pub fn wrap(&mut self, j: u16) -> Result<Wrap, WindError> {
        let nails = self.board.nails();
        if j >= nails {
            return Err(WindError::BadNail(j));
        }
        let s = &self.scale;
        let before = s.shorter_rotation(self.base, self.board.gap_before(j));
        let after = s.shorter_rotation(self.base, self.board.gap_after(j));
        // Steps across nail j, from its gap before to its gap after.
        let span = (after - before).rem_euclid(s.steps_per_turn);
        let (g_before, g_after) = ((j + nails - 1) % nails, j);
        let (first, second, gaps) = if (before - self.base).abs() <= (after - self.base).abs() {
            (before, before + span, [g_before, g_after])
        } else {
            (after, after - span, [g_after, g_before])
        };
        let outer = s.radial_steps(&self.board, self.board.nail(j).radius + OUTER_MARGIN_MM);
        self.base = second;
        Ok(Wrap {
            targets: [first, outer, second, self.inner],
            next: 0,
            gaps,
        })
    }

    /// The base's position after the moves handed out so far.
    pub fn base(&self) -> i32 {
        self.base
    }

    /// All drivers off at the end of the job.
    pub fn finish(&self) -> MachineStep {
        MachineStep::Drivers {
            mask: super::MACHINE_DRIVERS,
            on: false,
        }
    }
}

/// The whole winding as one sequence: entry, a wrap per nail, drivers off.
pub struct Winding<I, W: Wraps = Winder> {
    winder: W,
    pattern: I,
    /// The entry's next step, until it has been handed out.
    entry: Option<u8>,
    wrap: Option<W::Wrap>,
    /// The step before the wrap's own ([`Wraps::lead_in`]).
    lead: Option<MachineStep>,
    finished: bool,
}

impl<I: Iterator<Item = u16>, W: Wraps> Winding<I, W> {
    pub fn new(winder: W, pattern: I) -> Self {
        Winding {
            winder,
            pattern,
            entry: Some(0),
            wrap: None,
            lead: None,
            finished: false,
        }
    }
}

impl<I: Iterator<Item = u16>, W: Wraps> Iterator for Winding<I, W> {
    type Item = Result<MachineStep, WindError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.finished {
            return None;
        }
        if let Some(i) = self.entry {
            match self.winder.entry_step(None, i) {
                Some(step) => {
                    self.entry = Some(i + 1);
                    return Some(Ok(step));
                }
                None => self.entry = None,
            }
        }
        loop {
            if let Some(step) = self.lead.take() {
                return Some(Ok(step));
            }
            if let Some(step) = self.wrap.as_mut().and_then(Iterator::next) {
                return Some(Ok(step));
            }
            let from = self.winder.base();
            match self.pattern.next() {
                Some(j) => match self.winder.wrap(j) {
                    Ok(w) => {
                        self.lead = self.winder.lead_in(from, &w);
                        self.wrap = Some(w);
                    }
                    Err(e) => {
                        self.finished = true;
                        return Some(Err(e));
                    }
                },
                None => {
                    self.finished = true;
                    return Some(Ok(self.winder.finish()));
                }
            }
        }
    }
}
