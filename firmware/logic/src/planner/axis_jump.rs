//! Per-axis bounds on the velocity change at a junction, on top of Grbl's
//! junction deviation (which bounds a fictitious arc's acceleration, not
//! what each motor sees).
//!
//! At a junction the path's speed v is kept, and each axis's velocity
//! jumps from v·u_i to v·u′_i (u, u′ the unit directions of the two
//! blocks). A stepper whose commanded velocity jumps by Δv falls behind
//! until it has caught up at its acceleration a: by Δv² / 2a. It keeps
//! step while that lag is under two full steps (half an electrical turn);
//! we allow half of that, one full step — 8 steps at the string-art
//! machine's ×8 microstepping — so Δv ≤ √(2·a·8 steps) per axis: 89
//! steps/s at 500 steps/s². Within blocks the planner already keeps each
//! axis's share of speed and acceleration within its own limits
//! (`Geometry::limits`), so with this bound the axes' limits hold in
//! joint space at every block and every junction.

use crate::axis::AXES;
use crate::config::MachineConfig;

/// The commanded position may lead a motor by this many steps at a
/// junction.
pub const LAG_STEPS: u32 = 8;

/// Each axis's largest velocity change at a junction, path milli-units/s,
/// kept as its reciprocal: one division per junction, not one per axis
/// (~1 300 cycles each on the AVR).
pub struct AxisJumps {
    pub(super) per_milli: [f32; AXES],
}

impl AxisJumps {
    pub const EMPTY: AxisJumps = AxisJumps {
        per_milli: [0.0; AXES],
    };

    pub fn new(config: &MachineConfig) -> Self {
        let mut per_milli = [0.0; AXES];
        for (m, a) in per_milli.iter_mut().zip(&config.axes) {
            let steps_per_s = crate::fmath::sqrt((2 * a.accel * LAG_STEPS) as f32);
            *m = a.steps_per_unit.as_f32() / (steps_per_s * 1000.0);
        }
        AxisJumps { per_milli }
    }

    /// The largest path speed², (milli-units/s)², at which the turn from
    /// direction `prev` to `next` (unit vectors in path milli-units)
    /// changes no axis's velocity by more than its bound.
    pub fn limit_sqr(&self, prev: &[f32; AXES], next: &[f32; AXES]) -> u64 {
        // The axis whose change uses most of its bound sets the speed.
        let mut worst = 0.0f32;
        for i in 0..AXES {
            let used = (next[i] - prev[i]).abs() * self.per_milli[i];
            if used > worst {
                worst = used;
            }
        }
        if worst == 0.0 {
            return u64::MAX;
        }
        let v = 1.0 / worst;
        (v * v) as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planner::{Feed, Planner, PLANNER_BLOCKS};
    use proptest::prelude::*;

    proptest! {
        /// Any polyline of base and radial moves, planned: within each
        /// block every axis's speed and acceleration are its share of the
        /// block's and within its own limits, and at each junction each
        /// axis's velocity changes by at most its jump.
        #[test]
        fn every_axis_keeps_its_limits_in_joint_space(
            points in prop::collection::vec((-3000i32..3000, -800i32..800), 1..PLANNER_BLOCKS),
        ) {
            let c = MachineConfig::STRING_ART;
            let mut p = Planner::new(&c);
            for &(b, r) in &points {
                p.push([b, r, 0], Feed::Rapid).unwrap();
            }
            let mut last: Option<[f64; 2]> = None;
            while let Some(t) = p.take_speeds() {
                let e = f64::from(t.block.events);
                let sign = |i: usize| if t.block.dir & (1 << i) != 0 { 1.0 } else { -1.0 };
                let share = |i: usize| f64::from(t.block.steps[i]) / e * sign(i);
                let v = |sqr: u64| (sqr as f64).sqrt();
                for i in 0..2 {
                    let a = &c.axes[i];
                    prop_assert!(v(t.speeds.cruise_sqr) * share(i).abs() <= f64::from(a.max_rate) + 1.0);
                    prop_assert!(f64::from(t.accel) * share(i).abs() <= f64::from(a.accel) + 1.0);
                }
                let entry = [0, 1].map(|i| v(t.speeds.entry_sqr) * share(i));
                let jump = (2.0 * 500.0 * f64::from(LAG_STEPS)).sqrt();
                for i in 0..2 {
                    let before = last.map_or(0.0, |l| l[i]);
                    prop_assert!((entry[i] - before).abs() <= jump * 1.01 + 1.0,
                        "axis {}: {} → {} steps/s", i, before, entry[i]);
                }
                last = Some([0, 1].map(|i| v(t.speeds.exit_sqr) * share(i)));
            }
        }
    }

    #[test]
    fn a_right_angle_between_base_and_radial_is_a_near_stop() {
        let j = AxisJumps::new(&MachineConfig::STRING_ART);
        // Base 1° = 26.67 steps, radial 1 mm = 32 steps: √8000 steps/s is
        // 3354 mdeg/s of the base and 2795 µm/s of the carriage.
        let (base, radial) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let v = (j.limit_sqr(&base, &radial) as f32).sqrt();
        assert!((v - 2795.1).abs() < 1.0, "{v}");
        // Straight on: no bound; a reversal of the base: half its jump.
        assert_eq!(j.limit_sqr(&base, &base), u64::MAX);
        let back = [-1.0, 0.0, 0.0];
        let v = (j.limit_sqr(&base, &back) as f32).sqrt();
        assert!((v - 3354.1 / 2.0).abs() < 1.0, "{v}");
    }
}
