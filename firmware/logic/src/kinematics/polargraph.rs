//! Two-string hanging plotter (the whiteboard machine). The left
//! motor's string leaves its pulley at (0, 0), the right one's at (D, 0),
//! y up; the pen hangs below (y < 0) where the strings meet. Channel 0 winds
//! the left string, channel 1 the right one (both in mm of string), channel 2
//! lifts the pen. The user's (0, 0) is `origin` in that frame, and the step
//! counts are zero there (the pen is parked at the origin when zeroed).

use super::{milli, mm, ChannelScale, Frac, JointScale, KinError, Kinematics, Position, Steps};
use crate::axis::AXES;
use crate::config::Geometry;
use crate::fmath;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Polargraph {
    scale: JointScale,
    /// Distance between the string exits, mm.
    distance: f32,
    /// The user's origin in the motors' frame, mm.
    origin: [f32; 2],
    /// String lengths at the origin, mm.
    home: [f32; 2],
}

impl Polargraph {
    /// `origin` must hang below the motors, between them or not.
    /// `lengths[0]` is the distance between the strings' exits.
    pub fn new(scale: &ChannelScale, g: &Geometry) -> Result<Self, KinError> {
        let mut k = Polargraph {
            scale: JointScale::new(scale),
            distance: mm(g.lengths[0]),
            origin: [mm(g.origin[0]), mm(g.origin[1])],
            home: [0.0; 2],
        };
        if k.distance <= 0.0 {
            return Err(KinError::Unreachable);
        }
        k.home = k.lengths(k.origin)?;
        Ok(k)
    }

    /// String lengths to a point of the motors' frame.
    fn lengths(&self, [x, y]: [f32; 2]) -> Result<[f32; 2], KinError> {
        if y >= 0.0 {
            return Err(KinError::Unreachable);
        }
        let dx = self.distance - x;
        Ok([fmath::sqrt(x * x + y * y), fmath::sqrt(dx * dx + y * y)])
    }
}

impl Kinematics for Polargraph {
    fn inverse(&self, pos: &Position) -> Result<Steps, KinError> {
        self.inverse_fine(pos).map(|(steps, _)| steps)
    }

    // Out of line: one copy of the float maths, whoever calls.
    #[inline(never)]
    fn inverse_fine(&self, pos: &Position) -> Result<(Steps, Frac), KinError> {
        let p = [self.origin[0] + mm(pos[0]), self.origin[1] + mm(pos[1])];
        let len = self.lengths(p)?;
        let mut steps = self.scale.pen_steps(pos)?;
        let mut frac = [0; AXES];
        for i in 0..2 {
            (steps[i], frac[i]) = self.scale.steps_fine(i, len[i] - self.home[i])?;
        }
        Ok((steps, frac))
    }

    /// 5 mm: the strings' lengths bend so gently along a line that the pen
    /// strays under 0.01 mm from it (a step of chain is 0.057 mm).
    fn piece_um(&self) -> u32 {
        5000
    }

    /// Below the motors is a half-plane: the ends are enough.
    fn reaches_line(&self, a: &Position, b: &Position) -> bool {
        let below = |p: &Position| self.origin[1] + mm(p[1]) < 0.0;
        below(a) && below(b)
    }

    #[inline(never)]
    fn forward(&self, steps: &Steps) -> Position {
        let l = self.home[0] + self.scale.value_f32(0, steps[0]);
        let r = self.home[1] + self.scale.value_f32(1, steps[1]);
        let d = self.distance;
        // Intersection of the two circles, the lower one.
        let x = (l * l - r * r + d * d) / (2.0 * d);
        let y = -fmath::sqrt((l * l - x * x).max(0.0));
        let mut pos = self.scale.pen_milli(steps);
        pos[0] = milli(x - self.origin[0]);
        pos[1] = milli(y - self.origin[1]);
        pos
    }

    fn is_linear(&self) -> bool {
        false
    }

    fn words(&self) -> [u8; AXES] {
        *b"XYZ"
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::units::Milli;
    use crate::units::StepsPerUnit;
    use proptest::prelude::*;

    pub(crate) fn geometry(distance: i32, origin: [i32; 2]) -> Geometry {
        Geometry {
            lengths: [Milli(distance), Milli(0)],
            origin: origin.map(Milli),
            ..Geometry::NONE
        }
    }

    /// Motors 1.2 m apart, origin 0.6 m below their middle; 2000 steps per
    /// turn of a 40 mm sprocket: 50 steps/mm (20 µm per step).
    fn kin() -> Polargraph {
        let s = StepsPerUnit::new(50, 1);
        let scale = ChannelScale([s, s, s]);
        Polargraph::new(&scale, &geometry(1_200_000, [600_000, -600_000])).unwrap()
    }

    #[test]
    fn origin_is_zero_steps() {
        let k = kin();
        assert_eq!(k.inverse(&[Milli(0); AXES]), Ok([0; AXES]));
        assert_eq!(k.forward(&[0; AXES]), [Milli(0); AXES]);
    }

    #[test]
    fn hand_computed_lengths() {
        let k = kin();
        // The user's (−300, −200) is (300, −800) in the motors' frame; strings
        // √(300²+800²) = 854.400 mm and √(900²+800²) = 1204.159 mm; at the
        // origin both are √(600²+600²) = 848.528 mm.
        let s = k
            .inverse(&[Milli(-300_000), Milli(-200_000), Milli(0)])
            .unwrap();
        assert!((s[0] - 294).abs() <= 1, "{}", s[0]); // 5.872 mm × 50
        assert!((s[1] - 17782).abs() <= 1, "{}", s[1]); // 355.631 mm × 50
    }

    #[test]
    fn above_the_motors_is_unreachable() {
        let k = kin();
        assert_eq!(
            k.inverse(&[Milli(0), Milli(600_000), Milli(0)]),
            Err(KinError::Unreachable)
        );
        let s = StepsPerUnit::new(50, 1);
        assert!(Polargraph::new(&ChannelScale([s; AXES]), &geometry(1_000_000, [0, 10])).is_err());
    }

    proptest! {
        /// Over the board (1.1 m × 0.8 m, kept 300 mm below the motor line
        /// where flat strings make the pen's height ill-conditioned): back
        /// within one step (20 µm) plus f32 slack.
        #[test]
        fn forward_of_inverse_within_a_step(x in -550_000i32..550_000, y in -500_000i32..300_000) {
            let k = kin();
            let pos = [Milli(x), Milli(y), Milli(0)];
            let back = k.forward(&k.inverse(&pos).unwrap());
            let err = libm::hypotf((back[0].0 - x) as f32, (back[1].0 - y) as f32);
            prop_assert!(err <= 25.0, "{:?} -> {:?}", pos, back);
        }

        #[test]
        fn inverse_of_forward_within_a_step(x in -550_000i32..550_000, y in -500_000i32..300_000) {
            let k = kin();
            let s = k.inverse(&[Milli(x), Milli(y), Milli(0)]).unwrap();
            let again = k.inverse(&k.forward(&s)).unwrap();
            prop_assert!((again[0] - s[0]).abs() <= 1 && (again[1] - s[1]).abs() <= 1, "{:?} {:?}", s, again);
        }
    }
}
