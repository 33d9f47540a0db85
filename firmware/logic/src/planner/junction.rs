//! Per-block geometry, in floats once per block: the path length and
//! direction in milli-units (or along the pen, for a piece), the axes'
//! limits in events, and Grbl's junction-deviation speed at a corner.

use super::axis_jump::AxisJumps;
use crate::axis::AXES;
use crate::config::MachineConfig;
use crate::kinematics::Frac;
use crate::machine::Machine;
use crate::segment::{StepBlock, MAX_ACCEL};
/// 1/√x for the positive, finite values used here, without libm's
/// 256-byte table (which the AVR would copy into SRAM) and without a
/// division (~5 multiplies on the AVR): a bit-level first guess and three
/// Newton steps of multiplies, good to a few f32 ulps. Lengths are
/// normalised by multiplying with it.
fn rsqrt(x: f32) -> f32 {
    let y = rsqrt_rough(x);
    y * (1.5 - 0.5 * x * y * y)
}

/// [`rsqrt`] one Newton step short: good to ~5·10⁻⁶, plenty for a
/// junction's speed limit, and ~600 cycles less on the AVR.
fn rsqrt_rough(x: f32) -> f32 {
    let half = 0.5 * x;
    let mut y = f32::from_bits(0x5F37_5A86 - (x.to_bits() >> 1));
    for _ in 0..2 {
        y *= 1.5 - half * y * y;
    }
    y
}

/// Below this a corner counts as a straight line or a full reversal
/// (Grbl's 0.999999).
const STRAIGHT: f32 = 0.999_999;

/// The axes' figures in the units the planner needs.
pub struct Geometry {
    milli_per_step: [f32; AXES],
    /// 1 / acceleration along each axis, s²/milli-unit: the junction's
    /// limit multiplies rather than divides.
    per_accel_milli: [f32; AXES],
    accel: [u32; AXES],
    max_rate: [u32; AXES],
    deviation_milli: f32,
}

/// Direction and events per milli-unit of a block's path.
pub struct Path {
    pub unit: [f32; AXES],
    pub ev_per_milli: f32,
}

/// The pen's limits where moves come as pieces of its path (the
/// whiteboard, the arm), in µm: Klipper's toolhead `max_velocity` and
/// `max_accel`, on top of each joint's own.
#[derive(Clone, Copy, Debug)]
pub struct PenLimits {
    /// µm/s².
    accel: f32,
    /// s²/µm.
    per_accel: f32,
    /// µm/s.
    max_speed: f32,
}

impl PenLimits {
    /// The pen's limits of a machine whose kinematics are not linear;
    /// `None` where the axes are the pen's (their own limits are then the
    /// pen's, as in Grbl).
    pub fn of(config: &MachineConfig) -> Option<PenLimits> {
        match config.machine {
            Machine::Whiteboard | Machine::Scara => {
                let accel = config.pen_accel as f32 * 1000.0;
                Some(PenLimits {
                    accel,
                    per_accel: 1.0 / accel,
                    max_speed: config.pen_max_feed as f32 * (1000.0 / 60.0),
                })
            }
            _ => None,
        }
    }

    /// (µm/s)².
    pub fn max_speed_sqr(&self) -> f32 {
        self.max_speed * self.max_speed
    }

    /// What the pen's acceleration adds to its speed² over `len` µm, half
    /// of it ((µm/s)²).
    pub fn accel_len_sqr(&self, len: f32) -> f32 {
        self.accel * len
    }

    /// A block's acceleration (events/s²) and top speed (events/s) that
    /// the joints allow, brought within the pen's own too. In place: on
    /// the AVR a pair of them returned came back as garbage.
    pub fn cap(&self, accel: &mut u32, rate: &mut u32, ev_per_milli: f32) {
        // Saturating conversions.
        let pen_accel = (self.accel * ev_per_milli) as u32;
        let pen_rate = (self.max_speed * ev_per_milli) as u32;
        *accel = (*accel).min(pen_accel).max(1);
        *rate = (*rate).min(pen_rate).max(1);
    }
}

/// A piece staged for planning: the pen's move, µm, and the rounding of
/// the joints at its start and end.
#[derive(Clone, Copy, Debug)]
pub struct PenMove {
    pub delta: [i32; AXES],
    pub frac: [Frac; 2],
}

impl PenMove {
    pub const NONE: PenMove = PenMove {
        delta: [0; AXES],
        frac: [[0; AXES]; 2],
    };
}

/// A piece's path along the pen.
pub struct PenPath {
    /// The pen's direction.
    pub unit: [f32; AXES],
    /// Each joint's share of the pen's speed: its milli-units per µm of
    /// the pen, exact (the joints' rounding put back).
    pub joint: [f32; AXES],
    /// µm.
    pub len: f32,
    pub ev_per_milli: f32,
}

impl Geometry {
    /// No axis can move until [`Geometry::new`] replaces it.
    pub const EMPTY: Geometry = Geometry {
        milli_per_step: [0.0; AXES],
        per_accel_milli: [0.0; AXES],
        accel: [0; AXES],
        max_rate: [0; AXES],
        deviation_milli: 0.0,
    };

    pub fn new(config: &MachineConfig) -> Self {
        let mut g = Geometry {
            milli_per_step: [0.0; AXES],
            per_accel_milli: [0.0; AXES],
            accel: [0; AXES],
            max_rate: [0; AXES],
            deviation_milli: config.junction_deviation_um as f32,
        };
        for (i, a) in config.axes.iter().enumerate() {
            g.milli_per_step[i] = 1000.0 / a.steps_per_unit.as_f32();
            g.per_accel_milli[i] = 1.0 / (a.accel as f32 * g.milli_per_step[i]);
            g.accel[i] = a.accel;
            g.max_rate[i] = a.max_rate;
        }
        g
    }

    /// The fastest any move can go along the path, squared,
    /// (milli-units/s)²: every axis at its own top speed.
    pub fn max_speed_sqr(&self) -> f32 {
        let mut sum = 0.0;
        for i in 0..AXES {
            let v = self.max_rate[i] as f32 * self.milli_per_step[i];
            sum += v * v;
        }
        sum
    }

    /// Acceleration (events/s²) and speed (events/s) of the block that
    /// keep every axis within its own: an axis making `n` of the `e` steps
    /// runs at `n / e` of the event rate. The tightest axis is found by
    /// comparing the fractions crosswise, then divided once: a `u64`
    /// division is ~1 000–2 500 cycles on the AVR, a multiply ~350, and
    /// a move planned in parts keeps a ready task waiting for the slowest.
    pub fn limits(&self, step: &StepBlock) -> (u32, u32) {
        let (mut accel, mut rate) = (None::<usize>, None::<usize>);
        for i in 0..AXES {
            // An axis that does not move sets no limit.
            if step.steps[i] == 0 {
                continue;
            }
            let tighter = |a: &[u32; AXES], j: usize| {
                (a[i] as u64 * step.steps[j] as u64) < a[j] as u64 * step.steps[i] as u64
            };
            if accel.is_none_or(|j| tighter(&self.accel, j)) {
                accel = Some(i);
            }
            if rate.is_none_or(|j| tighter(&self.max_rate, j)) {
                rate = Some(i);
            }
        }
        let share = |a: &[u32; AXES], i: Option<usize>, cap: u32| match i {
            Some(i) => scale(a[i], step.events, step.steps[i]).min(cap as u64) as u32,
            None => cap,
        };
        (
            share(&self.accel, accel, MAX_ACCEL).max(1),
            share(&self.max_rate, rate, u32::MAX).max(1),
        )
    }

    /// Direction and scale of the move `step`.
    pub fn path(&self, step: &StepBlock) -> Path {
        let mut unit = [0.0; AXES];
        let mut len_sqr = 0.0;
        for (i, u) in unit.iter_mut().enumerate() {
            // Most moves leave an axis or two idle: a multiply is ~100
            // cycles on the AVR.
            if step.steps[i] == 0 {
                continue;
            }
            let milli = step.steps[i] as f32 * self.milli_per_step[i];
            *u = if step.dir >> i & 1 != 0 {
                milli
            } else {
                -milli
            };
            len_sqr += *u * *u;
        }
        let per_len = rsqrt(len_sqr);
        unit.iter_mut().for_each(|u| *u *= per_len);
        Path {
            unit,
            ev_per_milli: step.events as f32 * per_len,
        }
    }

    /// The path of the piece `step` along the pen's move `pen`.
    pub fn pen_path(&self, step: &StepBlock, pen: &PenMove) -> PenPath {
        let mut unit = [0.0; AXES];
        let mut len_sqr = 0.0;
        for (u, d) in unit.iter_mut().zip(pen.delta) {
            if d != 0 {
                *u = d as f32;
                len_sqr += *u * *u;
            }
        }
        // Under a µm (a step's rounding, the position just set): 1 µm,
        // the joints' own limits then set its speed.
        if len_sqr < 1.0 {
            len_sqr = 1.0;
        }
        let per_len = rsqrt(len_sqr);
        unit.iter_mut().for_each(|u| *u *= per_len);
        let mut joint = [0.0; AXES];
        for (i, j) in joint.iter_mut().enumerate() {
            let frac = i32::from(pen.frac[1][i]) - i32::from(pen.frac[0][i]);
            if step.steps[i] == 0 && frac == 0 {
                continue;
            }
            let steps = match step.dir >> i & 1 != 0 {
                true => step.steps[i] as f32,
                false => -(step.steps[i] as f32),
            };
            *j = (steps + frac as f32 * (1.0 / 256.0)) * self.milli_per_step[i] * per_len;
        }
        PenPath {
            unit,
            joint,
            len: len_sqr * per_len,
            ev_per_milli: step.events as f32 * per_len,
        }
    }

    /// The pen's speed², (µm/s)², at which the joints' shares of it
    /// changing from `prev` to `next` (joint milli-units per µm) keep
    /// every joint within its jump (`AxisJumps`: v·Δshare) and within its
    /// acceleration over `len` µm of the pen's path (its speed changes
    /// by v·Δshare over the time len / v). Infinite: no limit.
    pub fn joints_sqr(
        &self,
        jumps: &AxisJumps,
        prev: &[f32; AXES],
        next: &[f32; AXES],
        len: f32,
    ) -> f32 {
        let (mut jump, mut curve) = (0.0f32, 0.0f32);
        for i in 0..AXES {
            let change = (next[i] - prev[i]).abs();
            let j = change * jumps.per_milli[i];
            if j > jump {
                jump = j;
            }
            let c = change * self.per_accel_milli[i];
            if c > curve {
                curve = c;
            }
        }
        // The lower of 1 / jump² and len / curve, one division.
        let jump_sqr = jump * jump;
        match curve > len * jump_sqr {
            true => len / curve,
            false => 1.0 / jump_sqr,
        }
    }

    /// [`Geometry::turn`] of the pen, whose acceleration is the same in
    /// every direction: `pen`'s.
    pub fn turn_pen(&self, prev: &[f32; AXES], next: &[f32; AXES], pen: &PenLimits) -> Turn {
        let mut cos = 0.0f32;
        for i in 0..AXES {
            cos -= prev[i] * next[i];
        }
        // `speed_sqr` divides by |next − prev| = √(2·(1 + cos)).
        let change = 2.0 * (1.0 + cos);
        let per_accel = match change > 0.0 {
            true => pen.per_accel * change * rsqrt_rough(change),
            false => 0.0,
        };
        Turn { cos, per_accel }
    }

    /// Grbl's junction speed² between moves along the unit vectors
    /// `prev` and `next` — the speed at which a circle tangent to both
    /// moves, passing `junction_deviation` from the corner, is driven at
    /// the acceleration the axes allow in the direction the velocity
    /// changes — in two halves, planned in parts of their own: this one
    /// sums over the axes, [`Turn::speed_sqr`] takes the roots.
    pub fn turn(&self, prev: &[f32; AXES], next: &[f32; AXES]) -> Turn {
        // Grbl's `junction_cos_theta` (1 = full reversal, -1 = straight
        // on), and 1 / the acceleration allowed along the change, per unit
        // of change: the axes' tightest, scaled by its share along each.
        let mut cos = 0.0f32;
        let mut per_accel = 0.0f32;
        for i in 0..AXES {
            // An axis idle in both moves adds nothing (sign bits aside).
            if (prev[i].to_bits() | next[i].to_bits()) << 1 == 0 {
                continue;
            }
            cos -= prev[i] * next[i];
            let a = (next[i] - prev[i]).abs() * self.per_accel_milli[i];
            // Not `f32::max`: a library call several times a compare's
            // cost on the AVR.
            if a > per_accel {
                per_accel = a;
            }
        }
        Turn { cos, per_accel }
    }
}

/// A junction's figures between [`Geometry::turn`] and
/// [`Turn::speed_sqr`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Turn {
    cos: f32,
    per_accel: f32,
}

impl Turn {
    /// Packed into two `u32`s: the planner keeps it in two of a block's
    /// fields that are written again before they are read (no RAM of its
    /// own).
    pub fn pack(self) -> (u32, u32) {
        (self.cos.to_bits(), self.per_accel.to_bits())
    }

    pub fn unpack((cos, per_accel): (u32, u32)) -> Turn {
        Turn {
            cos: f32::from_bits(cos),
            per_accel: f32::from_bits(per_accel),
        }
    }

    /// The junction speed², (milli-units/s)² (see [`Geometry::turn`]).
    pub fn speed_sqr(self, g: &Geometry) -> u64 {
        let Turn { cos, per_accel } = self;
        if cos > STRAIGHT {
            return 0;
        }
        if cos < -STRAIGHT {
            return u64::MAX;
        }
        // The change's length without summing its squares: |next − prev|²
        // = 2·(1 + cos) for unit vectors.
        let per_accel = per_accel * rsqrt_rough(2.0 * (1.0 + cos));
        let half = 0.5 * (1.0 - cos);
        let sin_half = half * rsqrt_rough(half);
        (g.deviation_milli * sin_half / ((1.0 - sin_half) * per_accel)) as u64
    }
}

/// `a · e / n` rounded down, in 32 bits when the product fits (a third
/// of a 64-bit division's cost on the AVR).
fn scale(a: u32, e: u32, n: u32) -> u64 {
    match a.checked_mul(e) {
        Some(p) => (p / n) as u64,
        None => a as u64 * e as u64 / n as u64,
    }
}

#[cfg(test)]
mod rsqrt_tests {
    #[test]
    fn rsqrt_matches_std() {
        let sweep = (0..20_000).map(|k| 1e-9f32 * 1.002f32.powi(k));
        for x in [1e-12f32, 0.25, 0.5, 1.0, 2.0, 3.0, 12345.678, 3e30]
            .into_iter()
            .chain(sweep)
        {
            let (got, want) = (super::rsqrt(x), 1.0 / x.sqrt());
            assert!((got - want).abs() <= want * 4e-7, "{x}: {got} vs {want}");
            let rough = super::rsqrt_rough(x);
            assert!(
                (rough - want).abs() <= want * 5e-6,
                "{x}: {rough} vs {want}"
            );
        }
    }
}

#[cfg(test)]
mod limits_tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// The crosswise search and its one division give what dividing
        /// for every axis gives.
        #[test]
        fn limits_as_every_axis_divided(
            steps in prop::array::uniform3(prop_oneof![Just(0u32), 1u32..5_000_000]),
            accel in prop::array::uniform3(1u32..2_000_000),
            rate in prop::array::uniform3(1u32..200_000),
        ) {
            let e = steps.iter().copied().max().unwrap();
            prop_assume!(e > 0);
            let mut g = Geometry::EMPTY;
            g.accel = accel;
            g.max_rate = rate;
            let (mut a, mut r) = (MAX_ACCEL as u64, u32::MAX as u64);
            for i in 0..AXES {
                if steps[i] > 0 {
                    a = a.min(accel[i] as u64 * e as u64 / steps[i] as u64);
                    r = r.min(rate[i] as u64 * e as u64 / steps[i] as u64);
                }
            }
            let block = StepBlock { steps, events: e, dir: 0 };
            prop_assert_eq!(g.limits(&block), (a.max(1) as u32, r.max(1) as u32));
        }
    }
}
