//! The ring of nails in the base's step units: its radius at any angle
//! (the circle of a round board, the polygon through the nails of a
//! polygonal one), which gap an angle lies in, and which nails a rotation
//! passes.

use std::f64::consts::TAU;
use taut_logic::geometry::{Board, NAIL_MARGIN_MM};

/// A nail where the board's geometry puts it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Nail {
    /// Radians, CCW, [0, 2π).
    angle: f64,
    /// In base steps, fractional: `angle / 2π · steps_per_turn`.
    steps: f64,
    x: f64,
    y: f64,
}

#[derive(Clone, Debug)]
pub struct Ring {
    nails: Vec<Nail>,
    /// `Some(r)` for a round board: the ring is that circle.
    circle: Option<f64>,
    steps_per_turn: i64,
}

impl Ring {
    /// A polygonal board is told from a round one by its smallest nail
    /// radius, which only a polygon has below `R − 1.5 cm`.
    pub fn new(board: &Board, steps_per_turn: i32) -> Ring {
        let turn = f64::from(steps_per_turn);
        let nails = (0..board.nails())
            .map(|i| {
                let n = board.nail(i);
                let (angle, r) = (f64::from(n.angle), f64::from(n.radius));
                Nail {
                    angle,
                    steps: angle / TAU * turn,
                    x: r * angle.cos(),
                    y: r * angle.sin(),
                }
            })
            .collect();
        let scale = board.radius() - NAIL_MARGIN_MM;
        let round = board.min_nail_radius() >= scale - 1e-4 * scale;
        Ring {
            nails,
            circle: round.then_some(f64::from(scale)),
            steps_per_turn: i64::from(steps_per_turn),
        }
    }

    pub fn nails(&self) -> u16 {
        self.nails.len() as u16
    }

    /// Nail `i`'s position on the board, mm (x towards nail 0's angle, CCW).
    pub fn nail_xy(&self, i: u16) -> (f64, f64) {
        let n = &self.nails[usize::from(i)];
        (n.x, n.y)
    }

    /// Nail `i`'s angle in base steps (fractional, [0, steps_per_turn)).
    pub fn nail_steps(&self, i: u16) -> f64 {
        self.nails[usize::from(i)].steps
    }

    pub fn steps_per_turn(&self) -> i64 {
        self.steps_per_turn
    }

    /// The angle, [0, 2π), of a base position in steps.
    pub fn angle(&self, base: i64) -> f64 {
        base.rem_euclid(self.steps_per_turn) as f64 / self.steps_per_turn as f64 * TAU
    }

    /// The index of the nail at or before `angle` ([0, 2π)).
    fn nail_before(&self, angle: f64) -> usize {
        match self.nails.partition_point(|n| n.angle <= angle) {
            0 => self.nails.len() - 1,
            k => k - 1,
        }
    }

    /// The ring's distance from the centre at `angle` (radians), mm.
    pub fn radius_at(&self, angle: f64) -> f64 {
        if let Some(r) = self.circle {
            return r;
        }
        let angle = angle.rem_euclid(TAU);
        let i = self.nail_before(angle);
        let (p, q) = (&self.nails[i], &self.nails[(i + 1) % self.nails.len()]);
        // The ray at `angle` meets the segment p–q at t·u: t = (p × d)/(u × d).
        let (ux, uy) = (angle.cos(), angle.sin());
        let (dx, dy) = (q.x - p.x, q.y - p.y);
        (p.x * dy - p.y * dx) / (ux * dy - uy * dx)
    }

    /// `Some(i)` when base position `base` lies in the gap after nail `i`:
    /// strictly between nail i and nail i+1, more than one base step from
    /// either; `None` at (within a step of) a nail.
    pub fn gap_at(&self, base: i64) -> Option<u16> {
        let turn = self.steps_per_turn as f64;
        let s = base.rem_euclid(self.steps_per_turn) as f64;
        // 1e-3: a nail whose angle is a whole step (in f32) counts as on it.
        let near = |n: &Nail| {
            let d = (s - n.steps).rem_euclid(turn);
            d.min(turn - d) <= 1.0 + 1e-3
        };
        if self.nails.iter().any(near) {
            return None;
        }
        Some(self.nail_before(self.angle(base)) as u16)
    }

    /// The nails whose angle lies strictly between base positions `from`
    /// and `to` on the rotation from one to the other, in the order passed
    /// (a rotation of more than a turn passes nails more than once).
    pub fn nails_between(&self, from: i64, to: i64) -> Vec<u16> {
        let turn = self.steps_per_turn as f64;
        let (lo, hi) = (from.min(to) as f64, from.max(to) as f64);
        let mut passed: Vec<(f64, u16)> = Vec::new();
        let first_turn = (lo / turn).floor() as i64;
        let last_turn = (hi / turn).floor() as i64;
        for k in first_turn..=last_turn {
            for (i, n) in self.nails.iter().enumerate() {
                let at = n.steps + k as f64 * turn;
                if lo < at && at < hi {
                    passed.push((at, i as u16));
                }
            }
        }
        passed.sort_by(|a, b| a.0.total_cmp(&b.0));
        if to < from {
            passed.reverse();
        }
        passed.into_iter().map(|(_, i)| i).collect()
    }
}
