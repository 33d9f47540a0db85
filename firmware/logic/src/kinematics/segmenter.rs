//! Cuts a straight move into pieces no longer than `segment_len` for
//! kinematics that are not linear (Marlin's and Klipper's approach). Each
//! piece's endpoint is interpolated from the absolute start and end in
//! integers and converted by the inverse from scratch, so no error piles up
//! from piece to piece; the last piece ends exactly on the target. Each
//! piece's end goes through the kinematics' inverse where it is queued.

use super::{Frac, Kinematics, Position, Steps};
use crate::axis::AXES;
use crate::segment::isqrt;
use crate::units::{div_round, Milli};

/// One piece of a path on a machine whose kinematics are not linear: the
/// pen's straight move (machine coordinates) and the motors' target. The
/// planner measures its speeds along `from → to`, the pen's path, and
/// keeps each motor within its own limits over `steps`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Piece {
    pub from: Position,
    pub to: Position,
    /// The inverse of `to`, and what its rounding took off.
    pub steps: Steps,
    pub frac: Frac,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Segmenter {
    from: Position,
    delta: [i64; AXES],
    pieces: u32,
    done: u32,
}

impl Segmenter {
    /// `segment_len` in thousandths of the unit (µm); a linear kinematics
    /// gets a single piece. The length counts every coordinate.
    pub fn new(kin: &impl Kinematics, from: Position, to: &Position, segment_len: u32) -> Self {
        let delta: [i64; AXES] = core::array::from_fn(|i| to[i].0 as i64 - from[i].0 as i64);
        let pieces = if kin.is_linear() {
            1
        } else {
            // Rounded up, so no piece is longer than asked.
            let len2: u64 = delta.iter().map(|d| (d * d) as u64).sum();
            let root = isqrt(len2);
            let len = if root * root < len2 { root + 1 } else { root };
            let seg = segment_len.max(1) as u64;
            len.div_ceil(seg).clamp(1, u32::MAX as u64) as u32
        };
        Segmenter {
            from,
            delta,
            pieces,
            done: 0,
        }
    }

    pub fn pieces(&self) -> u32 {
        self.pieces
    }

    pub fn start(&self) -> Position {
        self.from
    }

    pub fn end(&self) -> Position {
        core::array::from_fn(|i| Milli(self.from[i].0 + self.delta[i] as i32))
    }

    /// Where the next piece starts: the last piece's end.
    pub fn at(&self) -> Position {
        self.point(self.done)
    }

    /// The end of piece `k` (0: the start).
    fn point(&self, k: u32) -> Position {
        let (k, n) = (k as i64, self.pieces as i64);
        core::array::from_fn(|i| Milli(self.from[i].0 + div_round(self.delta[i] * k, n) as i32))
    }
}

impl Iterator for Segmenter {
    type Item = Position;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done == self.pieces {
            return None;
        }
        self.done += 1;
        Some(self.point(self.done))
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = (self.pieces - self.done) as usize;
        (left, Some(left))
    }
}

#[cfg(test)]
mod tests {
    use super::super::{ChannelScale, Linear, Polargraph};
    use super::*;
    use crate::config::MachineConfig;
    use crate::units::StepsPerUnit;
    use proptest::prelude::*;

    fn polargraph() -> Polargraph {
        let s = StepsPerUnit::new(50, 1);
        let g = super::super::polargraph::tests::geometry(1_200_000, [600_000, -600_000]);
        Polargraph::new(&ChannelScale([s; AXES]), &g).unwrap()
    }

    fn pos(x: i32, y: i32) -> Position {
        [Milli(x), Milli(y), Milli(0)]
    }

    #[test]
    fn linear_kinematics_take_one_piece() {
        let k = Linear::cylindrical(&MachineConfig::STRING_ART);
        let to = [Milli(90_000), Milli(-5000), Milli(0)];
        let mut s = Segmenter::new(&k, pos(0, 0), &to, 1000);
        assert_eq!(s.next().map(|p| k.inverse(&p)), Some(Ok([2400, -160, 0])));
        assert_eq!(s.next(), None);
    }

    #[test]
    fn pieces_no_longer_than_asked() {
        let k = polargraph();
        // 3-4-5: 50 mm in 1 mm pieces is exactly 50; 50.001 mm needs 51.
        assert_eq!(
            Segmenter::new(&k, pos(0, 0), &pos(30_000, 40_000), 1000).pieces(),
            50
        );
        assert_eq!(
            Segmenter::new(&k, pos(0, 0), &pos(30_000, 40_001), 1000).pieces(),
            51
        );
        assert_eq!(Segmenter::new(&k, pos(5, 5), &pos(5, 5), 1000).count(), 1);
    }

    /// A machine's kinematics with 1000 times its steps: a joint's
    /// rounding then moves the pen by well under a µm.
    fn fine(machine: crate::machine::Machine) -> super::super::AnyKinematics {
        let mut cfg = MachineConfig::defaults(machine);
        for a in &mut cfg.axes {
            a.steps_per_unit.num *= 1000;
        }
        super::super::AnyKinematics::of(&cfg).unwrap()
    }

    /// How far the pen strays from a piece `a → b` (µm) while the joints
    /// run straight from one end's steps to the other's: at its middle.
    fn stray(k: &impl Kinematics, a: &Position, b: &Position) -> f64 {
        let (sa, sb) = (k.inverse(a).unwrap(), k.inverse(b).unwrap());
        let mid = k.forward(&core::array::from_fn(|i| (sa[i] + sb[i]) / 2));
        let (dx, dy) = ((b[0].0 - a[0].0) as f64, (b[1].0 - a[1].0) as f64);
        let (mx, my) = ((mid[0].0 - a[0].0) as f64, (mid[1].0 - a[1].0) as f64);
        (mx * dy - my * dx).abs() / dx.hypot(dy)
    }

    proptest! {
        /// What the kinematics' `piece_um` promise: a whiteboard piece
        /// strays under 10 µm anywhere on the board, an arm's under 30 µm
        /// within 60–250 mm of the shoulder (under 0.1 mm further out,
        /// the arm near straight).
        #[test]
        fn pieces_stray_from_the_line_by_far_less_than_a_step(
            x in -500_000i32..500_000, y in -500_000i32..300_000,
            r in 60_000i32..250_000, b in -1.5f32..1.5, angle in 0.0f32..6.283,
        ) {
            use crate::machine::Machine;
            let k = fine(Machine::Whiteboard);
            let len = k.piece_um() as f32;
            let step = |x: i32, y: i32| pos(
                x + libm::roundf(len * libm::cosf(angle)) as i32,
                y + libm::roundf(len * libm::sinf(angle)) as i32,
            );
            prop_assert!(stray(&k, &pos(x, y), &step(x, y)) < 10.0);
            let k = fine(Machine::Scara);
            let len = k.piece_um() as f32;
            let (x, y) = (100_000 - (r as f32 * libm::sinf(b)) as i32, -56_000 + (r as f32 * libm::cosf(b)) as i32);
            let to = pos(
                x + libm::roundf(len * libm::cosf(angle)) as i32,
                y + libm::roundf(len * libm::sinf(angle)) as i32,
            );
            prop_assert!(stray(&k, &pos(x, y), &to) < 30.0);
        }

        /// Every piece endpoint lies on the straight line (within a step of
        /// it, after the round trip) and the last is exactly the target's.
        #[test]
        fn pieces_follow_the_line(x0 in -500_000i32..500_000, y0 in -400_000i32..300_000, x1 in -500_000i32..500_000, y1 in -400_000i32..300_000, seg in 500u32..20_000) {
            let k = polargraph();
            let (a, b) = (pos(x0, y0), pos(x1, y1));
            let s = Segmenter::new(&k, a, &b, seg);
            let n = s.pieces();
            let mut last = None;
            for (i, piece) in s.enumerate() {
                let steps = k.inverse(&piece).unwrap();
                let p = k.forward(&steps);
                let t = (i + 1) as f64 / n as f64;
                let ideal = [x0 as f64 + t * (x1 - x0) as f64, y0 as f64 + t * (y1 - y0) as f64];
                let err = ((p[0].0 as f64 - ideal[0]).powi(2) + (p[1].0 as f64 - ideal[1]).powi(2)).sqrt();
                prop_assert!(err <= 26.0, "piece {} of {}: {:?} vs {:?}", i, n, p, ideal);
                last = Some(steps);
            }
            prop_assert_eq!(last, Some(k.inverse(&b).unwrap()));
            let len = (((x1 - x0) as f64).powi(2) + ((y1 - y0) as f64).powi(2)).sqrt();
            prop_assert!(len / n as f64 <= seg as f64);
        }
    }
}
