//! Per-block geometry, in floats once per block: the path length and
//! direction in milli-units, the axes' limits in events, and Grbl's
//! junction-deviation speed at a corner.

use crate::axis::AXES;
use crate::config::MachineConfig;
use crate::segment::{StepBlock, MAX_ACCEL};
/// Square root without libm's 256-byte table (which the AVR would copy
/// into SRAM): a bit-level first guess and three Newton steps, good to
/// f32 precision for the positive, finite values used here.
fn sqrtf(x: f32) -> f32 {
    if x <= 0.0 {
        return 0.0;
    }
    let mut y = f32::from_bits((x.to_bits() >> 1) + 0x1FC0_0000);
    for _ in 0..3 {
        y = 0.5 * (y + x / y);
    }
    y
}

/// Below this a corner counts as a straight line or a full reversal
/// (Grbl's 0.999999).
const STRAIGHT: f32 = 0.999_999;

/// The axes' figures in the units the planner needs.
pub struct Geometry {
    milli_per_step: [f32; AXES],
    /// Acceleration along each axis, milli-units/s².
    accel_milli: [f32; AXES],
    accel: [u32; AXES],
    max_rate: [u32; AXES],
    deviation_milli: f32,
}

/// Direction and events per milli-unit of a block's path.
pub struct Path {
    pub unit: [f32; AXES],
    pub ev_per_milli: f32,
}

/// A junction between two moves: Grbl's `junction_cos_theta` (1 = full
/// reversal, -1 = straight on) and the direction the velocity changes in.
pub struct Corner {
    cos: f32,
    change: [f32; AXES],
}

impl Geometry {
    /// No axis can move until [`Geometry::new`] replaces it.
    pub const EMPTY: Geometry = Geometry {
        milli_per_step: [0.0; AXES],
        accel_milli: [0.0; AXES],
        accel: [0; AXES],
        max_rate: [0; AXES],
        deviation_milli: 0.0,
    };

    pub fn new(config: &MachineConfig) -> Self {
        let mut g = Geometry {
            milli_per_step: [0.0; AXES],
            accel_milli: [0.0; AXES],
            accel: [0; AXES],
            max_rate: [0; AXES],
            deviation_milli: config.junction_deviation_um as f32,
        };
        for (i, a) in config.axes.iter().enumerate() {
            g.milli_per_step[i] = 1000.0 / a.steps_per_unit.as_f32();
            g.accel_milli[i] = a.accel as f32 * g.milli_per_step[i];
            g.accel[i] = a.accel;
            g.max_rate[i] = a.max_rate;
        }
        g
    }

    /// Acceleration (events/s²) and speed (events/s) of the block that
    /// keep every axis within its own: an axis making `n` of the `e` steps
    /// runs at `n / e` of the event rate.
    pub fn limits(&self, step: &StepBlock) -> (u32, u32) {
        let e = step.events as u64;
        let (mut accel, mut rate) = (MAX_ACCEL as u64, u32::MAX as u64);
        for i in 0..AXES {
            let n = step.steps[i] as u64;
            // An axis that does not move sets no limit.
            if let Some(a) = (self.accel[i] as u64 * e).checked_div(n) {
                accel = accel.min(a);
                rate = rate.min(self.max_rate[i] as u64 * e / n);
            }
        }
        (accel.max(1) as u32, rate.max(1) as u32)
    }

    /// Direction and scale of a move of `delta` steps per axis.
    pub fn path(&self, delta: &[i64; AXES]) -> Path {
        let mut unit = [0.0; AXES];
        let mut len_sqr = 0.0;
        let mut events = 0;
        for i in 0..AXES {
            unit[i] = delta[i] as f32 * self.milli_per_step[i];
            len_sqr += unit[i] * unit[i];
            events = events.max(delta[i].unsigned_abs());
        }
        let len = sqrtf(len_sqr);
        unit.iter_mut().for_each(|u| *u /= len);
        Path {
            unit,
            ev_per_milli: events as f32 / len,
        }
    }

    /// Grbl's junction speed²: the speed at which a circle tangent to both
    /// moves, passing `junction_deviation` from the corner, is driven at the
    /// acceleration the axes allow in the direction the velocity changes.
    pub fn junction_sqr(&self, c: &Corner) -> u64 {
        if c.cos > STRAIGHT {
            return 0;
        }
        if c.cos < -STRAIGHT {
            return u64::MAX;
        }
        let mut accel = f32::MAX;
        for i in 0..AXES {
            if c.change[i] != 0.0 {
                accel = accel.min(self.accel_milli[i] / c.change[i].abs());
            }
        }
        let sin_half = sqrtf(0.5 * (1.0 - c.cos));
        (accel * self.deviation_milli * sin_half / (1.0 - sin_half)) as u64
    }
}

impl Corner {
    pub fn new(prev: &[f32; AXES], next: &[f32; AXES]) -> Self {
        let mut cos = 0.0;
        let mut change = [0.0; AXES];
        let mut len_sqr = 0.0;
        for i in 0..AXES {
            cos -= prev[i] * next[i];
            change[i] = next[i] - prev[i];
            len_sqr += change[i] * change[i];
        }
        let len = sqrtf(len_sqr);
        if len > 0.0 {
            change.iter_mut().for_each(|c| *c /= len);
        }
        Corner { cos, change }
    }
}

#[cfg(test)]
mod sqrt_tests {
    #[test]
    fn sqrt_matches_std() {
        for x in [1e-6f32, 0.25, 0.5, 1.0, 2.0, 3.0, 1e3, 12345.678, 1e12] {
            let (got, want) = (super::sqrtf(x), x.sqrt());
            assert!((got - want).abs() <= want * 2e-7, "{x}: {got} vs {want}");
        }
        assert_eq!(super::sqrtf(0.0), 0.0);
    }
}
