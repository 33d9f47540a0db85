//! The machine's figures in one typed structure. Defaults are the
//! string-art machine's (`docs/string-art.md`); `machine.txt`
//! on the card and `$` settings override them.

use crate::axis::{Axis, PerAxis};
use crate::machine::Machine;
use crate::text::ErrorKind;
use crate::units::{Milli, StepsPerUnit};
use core::mem::MaybeUninit;

/// Homing's figures (Grbl's `$24`–`$27`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HomingConfig {
    /// Bit `i`: channel `i` homes against its MIN switch.
    pub axes: u8,
    /// Home them at power-on (the flatbed's X).
    pub at_start: bool,
    /// Seeking and locating rates, steps/s.
    pub seek: u16,
    pub locate: u16,
    /// How far off the switch the axis ends, µm.
    pub pull_off_um: u16,
}

impl HomingConfig {
    pub const NONE: HomingConfig = HomingConfig {
        axes: 0,
        at_start: false,
        seek: 1000,
        locate: 100,
        pull_off_um: 1000,
    };
}

/// Per-axis figures. Rates are in steps so the step generator never converts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AxisConfig {
    /// Steps per axis unit (degree for the base, mm for the others).
    pub steps_per_unit: StepsPerUnit,
    /// Highest step rate, steps/s.
    pub max_rate: u32,
    /// Acceleration, steps/s².
    pub accel: u32,
    /// Level of the DIR pin that means the positive direction.
    pub dir_high_is_positive: bool,
    /// Level of the ENABLE pin that switches the driver on.
    pub enable_active_high: bool,
    /// What drives the motor: a STEP/DIR driver, or a ULN2003 board's
    /// four coil inputs.
    pub driver: Driver,
    /// Soft limits: the console refuses a target outside `travel` before
    /// any step. Off for an axis that turns freely (the base).
    pub soft_limits: bool,
    /// Travel allowed, thousandths of the unit, from the axis's zero.
    pub travel: (Milli, Milli),
}

/// What an axis's motor hangs on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Driver {
    /// A STEP/DIR driver (TB6600, A4988, …) on the RAMPS socket's STEP,
    /// DIR and ENABLE pins.
    StepDir = 0,
    /// A ULN2003 board driving a 28BYJ-48's coils in the half-step
    /// sequence from its IN1..IN4 (`pinmap::COILS`).
    Uln2003 = 1,
}

impl Driver {
    pub const ALL: [Driver; 2] = [Driver::StepDir, Driver::Uln2003];

    /// As `$x_driver` names it.
    pub fn name(self) -> taut_progmem::Text {
        taut_progmem::text_table!(Driver; [
            StepDir => "stepdir",
            Uln2003 => "uln2003",
        ])
        .get(self as usize)
    }

    /// The driver of discriminant `i`.
    pub fn from_index(i: u32) -> Option<Driver> {
        match i {
            0 => Some(Driver::StepDir),
            1 => Some(Driver::Uln2003),
            _ => None,
        }
    }

    /// The driver `text` names, in any case.
    pub fn parse(text: &[u8]) -> Option<Driver> {
        (0..2)
            .filter_map(Driver::from_index)
            .find(|d| d.name().eq_ignore_ascii_case(text))
    }
}

/// A 28BYJ-48 at 5 V pulls out above ~1 000 half-steps/s: an axis
/// switched to coil drive is slowed to this (its `max_rate` stays
/// settable).
pub const COIL_MAX_RATE: u32 = 1000;

/// Grbl's `$1` of 255: the drivers stay on once motion has switched them on.
pub const KEEP_DRIVERS_ON: u8 = 255;

/// Pulse timing of the STEP/DIR/ENABLE interface, µs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PulseTiming {
    /// STEP high time.
    pub step_pulse_us: u8,
    /// DIR stable before the STEP rising edge.
    pub dir_setup_us: u8,
    /// ENABLE stable before DIR may change.
    pub enable_setup_us: u8,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MachineConfig {
    pub axes: PerAxis<AxisConfig>,
    pub pulse: PulseTiming,
    /// Grbl's junction deviation, µm: how far the path may cut a corner at
    /// the junction speed. Larger means faster corners.
    pub junction_deviation_um: u32,
    /// How far an arc's chords may stray from the circle, µm (Grbl's
    /// `$12`, 0.01 mm by default).
    pub arc_tolerance_um: u32,
    /// The pen's top speed, mm/min, and its acceleration, mm/s², where
    /// the kinematics are not linear (the whiteboard, the arm): `F` is
    /// the pen's speed there, and each joint keeps its own `max_rate` and
    /// `accel` too. The linear machines' axes are the pen's: theirs are
    /// their own limits, as in Grbl.
    pub pen_max_feed: u32,
    pub pen_accel: u32,
    /// Which of the five machines this is.
    pub machine: Machine,
    /// The plotters' pen servo.
    pub pen: PenConfig,
    /// Which axes home against their MIN switches, and how.
    pub homing: HomingConfig,
    /// `G4 P` in milliseconds (Marlin's reading, what the Inkscape
    /// "unicorn" extension writes) rather than seconds (Grbl's).
    pub dwell_p_ms: bool,
    /// Its arms or strings, for the machines that have them.
    pub geometry: Geometry,
    /// Grbl's `$10`: what status reports carry (bit 0: `MPos` rather than
    /// `WPos`, bit 1: the buffer state `Bf:`).
    pub status_report: u8,
    /// Grbl's `$13`: positions and feeds in reports in inches.
    pub report_inches: bool,
    /// The string-art machine's nails and winding needle.
    pub winding: WindingConfig,
    /// Grbl's `$1`: how long the drivers stay on once motion stands, ms;
    /// [`KEEP_DRIVERS_ON`] (255) keeps them on.
    pub idle_delay_ms: u8,
}

/// What the needle must clear while winding (`stringart::clearance`): the
/// nails' and the needle's diameters, µm.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WindingConfig {
    pub nail_um: u16,
    pub needle_um: u16,
}

impl WindingConfig {
    /// A 1.8 mm panel pin and a 1.5 mm hollow needle the thread runs
    /// through.
    pub const DEFAULT: WindingConfig = WindingConfig {
        nail_um: 1800,
        needle_um: 1500,
    };
    /// Either diameter, at most (`stringart::clearance` relies on it).
    pub const MAX_UM: u16 = 10_000;
    pub const MIN_UM: u16 = 100;
}

/// The arm or string geometry of the non-linear machines, mm.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Geometry {
    /// SCARA: the arms L1, L2. Whiteboard: `length_1` is the distance
    /// between the two strings' exits; `length_2` is unused.
    pub lengths: [Milli; 2],
    /// SCARA: the shoulder joint's place in the drawing's frame.
    /// Whiteboard: the drawing's (0, 0) from the left string's exit (y up,
    /// so below the motors is negative).
    pub origin: [Milli; 2],
    /// SCARA: the elbow crosstalk ratio n_S / n_E (0/1: none).
    pub crosstalk: StepsPerUnit,
}

impl Geometry {
    pub const NONE: Geometry = Geometry {
        lengths: [Milli(0); 2],
        origin: [Milli(0); 2],
        crosstalk: StepsPerUnit::new(0, 1),
    };
}

/// An SG90-class pen servo on SERVO0 (D11): angles 0–180° are pulses of
/// 1–2 ms every 20 ms.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PenConfig {
    /// `M5`, `M300 S50`, a `Z` above 0: degrees.
    pub up_deg: u8,
    /// `M3`, `M300 S30`, a `Z` of 0 or below.
    pub down_deg: u8,
    /// How long the pen takes to get there, ms: motion waits for it.
    pub settle_ms: u16,
}

impl PenConfig {
    /// The Inkscape "unicorn" extension's angles (`M300 S50` up, `S30`
    /// down), 150 ms to settle.
    pub const UNICORN: PenConfig = PenConfig {
        up_deg: 50,
        down_deg: 30,
        settle_ms: 150,
    };

    /// The servo pulse of `deg` (clamped to 180), µs, rounded.
    pub const fn pulse_us(deg: u8) -> u16 {
        let deg = if deg > 180 { 180 } else { deg as u32 };
        (1000 + (deg * 1000 + 90) / 180) as u16
    }
}

/// TB6600 defaults: 5 µs pulse, 5 µs DIR set-up, 5 µs ENABLE set-up.
pub const TB6600: PulseTiming = PulseTiming {
    step_pulse_us: 5,
    dir_setup_us: 5,
    enable_setup_us: 5,
};

/// The radial carriage's travel from its zero at the board's edge: to the
/// centre of a 45 cm board inwards, and past the outer winding radius
/// (nail radius + 2.9 cm, nails 1.5 cm inside the edge) outwards.
pub const RADIAL_TRAVEL_MM: (i32, i32) = (-450, 30);
/// The drill's travel from its zero on the board's surface (positive is
/// down, along the tilted axis): 3 cm up, and the 1 cm hole (10.4 mm of
/// travel at 74.333°) with 1.6 mm to spare down.
pub const DRILL_TRAVEL_MM: (i32, i32) = (-30, 12);

impl MachineConfig {
    /// The string-art machine: base 200×6×8 = 9600 steps per turn, radial
    /// 200/5 mm × 8 = 32 steps/mm, drill 200/12 mm × 8 = 1600 steps per 12 mm.
    pub const STRING_ART: MachineConfig = seed(Machine::StringArt);

    /// The seed's figures, a copy of them from a table in flash (1 KB
    /// less than the code that built them).
    pub fn defaults(machine: Machine) -> MachineConfig {
        seeds().get(machine as usize)
    }

    /// [`MachineConfig::defaults`] in place of `self`: no copy on the
    /// (AVR's small) stack.
    #[inline(never)]
    pub fn load_defaults(&mut self, machine: Machine) {
        seeds().get_into(machine as usize, self)
    }

    /// [`MachineConfig::defaults`] written into `out`, in place.
    pub fn init_defaults(machine: Machine, out: &mut MaybeUninit<MachineConfig>) -> &mut Self {
        seeds().init(machine as usize, out)
    }

    pub fn axis(&self, i: usize) -> &AxisConfig {
        &self.axes[i]
    }

    /// Check the figures a user may have overridden, each and against
    /// each other; the error says what is wrong.
    pub fn validate(&self) -> Result<(), ErrorKind> {
        for (a, axis) in Axis::ALL.into_iter().zip(&self.axes) {
            if axis.steps_per_unit.num == 0 || axis.steps_per_unit.den == 0 {
                return Err(ErrorKind::Invalid(taut_progmem::text!("steps_per_unit")));
            }
            if axis.max_rate == 0 || axis.max_rate > 200_000 {
                return Err(ErrorKind::Invalid(taut_progmem::text!("max_rate")));
            }
            if axis.accel == 0 {
                return Err(ErrorKind::Invalid(taut_progmem::text!("accel")));
            }
            if axis.travel.0 > axis.travel.1 {
                return Err(ErrorKind::Invalid(taut_progmem::text!(
                    "travel_min above travel_max"
                )));
            }
            // The pulse must fit the step period at the highest rate, with
            // as long a low time (the step interrupt holds it high).
            let max_us = 500_000 / axis.max_rate;
            if u32::from(self.pulse.step_pulse_us) > max_us {
                return Err(ErrorKind::PulseTooLong {
                    axis: a,
                    machine: self.machine,
                    max_us,
                });
            }
        }
        if self.pulse.step_pulse_us == 0 {
            return Err(ErrorKind::Invalid(taut_progmem::text!("step_pulse_us")));
        }
        Ok(())
    }
}

impl Default for MachineConfig {
    fn default() -> Self {
        Self::STRING_ART
    }
}

/// The seeds' figures, in flash.
fn seeds() -> taut_progmem::Table<MachineConfig> {
    taut_progmem::table!(MachineConfig; 5; [
        seed(Machine::StringArt),
        seed(Machine::Drum),
        seed(Machine::Flatbed),
        seed(Machine::Whiteboard),
        seed(Machine::Scara),
    ])
}

/// The seed's figures, at compile time.
const fn seed(machine: Machine) -> MachineConfig {
    match machine {
        Machine::StringArt => {
            let mut cfg = plotter(
                machine,
                [
                    axis(StepsPerUnit::new(9600, 360), 2000, 500, None),
                    axis(StepsPerUnit::new(32, 1), 2000, 500, Some(RADIAL_TRAVEL_MM)),
                ],
            );
            cfg.axes[2] = axis(
                StepsPerUnit::new(1600, 12),
                2000,
                500,
                Some(DRILL_TRAVEL_MM),
            );
            cfg
        }
        // 28BYJ-48s on ULN2003 boards, half-stepped: 4096 half-steps a
        // turn (2048 full steps); a GT2 belt pulls 40 mm a turn; the 90 mm
        // drum carries π·90 mm of paper a turn. At most the motor's
        // pull-out rate; the coils released a quarter second after the
        // drawing stops (they heat when held), kept through a pen lift.
        Machine::Drum => {
            let mut x = axis(
                StepsPerUnit::new(4096, 40),
                COIL_MAX_RATE,
                1500,
                Some((0, 200)),
            );
            let mut y = axis(
                StepsPerUnit::new(4_096_000, 282_743),
                COIL_MAX_RATE,
                1500,
                None,
            );
            x.driver = Driver::Uln2003;
            y.driver = Driver::Uln2003;
            let mut cfg = plotter(machine, [x, y]);
            cfg.idle_delay_ms = 250;
            cfg
        }
        // EasyDriver at 1/8 step: 0.025 mm a step; X 140 mm, homed
        // against its switch at power-on.
        Machine::Flatbed => {
            let mut cfg = plotter(
                machine,
                [
                    axis(StepsPerUnit::new(40, 1), 2000, 4000, Some((0, 140))),
                    axis(StepsPerUnit::new(40, 1), 2000, 4000, None),
                ],
            );
            cfg.homing.axes = 1;
            cfg.homing.at_start = true;
            cfg
        }
        // 2000 steps a turn on a 9-tooth sprocket of ½" chain
        // (114.3 mm a turn); the motors 1.2 m apart, the drawing's
        // origin 0.6 m right of and below the left one.
        Machine::Whiteboard => {
            let chain = axis(StepsPerUnit::new(20_000, 1143), 2000, 1000, None);
            let mut cfg = plotter(machine, [chain, chain]);
            // A chain carries at most the pen's speed and acceleration
            // (114 mm/s and 57 mm/s² here): the pen's keep within them.
            cfg.pen_accel = 50;
            cfg.geometry = Geometry {
                lengths: [Milli::from_units(1200), Milli(0)],
                origin: [Milli::from_units(600), Milli::from_units(-600)],
                crosstalk: StepsPerUnit::new(0, 1),
            };
            cfg
        }
        // Marlin's MORGAN_SCARA figures: 150 mm arms, the shoulder at
        // (100, −56); 200 × 16 steps and a 3:1 belt a turn, ECR 3. The
        // pen's 100 mm/s² keeps the joints (75 °/s²) within theirs over
        // most of the reach.
        Machine::Scara => {
            let joint = axis(StepsPerUnit::new(9600, 360), 2000, 2000, None);
            let mut cfg = plotter(machine, [joint, joint]);
            cfg.geometry = Geometry {
                lengths: [Milli::from_units(150), Milli::from_units(150)],
                origin: [Milli::from_units(100), Milli::from_units(-56)],
                crosstalk: StepsPerUnit::new(3, 1),
            };
            cfg
        }
    }
}

/// A plotter axis: `travel` in mm enables the soft limits.
const fn axis(
    steps_per_unit: StepsPerUnit,
    max_rate: u32,
    accel: u32,
    travel: Option<(i32, i32)>,
) -> AxisConfig {
    let (soft_limits, (min, max)) = match travel {
        Some(t) => (true, t),
        None => (false, (0, 0)),
    };
    AxisConfig {
        steps_per_unit,
        max_rate,
        accel,
        dir_high_is_positive: true,
        enable_active_high: true,
        driver: Driver::StepDir,
        soft_limits,
        travel: (Milli::from_units(min), Milli::from_units(max)),
    }
}

/// Two drawing axes; the third channel is a spare Z (the pen is a
/// servo).
const fn plotter(machine: Machine, xy: [AxisConfig; 2]) -> MachineConfig {
    let spare = axis(StepsPerUnit::new(80, 1), 2000, 500, None);
    MachineConfig {
        axes: [xy[0], xy[1], spare],
        pulse: TB6600,
        junction_deviation_um: 10,
        arc_tolerance_um: 10,
        pen_max_feed: 6000,
        pen_accel: 100,
        machine,
        pen: PenConfig::UNICORN,
        homing: HomingConfig::NONE,
        dwell_p_ms: !machine.is_string_art(),
        geometry: Geometry::NONE,
        // Machine positions and the buffer state: CNCjs sizes its
        // character count from `Bf:`.
        status_report: 3,
        report_inches: false,
        winding: WindingConfig::DEFAULT,
        idle_delay_ms: KEEP_DRIVERS_ON,
    }
}

/// Two identical axes, 100 steps per unit, 4000 steps/s, 1000 steps/s²,
/// junction deviation 50 µm: corners are plain geometry (planner tests).
#[cfg(test)]
pub(crate) fn square() -> MachineConfig {
    let axis = AxisConfig {
        steps_per_unit: StepsPerUnit::new(100, 1),
        max_rate: 4000,
        accel: 1000,
        ..MachineConfig::STRING_ART.axes[0]
    };
    MachineConfig {
        axes: [axis; crate::axis::AXES],
        junction_deviation_um: 50,
        ..MachineConfig::STRING_ART
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_servo_pulse_table() {
        let table: [(u8, u16); 6] = [
            (0, 1000),
            (30, 1167),
            (50, 1278),
            (90, 1500),
            (180, 2000),
            (255, 2000),
        ];
        for (deg, us) in table {
            assert_eq!(PenConfig::pulse_us(deg), us, "{deg}°");
        }
    }

    #[test]
    fn defaults_match_the_spec() {
        let c = MachineConfig::default();
        assert_eq!(c.axes[0].steps_per_unit.steps(Milli(360_000)), 9600);
        assert_eq!(c.axes[1].steps_per_unit.steps(Milli(10_000)), 320);
        assert_eq!(c.axes[2].steps_per_unit.steps(Milli(120_000)), 16000);
        assert!(c.validate().is_ok());
    }

    #[test]
    fn a_pulse_longer_than_half_a_step_at_the_max_rate_is_refused() {
        let mut c = MachineConfig::default();
        c.pulse.step_pulse_us = 250;
        assert!(c.validate().is_ok(), "2000 steps/s: 500 µs periods");
        c.pulse.step_pulse_us = 251;
        assert_eq!(
            c.validate(),
            Err(ErrorKind::PulseTooLong {
                axis: Axis::Base,
                machine: Machine::StringArt,
                max_us: 250
            })
        );
    }
}
