//! The three stepper channels of a RAMPS 1.4 board the machines drive.

/// Number of stepper channels the firmware drives (RAMPS X, Y, Z): every
/// machine has at most three motors, and each channel costs RAM in every
/// position, block and setting.
pub const AXES: usize = 3;

/// A stepper channel. The names are the string-art machine's; plotter
/// kinematics use the same channels for X, Y and the pen.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[repr(u8)]
pub enum Axis {
    /// Rotating board (RAMPS X driver). G-code word `C`, degrees.
    Base = 0,
    /// Radial carriage (RAMPS Y driver). G-code word `X`, mm.
    Radial = 1,
    /// Drill / needle along the tilted tool axis (RAMPS Z driver). Word `Z`, mm.
    Drill = 2,
}

impl Axis {
    pub const ALL: [Axis; AXES] = [Axis::Base, Axis::Radial, Axis::Drill];

    pub const fn index(self) -> usize {
        self as usize
    }

    /// Name used in logs and as the VCD signal prefix.
    pub const fn name(self) -> &'static str {
        match self {
            Axis::Base => "base",
            Axis::Radial => "radial",
            Axis::Drill => "drill",
        }
    }
}

/// A value per stepper channel.
pub type PerAxis<T> = [T; AXES];
