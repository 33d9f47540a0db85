//! The string-art machine: the G-code words are already the machine's own
//! coordinates — base angle `C` (degrees, counter-clockwise seen from above),
//! radial carriage `X` (mm, positive outwards, zero with the tool at the
//! board's edge) and drill/needle `Z` (mm along the tilted tool axis,
//! positive down into the board) — so each maps straight onto its channel.

use super::{ChannelScale, KinError, Kinematics, Position, Steps};
use crate::axis::AXES;
use crate::config::MachineConfig;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cylindrical {
    pub scale: ChannelScale,
}

impl Cylindrical {
    pub fn from_config(config: &MachineConfig) -> Self {
        Cylindrical {
            scale: ChannelScale::from_config(config),
        }
    }
}

impl Kinematics for Cylindrical {
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
        *b"CXZA"
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::units::Milli;
    use proptest::prelude::*;

    fn kin() -> Cylindrical {
        Cylindrical::from_config(&MachineConfig::STRING_ART)
    }

    #[test]
    fn spec_figures() {
        let k = kin();
        let pos = [Milli(360_000), Milli(-10_000), Milli(10_386), Milli(0)];
        assert_eq!(k.inverse(&pos), Ok([9600, -320, 1385, 0]));
        assert_eq!(
            k.forward(&[4800, 32, 1600, 0])[..3],
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
        let k = Cylindrical::from_config(&config);
        let pos = [Milli(0), Milli(i32::MAX), Milli(0), Milli(0)];
        assert_eq!(k.inverse(&pos), Err(KinError::Overflow));
    }

    proptest! {
        #[test]
        fn forward_of_inverse_within_half_a_step(c in -3_600_000i32..3_600_000, x in -500_000i32..500_000, z in -100_000i32..100_000) {
            let k = kin();
            let pos = [Milli(c), Milli(x), Milli(z), Milli(0)];
            let back = k.forward(&k.inverse(&pos).unwrap());
            // Half a step in milli-units, +1 for the rounding of `milli`.
            let half = [19, 16, 4];
            for i in 0..3 {
                prop_assert!((back[i].0 - pos[i].0).abs() <= half[i], "axis {} {:?} -> {:?}", i, pos, back);
            }
        }

        #[test]
        fn inverse_of_forward_is_exact(s in prop::array::uniform4(-1_000_000i32..1_000_000)) {
            let k = kin();
            prop_assert_eq!(k.inverse(&k.forward(&s)).unwrap(), s);
        }
    }
}
