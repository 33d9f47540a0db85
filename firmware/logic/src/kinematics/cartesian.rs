//! Cartesian X/Y plotters (seed 001's drum, seed 002's flatbed): X and Y on
//! channels 0 and 1, the pen's Z on channel 2. For the drum, Y's steps per
//! mm are those of the paper's surface (drum steps per turn / circumference).

use super::{ChannelScale, KinError, Kinematics, Position, Steps};
use crate::axis::AXES;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cartesian {
    pub scale: ChannelScale,
}

impl Kinematics for Cartesian {
    fn inverse(&self, pos: &Position) -> Result<Steps, KinError> {
        self.scale.all_steps(pos)
    }

    fn forward(&self, steps: &Steps) -> Position {
        self.scale.all_milli(steps)
    }

    fn is_linear(&self) -> bool {
        true
    }

    fn words(&self) -> [u8; AXES] {
        *b"XYZA"
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::units::{Milli, StepsPerUnit};
    use proptest::prelude::*;

    /// Seed 002: 0.025 mm per step on X and Y; seed 001's drum: 2048 steps
    /// per turn of a 90 mm tube (π·90 ≈ 282.743 mm ≈ 282743/1000).
    fn kin() -> Cartesian {
        Cartesian {
            scale: ChannelScale([
                StepsPerUnit::new(40, 1),
                StepsPerUnit::new(2_048_000, 282_743),
                StepsPerUnit::new(100, 1),
                StepsPerUnit::new(1, 1),
            ]),
        }
    }

    #[test]
    fn seed_002_resolution() {
        let k = kin();
        let pos = [Milli(140_000), Milli(0), Milli(1000), Milli(0)];
        assert_eq!(k.inverse(&pos), Ok([5600, 0, 100, 0]));
        // 0.0125 mm is half a step: rounds away from zero (seed 001's v3
        // fix: round, never truncate).
        assert_eq!(
            k.inverse(&[Milli(13), Milli(0), Milli(0), Milli(0)])
                .unwrap()[0],
            1
        );
        assert_eq!(
            k.inverse(&[Milli(12), Milli(0), Milli(0), Milli(0)])
                .unwrap()[0],
            0
        );
    }

    proptest! {
        #[test]
        fn forward_of_inverse_within_half_a_step(x in -1_000_000i32..1_000_000, y in -1_000_000i32..1_000_000) {
            let k = kin();
            let pos = [Milli(x), Milli(y), Milli(0), Milli(0)];
            let back = k.forward(&k.inverse(&pos).unwrap());
            prop_assert!((back[0].0 - x).abs() <= 13);
            prop_assert!((back[1].0 - y).abs() <= 70); // 138 µm per drum step
        }

        #[test]
        fn inverse_of_forward_is_exact(s in prop::array::uniform4(-100_000i32..100_000)) {
            let k = kin();
            prop_assert_eq!(k.inverse(&k.forward(&s)).unwrap(), s);
        }
    }
}
