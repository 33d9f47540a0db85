//! SCARA arm (Klipper's formulas). Channel 0 turns the shoulder,
//! channel 1 the elbow's motor, both in degrees; the elbow's belt passes
//! through the shoulder joint, so turning the shoulder also turns the elbow
//! by 1/ECR (the elbow crosstalk ratio ECR = n_S / n_E). At zero steps both
//! arms point along +y. Angles are counted counter-clockwise from +y, so
//! x = −sin: the original arm's sign convention.
//!
//! The inverse takes the elbow bent to positive angles (one of the two
//! solutions) and the shoulder within one turn, counted from the pen's
//! bearing: that jumps a whole turn where the pen crosses the ray behind
//! the shoulder (its −y direction, where the base stands). A real arm's
//! shoulder has stops and cables and cannot follow round there, so a
//! straight move (or an arc's chord) that would cross that ray is out of
//! reach ([`Kinematics::reaches_line`]): refused before anything moves,
//! never drawn the long way round.

use super::{milli, mm, ChannelScale, Frac, JointScale, KinError, Kinematics, Position, Steps};
use crate::axis::AXES;
use crate::config::Geometry;
use crate::fmath::{self, magnitude};
use crate::units::Milli;
use core::f32::consts::PI;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scara {
    scale: JointScale,
    /// Arm lengths, mm.
    l1: f32,
    l2: f32,
    /// Position of the shoulder joint: the pen's place less this is exact
    /// in integers, and one conversion to mm.
    offset: [Milli; 2],
    /// 1/ECR; 0 when the elbow motor sits on the elbow (no crosstalk).
    crosstalk: f32,
}

const DEG: f32 = 180.0 / PI;

/// 1.0's bits.
const ONE: u32 = 0x3f80_0000;

impl Scara {
    /// `lengths` are L1 and L2, `origin` the shoulder's place, `crosstalk`
    /// the ECR (0: none).
    pub fn new(scale: &ChannelScale, g: &Geometry) -> Result<Self, KinError> {
        let [l1, l2] = g.lengths;
        let ecr = g.crosstalk;
        if l1.0 <= 0 || l2.0 <= 0 || ecr.den == 0 {
            return Err(KinError::Unreachable);
        }
        Ok(Scara {
            scale: JointScale::new(scale),
            l1: mm(l1),
            l2: mm(l2),
            offset: g.origin,
            crosstalk: match ecr.num {
                0 => 0.0,
                n => ecr.den as f32 / n as f32,
            },
        })
    }

    /// `pos` from the shoulder, mm.
    fn shoulder_to(&self, pos: &Position) -> [f32; 2] {
        // Saturated: a place that far is out of reach either way.
        let x = pos[0].0.saturating_sub(self.offset[0].0);
        let y = pos[1].0.saturating_sub(self.offset[1].0);
        [mm(Milli(x)), mm(Milli(y))]
    }
}

impl Kinematics for Scara {
    fn inverse(&self, pos: &Position) -> Result<Steps, KinError> {
        self.inverse_fine(pos).map(|(steps, _)| steps)
    }

    /// 2 mm: the pen strays from the line by under 0.03 mm within 250 mm
    /// of the shoulder and under 0.09 mm with the arm nearly straight,
    /// under half a step of the shoulder there.
    fn piece_um(&self) -> u32 {
        2000
    }

    // Out of line: one copy of the float maths, whoever calls.
    #[inline(never)]
    fn inverse_fine(&self, pos: &Position) -> Result<(Steps, Frac), KinError> {
        let (l1, l2) = (self.l1, self.l2);
        let [x, y] = self.shoulder_to(pos);
        let x = -x;
        let h2 = x * x + y * y;
        // Reach, with 1 µm of slack for the decimal input: on squares,
        // no root.
        // (Compared as magnitudes' bits: `fmath::magnitude`.)
        let (outer, inner) = (l1 + l2 + 0.001, (l1 - l2).abs() - 0.001);
        let h = magnitude(h2);
        let hole = inner.to_bits() as i32 > 0 && h < magnitude(inner * inner);
        if h == 0 || h > magnitude(outer * outer) || hole {
            return Err(KinError::Unreachable);
        }
        // The elbow's bend from the law of cosines (the original arm's
        // notes print "+ L1² + L2²"; it has minus), and the shoulder's
        // angle off the pen's bearing from the same sine and cosine: one
        // root, where two arc cosines took three and a division.
        let c = (h2 - l1 * l1 - l2 * l2) / (2.0 * l1 * l2);
        // Within ±1 (by a rounding, or the slack), sign kept.
        let c = match magnitude(c) > ONE {
            true => f32::from_bits(ONE | c.to_bits() & 0x8000_0000),
            false => c,
        };
        let s = fmath::sqrt(1.0 - c * c);
        let bend = fmath::atan2(s, c);
        let shoulder = shoulder(x, y, l2 * s, l1 + l2 * c);
        let elbow = shoulder * self.crosstalk + bend;
        let mut steps = self.scale.pen_steps(pos)?;
        let mut frac = [0; AXES];
        (steps[0], frac[0]) = self.scale.steps_fine(0, shoulder * DEG)?;
        (steps[1], frac[1]) = self.scale.steps_fine(1, elbow * DEG)?;
        Ok((steps, frac))
    }

    #[inline(never)]
    fn forward(&self, steps: &Steps) -> Position {
        let a = self.scale.value_f32(0, steps[0]) / DEG;
        let b = self.scale.value_f32(1, steps[1]) / DEG;
        let s = a;
        let e = b - a * self.crosstalk;
        let (sin_s, cos_s) = fmath::sin_cos(s);
        let (sin_se, cos_se) = fmath::sin_cos(s + e);
        let x = -sin_s * self.l1 - sin_se * self.l2 + mm(self.offset[0]);
        let y = cos_s * self.l1 + cos_se * self.l2 + mm(self.offset[1]);
        let mut pos = self.scale.pen_milli(steps);
        pos[0] = milli(x);
        pos[1] = milli(y);
        pos
    }

    fn is_linear(&self) -> bool {
        false
    }

    /// The ends within L1 + L2 of the shoulder, the line never closer
    /// to it than |L1 − L2| (the reach is a ring), and never across the
    /// ray behind it (see the module's notes).
    fn reaches_line(&self, a: &Position, b: &Position) -> bool {
        let outer = self.l1 + self.l2 + 0.001;
        let [ax, ay] = self.shoulder_to(a);
        let [bx, by] = self.shoulder_to(b);
        let (a2, b2) = (ax * ax + ay * ay, bx * bx + by * by);
        if a2 > outer * outer || b2 > outer * outer {
            return false;
        }
        // The inverse's bearing is atan2(−x, y): on the ray (x = 0, y < 0)
        // it is −π, that of the side x ≥ 0. A line from one side to the
        // other crosses x = 0 at y = (ay·bx − ax·by) / (bx − ax): behind
        // the shoulder (y < 0), the shoulder would turn the long way.
        if (ax >= 0.0) != (bx >= 0.0) {
            let (y, den) = (ay * bx - ax * by, bx - ax);
            if (den > 0.0 && y <= 0.0) || (den < 0.0 && y >= 0.0) {
                return false;
            }
        }
        let (dx, dy) = (bx - ax, by - ay);
        // The shoulder itself is out of reach even with equal arms.
        // (A comparison: `max` is a call on the AVR.)
        let inner = match (self.l1 - self.l2).abs() - 0.001 {
            d if d > 0.001 => d,
            _ => 0.001,
        };
        // Every point of the line is within its length (at most
        // |dx| + |dy|) of `a`: a short line well clear of the hole needs
        // no closest point (a division and a dozen products).
        let clear = inner + dx.abs() + dy.abs();
        if a2 >= clear * clear {
            return true;
        }
        let len2 = dx * dx + dy * dy;
        let t = match len2 > 0.0 {
            true => (-(ax * dx + ay * dy) / len2).clamp(0.0, 1.0),
            false => 0.0,
        };
        let (cx, cy) = (ax + t * dx, ay + t * dy);
        cx * cx + cy * cy >= inner * inner
    }

    fn words(&self) -> [u8; AXES] {
        *b"XYZ"
    }
}

/// The shoulder's angle: the pen's bearing `atan2(x, y)` (in (−π, π],
/// −π on the ray behind the shoulder) less the elbow's offset
/// `atan2(ox, oy)` (in [0, π]), as one arc tangent of the difference's
/// sine and cosine: that lies in (−π, π], a whole turn above the
/// difference where the bearing is on the left (x below 0, or −0: its
/// bearing there is −π) and the difference is below −π.
fn shoulder(x: f32, y: f32, ox: f32, oy: f32) -> f32 {
    let a = fmath::atan2(x * oy - y * ox, y * oy + x * ox);
    // a > 0 as bits (not NaN: its arguments are finite).
    match x.is_sign_negative() && a.to_bits() as i32 > 0 {
        true => a - 2.0 * PI,
        false => a,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::units::Milli;
    use crate::units::StepsPerUnit;
    use proptest::prelude::*;

    /// 150 mm + 120 mm arms, 200 × 16 microsteps × 4:1 belt per turn
    /// (12 800 steps per 360°: 0.028° a step), ECR 3, shoulder at (10, 20).
    fn kin() -> Scara {
        let s = StepsPerUnit::new(12_800, 360);
        let scale = ChannelScale([s, s, StepsPerUnit::new(100, 1)]);
        let g = Geometry {
            lengths: [Milli(150_000), Milli(120_000)],
            origin: [Milli(10_000), Milli(20_000)],
            crosstalk: StepsPerUnit::new(3, 1),
        };
        Scara::new(&scale, &g).unwrap()
    }

    #[test]
    fn a_line_through_the_hole_round_the_shoulder_is_out_of_reach() {
        // Arms 150 and 120: nothing within 30 mm of the shoulder (10, 20).
        let k = kin();
        let at = |x: i32, y: i32| [Milli(x), Milli(y), Milli(0)];
        assert!(k.reaches_line(&at(-90_000, 20_000), &at(-90_000, 120_000)));
        assert!(!k.reaches_line(&at(-90_000, 20_000), &at(110_000, 20_000)));
        assert!(k.reaches_line(&at(-90_000, 60_000), &at(110_000, 60_000)));
    }

    #[test]
    fn a_line_across_the_ray_behind_the_shoulder_is_out_of_reach() {
        // The shoulder at (10, 20): the ray behind it is x = 10, y < 20.
        let k = kin();
        let at = |x: i32, y: i32| [Milli(x * 1000), Milli(y * 1000), Milli(0)];
        assert!(!k.reaches_line(&at(-90, -80), &at(110, -80)));
        assert!(!k.reaches_line(&at(110, -80), &at(-90, -80)));
        // On the ray the shoulder is where it is right of it.
        assert!(!k.reaches_line(&at(10, -80), &at(-90, -80)));
        assert!(k.reaches_line(&at(10, -80), &at(110, -80)));
        assert!(k.reaches_line(&at(10, -80), &at(10, -150)));
        // Round the front instead.
        assert!(k.reaches_line(&at(-90, -80), &at(-90, 120)));
        assert!(k.reaches_line(&at(-90, 120), &at(110, 120)));
        assert!(k.reaches_line(&at(110, 120), &at(110, -80)));
    }

    #[test]
    fn zero_steps_is_the_arm_straight_along_y() {
        let p = kin().forward(&[0; AXES]);
        assert_eq!((p[0], p[1]), (Milli(10_000), Milli(290_000)));
    }

    #[test]
    fn right_angle_elbow_by_hand() {
        // Shoulder 0°, elbow bent 90°: with ECR 3 the elbow motor reads
        // 90° too (no shoulder turn to compensate). The tip is L1 up and
        // L2 to −x: (10 − 120, 20 + 150).
        let k = kin();
        let steps = k
            .inverse(&[Milli(-110_000), Milli(170_000), Milli(0)])
            .unwrap();
        assert!(
            steps[0].abs() <= 1 && (steps[1] - 3200).abs() <= 1,
            "{:?}",
            steps
        );
        // Shoulder at 30°: the elbow motor must be 30°/3 further.
        let s = 30.0 / DEG;
        let tip = [
            -libm::sinf(s) * 150.0 - libm::sinf(s + PI / 2.0) * 120.0 + 10.0,
            libm::cosf(s) * 150.0 + libm::cosf(s + PI / 2.0) * 120.0 + 20.0,
        ];
        let steps = k
            .inverse(&[milli(tip[0]), milli(tip[1]), Milli(0)])
            .unwrap();
        assert!(
            (steps[0] - 1067).abs() <= 1 && (steps[1] - 3556).abs() <= 1,
            "{:?}",
            steps
        );
    }

    #[test]
    fn out_of_reach() {
        let k = kin();
        let far = [Milli(10_000), Milli(300_000), Milli(0)];
        let near = [Milli(20_000), Milli(20_000), Milli(0)];
        assert_eq!(k.inverse(&far), Err(KinError::Unreachable));
        assert_eq!(k.inverse(&near), Err(KinError::Unreachable));
    }

    /// A point of the annulus the arm reaches, in front of the base.
    fn reachable() -> impl Strategy<Value = (i32, i32)> {
        (35_000i32..265_000, -2.5f32..2.5).prop_map(|(r, t)| {
            let r = r as f32;
            (
                libm::roundf(10_000.0 - r * libm::sinf(t)) as i32,
                libm::roundf(20_000.0 + r * libm::cosf(t)) as i32,
            )
        })
    }

    /// A point anywhere in the ring the arm reaches, round the shoulder.
    fn anywhere() -> impl Strategy<Value = (i32, i32)> {
        (35_000i32..265_000, -3.2f32..3.2).prop_map(|(r, t)| {
            let r = r as f32;
            (
                libm::roundf(10_000.0 - r * libm::sinf(t)) as i32,
                libm::roundf(20_000.0 + r * libm::cosf(t)) as i32,
            )
        })
    }

    proptest! {
        /// A line is within reach exactly when its pieces' shoulder turns
        /// continuously: no piece turns it by half a turn (6400 steps),
        /// which only a jump across the ray behind the shoulder does.
        #[test]
        fn reached_lines_turn_the_shoulder_continuously(a in anywhere(), b in anywhere()) {
            use super::super::Segmenter;
            let k = kin();
            let (a, b) = ([Milli(a.0), Milli(a.1), Milli(0)], [Milli(b.0), Milli(b.1), Milli(0)]);
            // Clear of the hole round the shoulder (30 mm), by a piece.
            let (dx, dy) = ((b[0].0 - a[0].0) as f64, (b[1].0 - a[1].0) as f64);
            let (px, py) = ((a[0].0 - 10_000) as f64, (a[1].0 - 20_000) as f64);
            let t = (-(px * dx + py * dy) / (dx * dx + dy * dy).max(1.0)).clamp(0.0, 1.0);
            prop_assume!((px + t * dx).hypot(py + t * dy) > 33_000.0);
            let mut last = k.inverse(&a).unwrap();
            let mut jumped = false;
            for piece in Segmenter::new(&k, a, &b, k.piece_um()) {
                let steps = k.inverse(&piece).unwrap();
                jumped |= (steps[0] - last[0]).abs() > 6400;
                last = steps;
            }
            prop_assert_eq!(k.reaches_line(&a, &b), !jumped);
        }

        /// The one arc tangent is the bearing less the offset, as two
        /// were, on either side of the ray behind the shoulder and on it.
        #[test]
        fn the_shoulder_is_the_bearing_less_the_elbows_offset(
            (x, y) in prop_oneof![
                (-300.0f32..300.0, -300.0f32..300.0),
                (prop_oneof![Just(0.0f32), Just(-0.0f32), -1e-3f32..1e-3], -300.0f32..-1.0),
            ],
            bend in 0.05f32..3.09,
        ) {
            let (l1, l2) = (150.0f32, 120.0f32);
            let (s, c) = (libm::sinf(bend), libm::cosf(bend));
            let (ox, oy) = (l2 * s, l1 + l2 * c);
            let two = fmath::atan2(x, y) - fmath::atan2(ox, oy);
            let one = shoulder(x, y, ox, oy);
            prop_assert!((one - two).abs() < 2e-5, "{x} {y} {bend}: {one} {two}");
        }

        /// One step moves the tip at most (L1 + L2)·0.028° ≈ 132 µm; the
        /// two joints round by half a step each.
        #[test]
        fn forward_of_inverse_within_a_step((x, y) in reachable()) {
            let k = kin();
            let pos = [Milli(x), Milli(y), Milli(0)];
            let back = k.forward(&k.inverse(&pos).unwrap());
            let err = libm::hypotf((back[0].0 - x) as f32, (back[1].0 - y) as f32);
            prop_assert!(err <= 132.0, "{:?} -> {:?}", pos, back);
        }

        /// Away from the straight and folded arm (where the elbow angle is
        /// ill-conditioned) the steps come back within one.
        #[test]
        fn inverse_of_forward_within_a_step(a in -3000i32..3000, bend in 400i32..6000) {
            let k = kin();
            // Elbow motor = bend + shoulder/ECR, as the arm is built.
            let s = [a, bend + a / 3, 0];
            let again = k.inverse(&k.forward(&s)).unwrap();
            prop_assert!((again[0] - s[0]).abs() <= 1 && (again[1] - s[1]).abs() <= 1, "{:?} {:?}", s, again);
        }
    }
}
