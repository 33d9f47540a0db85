//! The machine's settings by name, as `$$` lists them, `$name=value` sets
//! them and `machine.txt` overrides them: `base_max_rate = 2000`,
//! `drill_steps_per_unit = 1600/12`, `step_pulse_us = 5`.
//!
//! Names are composed (axis name + `_` + field) rather than stored whole:
//! every string costs SRAM on the AVR. Printing uses ufmt only.

use crate::axis::{Axis, AXES};
use crate::config::{Driver, MachineConfig, WindingConfig, COIL_MAX_RATE};
use crate::kinematics::AnyKinematics;
use crate::machine::Machine;
use crate::text::num::{parse_milli, parse_ratio, parse_u32, trim, NumError};
use crate::text::ErrorKind;
use crate::units::{Decimal, Milli, StepsPerUnit};
use taut_progmem::{text, Text};
use ufmt::{uDisplay, uWrite, uwrite, Formatter};

pub mod eeprom;
pub mod grbl;
pub mod image;
pub mod record;

/// A setting value that did not fit: what, and at which byte of the value.
pub type SettingError = NumError;

/// The figures every axis has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AxisField {
    /// Exact `num/den` steps per degree (base) or mm.
    StepsPerUnit,
    /// Steps/s.
    MaxRate,
    /// Steps/s².
    Accel,
    /// 1: DIR low is the positive direction.
    DirInvert,
    /// 1: the driver is on while ENABLE is high.
    EnableActiveHigh,
    /// 1: targets outside the travel are refused (Grbl's `$20`, per axis).
    SoftLimits,
    /// The travel's ends, units from the zero (Grbl's `$130…`, both ends).
    TravelMin,
    TravelMax,
    /// `stepdir` or `uln2003` (a 28BYJ-48's coils).
    Driver,
}

/// The machine-wide figures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GlobalField {
    /// Which machine: `string_art`, `drum`, `flatbed`, `whiteboard`,
    /// `scara`. Setting it loads that machine's defaults whole, so it comes
    /// first in `$$` and in `machine.txt`.
    Machine,
    StepPulseUs,
    DirSetupUs,
    EnableSetupUs,
    JunctionDeviationUm,
    ArcToleranceUm,
    /// SCARA: the arms; whiteboard: `length_1` is the motors' distance.
    Length1,
    Length2,
    /// SCARA: the shoulder's place; whiteboard: the drawing's origin from
    /// the left motor.
    OriginX,
    OriginY,
    /// SCARA: the elbow crosstalk ratio (0: none).
    Crosstalk,
    /// The pen servo's angles, degrees, and its settle time, ms.
    PenUp,
    PenDown,
    PenSettleMs,
    /// 1: `G4 P` in milliseconds (Marlin), 0: in seconds (Grbl).
    DwellPMs,
    /// Homing: the axes (bit per channel), at power-on or not, the seek
    /// and locate rates (steps/s), the pull-off (mm).
    HomingAxes,
    HomingAtStart,
    HomingSeek,
    HomingLocate,
    HomingPullOff,
    /// Grbl's `$10` and `$13`: the status report's fields, and inches.
    StatusReport,
    ReportInches,
    /// String art: the nails' and the winding needle's diameters (mm),
    /// which the needle's clearance from the nails is worked out from.
    NailDiameter,
    NeedleDiameter,
    /// The pen's top speed (mm/min) and acceleration (mm/s²) on the
    /// whiteboard and the arm, whose joints keep their own limits too.
    PenMaxFeed,
    PenAccel,
    /// Grbl's `$1`: ms the drivers stay on once motion stands (255: on).
    StepIdleDelay,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Setting {
    Axis(Axis, AxisField),
    Global(GlobalField),
}

/// A setting's value, printable for `$$`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Value {
    Number(u32),
    Ratio(StepsPerUnit),
    /// Thousandths of a unit, printed `-450.000`.
    Milli(Milli),
    Machine(Machine),
    Driver(Driver),
}

const AXIS_FIELDS: [AxisField; 9] = [
    AxisField::StepsPerUnit,
    AxisField::MaxRate,
    AxisField::Accel,
    AxisField::DirInvert,
    AxisField::EnableActiveHigh,
    AxisField::SoftLimits,
    AxisField::TravelMin,
    AxisField::TravelMax,
    AxisField::Driver,
];

const GLOBAL_FIELDS: [GlobalField; 27] = [
    GlobalField::Machine,
    GlobalField::StepPulseUs,
    GlobalField::DirSetupUs,
    GlobalField::EnableSetupUs,
    GlobalField::JunctionDeviationUm,
    GlobalField::ArcToleranceUm,
    GlobalField::Length1,
    GlobalField::Length2,
    GlobalField::OriginX,
    GlobalField::OriginY,
    GlobalField::Crosstalk,
    GlobalField::PenUp,
    GlobalField::PenDown,
    GlobalField::PenSettleMs,
    GlobalField::DwellPMs,
    GlobalField::HomingAxes,
    GlobalField::HomingAtStart,
    GlobalField::HomingSeek,
    GlobalField::HomingLocate,
    GlobalField::HomingPullOff,
    GlobalField::StatusReport,
    GlobalField::ReportInches,
    GlobalField::NailDiameter,
    GlobalField::NeedleDiameter,
    GlobalField::PenMaxFeed,
    GlobalField::PenAccel,
    GlobalField::StepIdleDelay,
];

// The tables above in order of discriminant: `at` works them out.
const _: () = {
    let mut i = 0;
    while i < GLOBAL_FIELDS.len() {
        assert!(GLOBAL_FIELDS[i] as usize == i);
        i += 1;
    }
    let mut i = 0;
    while i < AXIS_FIELDS.len() {
        assert!(AXIS_FIELDS[i] as usize == i);
        i += 1;
    }
};

impl GlobalField {
    /// `GLOBAL_FIELDS[i]`, worked out rather than looked up: a table
    /// would sit in SRAM on the AVR.
    fn at(i: usize) -> Option<GlobalField> {
        use GlobalField::*;
        Some(match i {
            0 => Machine,
            1 => StepPulseUs,
            2 => DirSetupUs,
            3 => EnableSetupUs,
            4 => JunctionDeviationUm,
            5 => ArcToleranceUm,
            6 => Length1,
            7 => Length2,
            8 => OriginX,
            9 => OriginY,
            10 => Crosstalk,
            11 => PenUp,
            12 => PenDown,
            13 => PenSettleMs,
            14 => DwellPMs,
            15 => HomingAxes,
            16 => HomingAtStart,
            17 => HomingSeek,
            18 => HomingLocate,
            19 => HomingPullOff,
            20 => StatusReport,
            21 => ReportInches,
            22 => NailDiameter,
            23 => NeedleDiameter,
            24 => PenMaxFeed,
            25 => PenAccel,
            26 => StepIdleDelay,
            _ => return None,
        })
    }
}

impl AxisField {
    /// `AXIS_FIELDS[i % 9]`, worked out (see [`GlobalField::at`]).
    fn at(i: usize) -> AxisField {
        use AxisField::*;
        match i % AXIS_FIELDS.len() {
            0 => StepsPerUnit,
            1 => MaxRate,
            2 => Accel,
            3 => DirInvert,
            4 => EnableActiveHigh,
            5 => SoftLimits,
            6 => TravelMin,
            7 => TravelMax,
            _ => Driver,
        }
    }
}

/// Largest denominator of steps per unit (nine decimals): Grbl's units
/// of `$110` and `$120` are then worked out in 64 bits.
pub const MAX_DEN: u32 = 1_000_000_000;

/// Number of settings; [`Setting::index`] is below it.
pub const COUNT: usize = AXES * AXIS_FIELDS.len() + GLOBAL_FIELDS.len();

impl AxisField {
    pub fn name(self) -> Text {
        taut_progmem::text_table!(AxisField; [
            StepsPerUnit => "steps_per_unit",
            MaxRate => "max_rate",
            Accel => "accel",
            DirInvert => "dir_invert",
            EnableActiveHigh => "enable_active_high",
            SoftLimits => "soft_limits",
            TravelMin => "travel_min",
            TravelMax => "travel_max",
            Driver => "driver",
        ])
        .get(self as usize)
    }
}

impl GlobalField {
    pub fn name(self) -> Text {
        taut_progmem::text_table!(GlobalField; [
            Machine => "machine",
            StepPulseUs => "step_pulse_us",
            DirSetupUs => "dir_setup_us",
            EnableSetupUs => "enable_setup_us",
            JunctionDeviationUm => "junction_deviation_um",
            ArcToleranceUm => "arc_tolerance_um",
            Length1 => "length_1",
            Length2 => "length_2",
            OriginX => "origin_x",
            OriginY => "origin_y",
            Crosstalk => "crosstalk",
            PenUp => "pen_up",
            PenDown => "pen_down",
            PenSettleMs => "pen_settle_ms",
            DwellPMs => "dwell_p_ms",
            HomingAxes => "homing_axes",
            HomingAtStart => "homing_at_start",
            HomingSeek => "homing_seek",
            HomingLocate => "homing_locate",
            HomingPullOff => "homing_pull_off",
            StatusReport => "status_report",
            ReportInches => "report_inches",
            NailDiameter => "nail_diameter",
            NeedleDiameter => "needle_diameter",
            PenMaxFeed => "pen_max_feed",
            PenAccel => "pen_accel",
            StepIdleDelay => "step_idle_delay_ms",
        ])
        .get(self as usize)
    }
}

/// Every setting in `$$` order: the machine, per axis, then the other
/// machine-wide ones. By index ([`Setting::at`]): chained iterators over
/// the axes and the fields were hundreds of bytes more on the AVR.
pub fn all() -> impl Iterator<Item = Setting> {
    (0..COUNT).filter_map(Setting::at)
}

/// Calls `f` with every setting and its value, in `$$` order.
pub fn for_each(cfg: &MachineConfig, mut f: impl FnMut(Setting, Value)) {
    for s in all() {
        f(s, s.get(cfg));
    }
}

/// Line `index` of `$$`: Grbl's numbered settings, then ours by name,
/// the console's `$flow` and `$uart1_baud` last (0 on the string-art
/// machine, where UART1 is off: D18 is its `zero_drill` button).
pub fn listed(index: usize, cfg: &MachineConfig, ex: &grbl::Extras) -> Option<Listed> {
    Some(match index.checked_sub(grbl::COUNT) {
        None => {
            let n = grbl::Numbered::at(index)?;
            Listed(Key::Number(n.number()), n.get(cfg, ex))
        }
        Some(COUNT) => Listed(Key::Flow, Value::Number(ex.xonxoff() as u32)),
        Some(i) if i == COUNT + 1 => {
            Listed(Key::Uart1Baud, Value::Number(ex.uart1(cfg.machine).bps()))
        }
        Some(i) => {
            let s = Setting::at(i)?;
            Listed(Key::Named(Named(s, cfg.machine)), s.get(cfg))
        }
    })
}

/// Whether `key` is `$flow`'s (any case): the console's flow control,
/// kept with Grbl's extras ([`grbl::Extras::set_flow`]), the same on
/// every machine.
pub fn is_flow(key: &[u8]) -> bool {
    text!("flow").eq_ignore_ascii_case(key)
}

/// Whether `key` is `$uart1_baud`'s (any case): the second console's
/// rate ([`grbl::Extras::set_uart1_baud`]).
pub fn is_uart1_baud(key: &[u8]) -> bool {
    text!("uart1_baud").eq_ignore_ascii_case(key)
}

/// A line of `$$`: `$110=3750.000`, `$radial_max_rate=2000`.
pub struct Listed(Key, Value);

enum Key {
    Number(u8),
    Named(Named),
    /// `$flow=xonxoff` (value 1) or `$flow=off`.
    Flow,
    /// `$uart1_baud=9600`, its rate (0: off).
    Uart1Baud,
}

impl uDisplay for Listed {
    fn fmt<W: uWrite + ?Sized>(&self, f: &mut Formatter<'_, W>) -> Result<(), W::Error> {
        match &self.0 {
            Key::Number(n) => uwrite!(f, "${}={}", n, self.1),
            Key::Named(name) => uwrite!(f, "${}={}", name, self.1),
            Key::Flow => match self.1 {
                Value::Number(0) => text!("$flow=off").fmt(f),
                _ => text!("$flow=xonxoff").fmt(f),
            },
            Key::Uart1Baud => uwrite!(f, "{}{}", text!("$uart1_baud="), self.1),
        }
    }
}

/// Sets a setting from its text, by name (in any case, axes named as
/// `cfg`'s machine names them). Grbl's numbers: [`grbl::Numbered::set`].
pub fn set(cfg: &mut MachineConfig, key: &str, value: &str) -> Result<(), SettingError> {
    let setting = Setting::parse(key.as_bytes(), cfg.machine).ok_or(NumError {
        at: 0,
        kind: ErrorKind::UnknownKey,
    })?;
    setting.set(cfg, value.as_bytes())
}

/// What a setting holds, as [`Spec`] tells it.
#[derive(Clone, Copy, Debug)]
enum Kind {
    /// A whole number within `min..=max`.
    Number,
    /// Thousandths within `min..=max` (as `i32`), else invalid.
    Milli,
    /// Thousandths, any.
    Length,
    /// `num/den`: `num` at least `min`, `den` from 1 to `max`, else invalid.
    Ratio,
    Machine,
    Driver,
}

/// A setting's kind and bounds, read from a flash table by
/// [`Setting::spec`]: one generic parse and check, not an arm per field.
#[derive(Clone, Copy, Debug)]
struct Spec {
    kind: Kind,
    /// Every lower bound is small (0, 1, or 100 µm).
    min: u8,
    max: u32,
}

const fn spec(kind: Kind, min: u8, max: u32) -> Spec {
    Spec { kind, min, max }
}

const fn number(min: u8, max: u32) -> Spec {
    spec(Kind::Number, min, max)
}

// The string-art needle's and nails' diameters, µm.
const MIN_UM: u8 = WindingConfig::MIN_UM as u8;
const MAX_UM: u32 = WindingConfig::MAX_UM as u32;
const _: () = assert!(MIN_UM as u16 == WindingConfig::MIN_UM);

const SWITCH: Spec = number(0, 1);
const LENGTH: Spec = spec(Kind::Length, 0, 0);

impl Setting {
    /// The setting named `key`, in any case, on `machine`.
    pub fn parse(key: &[u8], machine: Machine) -> Option<Setting> {
        all().find(|s| s.is_named(key, machine))
    }

    /// Whether `key` spells this setting's name on `machine`, in any case.
    fn is_named(self, key: &[u8], machine: Machine) -> bool {
        match self {
            Setting::Axis(axis, field) => {
                let prefix = machine.channel(axis);
                let n = prefix.len();
                key.len() > n
                    && prefix.is_prefix_of(key)
                    && key[n] == b'_'
                    && field.name().eq_ignore_ascii_case(&key[n + 1..])
            }
            Setting::Global(g) => g.name().eq_ignore_ascii_case(key),
        }
    }

    /// The setting at `index` in [`all`]. Worked out rather than looked
    /// up: a table would sit in SRAM on the AVR.
    pub fn at(index: usize) -> Option<Setting> {
        let per_axis = AXES * AXIS_FIELDS.len();
        match index {
            0 => Some(Setting::Global(GlobalField::Machine)),
            i if i <= per_axis => {
                let (axis, field) = ((i - 1) / AXIS_FIELDS.len(), (i - 1) % AXIS_FIELDS.len());
                Some(Setting::Axis(Axis::ALL[axis], AxisField::at(field)))
            }
            i => GlobalField::at(i - per_axis).map(Setting::Global),
        }
    }

    /// Position in [`all`], below [`COUNT`].
    pub fn index(self) -> usize {
        match self {
            Setting::Global(GlobalField::Machine) => 0,
            Setting::Axis(a, f) => 1 + a.index() * AXIS_FIELDS.len() + f as usize,
            // `Machine` is field 0.
            Setting::Global(g) => AXES * AXIS_FIELDS.len() + g as usize,
        }
    }

    pub fn get(self, cfg: &MachineConfig) -> Value {
        let (p, g) = (&cfg.pulse, &cfg.geometry);
        Value::Number(match self {
            Setting::Axis(a, field) => {
                let axis = &cfg.axes[a.index()];
                match field {
                    AxisField::StepsPerUnit => return Value::Ratio(axis.steps_per_unit),
                    AxisField::MaxRate => axis.max_rate,
                    AxisField::Accel => axis.accel,
                    AxisField::DirInvert => !axis.dir_high_is_positive as u32,
                    AxisField::EnableActiveHigh => axis.enable_active_high as u32,
                    AxisField::SoftLimits => axis.soft_limits as u32,
                    AxisField::TravelMin => return Value::Milli(axis.travel.0),
                    AxisField::TravelMax => return Value::Milli(axis.travel.1),
                    AxisField::Driver => return Value::Driver(axis.driver),
                }
            }
            Setting::Global(GlobalField::StepPulseUs) => p.step_pulse_us as u32,
            Setting::Global(GlobalField::DirSetupUs) => p.dir_setup_us as u32,
            Setting::Global(GlobalField::EnableSetupUs) => p.enable_setup_us as u32,
            Setting::Global(GlobalField::JunctionDeviationUm) => cfg.junction_deviation_um,
            Setting::Global(GlobalField::ArcToleranceUm) => cfg.arc_tolerance_um,
            Setting::Global(GlobalField::Machine) => return Value::Machine(cfg.machine),
            Setting::Global(GlobalField::Length1) => return Value::Milli(g.lengths[0]),
            Setting::Global(GlobalField::Length2) => return Value::Milli(g.lengths[1]),
            Setting::Global(GlobalField::OriginX) => return Value::Milli(g.origin[0]),
            Setting::Global(GlobalField::OriginY) => return Value::Milli(g.origin[1]),
            Setting::Global(GlobalField::Crosstalk) => return Value::Ratio(g.crosstalk),
            Setting::Global(GlobalField::PenUp) => cfg.pen.up_deg as u32,
            Setting::Global(GlobalField::PenDown) => cfg.pen.down_deg as u32,
            Setting::Global(GlobalField::PenSettleMs) => cfg.pen.settle_ms as u32,
            Setting::Global(GlobalField::DwellPMs) => cfg.dwell_p_ms as u32,
            Setting::Global(GlobalField::HomingAxes) => cfg.homing.axes as u32,
            Setting::Global(GlobalField::HomingAtStart) => cfg.homing.at_start as u32,
            Setting::Global(GlobalField::HomingSeek) => cfg.homing.seek as u32,
            Setting::Global(GlobalField::HomingLocate) => cfg.homing.locate as u32,
            Setting::Global(GlobalField::HomingPullOff) => {
                return Value::Milli(Milli(i32::from(cfg.homing.pull_off_um)))
            }
            Setting::Global(GlobalField::StatusReport) => cfg.status_report as u32,
            Setting::Global(GlobalField::ReportInches) => cfg.report_inches as u32,
            Setting::Global(GlobalField::NailDiameter) => {
                return Value::Milli(Milli(i32::from(cfg.winding.nail_um)))
            }
            Setting::Global(GlobalField::NeedleDiameter) => {
                return Value::Milli(Milli(i32::from(cfg.winding.needle_um)))
            }
            Setting::Global(GlobalField::PenMaxFeed) => cfg.pen_max_feed,
            Setting::Global(GlobalField::PenAccel) => cfg.pen_accel,
            Setting::Global(GlobalField::StepIdleDelay) => cfg.idle_delay_ms as u32,
        })
    }

    /// Sets this setting from its text and checks the whole configuration
    /// ([`MachineConfig::validate`]); nothing changes on an error.
    pub fn set(self, cfg: &mut MachineConfig, text: &[u8]) -> Result<(), SettingError> {
        let (lead, trimmed) = trim(text);
        // One error built, the value's or the setting's.
        let e = match self.parse_value(trimmed) {
            Ok(value) => match self.put(cfg, value) {
                Ok(()) => return Ok(()),
                Err(kind) => NumError { at: 0, kind },
            },
            Err(e) => e,
        };
        Err(NumError {
            at: lead + e.at,
            kind: e.kind,
        })
    }

    /// The kind and bounds: the axis fields' first, then the global ones,
    /// each in order of discriminant.
    fn spec(self) -> Spec {
        use Kind::*;
        let specs = taut_progmem::table!(Spec; AXIS_FIELDS.len() + GLOBAL_FIELDS.len(); [
            // Axis fields.
            spec(Ratio, 1, MAX_DEN),
            number(1, 200_000),
            number(1, 10_000_000),
            SWITCH,
            SWITCH,
            SWITCH,
            LENGTH,
            LENGTH,
            spec(Driver, 0, 0),
            // Global fields.
            spec(Machine, 0, 0),
            number(1, 255),
            number(0, 255),
            number(0, 255),
            number(0, 100_000),
            number(1, 100_000),
            LENGTH,
            LENGTH,
            LENGTH,
            LENGTH,
            spec(Ratio, 0, u32::MAX),
            number(0, 180),
            number(0, 180),
            number(0, 5000),
            SWITCH,
            number(0, (1 << AXES) - 1),
            SWITCH,
            number(1, 65_535),
            number(1, 65_535),
            spec(Milli, 0, 65_535),
            number(0, 3),
            SWITCH,
            spec(Milli, MIN_UM, MAX_UM),
            spec(Milli, MIN_UM, MAX_UM),
            number(1, 1_000_000),
            number(1, 100_000),
            number(0, 255),
        ]);
        specs.get(match self {
            Setting::Axis(_, f) => f as usize,
            Setting::Global(g) => AXIS_FIELDS.len() + g as usize,
        })
    }

    /// The field's name, without the axis.
    fn field_name(self) -> Text {
        match self {
            Setting::Axis(_, f) => f.name(),
            Setting::Global(g) => g.name(),
        }
    }

    /// The value `text` (trimmed) gives this setting, in the setting's kind.
    fn parse_value(self, text: &[u8]) -> Result<Value, SettingError> {
        Ok(match self.spec().kind {
            Kind::Machine => match crate::machine::Machine::parse(text) {
                Some(m) => Value::Machine(m),
                None => {
                    return Err(NumError {
                        at: 0,
                        kind: ErrorKind::UnknownMachine,
                    })
                }
            },
            Kind::Driver => match Driver::parse(text) {
                Some(d) => Value::Driver(d),
                None => {
                    return Err(NumError {
                        at: 0,
                        kind: ErrorKind::Invalid(self.field_name()),
                    })
                }
            },
            Kind::Milli | Kind::Length => Value::Milli(parse_milli(text)?),
            Kind::Ratio => Value::Ratio(parse_ratio(text)?),
            Kind::Number => Value::Number(parse_u32(text)?),
        })
    }

    /// Sets this setting to `value` (of the setting's kind) if it is in its
    /// range and the whole configuration stays valid; nothing changes on
    /// an error.
    pub fn put(self, cfg: &mut MachineConfig, value: Value) -> Result<(), ErrorKind> {
        self.check(value)?;
        // Another machine: its defaults, whole (they always hold).
        if let Value::Machine(m) = value {
            cfg.load_defaults(m);
            return Ok(());
        }
        // Changed in place and put back on an error: no copy of the whole
        // configuration on the AVR's small stack.
        let old = self.get(cfg);
        self.force(cfg, value);
        // Coils: no faster than a 28BYJ-48 pulls out (settable after).
        if let (Setting::Axis(a, _), Value::Driver(Driver::Uln2003)) = (self, value) {
            let rate = &mut cfg.axes[a.index()].max_rate;
            *rate = (*rate).min(COIL_MAX_RATE);
        }
        check_whole(cfg).inspect_err(|_| self.force(cfg, old))
    }

    /// Whether `value` is of this setting's kind and in its range.
    pub fn check(self, value: Value) -> Result<(), ErrorKind> {
        let Spec { kind, min, max } = self.spec();
        let within = match (kind, value) {
            (Kind::Number, Value::Number(n)) => {
                let min = min as u32;
                return match (min..=max).contains(&n) {
                    true => Ok(()),
                    false => Err(ErrorKind::Range { min, max }),
                };
            }
            (Kind::Length, Value::Milli(_))
            | (Kind::Machine, Value::Machine(_))
            | (Kind::Driver, Value::Driver(_)) => return Ok(()),
            (Kind::Milli, Value::Milli(m)) => (min as i32..=max as i32).contains(&m.0),
            (Kind::Ratio, Value::Ratio(r)) => r.num >= min as u32 && r.den != 0 && r.den <= max,
            _ => return Err(ErrorKind::NotANumber),
        };
        match within {
            true => Ok(()),
            false => Err(ErrorKind::Invalid(self.field_name())),
        }
    }

    /// Sets the field, unchecked (a value of another kind is ignored):
    /// callers check it first.
    pub(crate) fn force(self, cfg: &mut MachineConfig, value: Value) {
        let n = match value {
            Value::Number(n) => n,
            _ => 0,
        };
        match (self, value) {
            (Setting::Axis(a, field), _) => {
                let axis = &mut cfg.axes[a.index()];
                match (field, value) {
                    (AxisField::StepsPerUnit, Value::Ratio(r)) => axis.steps_per_unit = r,
                    (AxisField::TravelMin, Value::Milli(m)) => axis.travel.0 = m,
                    (AxisField::TravelMax, Value::Milli(m)) => axis.travel.1 = m,
                    (AxisField::MaxRate, Value::Number(_)) => axis.max_rate = n,
                    (AxisField::Accel, Value::Number(_)) => axis.accel = n,
                    (AxisField::DirInvert, Value::Number(_)) => axis.dir_high_is_positive = n == 0,
                    (AxisField::EnableActiveHigh, Value::Number(_)) => {
                        axis.enable_active_high = n == 1
                    }
                    (AxisField::SoftLimits, Value::Number(_)) => axis.soft_limits = n == 1,
                    (AxisField::Driver, Value::Driver(d)) => axis.driver = d,
                    _ => {}
                }
            }
            (Setting::Global(GlobalField::Machine), Value::Machine(m)) => cfg.machine = m,
            (Setting::Global(GlobalField::Length1), Value::Milli(m)) => cfg.geometry.lengths[0] = m,
            (Setting::Global(GlobalField::Length2), Value::Milli(m)) => cfg.geometry.lengths[1] = m,
            (Setting::Global(GlobalField::OriginX), Value::Milli(m)) => cfg.geometry.origin[0] = m,
            (Setting::Global(GlobalField::OriginY), Value::Milli(m)) => cfg.geometry.origin[1] = m,
            (Setting::Global(GlobalField::Crosstalk), Value::Ratio(r)) => {
                cfg.geometry.crosstalk = r
            }
            (Setting::Global(GlobalField::HomingPullOff), Value::Milli(m)) => {
                cfg.homing.pull_off_um = m.0 as u16
            }
            // `check` keeps these within u16.
            (Setting::Global(GlobalField::NailDiameter), Value::Milli(m)) => {
                cfg.winding.nail_um = m.0 as u16
            }
            (Setting::Global(GlobalField::NeedleDiameter), Value::Milli(m)) => {
                cfg.winding.needle_um = m.0 as u16
            }
            (_, Value::Ratio(_) | Value::Milli(_) | Value::Machine(_) | Value::Driver(_)) => {}
            // The ranges keep these within u8.
            (Setting::Global(GlobalField::StepPulseUs), _) => cfg.pulse.step_pulse_us = n as u8,
            (Setting::Global(GlobalField::DirSetupUs), _) => cfg.pulse.dir_setup_us = n as u8,
            (Setting::Global(GlobalField::EnableSetupUs), _) => cfg.pulse.enable_setup_us = n as u8,
            (Setting::Global(GlobalField::JunctionDeviationUm), _) => cfg.junction_deviation_um = n,
            (Setting::Global(GlobalField::ArcToleranceUm), _) => cfg.arc_tolerance_um = n,
            (Setting::Global(GlobalField::PenUp), _) => cfg.pen.up_deg = n as u8,
            (Setting::Global(GlobalField::PenDown), _) => cfg.pen.down_deg = n as u8,
            (Setting::Global(GlobalField::PenSettleMs), _) => cfg.pen.settle_ms = n as u16,
            (Setting::Global(GlobalField::DwellPMs), _) => cfg.dwell_p_ms = n == 1,
            (Setting::Global(GlobalField::HomingAxes), _) => cfg.homing.axes = n as u8,
            (Setting::Global(GlobalField::HomingAtStart), _) => cfg.homing.at_start = n == 1,
            (Setting::Global(GlobalField::HomingSeek), _) => cfg.homing.seek = n as u16,
            (Setting::Global(GlobalField::HomingLocate), _) => cfg.homing.locate = n as u16,
            (Setting::Global(GlobalField::StatusReport), _) => cfg.status_report = n as u8,
            (Setting::Global(GlobalField::ReportInches), _) => cfg.report_inches = n == 1,
            (Setting::Global(GlobalField::PenMaxFeed), _) => cfg.pen_max_feed = n,
            (Setting::Global(GlobalField::PenAccel), _) => cfg.pen_accel = n,
            (Setting::Global(GlobalField::StepIdleDelay), _) => cfg.idle_delay_ms = n as u8,
            (Setting::Global(_), Value::Number(_)) => {}
        }
    }
}

/// The configuration as a whole: each figure's bounds, and a geometry its
/// machine's kinematics can use.
pub fn check_whole(cfg: &MachineConfig) -> Result<(), ErrorKind> {
    cfg.validate()?;
    match AnyKinematics::of(cfg) {
        Ok(_) => Ok(()),
        Err(_) => Err(ErrorKind::Invalid(text!("geometry"))),
    }
}

/// A setting's name as `machine` calls it: `radial_max_rate`,
/// `x_max_rate`, `step_pulse_us`.
pub struct Named(pub Setting, pub Machine);

impl uDisplay for Named {
    fn fmt<W: uWrite + ?Sized>(&self, f: &mut Formatter<'_, W>) -> Result<(), W::Error> {
        match self.0 {
            Setting::Axis(a, field) => uwrite!(f, "{}_{}", self.1.channel(a), field.name()),
            Setting::Global(g) => uwrite!(f, "{}", g.name()),
        }
    }
}

impl uDisplay for Value {
    /// Re-readable by [`set`]: `32`, `1600/12`.
    fn fmt<W: uWrite + ?Sized>(&self, f: &mut Formatter<'_, W>) -> Result<(), W::Error> {
        match *self {
            Value::Number(n) => uwrite!(f, "{}", n),
            Value::Machine(m) => uwrite!(f, "{}", m.name()),
            Value::Driver(d) => uwrite!(f, "{}", d.name()),
            Value::Ratio(r) if r.den == 1 => uwrite!(f, "{}", r.num),
            Value::Ratio(r) => uwrite!(f, "{}/{}", r.num, r.den),
            Value::Milli(m) => uwrite!(f, "{}", Decimal(m.0, 3)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text::error::tests::show;
    use proptest::prelude::*;
    use std::string::String;
    use std::vec::Vec;

    #[test]
    fn fields_worked_out_are_the_tables() {
        for (i, g) in GLOBAL_FIELDS.iter().enumerate() {
            assert_eq!(GlobalField::at(i), Some(*g));
        }
        assert_eq!(GlobalField::at(GLOBAL_FIELDS.len()), None);
        for (i, a) in AXIS_FIELDS.iter().enumerate() {
            assert_eq!(AxisField::at(i), *a);
        }
    }

    #[test]
    fn each_spec_is_of_its_setting_s_kind() {
        let cfg = MachineConfig::STRING_ART;
        for s in all() {
            let kind = s.spec().kind;
            let same = match s.get(&cfg) {
                Value::Number(_) => matches!(kind, Kind::Number),
                Value::Milli(_) => matches!(kind, Kind::Milli | Kind::Length),
                Value::Ratio(_) => matches!(kind, Kind::Ratio),
                Value::Machine(_) => matches!(kind, Kind::Machine),
                Value::Driver(_) => matches!(kind, Kind::Driver),
            };
            assert!(same, "{s:?}: {kind:?}");
        }
    }

    fn listing(cfg: &MachineConfig) -> Vec<String> {
        let mut lines = Vec::new();
        for_each(cfg, |s, v| {
            lines.push(show(&Named(s, cfg.machine)) + " = " + &show(&v))
        });
        lines
    }

    #[test]
    fn listing_shows_every_setting_once_with_defaults() {
        let lines = listing(&MachineConfig::STRING_ART);
        assert_eq!(lines.len(), COUNT);
        assert_eq!(lines[0], "machine = string_art");
        assert_eq!(lines[1], "base_steps_per_unit = 9600/360");
        assert_eq!(lines[2], "base_max_rate = 2000");
        assert_eq!(lines[6], "base_soft_limits = 0");
        assert_eq!(lines[9], "base_driver = stepdir");
        assert_eq!(lines[10], "radial_steps_per_unit = 32");
        assert_eq!(lines[15], "radial_soft_limits = 1");
        assert_eq!(lines[16], "radial_travel_min = -450.000");
        assert_eq!(lines[17], "radial_travel_max = 30.000");
        assert_eq!(lines[19], "drill_steps_per_unit = 1600/12");
        assert_eq!(lines[22], "drill_dir_invert = 0");
        assert_eq!(lines[23], "drill_enable_active_high = 1");
        assert_eq!(lines[28], "step_pulse_us = 5");
        assert_eq!(lines[31], "junction_deviation_um = 10");
        assert_eq!(lines[32], "arc_tolerance_um = 10");
        assert_eq!(lines[33], "length_1 = 0.000");
        assert_eq!(lines[37], "crosstalk = 0");
        assert_eq!(lines[COUNT - 1], "step_idle_delay_ms = 255");
        // Another machine names its channels its own way.
        let scara = listing(&MachineConfig::defaults(Machine::Scara));
        assert_eq!(scara[0], "machine = scara");
        assert_eq!(scara[1], "shoulder_steps_per_unit = 9600/360");
        assert_eq!(scara[10], "elbow_steps_per_unit = 9600/360");
        assert_eq!(scara[33], "length_1 = 150.000");
        assert_eq!(scara[35], "origin_x = 100.000");
        assert_eq!(scara[36], "origin_y = -56.000");
        assert_eq!(scara[37], "crosstalk = 3");
        let drum = listing(&MachineConfig::defaults(Machine::Drum));
        assert_eq!(drum[9], "x_driver = uln2003");
        assert_eq!(drum[18], "y_driver = uln2003");
        assert_eq!(drum[27], "z_driver = stepdir");
        for (i, s) in all().enumerate() {
            assert_eq!(s.index(), i);
            assert_eq!(Setting::at(i), Some(s));
        }
        assert_eq!(Setting::at(COUNT), None);
    }

    #[test]
    fn every_listed_value_reads_back() {
        let cfg = MachineConfig::STRING_ART;
        let mut copy = cfg;
        copy.axes[0].max_rate = 1;
        copy.pulse.dir_setup_us = 0;
        for line in listing(&cfg) {
            let (key, value) = line.split_once(" = ").unwrap();
            set(&mut copy, key, value).unwrap();
        }
        assert_eq!(copy, cfg);
    }

    #[test]
    fn values_land_in_their_fields() {
        let mut cfg = MachineConfig::STRING_ART;
        set(&mut cfg, "DRILL_STEPS_PER_UNIT", "1600 / 12").unwrap();
        set(&mut cfg, "radial_steps_per_unit", "26.5").unwrap();
        set(&mut cfg, "radial_dir_invert", "1").unwrap();
        set(&mut cfg, "drill_enable_active_high", "0").unwrap();
        set(&mut cfg, "base_accel", " 750 ").unwrap();
        set(&mut cfg, "enable_setup_us", "0").unwrap();
        set(&mut cfg, "junction_deviation_um", "20").unwrap();
        set(&mut cfg, "arc_tolerance_um", "2").unwrap();
        set(&mut cfg, "step_idle_delay_ms", "25").unwrap();
        set(&mut cfg, "drill_driver", " ULN2003 ").unwrap();
        assert_eq!(cfg.idle_delay_ms, 25);
        assert_eq!(cfg.axes[2].driver, Driver::Uln2003);
        // Coils: no faster than a 28BYJ-48 pulls out; then as set.
        assert_eq!(cfg.axes[2].max_rate, COIL_MAX_RATE);
        set(&mut cfg, "drill_max_rate", "1200").unwrap();
        assert_eq!(cfg.axes[2].max_rate, 1200);
        assert_eq!(cfg.axes[2].steps_per_unit, StepsPerUnit::new(1600, 12));
        assert_eq!(cfg.axes[1].steps_per_unit, StepsPerUnit::new(53, 2));
        assert!(!cfg.axes[1].dir_high_is_positive);
        assert!(!cfg.axes[2].enable_active_high);
        assert_eq!(cfg.axes[0].accel, 750);
        assert_eq!(cfg.pulse.enable_setup_us, 0);
        assert_eq!(cfg.junction_deviation_um, 20);
        assert_eq!(cfg.arc_tolerance_um, 2);
    }

    #[test]
    fn another_machine_loads_its_defaults_and_names() {
        let mut cfg = MachineConfig::STRING_ART;
        set(&mut cfg, "base_max_rate", "1500").unwrap();
        set(&mut cfg, "machine", " Flatbed ").unwrap();
        assert_eq!(cfg, MachineConfig::defaults(Machine::Flatbed));
        set(&mut cfg, "x_travel_max", "150").unwrap();
        assert_eq!(cfg.axes[0].travel.1, Milli(150_000));
        let e = set(&mut cfg, "radial_max_rate", "100").unwrap_err();
        assert_eq!(e.kind, ErrorKind::UnknownKey);
        let e = set(&mut cfg, "machine", " polar").unwrap_err();
        assert_eq!((e.at, e.kind), (1, ErrorKind::UnknownMachine));
        // A geometry its kinematics cannot use is refused.
        set(&mut cfg, "machine", "whiteboard").unwrap();
        let e = set(&mut cfg, "origin_y", "5").unwrap_err();
        assert_eq!(e.kind, ErrorKind::Invalid(text!("geometry")));
        assert_eq!(cfg, MachineConfig::defaults(Machine::Whiteboard));
    }

    #[test]
    fn bad_settings_change_nothing() {
        let mut cfg = MachineConfig::STRING_ART;
        let error = |cfg: &mut MachineConfig, k, v| {
            let e = set(cfg, k, v).unwrap_err();
            (e.at, show(&e.kind))
        };
        assert_eq!(
            error(&mut cfg, "base_speed", "1"),
            (0, "unknown key".into())
        );
        assert_eq!(error(&mut cfg, "base_", "1"), (0, "unknown key".into()));
        assert_eq!(error(&mut cfg, "drill", "1"), (0, "unknown key".into()));
        assert_eq!(
            error(&mut cfg, "base_max_rate", "0"),
            (0, "expected 1 to 200000".into())
        );
        assert_eq!(
            error(&mut cfg, "base_max_rate", " 2k"),
            (2, "expected a number".into())
        );
        assert_eq!(
            error(&mut cfg, "base_dir_invert", "2"),
            (0, "expected 0 to 1".into())
        );
        assert_eq!(
            error(&mut cfg, "step_pulse_us", "0"),
            (0, "expected 1 to 255".into())
        );
        assert_eq!(
            error(&mut cfg, "dir_setup_us", "256"),
            (0, "expected 0 to 255".into())
        );
        assert_eq!(
            error(&mut cfg, "drill_steps_per_unit", "1600/0"),
            (0, "invalid steps_per_unit".into())
        );
        assert_eq!(
            error(&mut cfg, "drill_steps_per_unit", "1600/x"),
            (5, "expected a number".into())
        );
        assert_eq!(
            error(&mut cfg, "drill_driver", "a4988"),
            (0, "invalid driver".into())
        );
        assert_eq!(cfg, MachineConfig::STRING_ART);
    }

    proptest! {
        #[test]
        fn any_accepted_value_is_listed_as_set(index in 0..COUNT, n in 0u32..300_000, den in 1u32..1000) {
            let mut cfg = MachineConfig::STRING_ART;
            let s = all().nth(index).unwrap();
            let ratio = matches!(
                s,
                Setting::Axis(_, AxisField::StepsPerUnit) | Setting::Global(GlobalField::Crosstalk)
            );
            let milli = matches!(
                s.get(&cfg),
                Value::Milli(_)
            );
            let text = match s {
                _ if ratio => std::format!("{}/{}", n.max(1), den),
                Setting::Global(GlobalField::Machine) => std::string::ToString::to_string(&Machine::ALL[n as usize % 5].name()),
                _ => std::format!("{n}"),
            };
            let listed = match s {
                _ if milli => std::format!("{n}.000"),
                // A ratio over 1 is listed as a whole number.
                _ => text.strip_suffix("/1").unwrap_or(&text).into(),
            };
            let name = show(&Named(s, cfg.machine));
            match set(&mut cfg, &name, &text) {
                Ok(()) => {
                    prop_assert_eq!(show(&s.get(&cfg)), listed);
                    prop_assert!(cfg.validate().is_ok());
                }
                Err(e) => {
                    // Out of the setting's range, or at odds with the others.
                    let Spec { min, max, .. } = s.spec();
                    let at_odds = matches!(e.kind, ErrorKind::PulseTooLong { .. } | ErrorKind::Invalid(_));
                    prop_assert!(!(min as u32..=max).contains(&n) || at_odds, "{:?}", e);
                    prop_assert_eq!(cfg, MachineConfig::STRING_ART);
                }
            }
        }
    }
}
