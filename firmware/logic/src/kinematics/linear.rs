//! Kinematics where each G-code word drives one channel directly, so a
//! straight line in space is straight in joint space:
//! - the string-art machine (cylindrical): the words are already the
//!   machine's own coordinates — base angle `C` (degrees, counter-clockwise
//!   seen from above), radial carriage `X` (mm, positive outwards, zero with
//!   the tool at the board's edge) and drill/needle `Z` (mm along the tilted
//!   tool axis, positive down into the board);
//! - cartesian X/Y plotters (a drum plotter, a flatbed plotter made from an
//!   old printer): X and Y on channels 0 and 1, the pen's Z on channel 2. For the drum, Y's steps per
//!   mm are those of the paper's surface (drum steps per turn / circumference).

use super::{ChannelScale, KinError, Kinematics, Position, Steps};
use crate::axis::AXES;
use crate::config::MachineConfig;
use crate::machine::{CARTESIAN, CYLINDRICAL};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Linear {
    pub scale: ChannelScale,
    /// The G-code letter of each channel.
    pub words: [u8; AXES],
}

impl Linear {
    /// The string-art machine, with the figures of `config`.
    pub fn cylindrical(config: &MachineConfig) -> Self {
        Linear {
            scale: ChannelScale::from_config(config),
            words: CYLINDRICAL,
        }
    }

    /// A cartesian plotter with per-channel steps per mm.
    pub fn cartesian(scale: ChannelScale) -> Self {
        Linear {
            scale,
            words: CARTESIAN,
        }
    }
}

impl Kinematics for Linear {
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
        self.words
    }
}

#[cfg(test)]
mod cylindrical_tests {
    use super::*;
    use crate::units::Milli;
    use proptest::prelude::*;

    fn kin() -> Linear {
        Linear::cylindrical(&MachineConfig::STRING_ART)
    }

    #[test]
    fn spec_figures() {
        let k = kin();
        let pos = [Milli(360_000), Milli(-10_000), Milli(10_386)];
        assert_eq!(k.inverse(&pos), Ok([9600, -320, 1385]));
        assert_eq!(
            k.forward(&[4800, 32, 1600])[..3],
            [Milli(180_000), Milli(1000), Milli(12_000)]
        );
    }

    #[test]
    fn one_degree_moves_end_one_turn_later() {
        let k = kin();
        let mut pos = [Milli(0); AXES];
        for _ in 0..360 {
            pos[0].0 += 1000;
            k.inverse(&pos).unwrap();
        }
        assert_eq!(k.inverse(&pos).unwrap()[0], 9600);
    }

    #[test]
    fn overflow_is_reported() {
        let mut config = MachineConfig::STRING_ART;
        config.axes[1].steps_per_unit.num = 100_000;
        let k = Linear::cylindrical(&config);
        let pos = [Milli(0), Milli(i32::MAX), Milli(0)];
        assert_eq!(k.inverse(&pos), Err(KinError::Overflow));
    }

    proptest! {
        #[test]
        fn forward_of_inverse_within_half_a_step(c in -3_600_000i32..3_600_000, x in -500_000i32..500_000, z in -100_000i32..100_000) {
            let k = kin();
            let pos = [Milli(c), Milli(x), Milli(z)];
            let back = k.forward(&k.inverse(&pos).unwrap());
            // Half a step in milli-units, +1 for the rounding of `milli`.
            let half = [19, 16, 4];
            for i in 0..3 {
                prop_assert!((back[i].0 - pos[i].0).abs() <= half[i], "axis {} {:?} -> {:?}", i, pos, back);
            }
        }

        #[test]
        fn inverse_of_forward_is_exact(s in prop::array::uniform3(-1_000_000i32..1_000_000)) {
            let k = kin();
            prop_assert_eq!(k.inverse(&k.forward(&s)).unwrap(), s);
        }
    }
}

#[cfg(test)]
mod cartesian_tests {
    use super::*;
    use crate::units::{Milli, StepsPerUnit};
    use proptest::prelude::*;

    /// The flatbed plotter: 0.025 mm per step on X and Y; the drum plotter:
    /// 2048 steps per turn of a 90 mm tube (π·90 ≈ 282.743 mm ≈ 282743/1000).
    fn kin() -> Linear {
        Linear::cartesian(ChannelScale([
            StepsPerUnit::new(40, 1),
            StepsPerUnit::new(2_048_000, 282_743),
            StepsPerUnit::new(100, 1),
        ]))
    }

    #[test]
    fn flatbed_plotter_resolution() {
        let k = kin();
        let pos = [Milli(140_000), Milli(0), Milli(1000)];
        assert_eq!(k.inverse(&pos), Ok([5600, 0, 100]));
        // 0.0125 mm is half a step: rounds away from zero (round, never
        // truncate: truncating cost the drum plotter's first firmware accuracy).
        assert_eq!(k.inverse(&[Milli(13), Milli(0), Milli(0)]).unwrap()[0], 1);
        assert_eq!(k.inverse(&[Milli(12), Milli(0), Milli(0)]).unwrap()[0], 0);
    }

    proptest! {
        #[test]
        fn forward_of_inverse_within_half_a_step(x in -1_000_000i32..1_000_000, y in -1_000_000i32..1_000_000) {
            let k = kin();
            let pos = [Milli(x), Milli(y), Milli(0)];
            let back = k.forward(&k.inverse(&pos).unwrap());
            prop_assert!((back[0].0 - x).abs() <= 13);
            prop_assert!((back[1].0 - y).abs() <= 70); // 138 µm per drum step
        }

        #[test]
        fn inverse_of_forward_is_exact(s in prop::array::uniform3(-100_000i32..100_000)) {
            let k = kin();
            prop_assert_eq!(k.inverse(&k.forward(&s)).unwrap(), s);
        }
    }
}
