//! Blended winding: a wrap is one path around the nail, the base and the
//! carriage moving together, handed to the planner as one look-ahead run.
//!
//! Method. The path is a polyline in joint space (base steps, radial
//! steps); the planner never leaves a polyline — it only chooses speeds
//! along it (its blocks are Bresenham-exact straight lines between integer
//! vertices, and it does not cut corners) — so a constraint that holds for
//! every straight piece holds for every step the machine makes, by
//! construction, and a replay of the steps can check it.
//!
//! The constraint is [`super::clearance`]'s: the needle stays
//! [`Clearance`] from every nail. Each nail blocks the angles within α
//! of its own; between two nails lies a gap's *window* of whole base
//! steps where any radius is safe. Inside `inner` (the smallest nail
//! radius − c) the needle is clear of the nails at any angle, and over
//! nail j (at the angles it blocks) outside `outer` (the ring's largest
//! radius there + c). A wrap of nail j, approached from below (forwards):
//!
//! ```text
//!   A = (base clamped into the window before j, inner)   rotation, inside
//!   B = (that window's top, outer)     across the band inside the window
//!   C = (the window after j's bottom, outer)   over nail j, outside
//!   D = (that window's top, inner)     back across the band in the window
//! ```
//!
//! (mirrored when approached from above). A→B and C→D lie within one
//! window, so every step of them is at a window angle; B→C is at `outer`,
//! D→A′ (the rotation to the next nail) at `inner`. Consecutive wraps are
//! one polyline: the rotation to the next nail starts from D.
//!
//! Compared with the original's four single-axis moves to fixed radii
//! (20 mm inside the ring, 29 mm beyond the nail), the needle goes only
//! as far as the clearance needs, and each crossing of the band moves
//! both axes at once across the window. The speeds at the vertices come
//! from the planner (`planner::axis_jump`): every axis's share of a block's
//! speed and acceleration within its own limits, and at a vertex each
//! axis's velocity changes by at most the jump a start from rest makes.
//!
//! Cost on the AVR: per wrap, three nails (`Board::nail`, the polygon's
//! trigonometry), three square roots and divisions; nothing per block.

use super::clearance::{around, turns_to, Blocked, Clearance, Window};
use super::winding::{WindError, Wraps};
use super::{bit, MachineStep, MACHINE_DRIVERS};
use crate::axis::Axis;
use crate::config::MachineConfig;
use crate::geometry::{Board, StepScale};

/// Rounding of f32 radii to whole steps always away from the nails.
const EPS: f32 = 0.01;

/// Plans blended wraps one nail at a time (the pattern streams from the
/// card).
pub struct BlendWinder {
    board: Board,
    scale: StepScale,
    clearance: Clearance,
    /// Inside the band at every angle, radial steps.
    inner: i32,
    base: i32,
}

/// The four vertices that wrap one nail: (base, radial) steps.
///
/// The two moves along a circle before a crossing of the band — the
/// rotation to A ([`BlendWrap::half_turn`], handed out by the job before
/// the wrap) and B→C over the nail — go out in halves (when at least two
/// steps long): the checkpoint's record for the crossing is written while
/// the first half runs, and the second half is still in the planner when
/// it is durable, so the crossing blends in (`job::feed`). A half ends on
/// the circle, so the path is the same; and the first half's profile is
/// too, as the planner stops at the queue's end (from rest, the
/// triangle's peak or the cruise is reached by the middle).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BlendWrap {
    moves: [(i32, i32); 4],
    /// Pieces handed out: A, B, the half, C, D.
    next: u8,
    gaps: [u16; 2],
}

/// The middle of a move along a circle from base `from` to `to`, if it
/// has one (at least two steps: both halves move).
fn halfway(from: i32, to: i32) -> Option<i32> {
    ((to - from + 1) as u32 > 2).then_some((from + to) >> 1)
}

impl BlendWrap {
    /// Vertices (A, B, C, D) handed out so far (0 to 4).
    pub fn handed(&self) -> u8 {
        self.next - (self.next > 2) as u8
    }

    /// The first half of the rotation to A from base `from` (where the
    /// last wrap ended), if it has one.
    pub fn half_turn(&self, from: i32) -> Option<MachineStep> {
        let (a, radial) = self.moves[0];
        halfway(from, a).map(|b| to(b, radial))
    }

    /// The gap the needle goes out through, and the one it comes back in
    /// through, each named by the nail before it.
    pub fn gaps(&self) -> [u16; 2] {
        self.gaps
    }

    /// The base's position once the wrap is done.
    pub fn end_base(&self) -> i32 {
        self.moves[3].0
    }
}

impl Iterator for BlendWrap {
    type Item = MachineStep;

    fn next(&mut self) -> Option<MachineStep> {
        let mut i = self.next;
        if i == 2 {
            // Over the nail: its half first, if it has one.
            i = 3;
            let ((b, radial), (c, _)) = (self.moves[1], self.moves[2]);
            if let Some(half) = halfway(b, c) {
                self.next = 3;
                return Some(to(half, radial));
            }
        }
        let (base, radial) = *self.moves.get(i as usize - (i > 2) as usize)?;
        self.next = i + 1;
        Some(to(base, radial))
    }
}

/// Base and carriage together to `(base, radial)`.
fn to(base: i32, radial: i32) -> MachineStep {
    MachineStep::Move([Some(base), Some(radial), None])
}

impl Wraps for BlendWinder {
    type Wrap = BlendWrap;
    fn entry_step(&mut self, resume: Option<u16>, i: u8) -> Option<MachineStep> {
        BlendWinder::entry_step(self, resume, i)
    }
    fn wrap(&mut self, j: u16) -> Result<BlendWrap, WindError> {
        BlendWinder::wrap(self, j)
    }
    fn finish(&self) -> MachineStep {
        BlendWinder::finish(self)
    }
    fn base(&self) -> i32 {
        BlendWinder::base(self)
    }
    fn lead_in(&self, from: i32, wrap: &BlendWrap) -> Option<MachineStep> {
        wrap.half_turn(from)
    }
}

impl BlendWinder {
    /// From the winding zero pose: nail 0 under the needle, needle at the
    /// board's edge; every gap checked ([`BlendWinder::check_gaps`]).
    pub fn new(board: Board, config: &MachineConfig) -> Result<Self, WindError> {
        let w = BlendWinder::unchecked(board, config)?;
        w.check_gaps()?;
        Ok(w)
    }

    /// [`BlendWinder::new`] before its gaps are checked: a caller deep in
    /// the stack keeps the winder where it stays, then checks it there.
    #[inline(never)]
    pub fn unchecked(board: Board, config: &MachineConfig) -> Result<Self, WindError> {
        let clearance = Clearance::of(config);
        let inner_mm = board.min_nail_radius() - clearance.mm;
        if inner_mm <= 0.0 {
            return Err(WindError::BoardTooSmall);
        }
        let scale = StepScale::from_config(config);
        let inner = libm::floorf((inner_mm - board.radius()) * scale.radial.as_f32() - EPS);
        Ok(BlendWinder {
            board,
            scale,
            clearance,
            inner: inner as i32,
            base: 0,
        })
    }

    /// Every gap once, at reading time: a board too dense for the needle
    /// is refused before anything moves, and no wrap can fail for it
    /// later. Each nail is worked out once (a polygon's costs
    /// trigonometry): the job task's run stays well inside the step
    /// queue's 30 ms. Out of line: the deepest of the job's calls.
    #[inline(never)]
    pub fn check_gaps(&self) -> Result<(), WindError> {
        let (board, scale, clearance) = (&self.board, &self.scale, &self.clearance);
        let (n, turn) = (board.nails(), scale.steps_per_turn as f32);
        let first = clearance.blocked(board, scale, 0);
        let mut below = first;
        for g in 0..n {
            let mut above = match g + 1 {
                next if next < n => clearance.blocked(board, scale, next),
                _ => first,
            };
            if above.at <= below.at {
                above.at += turn;
            }
            (clearance.window(&below, &above)).ok_or(WindError::GapTooNarrow(g))?;
            below = above;
            if below.at >= turn {
                below.at -= turn;
            }
        }
        Ok(())
    }

    /// The window of the gap after nail `g`, in the turn nearest `near`
    /// (each was checked by [`BlendWinder::new`]).
    fn window_after(&self, g: u16, near: i32) -> Result<Window, WindError> {
        let n = self.board.nails();
        let (s, turn, c) = (&self.scale, self.scale.steps_per_turn, &self.clearance);
        let b = around(
            [g, (g + 1) % n, (g + 2) % n].map(|i| c.blocked(&self.board, s, i)),
            turn,
        );
        let w = c.window(&b[0], &b[1]).ok_or(WindError::GapTooNarrow(g))?;
        let k = turns_to((b[0].at + b[1].at) / 2.0, near, turn);
        Ok(Window {
            lo: w.lo + k,
            hi: w.hi + k,
        })
    }

    /// Step `i` of the entry from the zero pose (needle outside the ring
    /// at the board's edge): the drill's driver off, along the edge to
    /// the gap after nail 0 (after nail `g` when resuming after a power
    /// cut), then in across that gap's window. `None` after the last.
    pub fn entry_step(&mut self, resume: Option<u16>, i: u8) -> Option<MachineStep> {
        let w = self.window_after(resume.unwrap_or(0), 0).ok()?;
        let near = 0i32.clamp(w.lo, w.hi);
        let far = if near == w.lo { w.hi } else { w.lo };
        match i {
            0 => Some(MachineStep::Drivers {
                mask: bit(Axis::Drill),
                on: false,
            }),
            1 => Some(MachineStep::to(Axis::Base, near)),
            2 => {
                self.base = far;
                Some(to(far, self.inner))
            }
            _ => None,
        }
    }

    /// The vertices that wrap nail `j`, from the needle inside the ring at
    /// the base position of the last wrap's end.
    pub fn wrap(&mut self, j: u16) -> Result<BlendWrap, WindError> {
        let n = self.board.nails();
        if j >= n {
            return Err(WindError::BadNail(j));
        }
        // In two calls, the nails' trigonometry first: under the figures
        // of the wrap's frame, it made the job's deepest stack.
        let b = self.nails_around(j);
        self.wrap_between(j, &b)
    }

    /// Nails j − 1, j and j + 1 as [`around`] puts them.
    #[inline(never)]
    fn nails_around(&self, j: u16) -> [Blocked; 3] {
        let n = self.board.nails();
        let (s, c) = (&self.scale, &self.clearance);
        let b = [(j + n - 1) % n, j, (j + 1) % n].map(|i| c.blocked(&self.board, s, i));
        around(b, self.scale.steps_per_turn)
    }

    /// [`BlendWinder::wrap`] of nail `j`, `b` its [`nails_around`].
    ///
    /// [`nails_around`]: BlendWinder::nails_around
    #[inline(never)]
    fn wrap_between(&mut self, j: u16, b: &[Blocked; 3]) -> Result<BlendWrap, WindError> {
        let n = self.board.nails();
        let prev = (j + n - 1) % n;
        let (s, turn, c) = (&self.scale, self.scale.steps_per_turn, &self.clearance);
        let k = turns_to(b[1].at, self.base, turn);
        let shift = |w: Window| Window {
            lo: w.lo + k,
            hi: w.hi + k,
        };
        let before = shift(
            c.window(&b[0], &b[1])
                .ok_or(WindError::GapTooNarrow(prev))?,
        );
        let after = shift(c.window(&b[1], &b[2]).ok_or(WindError::GapTooNarrow(j))?);
        let top = ring_over(b) + c.mm;
        let outer = libm::ceilf((top - self.board.radius()) * s.radial.as_f32() + EPS) as i32;
        let inner = self.inner;
        // Nail j ahead: out through the window before it, forwards.
        let forwards = self.base <= (before.hi + after.lo).div_euclid(2);
        let (moves, gaps) = if forwards {
            let a = self.base.clamp(before.lo, before.hi);
            let m = [
                (a, inner),
                (before.hi, outer),
                (after.lo, outer),
                (after.hi, inner),
            ];
            (m, [prev, j])
        } else {
            let a = self.base.clamp(after.lo, after.hi);
            let m = [
                (a, inner),
                (after.lo, outer),
                (before.hi, outer),
                (before.lo, inner),
            ];
            (m, [j, prev])
        };
        self.base = moves[3].0;
        Ok(BlendWrap {
            moves,
            next: 0,
            gaps,
        })
    }

    pub fn board(&self) -> &Board {
        &self.board
    }

    pub fn scale(&self) -> &StepScale {
        &self.scale
    }

    /// The base's position after the moves handed out so far.
    pub fn base(&self) -> i32 {
        self.base
    }

    /// Inside the band at every angle, radial steps.
    pub fn inner(&self) -> i32 {
        self.inner
    }

    /// All drivers off at the end of the job.
    pub fn finish(&self) -> MachineStep {
        MachineStep::Drivers {
            mask: MACHINE_DRIVERS,
            on: false,
        }
    }
}

/// The ring's largest radius over the angles nail `b[1]` blocks, mm: the
/// ring runs straight from nail to nail, and a straight line's radius is
/// convex in the angle, so interpolating the nails' radii linearly in the
/// angle bounds it from above.
fn ring_over(b: &[Blocked; 3]) -> f32 {
    let j = &b[1];
    let side = |n: &Blocked| {
        let t = (j.half / (n.at - j.at).abs()).min(1.0);
        j.radius + (n.radius - j.radius).max(0.0) * t
    };
    side(&b[0]).max(side(&b[2]))
}

#[cfg(test)]
#[path = "blend/tests.rs"]
mod tests;
