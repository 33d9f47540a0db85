//! Kinematics: the machine's coordinates (what the G-code words name) ↔
//! absolute motor positions in steps.
//!
//! A [`Position`] holds one coordinate per channel in [`Milli`] (µm or
//! millidegrees); coordinate `i` is named by the G-code word
//! [`Kinematics::words`]`[i]`. Steps are always computed from the absolute
//! target and rounded once, so positions never drift.
//!
//! Linear kinematics (cylindrical, cartesian) map each coordinate to its own
//! channel with exact integer arithmetic. Polargraph and SCARA are not
//! linear: a straight line in space is curved in joint space, so a move is
//! cut by [`Segmenter`] into short pieces, each converted with f32/libm.
//! Cost on the AVR per piece: sqrtf ≈ 7 300 cycles, atan2f ≈ 20 000,
//! sinf/cosf ≈ 36 000, acosf ≈ 25 000 — a SCARA inverse is ≈ 60 000 cycles
//! (≈ 4 ms at 16 MHz), a polargraph inverse ≈ 20 000 (≈ 1.3 ms). That bounds
//! the piece rate, never the step rate: nothing here runs per step.

mod linear;
mod polargraph;
mod scara;
mod segmenter;

pub use linear::Linear;
pub use polargraph::Polargraph;
pub use scara::Scara;
pub use segmenter::{Piece, Segmenter};

use crate::axis::{PerAxis, AXES};
use crate::config::MachineConfig;
use crate::fmath::magnitude;
use crate::machine::Machine;
use crate::units::{div_round, Milli, StepsPerUnit};

/// Machine coordinates, one per channel, in thousandths of the unit.
pub type Position = PerAxis<Milli>;
/// Absolute motor positions, one per channel.
pub type Steps = PerAxis<i32>;
/// What rounding took off each channel's step count: the exact position
/// is `steps + frac / 256` (|frac| ≤ 128, saturated to `i8`). The
/// planner reads a path's curvature in joint space from it, not from the
/// rounded counts, whose ±½ step would look like a change of speed.
pub type Frac = PerAxis<i8>;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KinError {
    /// The position is outside the machine's reach.
    Unreachable,
    /// The step count does not fit an `i32`.
    Overflow,
}

impl KinError {
    pub const fn message(self) -> &'static str {
        match self {
            KinError::Unreachable => "unreachable",
            KinError::Overflow => "too far",
        }
    }
}

pub trait Kinematics {
    /// Absolute step targets of an absolute position.
    fn inverse(&self, pos: &Position) -> Result<Steps, KinError>;
    /// [`Kinematics::inverse`] with what rounding took off each channel.
    fn inverse_fine(&self, pos: &Position) -> Result<(Steps, Frac), KinError> {
        self.inverse(pos).map(|s| (s, [0; AXES]))
    }
    /// The position the motors are at.
    fn forward(&self, steps: &Steps) -> Position;
    /// True when a straight line in space is a straight line in joint
    /// space, so moves need no segmentation.
    fn is_linear(&self) -> bool;
    /// The G-code word (ASCII letter) naming each coordinate.
    fn words(&self) -> [u8; AXES];
    /// Whether the whole straight line from `a` to `b` is within reach.
    /// Its ends are enough where the reach is convex (linear machines,
    /// the hanging plotter's half-plane); the arm also keeps its distance
    /// from the shoulder. Geometry only: no inverse per piece, which on
    /// the AVR would cost ms each.
    fn reaches_line(&self, a: &Position, b: &Position) -> bool {
        self.inverse(a).is_ok() && self.inverse(b).is_ok()
    }
    /// Longest piece a straight move is cut into, µm, where the
    /// kinematics are not linear: the pen then strays from the line by
    /// far less than a step (`Segmenter`'s tests measure it).
    fn piece_um(&self) -> u32 {
        u32::MAX
    }
}

/// Each coordinate scaled onto its own channel: the whole of a linear
/// kinematics, and the pen/aux channels of the others.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ChannelScale(pub PerAxis<StepsPerUnit>);

impl ChannelScale {
    pub fn from_config(config: &MachineConfig) -> Self {
        ChannelScale(config.axes.map(|a| a.steps_per_unit))
    }

    /// Steps of one coordinate, rounded once from the absolute target.
    pub fn steps(&self, axis: usize, target: Milli) -> Result<i32, KinError> {
        steps_of(self.0[axis], target)
    }

    pub fn milli(&self, axis: usize, steps: i32) -> Milli {
        self.0[axis].milli(steps)
    }

    fn all_steps(&self, pos: &Position) -> Result<Steps, KinError> {
        let mut out = [0; AXES];
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.steps(i, pos[i])?;
        }
        Ok(out)
    }

    fn all_milli(&self, steps: &Steps) -> Position {
        core::array::from_fn(|i| self.milli(i, steps[i]))
    }
}

/// The scale of a kinematics that works its two joints (channels 0 and 1)
/// out in floats: their steps per unit as floats, made once (a float
/// division each, ~600 cycles on the AVR, was part of every piece), and
/// the pen's channel (2) exactly.
#[derive(Clone, Copy, Debug, PartialEq)]
struct JointScale {
    per_unit: [f32; 2],
    pen: StepsPerUnit,
}

impl JointScale {
    fn new(scale: &ChannelScale) -> Self {
        JointScale {
            per_unit: [scale.0[0].as_f32(), scale.0[1].as_f32()],
            pen: scale.0[2],
        }
    }

    /// Steps of a joint value computed in floating point (mm or degrees),
    /// and what the rounding took off, in 1/256 step.
    fn steps_fine(&self, joint: usize, value: f32) -> Result<(i32, i8), KinError> {
        let exact = value * self.per_unit[joint];
        let s = libm::roundf(exact);
        // 2^31 is exact in f32; NaN's magnitude is above it. (Compared as
        // bits: `fmath::magnitude`.)
        const I32_END: f32 = 2_147_483_648.0;
        if magnitude(s) < I32_END.to_bits() || s.to_bits() == (-I32_END).to_bits() {
            // Saturating: ±½ step is ±128.
            Ok((s as i32, ((exact - s) * 256.0) as i8))
        } else {
            Err(KinError::Overflow)
        }
    }

    /// The joint value (mm or degrees) of a step count.
    fn value_f32(&self, joint: usize, steps: i32) -> f32 {
        steps as f32 / self.per_unit[joint]
    }

    /// The pen channel's steps of `pos`; the joints' 0, for the caller to
    /// work out.
    fn pen_steps(&self, pos: &Position) -> Result<Steps, KinError> {
        Ok([0, 0, steps_of(self.pen, pos[2])?])
    }

    /// The pen channel's place at `steps`; the joints' 0, for the caller
    /// to work out.
    fn pen_milli(&self, steps: &Steps) -> Position {
        [Milli::ZERO, Milli::ZERO, self.pen.milli(steps[2])]
    }
}

/// Steps of one coordinate, rounded once from the absolute target.
fn steps_of(spu: StepsPerUnit, target: Milli) -> Result<i32, KinError> {
    let n = target.0 as i64 * spu.num as i64;
    let steps = div_round(n, spu.den as i64 * Milli::SCALE as i64);
    i32::try_from(steps).map_err(|_| KinError::Overflow)
}

/// µm → mm for the float kinematics: a product, within an ulp of the
/// quotient (a float division is ~4 times a product on the AVR).
fn mm(m: Milli) -> f32 {
    m.0 as f32 * (1.0 / Milli::SCALE as f32)
}

/// mm → µm, rounded.
fn milli(mm: f32) -> Milli {
    Milli(libm::roundf(mm * Milli::SCALE as f32) as i32)
}

/// One of the kinematics, chosen at run time from the machine's config.
#[derive(Clone, Copy, Debug)]
pub enum AnyKinematics {
    /// The string-art machine or a cartesian plotter.
    Linear(Linear),
    Polargraph(Polargraph),
    Scara(Scara),
}

impl AnyKinematics {
    /// The kinematics of the configured machine; an error when its
    /// geometry cannot be (arms of no length, a drawing above the motors).
    pub fn of(cfg: &MachineConfig) -> Result<AnyKinematics, KinError> {
        // Each machine's made on its own: one kinematics on the stack at a
        // time (this runs under the settings' checks, deep at boot).
        let scale = || ChannelScale::from_config(cfg);
        let g = &cfg.geometry;
        match cfg.machine {
            Machine::StringArt => Ok(AnyKinematics::Linear(Linear::cylindrical(cfg))),
            Machine::Drum | Machine::Flatbed => {
                Ok(AnyKinematics::Linear(Linear::cartesian(scale())))
            }
            Machine::Whiteboard => Polargraph::new(&scale(), g).map(AnyKinematics::Polargraph),
            Machine::Scara => Scara::new(&scale(), g).map(AnyKinematics::Scara),
        }
    }
}

impl Kinematics for AnyKinematics {
    fn inverse(&self, pos: &Position) -> Result<Steps, KinError> {
        match self {
            AnyKinematics::Linear(k) => k.inverse(pos),
            AnyKinematics::Polargraph(k) => k.inverse(pos),
            AnyKinematics::Scara(k) => k.inverse(pos),
        }
    }

    fn inverse_fine(&self, pos: &Position) -> Result<(Steps, Frac), KinError> {
        match self {
            AnyKinematics::Linear(k) => k.inverse_fine(pos),
            AnyKinematics::Polargraph(k) => k.inverse_fine(pos),
            AnyKinematics::Scara(k) => k.inverse_fine(pos),
        }
    }

    fn piece_um(&self) -> u32 {
        match self {
            AnyKinematics::Linear(k) => k.piece_um(),
            AnyKinematics::Polargraph(k) => k.piece_um(),
            AnyKinematics::Scara(k) => k.piece_um(),
        }
    }

    fn forward(&self, steps: &Steps) -> Position {
        match self {
            AnyKinematics::Linear(k) => k.forward(steps),
            AnyKinematics::Polargraph(k) => k.forward(steps),
            AnyKinematics::Scara(k) => k.forward(steps),
        }
    }

    fn reaches_line(&self, a: &Position, b: &Position) -> bool {
        match self {
            AnyKinematics::Linear(k) => k.reaches_line(a, b),
            AnyKinematics::Polargraph(k) => k.reaches_line(a, b),
            AnyKinematics::Scara(k) => k.reaches_line(a, b),
        }
    }

    fn is_linear(&self) -> bool {
        match self {
            AnyKinematics::Linear(k) => k.is_linear(),
            AnyKinematics::Polargraph(k) => k.is_linear(),
            AnyKinematics::Scara(k) => k.is_linear(),
        }
    }

    fn words(&self) -> [u8; AXES] {
        match self {
            AnyKinematics::Linear(k) => k.words(),
            AnyKinematics::Polargraph(k) => k.words(),
            AnyKinematics::Scara(k) => k.words(),
        }
    }
}
