//! Cuts a straight move into pieces no longer than `segment_len` for
//! kinematics that are not linear (Marlin's and Klipper's approach). Each
//! piece's endpoint is interpolated from the absolute start and end in
//! integers — `from + round(delta·k / n)`, kept as a whole and a remainder
//! that each piece adds to, so no division per piece (three 64-bit ones
//! were ~9 000 cycles of a piece's run on the AVR) — and converted by the
//! inverse from scratch, so no error piles up from piece to piece; the
//! last piece ends exactly on the target. Each piece's end goes through
//! the kinematics' inverse where it is queued.

use super::{Frac, Kinematics, Position, Steps};
use crate::axis::AXES;
use crate::segment::isqrt;
use crate::units::Milli;

/// One piece of a path on a machine whose kinematics are not linear: the
/// pen's straight move (machine coordinates) and the motors' target. The
/// planner measures its speeds along the pen's path, from the last
/// piece's end to `to`, and keeps each motor within its own limits over
/// `steps`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Piece {
    /// Where the path began: the first piece's start (a piece's own is
    /// the last one's end, which the planner keeps).
    pub start: Position,
    pub to: Position,
    /// The inverse of `to`, and what its rounding took off.
    pub steps: Steps,
    pub frac: Frac,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Segmenter {
    from: Position,
    to: Position,
    share: [Share; AXES],
    /// Bit `i`: coordinate `i` decreases.
    down: u8,
    pieces: u32,
    done: u32,
}

/// One coordinate's way along the line: |delta| = step·n + rest, and
/// after `k` pieces |delta|·k = whole·n + part (part < n).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Share {
    step: u32,
    rest: u32,
    whole: u32,
    part: u32,
}

impl Segmenter {
    /// `segment_len` in thousandths of the unit (µm); a linear kinematics
    /// gets a single piece. The length counts every coordinate.
    pub fn new(kin: &impl Kinematics, from: Position, to: &Position, segment_len: u32) -> Self {
        let delta: [i64; AXES] = core::array::from_fn(|i| to[i].0 as i64 - from[i].0 as i64);
        let pieces: u32 = match kin.is_linear() {
            true => 1,
            false => pieces(&delta, segment_len),
        };
        let mut down = 0;
        let share = core::array::from_fn(|i| {
            down |= ((delta[i] < 0) as u8) << i;
            // Two i32s differ by less than 2³²: 32-bit divisions.
            let d = delta[i].unsigned_abs() as u32;
            // One piece (every line of a stream of tiny ones): no
            // division (~600 cycles each on the AVR).
            let (step, rest) = match pieces {
                1 => (d, 0),
                n => (d / n, d % n),
            };
            Share {
                step,
                rest,
                whole: 0,
                part: 0,
            }
        });
        Segmenter {
            from,
            to: *to,
            share,
            down,
            pieces,
            done: 0,
        }
    }

    pub fn pieces(&self) -> u32 {
        self.pieces
    }

    /// Whether the move from `from` to `to` is plainly one piece of at
    /// most `segment_len` µm (as [`pieces`] finds without its root): a
    /// line of a stream of tiny ones, which then needs no segmenter.
    pub fn is_one_piece(from: &Position, to: &Position, segment_len: u32) -> bool {
        // In 32 bits: two i32s differ by less than 2³².
        (0..AXES).all(|i| under_half(to[i].0.abs_diff(from[i].0), segment_len))
    }

    pub fn start(&self) -> Position {
        self.from
    }

    pub fn end(&self) -> Position {
        self.to
    }
}

impl Iterator for Segmenter {
    type Item = Position;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done == self.pieces {
            return None;
        }
        self.done += 1;
        let n = self.pieces;
        // Rounded half away from zero: up from n − ⌊n/2⌋ of n.
        let half = n - n / 2;
        let point: Position = core::array::from_fn(|i| {
            let s = &mut self.share[i];
            s.whole += s.step;
            s.part += s.rest;
            if s.part >= n {
                s.part -= n;
                s.whole += 1;
            }
            let way = (s.whole + (s.part >= half) as u32) as i64;
            let way = if self.down >> i & 1 != 0 { -way } else { way };
            Milli((self.from[i].0 as i64 + way) as i32)
        });
        Some(point)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = (self.pieces - self.done) as usize;
        (left, Some(left))
    }
}

/// Pieces of at most `segment_len` (µm) along `delta`: its length
/// rounded up over `segment_len`, rounded up. A move shorter than a piece
/// (a stream of tiny lines: every one of them) is one piece without the
/// root and the 64-bit division: no coordinate over half a piece less a
/// µm keeps the length under √3/2 of one. Two i32s differ by less than
/// 2³²: a coordinate's change fits a `u32`.
fn pieces(delta: &[i64; AXES], segment_len: u32) -> u32 {
    if delta
        .iter()
        .all(|d| under_half(d.unsigned_abs() as u32, segment_len))
    {
        return 1;
    }
    pieces_by_root(delta, segment_len)
}

/// A coordinate's `change` is under half a piece: with every coordinate
/// so, the length is under √3/2 of one, a piece found without the root.
fn under_half(change: u32, segment_len: u32) -> bool {
    change < segment_len / 2
}

/// [`pieces`] from the length's root.
fn pieces_by_root(delta: &[i64; AXES], segment_len: u32) -> u32 {
    let seg = segment_len.max(1) as u64;
    let len2 = delta
        .iter()
        .map(|d| d.unsigned_abs().saturating_mul(d.unsigned_abs()))
        .fold(0u64, u64::saturating_add);
    let root = isqrt(len2);
    let len = if root * root < len2 { root + 1 } else { root };
    len.div_ceil(seg).clamp(1, u32::MAX as u64) as u32
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

    proptest! {
        #[test]
        fn a_move_under_a_piece_is_one_piece_as_its_length_says(
            d in prop::array::uniform3(prop_oneof![-3000i64..3000, -(1i64 << 32) + 1..(1i64 << 32)]),
            seg in prop_oneof![1u32..6000, 1000u32..=5000],
        ) {
            prop_assert_eq!(pieces(&d, seg), pieces_by_root(&d, seg));
        }
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
        /// Each piece's end is `from + round(delta·k / n)`, rounded half
        /// away from zero, as it was worked out with a division a piece.
        #[test]
        fn pieces_without_dividing_are_the_divided_ones(
            a in prop::array::uniform3(-(1i32 << 30)..1 << 30),
            b in prop::array::uniform3(-(1i32 << 30)..1 << 30),
            seg in prop_oneof![1u32..10, 1000u32..5000, 1u32 << 30..u32::MAX],
        ) {
            let k = polargraph();
            let (a, b) = (a.map(Milli), b.map(Milli));
            let s = Segmenter::new(&k, a, &b, seg);
            let n = s.pieces() as i64;
            prop_assume!(n <= 5000);
            for (k, p) in s.enumerate() {
                for i in 0..AXES {
                    let d = b[i].0 as i64 - a[i].0 as i64;
                    let want = a[i].0 as i64 + crate::units::div_round(d * (k as i64 + 1), n);
                    prop_assert_eq!(p[i].0 as i64, want, "piece {} axis {}", k, i);
                }
            }
        }

        /// What the kinematics' `piece_um` promise: a whiteboard piece
        /// strays under 10 µm anywhere on the board, an arm's under 30 µm
        /// within 60–250 mm of the shoulder (under 0.1 mm further out,
        /// the arm near straight).
        #[test]
        fn pieces_stray_from_the_line_by_far_less_than_a_step(
            x in -500_000i32..500_000, y in -500_000i32..300_000,
            r in 60_000i32..250_000, b in -1.5f32..1.5, angle in 0.0f32..core::f32::consts::TAU,
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
