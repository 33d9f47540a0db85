//! Nail geometry of the string-art board (`docs/string-art.md`) and
//! its conversion to absolute step targets.
//!
//! Nail `i` of `N` sits at `f(i/N)·(R − 1.5 cm)`: on a circle (shape 0) or on
//! a regular n-gon with vertex 0 at angle 0 (shape n ≥ 3). Angles are in
//! radians, counter-clockwise, in [0, 2π); radii in mm. Every step target is
//! rounded once from an angle or radius computed from the nail index, so
//! thousands of wraps accumulate no error (38.4 steps per nail on 250 nails).
//!
//! f32 and the table-free `fmath` (no constant tables in the AVR's SRAM),
//! once per nail: on the AVR (simavr) a polygon nail costs two `sin_cos`
//! (≈ 41 000 cycles; libm's sinf/cosf pairs took 138 000), an `atan2`
//! (≈ 16 000) and a `sqrt` (≈ 3 200): ≈ 4 ms, small next to the second a
//! move takes.

use crate::config::MachineConfig;
use crate::fmath;
use crate::units::{div_round, Milli, StepsPerUnit};
use core::f32::consts::{PI, TAU};

/// Nails stand this far inside the board's edge, mm.
pub const NAIL_MARGIN_MM: f32 = 15.0;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BoardError {
    /// Shape 1 or 2: neither a circle nor a polygon.
    Shape,
    /// Fewer than 3 nails: no nail would have two distinct gaps.
    Nails,
    /// The board is no larger than the nail margin.
    Radius,
}

impl BoardError {
    pub const fn message(self) -> &'static str {
        match self {
            BoardError::Shape => "bad shape",
            BoardError::Nails => "too few nails",
            BoardError::Radius => "board too small",
        }
    }
}

/// Where a nail stands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nail {
    /// Radians, counter-clockwise from nail 0, in [0, 2π).
    pub angle: f32,
    /// Distance from the board's centre, mm.
    pub radius: f32,
}

/// The board as `param.txt` describes it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Board {
    shape: u16,
    nails: u16,
    /// Board radius R, mm.
    radius: f32,
}

impl Board {
    /// `shape`: 0 circle, n ≥ 3 regular n-gon; `radius`: R in µm.
    pub fn new(shape: u16, nails: u16, radius: Milli) -> Result<Board, BoardError> {
        if shape == 1 || shape == 2 {
            return Err(BoardError::Shape);
        }
        if nails < 3 {
            return Err(BoardError::Nails);
        }
        let radius = radius.0 as f32 / Milli::SCALE as f32;
        if radius <= NAIL_MARGIN_MM {
            return Err(BoardError::Radius);
        }
        Ok(Board {
            shape,
            nails,
            radius,
        })
    }

    pub fn nails(&self) -> u16 {
        self.nails
    }

    /// Board radius R, mm.
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// The radius the shape is scaled to: R − 1.5 cm.
    fn scale(&self) -> f32 {
        self.radius - NAIL_MARGIN_MM
    }

    /// Nail `i` (taken modulo the nail count; checking indices from the
    /// card is the caller's job).
    pub fn nail(&self, i: u16) -> Nail {
        let (i, n_nails) = (i as u32 % self.nails as u32, self.nails as u32);
        if self.shape == 0 {
            return Nail {
                angle: TAU * i as f32 / n_nails as f32,
                radius: self.scale(),
            };
        }
        // t = i/N; n·t = k + frac, split exactly in integers.
        let n = self.shape as u32;
        let k = n * i / n_nails;
        let frac = (n * i % n_nails) as f32 / n_nails as f32;
        let vertex = |k: u32| {
            let a = TAU * (k % n) as f32 / n as f32;
            let (sin, cos) = fmath::sin_cos(a);
            (cos, sin)
        };
        let (p, q) = (vertex(k), vertex(k + 1));
        let x = p.0 + frac * (q.0 - p.0);
        let y = p.1 + frac * (q.1 - p.1);
        Nail {
            angle: in_turn(fmath::atan2(y, x)),
            radius: fmath::sqrt(x * x + y * y) * self.scale(),
        }
    }

    /// The smallest radius of the nail ring: R − 1.5 cm for the circle,
    /// (R − 1.5 cm)·cos(π/n) at an n-gon's edge midpoints. No nail is
    /// nearer the centre.
    pub fn min_nail_radius(&self) -> f32 {
        if self.shape == 0 {
            self.scale()
        } else {
            self.scale() * fmath::sin_cos(PI / self.shape as f32).1
        }
    }

    /// Angle of the gap between nail `i` and nail `i + 1` (halfway between
    /// their angles, across the 0/2π seam after the last nail).
    pub fn gap_after(&self, i: u16) -> f32 {
        let i = i % self.nails;
        let a = self.nail(i).angle;
        let mut b = self.nail((i + 1) % self.nails).angle;
        if b <= a {
            b += TAU;
        }
        in_turn((a + b) / 2.0)
    }

    /// Angle of the gap between nail `i − 1` and nail `i`.
    pub fn gap_before(&self, i: u16) -> f32 {
        self.gap_after((i % self.nails + self.nails - 1) % self.nails)
    }
}

/// An angle brought into [0, 2π).
fn in_turn(a: f32) -> f32 {
    let a = if a < 0.0 { a + TAU } else { a };
    if a >= TAU {
        0.0
    } else {
        a
    }
}

/// Steps of the base and the radial carriage, for the board's geometry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StepScale {
    /// Base steps in one turn of the board (9600). A turn must be a whole
    /// number of steps for absolute angles to repeat exactly.
    pub steps_per_turn: i32,
    pub radial: StepsPerUnit,
}

impl StepScale {
    pub fn from_config(config: &MachineConfig) -> Self {
        let base = config.axes[0].steps_per_unit;
        StepScale {
            steps_per_turn: div_round(360 * base.num as i64, base.den as i64) as i32,
            radial: config.axes[1].steps_per_unit,
        }
    }

    /// Base step position of an angle within the first turn, [0, turn).
    pub fn base_steps(&self, angle: f32) -> i32 {
        let s = libm::roundf(angle / TAU * self.steps_per_turn as f32) as i32;
        s.rem_euclid(self.steps_per_turn)
    }

    /// The absolute position equivalent to `in_turn` (mod one turn) that is
    /// nearest `current`: the shorter rotation, never more than half a turn.
    pub fn nearest(&self, current: i32, in_turn: i32) -> i32 {
        let turn = self.steps_per_turn;
        let mut d = (in_turn - current).rem_euclid(turn);
        if d > turn / 2 {
            d -= turn;
        }
        current + d
    }

    /// Absolute base target of `angle` reached the shorter way from
    /// `current` (correct across the 0/2π seam).
    pub fn shorter_rotation(&self, current: i32, angle: f32) -> i32 {
        self.nearest(current, self.base_steps(angle))
    }

    /// Radial step position of a radius (mm). The carriage's zero has the
    /// tool at the board's edge R and positive is outwards, so radius r is
    /// at r − R.
    pub fn radial_steps(&self, board: &Board, radius: f32) -> i32 {
        libm::roundf((radius - board.radius) * self.radial.as_f32()) as i32
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const R: Milli = Milli(402_000); // the spec's 40.2 cm

    fn scale() -> StepScale {
        StepScale::from_config(&MachineConfig::STRING_ART)
    }

    fn deg(a: f32) -> f32 {
        a * 180.0 / PI
    }

    fn close(a: f32, b: f32, tol: f32) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn bad_boards_are_refused() {
        assert_eq!(Board::new(2, 250, R), Err(BoardError::Shape));
        assert_eq!(Board::new(0, 2, R), Err(BoardError::Nails));
        assert_eq!(Board::new(0, 250, Milli(15_000)), Err(BoardError::Radius));
        assert!(Board::new(3, 3, Milli(15_001)).is_ok());
    }

    #[test]
    fn spec_circle_250_nails() {
        let b = Board::new(0, 250, R).unwrap();
        assert_eq!(b.min_nail_radius(), 387.0);
        assert_eq!(
            b.nail(0),
            Nail {
                angle: 0.0,
                radius: 387.0
            }
        );
        assert!(close(deg(b.nail(1).angle), 1.44, 1e-4));
        assert!(close(deg(b.nail(125).angle), 180.0, 1e-4));
        assert!(close(deg(b.nail(249).angle), 358.56, 1e-4));
        let s = scale();
        assert_eq!(s.steps_per_turn, 9600);
        for i in 0..250u16 {
            let exact = div_round(9600 * i as i64, 250) as i32;
            assert_eq!(s.base_steps(b.nail(i).angle), exact, "nail {i}");
        }
    }

    #[test]
    fn square_by_hand() {
        let b = Board::new(4, 12, R).unwrap();
        // Nail 1: n·t = 1/3 along the edge (1,0)→(0,1): (2/3, 1/3),
        // angle atan(1/2) = 26.565°, radius √5/3 · 387 = 288.453 mm.
        let n = b.nail(1);
        assert!(
            close(deg(n.angle), 26.565_05, 1e-3) && close(n.radius, 288.452_8, 1e-3),
            "{n:?}"
        );
        assert_eq!(scale().base_steps(n.angle), 708);
        // Nail 3 is vertex 1: 90°, 387 mm.
        let v = b.nail(3);
        assert!(close(deg(v.angle), 90.0, 1e-4) && close(v.radius, 387.0, 1e-3));
        assert!(close(b.min_nail_radius(), 273.650_3, 1e-3));
    }

    #[test]
    fn hexagon_by_hand() {
        let b = Board::new(6, 24, R).unwrap();
        let s = scale();
        // (angle°, radius mm, base steps) from (0.875, 0.2165), the edge
        // midpoint (0.75, 0.4330), and their mirror images.
        let expect = [
            (1, 13.897_886, 348.837_1, 371),
            (2, 30.0, 335.151_8, 800),
            (5, 73.897_89, 348.837_1, 1971),
            (23, 346.102_1, 348.837_1, 9229),
        ];
        for (i, a, r, steps) in expect {
            let n = b.nail(i);
            assert!(
                close(deg(n.angle), a, 1e-3) && close(n.radius, r, 1e-3),
                "nail {i}: {n:?}"
            );
            assert_eq!(s.base_steps(n.angle), steps, "nail {i}");
        }
        // The smallest radius is reached, at the edge midpoints, and no
        // nail is nearer the centre.
        assert!(close(b.min_nail_radius(), 335.151_8, 1e-3));
        assert!((0..24).all(|i| b.nail(i).radius >= b.min_nail_radius() - 1e-3));
    }

    #[test]
    fn gaps_lie_between_neighbours_across_the_seam() {
        let b = Board::new(0, 250, R).unwrap();
        let step = TAU / 250.0;
        assert!(close(b.gap_after(0), step / 2.0, 1e-6));
        assert!(close(b.gap_after(249), TAU - step / 2.0, 1e-5));
        assert_eq!(b.gap_before(0), b.gap_after(249));
        let hex = Board::new(6, 24, R).unwrap();
        // Halfway between 13.898° and 30°.
        assert!(close(deg(hex.gap_before(2)), 21.948_94, 1e-3));
    }

    #[test]
    fn shorter_rotation_across_the_seam() {
        let s = scale();
        let b = Board::new(0, 250, R).unwrap();
        // Just short of a full turn, nail 1 (38 steps) is ahead, past 0.
        assert_eq!(s.shorter_rotation(9590, b.nail(1).angle), 9638);
        // Just past zero, nail 249 (9562 steps) is behind.
        assert_eq!(s.shorter_rotation(-10, b.nail(249).angle), -38);
        assert_eq!(s.shorter_rotation(10, b.nail(249).angle), -38);
        assert_eq!(s.shorter_rotation(5 * 9600 + 4000, 0.0), 5 * 9600);
        assert_eq!(s.shorter_rotation(5 * 9600 + 5000, 0.0), 6 * 9600);
    }

    #[test]
    fn nails_in_order_never_drift() {
        // 20 turns nail by nail: each position is 38.4·k rounded once.
        let (s, b) = (scale(), Board::new(0, 250, R).unwrap());
        let mut pos = 0;
        for k in 1..=5000i64 {
            pos = s.shorter_rotation(pos, b.nail((k % 250) as u16).angle);
            assert_eq!(pos as i64, div_round(9600 * k, 250), "after {k} nails");
        }
        assert_eq!(pos, 20 * 9600);
    }

    #[test]
    fn radial_positions() {
        let (s, b) = (scale(), Board::new(0, 250, R).unwrap());
        assert_eq!(s.radial_steps(&b, 387.0), -480); // 1.5 cm inside the edge
        assert_eq!(s.radial_steps(&b, 387.0 + 29.0), 448);
        assert_eq!(s.radial_steps(&b, 387.0 - 20.0), -1120);
    }

    proptest! {
        #[test]
        fn rotation_is_at_most_half_a_turn_and_lands_on_the_angle(cur in -1_000_000i32..1_000_000, a in 0.0f32..TAU) {
            let s = scale();
            let t = s.shorter_rotation(cur, a);
            prop_assert!((t - cur).abs() <= 4800);
            prop_assert_eq!(t.rem_euclid(9600), s.base_steps(a));
        }

        #[test]
        fn polygon_nails_lie_on_the_ring(shape in prop_oneof![Just(0u16), 3u16..12], n in 3u16..400, i in 0u16..400) {
            let b = Board::new(shape, n, R).unwrap();
            let nail = b.nail(i % n);
            prop_assert!((0.0..TAU).contains(&nail.angle));
            prop_assert!(nail.radius <= 387.001 && nail.radius >= b.min_nail_radius() - 0.001);
            // Nails go round in order: nail i+1 is ahead of nail i.
            let next = b.nail((i % n + 1) % n);
            let ahead = (next.angle - nail.angle).rem_euclid(TAU);
            prop_assert!(ahead > 0.0 && ahead < PI, "{} {:?} {:?}", i, nail, next);
            let gap = b.gap_after(i % n);
            prop_assert!(close((gap - nail.angle).rem_euclid(TAU), ahead / 2.0, 1e-4));
        }
    }
}
