//! Cuts a straight move into pieces no longer than `segment_len` for
//! kinematics that are not linear (Marlin's and Klipper's approach). Each
//! piece's endpoint is interpolated from the absolute start and end in
//! integers and converted by the inverse from scratch, so no error piles up
//! from piece to piece; the last piece ends exactly on the target. Each
//! piece's end goes through the kinematics' inverse where it is queued.

use super::{Kinematics, Position};
use crate::axis::AXES;
use crate::segment::isqrt;
use crate::units::{div_round, Milli};

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
}

impl Iterator for Segmenter {
    type Item = Position;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done == self.pieces {
            return None;
        }
        self.done += 1;
        let (k, n) = (self.done as i64, self.pieces as i64);
        let point: Position = core::array::from_fn(|i| {
            Milli(self.from[i].0 + div_round(self.delta[i] * k, n) as i32)
        });
        Some(point)
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

    proptest! {
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
