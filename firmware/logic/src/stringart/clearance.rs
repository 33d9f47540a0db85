//! How close the needle may come to a nail, and where that leaves it free
//! to cross the ring of nails: the geometric constraint of blended winding.
//!
//! The needle's axis must stay at least `c` from every nail's axis, with
//! `c` = nail radius + needle radius + a margin (the thread it carries, a
//! nail leaning at half its height, the base's step of 0.25 mm at the
//! ring). A nail at radius r blocks the angles within α of its own, with
//! sin α = c / r: a ray at an angle outside that passes the nail at
//! r·sin α ≥ c, whatever its radius. Between two nails' blocked angles
//! lies the gap's *window*; at angles in no window (near a nail) the
//! needle must keep to radii outside r ± c. So the needle may be anywhere
//! inside `min radius − c` or, over nail j, outside `r_j + c`, and it
//! crosses the band between only at window angles.
//!
//! Windows are whole base steps, rounded inwards from the exact nail
//! angles: a needle standing on a window's edge step is still clear.

use crate::config::{MachineConfig, WindingConfig};
use crate::geometry::{Board, StepScale};
use core::f32::consts::TAU;

/// The thread beside the needle (0.3 mm), a nail leaning up to 0.5 mm at
/// the needle's height, and the base's step at the ring (0.25 mm at
/// 387 mm), rounded up, mm.
pub const CLEARANCE_MARGIN_MM: f32 = 1.5;

// The zero pose (radial 0, the needle at the board's edge) must be clear
// of the nails, which stand NAIL_MARGIN_MM inside it, whatever the
// diameters (the settings' range bounds them).
const _: () = assert!(
    WindingConfig::MAX_UM as f32 / 1000.0 + CLEARANCE_MARGIN_MM < crate::geometry::NAIL_MARGIN_MM
);

/// How far the needle's axis keeps from a nail's, from the nail and needle
/// diameters (`nail_diameter`, `needle_diameter`: by default a 1.8 mm
/// panel pin and a 1.5 mm hollow needle, 3.15 mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clearance {
    /// Centre to centre, needle to nail, at the least where the gaps allow
    /// it, mm.
    pub mm: f32,
    /// Centre to centre, needle touching a nail, mm.
    pub contact_mm: f32,
}

impl Clearance {
    pub fn of(config: &MachineConfig) -> Clearance {
        let w = &config.winding;
        let contact_mm = (f32::from(w.nail_um) + f32::from(w.needle_um)) / 2000.0;
        Clearance {
            mm: contact_mm + CLEARANCE_MARGIN_MM,
            contact_mm,
        }
    }

    /// Nail `i` as the window maths needs it: one `nail()` (trigonometry
    /// for a polygon's nail), a square root and a division.
    pub fn blocked(&self, board: &Board, scale: &StepScale, i: u16) -> Blocked {
        let nail = board.nail(i);
        let turn = scale.steps_per_turn as f32;
        // tan(asin x) ≥ asin x: a bound on α without an arcsine.
        let x = (self.mm / nail.radius).min(0.99);
        let alpha = x / crate::fmath::sqrt(1.0 - x * x);
        Blocked {
            at: nail.angle / TAU * turn,
            half: alpha / TAU * turn,
            radius: nail.radius,
        }
    }

    /// The window between nails `a` (below) and `b` (above), with `a.at`
    /// and `b.at` already in the same frame (`b.at > a.at`). Nails closer
    /// than the margin allows (dense boards: under ~6.3 mm apart with the
    /// default diameters) leave the gap's middle step, where the needle
    /// passes both by half the gap, as the four single-axis moves always
    /// crossed; `None`: not even the needle's own width passes between
    /// them.
    pub fn window(&self, a: &Blocked, b: &Blocked) -> Option<Window> {
        // The nails stay behind their references: LLVM would pass them
        // and the clearance by value instead, partly on the stack, where
        // the AVR backend read garbage for them at `opt-level = "z"`
        // (every window refused: "bad board"; inlining it costs 1.4 KB).
        let (a, b) = core::hint::black_box((a, b));
        let lo = libm::ceilf(a.at + a.half + EPS) as i32;
        let hi = libm::floorf(b.at - b.half - EPS) as i32;
        if lo <= hi {
            return Some(Window { lo, hi });
        }
        // α grows a little faster than c / r: scaling it down bounds the
        // angles the bare nail blocks from above.
        let bare = self.contact_mm / self.mm;
        let mid = libm::roundf((a.at + b.at) / 2.0);
        let clear = a.at + a.half * bare + EPS < mid && mid < b.at - b.half * bare - EPS;
        clear.then_some(Window {
            lo: mid as i32,
            hi: mid as i32,
        })
    }
}

/// A gap's window: the base positions (absolute steps, both included) at
/// which the needle may cross the ring.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Window {
    pub lo: i32,
    pub hi: i32,
}

/// Nail `i`'s exact position in base steps (fractional), and the half
/// width of the angles it blocks, steps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blocked {
    pub at: f32,
    pub half: f32,
    /// The nail's radius, mm.
    pub radius: f32,
}

/// Slack for f32 rounding when a blocked edge falls on a whole step.
const EPS: f32 = 0.01;

/// Nails `prev`, `j`, `next` around nail j, in nail j's turn: prev moved
/// below it and next above (across the 0/2π seam when they wrap), so the
/// windows come out as small numbers of the first turn.
pub fn around(mut n: [Blocked; 3], turn: i32) -> [Blocked; 3] {
    let turn = turn as f32;
    let wrap = |d: f32| if d <= 0.0 { d + turn } else { d };
    n[0].at = n[1].at - wrap(n[1].at - n[0].at);
    n[2].at = n[1].at + wrap(n[2].at - n[1].at);
    n
}

/// The whole turns to add to nail j's first-turn position `at` (steps) to
/// bring it nearest the base position `near`: integer, so no f32 loses
/// steps far from the base's zero.
pub fn turns_to(at: f32, near: i32, turn: i32) -> i32 {
    let at = libm::roundf(at) as i32;
    let d = near - at;
    (d + turn / 2).div_euclid(turn) * turn
}
