//! The four stepper channels of a RAMPS 1.4 board and what they drive.

/// Number of stepper channels the firmware drives (RAMPS X, Y, Z, E0).
pub const AXES: usize = 4;

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
    /// Spare channel (RAMPS E0 driver). Word `A`.
    Aux = 3,
}

impl Axis {
    pub const ALL: [Axis; AXES] = [Axis::Base, Axis::Radial, Axis::Drill, Axis::Aux];

    pub const fn index(self) -> usize {
        self as usize
    }

    /// Name used in logs and as the VCD signal prefix.
    pub const fn name(self) -> &'static str {
        match self {
            Axis::Base => "base",
            Axis::Radial => "radial",
            Axis::Drill => "drill",
            Axis::Aux => "aux",
        }
    }
}

/// A value per stepper channel.
pub type PerAxis<T> = [T; AXES];
