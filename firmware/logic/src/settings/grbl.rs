//! Grbl 1.1's numbered settings, all 34 (`$0` … `$132`): `$$` lists them
//! in Grbl's order and units before taut's named ones; `$<n>=<value>`
//! writes the named settings behind them, or, for those taut has no name
//! for, the [`Extras`] kept beside them. Per-axis numbers count Grbl's X,
//! Y, Z places of the status report ([`report_axes`]): on the string-art
//! machine `$100` is the radial carriage (word `X`), `$101` the base (`C`,
//! degrees), `$102` the drill.
//!
//! Values read back as typed: taut's figures are in steps (a rate in
//! steps/s), so a rate typed in Grbl's units (`$110=2345`, mm/min) is kept
//! beside the steps it makes ([`Typed`]) and listed as typed while the
//! steps are still its own; changing `$100` keeps `$110` and `$120` as
//! Grbl does (their steps change with it).

use super::record::Part;
use super::{check_whole, AxisField, GlobalField, Setting, Value};
use crate::axis::{Axis, AXES};
use crate::config::{AxisConfig, MachineConfig};
use crate::gcode::ErrorKind as Code;
use crate::machine::Machine;
use crate::text::num::{parse_milli, parse_ratio, trim, NumError};
use crate::text::ErrorKind;
use crate::units::{Milli, StepsPerUnit, StepsPerUnit as Ratio};
use taut_progmem::text;

/// A Grbl setting, by what it sets. The per-axis ones carry the report
/// place (0 X, 1 Y, 2 Z).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Numbered {
    /// `$0` step pulse, µs.
    StepPulse,
    /// `$1` step idle delay, ms (255: the drivers stay on).
    IdleDelay,
    /// `$2` step pulse invert, a bit per place.
    StepInvert,
    /// `$3` direction invert, a bit per place.
    DirInvert,
    /// `$4` step enable invert: the drivers are on while ENABLE is high.
    EnableInvert,
    /// `$5` limit pins invert.
    LimitInvert,
    /// `$6` probe pin invert.
    ProbeInvert,
    /// `$10` status report fields.
    StatusReport,
    /// `$11` junction deviation, mm.
    JunctionDeviation,
    /// `$12` arc tolerance, mm.
    ArcTolerance,
    /// `$13` report inches.
    ReportInches,
    /// `$20` soft limits.
    SoftLimits,
    /// `$21` hard limits.
    HardLimits,
    /// `$22` homing cycle.
    Homing,
    /// `$23` homing direction invert, a bit per place.
    HomingDirInvert,
    /// `$24` homing feed (the slow locate), units/min.
    HomingFeed,
    /// `$25` homing seek, units/min.
    HomingSeek,
    /// `$26` homing switch debounce, ms.
    HomingDebounce,
    /// `$27` homing pull-off, mm.
    HomingPullOff,
    /// `$30` spindle speed at full output, rpm.
    SpindleMax,
    /// `$31` spindle speed at the least output, rpm.
    SpindleMin,
    /// `$32` laser mode.
    LaserMode,
    /// `$100…` steps per unit.
    StepsPerUnit(u8),
    /// `$110…` maximum rate, units/min.
    MaxRate(u8),
    /// `$120…` acceleration, units/s².
    Accel(u8),
    /// `$130…` maximum travel, units.
    MaxTravel(u8),
}

/// How many numbered settings `$$` lists: Grbl 1.1's 22 below `$100` and
/// four per axis.
pub const COUNT: usize = SMALL + 4 * 3;
const SMALL: usize = 22;

/// Grbl's settings taut's named ones do not hold, and the rates as typed
/// in Grbl's units. Kept in EEPROM with the named settings, the same for
/// every machine.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Extras {
    /// `$1`: how long the drivers stay on after motion, ms; 255: always.
    pub idle_delay_ms: u8,
    /// `$2`: STEP pulses inverted, a bit per place.
    pub step_invert: u8,
    /// `$5`, `$6`, `$21`, `$22` (off), `$32`: the `FLAG_` bits.
    pub flags: u8,
    /// `$23`: homing towards the other end, a bit per place.
    pub homing_dir_invert: u8,
    /// `$26`: ms a homing switch must settle.
    pub homing_debounce_ms: u8,
    /// `$30`, `$31`: rpm at the spindle output's top and bottom.
    pub spindle_max: u32,
    pub spindle_min: u32,
    pub typed: Typed,
}

/// The rates as last typed in Grbl's units, thousandths of a unit per
/// minute (`$110`, `$24`, `$25`) or per second² (`$120`); 0: never typed
/// so. By channel. Listed while the steps figure is still the one they
/// make: a rate set by name since shows as its steps make it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Typed {
    pub max_rate: [u32; AXES],
    pub accel: [u32; AXES],
    pub homing_feed: u32,
    pub homing_seek: u32,
}

/// `$5`: the limit switches read inverted.
pub const FLAG_LIMIT_INVERT: u8 = 1;
/// `$6`: the probe reads inverted.
pub const FLAG_PROBE_INVERT: u8 = 2;
/// `$21`: hard limits.
pub const FLAG_HARD_LIMITS: u8 = 4;
/// `$22=0`: no homing cycle, whatever `homing_axes` names.
pub const FLAG_HOMING_OFF: u8 = 8;
/// `$32`: laser mode.
pub const FLAG_LASER: u8 = 16;

/// Bytes of [`Extras`] in EEPROM.
pub const EXTRAS_BYTES: u16 = 5 + 2 * 4 + (2 * AXES as u16 + 2) * 4;

impl Extras {
    /// Grbl's defaults (`defaults.h`), but `$1`: taut's drivers hold the
    /// machine still between moves.
    pub const DEFAULT: Extras = Extras {
        idle_delay_ms: 255,
        step_invert: 0,
        flags: 0,
        homing_dir_invert: 0,
        homing_debounce_ms: 250,
        spindle_max: 1000,
        spindle_min: 0,
        typed: Typed {
            max_rate: [0; AXES],
            accel: [0; AXES],
            homing_feed: 0,
            homing_seek: 0,
        },
    };

    /// Whether `$H` may home: `$22` on and a channel to home.
    pub fn homing_enabled(&self, cfg: &MachineConfig) -> bool {
        self.flags & FLAG_HOMING_OFF == 0 && cfg.homing.axes != 0
    }

    /// Part `k` of the EEPROM bytes: the bytes, then the two rpm figures,
    /// then the typed rates, little-endian.
    pub fn part(&self, k: u8) -> Option<Part> {
        let t = &self.typed;
        let pair = |a: u32, b: u32| {
            let (a, b) = (a.to_le_bytes(), b.to_le_bytes());
            ([a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3]], 8)
        };
        Some(match k {
            0 => (
                [
                    self.idle_delay_ms,
                    self.step_invert,
                    self.flags,
                    self.homing_dir_invert,
                    self.homing_debounce_ms,
                    0,
                    0,
                    0,
                ],
                5,
            ),
            1 => pair(self.spindle_max, self.spindle_min),
            2 => pair(t.max_rate[0], t.max_rate[1]),
            3 => pair(t.max_rate[2], t.accel[0]),
            4 => pair(t.accel[1], t.accel[2]),
            5 => pair(t.homing_feed, t.homing_seek),
            _ => return None,
        })
    }

    /// The extras from their bytes through `byte(i)`. Any value is taken:
    /// none is refused by the machine.
    pub fn decode(byte: impl Fn(u16) -> u8) -> Extras {
        let word = |i: u16| u32::from_le_bytes([byte(i), byte(i + 1), byte(i + 2), byte(i + 3)]);
        let w = |n: u16| word(5 + 4 * n);
        Extras {
            idle_delay_ms: byte(0),
            step_invert: byte(1),
            flags: byte(2),
            homing_dir_invert: byte(3),
            homing_debounce_ms: byte(4),
            spindle_max: w(0),
            spindle_min: w(1),
            typed: Typed {
                max_rate: [w(2), w(3), w(4)],
                accel: [w(5), w(6), w(7)],
                homing_feed: w(8),
                homing_seek: w(9),
            },
        }
    }
}

impl Default for Extras {
    fn default() -> Self {
        Extras::DEFAULT
    }
}

/// The channel in each of Grbl's X, Y, Z places: a plotter's X Y Z
/// channels in order; on the string-art machine the radial carriage
/// (word `X`) and the drill (`Z`) in their own places and the base (`C`,
/// which Grbl has not) in Y's.
pub const fn report_axes(machine: Machine) -> [Axis; 3] {
    match machine {
        Machine::StringArt => [Axis::Radial, Axis::Base, Axis::Drill],
        _ => [Axis::Base, Axis::Radial, Axis::Drill],
    }
}

/// The report places (bits) whose position is an angle, never in inches:
/// the string-art machine's base.
pub const fn report_angles(machine: Machine) -> u8 {
    match machine {
        Machine::StringArt => 0b010,
        _ => 0,
    }
}

/// Why a `$<n>=` was refused: Grbl's error, at which byte of the value,
/// and taut's reason when Grbl has none.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SetError {
    pub code: Code,
    pub at: usize,
    pub why: Option<ErrorKind>,
}

impl SetError {
    const fn refused(why: ErrorKind) -> SetError {
        SetError {
            code: Code::InvalidStatement,
            at: 0,
            why: Some(why),
        }
    }
}

impl From<NumError> for SetError {
    /// A value that is no number: Grbl's "bad number format".
    fn from(e: NumError) -> SetError {
        SetError {
            code: Code::BadNumberFormat,
            at: e.at,
            why: Some(e.kind),
        }
    }
}

impl Numbered {
    /// The setting at `index` in `$$` order: `$0`…`$6`, `$10`…`$13`,
    /// `$20`…`$27`, `$30`…`$32`, then `$100`…`$132`.
    pub fn at(index: usize) -> Option<Numbered> {
        // Grbl's numbers below 100 as bytes of a flash text: a table would
        // sit in SRAM on the AVR.
        let small = text!(
            "\0\x01\x02\x03\x04\x05\x06\n\x0b\x0c\r\x14\x15\x16\x17\x18\x19\x1a\x1b\x1e\x1f\x20"
        );
        let n = match index {
            i if i < SMALL => small.byte(i),
            i if i < COUNT => {
                let i = (i - SMALL) as u8;
                100 + i / 3 * 10 + i % 3
            }
            _ => return None,
        };
        Numbered::from_number(n)
    }

    /// The setting Grbl numbers `n`, if Grbl has it.
    pub fn from_number(n: u8) -> Option<Numbered> {
        use Numbered::*;
        let place = n % 10;
        Some(match n {
            0 => StepPulse,
            1 => IdleDelay,
            2 => StepInvert,
            3 => DirInvert,
            4 => EnableInvert,
            5 => LimitInvert,
            6 => ProbeInvert,
            10 => StatusReport,
            11 => JunctionDeviation,
            12 => ArcTolerance,
            13 => ReportInches,
            20 => SoftLimits,
            21 => HardLimits,
            22 => Homing,
            23 => HomingDirInvert,
            24 => HomingFeed,
            25 => HomingSeek,
            26 => HomingDebounce,
            27 => HomingPullOff,
            30 => SpindleMax,
            31 => SpindleMin,
            32 => LaserMode,
            100..=102 => StepsPerUnit(place),
            110..=112 => MaxRate(place),
            120..=122 => Accel(place),
            130..=132 => MaxTravel(place),
            _ => return None,
        })
    }

    /// The number a `$` key spells (`10`, `110`), if it is all digits:
    /// `Ok(None)` for a number Grbl has no setting of.
    pub fn parse(key: &[u8]) -> Option<Option<Numbered>> {
        if key.is_empty() || !key.iter().all(u8::is_ascii_digit) {
            return None;
        }
        Some(match crate::text::num::parse_u32(key) {
            Ok(n) if n <= u8::MAX as u32 => Numbered::from_number(n as u8),
            _ => None,
        })
    }

    pub fn number(self) -> u8 {
        use Numbered::*;
        match self {
            StepPulse => 0,
            IdleDelay => 1,
            StepInvert => 2,
            DirInvert => 3,
            EnableInvert => 4,
            LimitInvert => 5,
            ProbeInvert => 6,
            StatusReport => 10,
            JunctionDeviation => 11,
            ArcTolerance => 12,
            ReportInches => 13,
            SoftLimits => 20,
            HardLimits => 21,
            Homing => 22,
            HomingDirInvert => 23,
            HomingFeed => 24,
            HomingSeek => 25,
            HomingDebounce => 26,
            HomingPullOff => 27,
            SpindleMax => 30,
            SpindleMin => 31,
            LaserMode => 32,
            StepsPerUnit(p) => 100 + p,
            MaxRate(p) => 110 + p,
            Accel(p) => 120 + p,
            MaxTravel(p) => 130 + p,
        }
    }

    /// A flag of [`Extras::flags`] this setting is.
    fn flag(self) -> u8 {
        match self {
            Numbered::LimitInvert => FLAG_LIMIT_INVERT,
            Numbered::ProbeInvert => FLAG_PROBE_INVERT,
            Numbered::HardLimits => FLAG_HARD_LIMITS,
            Numbered::LaserMode => FLAG_LASER,
            _ => 0,
        }
    }

    /// The value in Grbl's units: whole numbers for switches, masks, times
    /// and rpm, three decimals for lengths and rates.
    #[inline(never)]
    pub fn get(self, cfg: &MachineConfig, ex: &Extras) -> Value {
        use Numbered::*;
        let places = report_axes(cfg.machine);
        let axis = |p: u8| &cfg.axes[places[p as usize].index()];
        let typed = &ex.typed;
        let milli = |m: i32| Value::Milli(Milli(m));
        let n = |v: u32| Value::Number(v);
        match self {
            StepPulse => n(cfg.pulse.step_pulse_us as u32),
            IdleDelay => n(ex.idle_delay_ms as u32),
            StepInvert => n(ex.step_invert as u32),
            HomingDirInvert => n(ex.homing_dir_invert as u32),
            HomingDebounce => n(ex.homing_debounce_ms as u32),
            SpindleMax => n(ex.spindle_max),
            SpindleMin => n(ex.spindle_min),
            LimitInvert | ProbeInvert | HardLimits | LaserMode => {
                n((ex.flags & self.flag() != 0) as u32)
            }
            Homing => n(ex.homing_enabled(cfg) as u32),
            DirInvert | EnableInvert | SoftLimits => n(self.over_places(cfg) as u32),
            StatusReport => n(cfg.status_report as u32),
            ReportInches => n(cfg.report_inches as u32),
            JunctionDeviation => milli(cfg.junction_deviation_um as i32),
            ArcTolerance => milli(cfg.arc_tolerance_um as i32),
            HomingPullOff => milli(cfg.homing.pull_off_um as i32),
            HomingFeed => milli(shown(
                typed.homing_feed,
                cfg.homing.locate as u32,
                axis(0),
                PER_MIN,
            )),
            HomingSeek => milli(shown(
                typed.homing_seek,
                cfg.homing.seek as u32,
                axis(0),
                PER_MIN,
            )),
            StepsPerUnit(p) => {
                let Ratio { num, den } = axis(p).steps_per_unit;
                milli(per(&[num, 1, den], 1000, 1))
            }
            MaxRate(p) => {
                let a = axis(p);
                milli(shown(
                    typed.max_rate[places[p as usize].index()],
                    a.max_rate,
                    a,
                    PER_MIN,
                ))
            }
            Accel(p) => {
                let a = axis(p);
                milli(shown(
                    typed.accel[places[p as usize].index()],
                    a.accel,
                    a,
                    PER_S,
                ))
            }
            MaxTravel(p) => milli(axis(p).travel.1 .0.wrapping_sub(axis(p).travel.0 .0)),
        }
    }

    /// A switch or mask over the report places: `$3` a bit each, `$4` and
    /// `$20` on when every place's driver is on high (`$4`) or any place
    /// has soft limits (`$20`).
    fn over_places(self, cfg: &MachineConfig) -> u8 {
        // Bytes: a `u32`'s shifts are four times as long on the AVR.
        let mut mask = [0u8; 3];
        for (p, axis) in report_axes(cfg.machine).iter().enumerate() {
            let a = &cfg.axes[axis.index()];
            mask[0] |= (!a.dir_high_is_positive as u8) << p;
            mask[1] |= (a.soft_limits as u8) << p;
            mask[2] |= (a.enable_active_high as u8) << p;
        }
        match self {
            Numbered::DirInvert => mask[0],
            Numbered::SoftLimits => (mask[1] != 0) as u8,
            _ => (mask[2] == 0b111) as u8,
        }
    }

    /// Sets this setting from `text` (Grbl's units, a number as Grbl reads
    /// one: sign, digits, a point), checked with the whole configuration;
    /// nothing changes on an error.
    #[inline(never)]
    pub fn set(
        self,
        cfg: &mut MachineConfig,
        ex: &mut Extras,
        text: &[u8],
    ) -> Result<(), SetError> {
        let (lead, text) = trim(text);
        self.put(cfg, ex, text).map_err(|e| SetError {
            at: lead + e.at,
            ..e
        })
    }

    fn put(self, cfg: &mut MachineConfig, ex: &mut Extras, text: &[u8]) -> Result<(), SetError> {
        use Numbered::*;
        // `$100` may be a ratio (`1600/12`); anything else a number.
        let ratio = matches!(self, StepsPerUnit(_)) && text.contains(&b'/');
        let value = match ratio {
            true => Milli(1),
            false => parse_milli(text)?,
        };
        if value.0 < 0 {
            return Err(SetError {
                code: Code::NegativeValue,
                at: 0,
                why: None,
            });
        }
        let milli = value.0 as u32;
        // The value listed now keeps the exact figure behind it (a sender
        // writes back what `$$` showed: `$101=26.667` stays 9600/360).
        let same = match self.get(cfg, ex) {
            Value::Milli(m) => m == value,
            Value::Number(n) => n == milli / 1000,
            _ => false,
        };
        if same && !ratio {
            return Ok(());
        }
        // Grbl truncates a whole-number setting's value.
        let whole = milli / 1000;
        let byte = |max: u32| match whole <= max {
            true => Ok(whole as u8),
            false => Err(SetError::refused(ErrorKind::Range { min: 0, max })),
        };
        let switch = || byte(1).map(|b| b == 1);
        let places = report_axes(cfg.machine);
        let named = |s: GlobalField| Setting::Global(s);
        match self {
            IdleDelay => ex.idle_delay_ms = byte(255)?,
            StepInvert => ex.step_invert = byte(255)?,
            HomingDirInvert => ex.homing_dir_invert = byte(255)?,
            HomingDebounce => ex.homing_debounce_ms = byte(255)?,
            SpindleMax => ex.spindle_max = whole,
            SpindleMin => ex.spindle_min = whole,
            LimitInvert | ProbeInvert | HardLimits | LaserMode => {
                let on = switch()?;
                ex.flags = (ex.flags & !self.flag()) | if on { self.flag() } else { 0 };
            }
            // Off, or on with the channels `homing_axes` names, which
            // `$22=1` cannot guess.
            Homing => match switch()? {
                false => ex.flags |= FLAG_HOMING_OFF,
                true if cfg.homing.axes == 0 => {
                    return Err(SetError::refused(ErrorKind::Invalid(
                        GlobalField::HomingAxes.name(),
                    )))
                }
                true => ex.flags &= !FLAG_HOMING_OFF,
            },
            DirInvert => {
                let mask = byte(7)?;
                for (p, axis) in places.iter().enumerate() {
                    cfg.axes[axis.index()].dir_high_is_positive = mask >> p & 1 == 0;
                }
            }
            EnableInvert => {
                let high = switch()?;
                for axis in places {
                    cfg.axes[axis.index()].enable_active_high = high;
                }
            }
            SoftLimits => {
                let on = switch()?;
                for axis in places {
                    let a = &mut cfg.axes[axis.index()];
                    // On only where a travel is set: the base turns freely.
                    a.soft_limits = on && a.travel.0 < a.travel.1;
                }
            }
            StepPulse => put(cfg, named(GlobalField::StepPulseUs), Value::Number(whole))?,
            StatusReport => put(cfg, named(GlobalField::StatusReport), Value::Number(whole))?,
            ReportInches => put(cfg, named(GlobalField::ReportInches), Value::Number(whole))?,
            JunctionDeviation => put(
                cfg,
                named(GlobalField::JunctionDeviationUm),
                Value::Number(milli),
            )?,
            ArcTolerance => put(
                cfg,
                named(GlobalField::ArcToleranceUm),
                Value::Number(milli),
            )?,
            HomingPullOff => put(cfg, named(GlobalField::HomingPullOff), Value::Milli(value))?,
            HomingFeed | HomingSeek => {
                let spu = cfg.axes[places[0].index()].steps_per_unit;
                let steps = Value::Number(steps_of(milli, spu, PER_MIN));
                match self {
                    HomingFeed => {
                        put(cfg, named(GlobalField::HomingLocate), steps)?;
                        ex.typed.homing_feed = milli;
                    }
                    _ => {
                        put(cfg, named(GlobalField::HomingSeek), steps)?;
                        ex.typed.homing_seek = milli;
                    }
                }
            }
            MaxRate(p) | Accel(p) => {
                let axis = places[p as usize];
                let a = &cfg.axes[axis.index()];
                let (field, scale) = match self {
                    MaxRate(_) => (AxisField::MaxRate, PER_MIN),
                    _ => (AxisField::Accel, PER_S),
                };
                let steps = Value::Number(steps_of(milli, a.steps_per_unit, scale));
                put(cfg, Setting::Axis(axis, field), steps)?;
                match self {
                    MaxRate(_) => ex.typed.max_rate[axis.index()] = milli,
                    _ => ex.typed.accel[axis.index()] = milli,
                }
            }
            // The travel keeps its upper end.
            MaxTravel(p) => {
                let axis = places[p as usize];
                let end = cfg.axes[axis.index()].travel.1 .0;
                let min = Value::Milli(Milli(end.saturating_sub(value.0)));
                put(cfg, Setting::Axis(axis, AxisField::TravelMin), min)?;
            }
            StepsPerUnit(p) => {
                // A ratio as typed; a decimal in lowest terms.
                let spu = match ratio {
                    true => parse_ratio(text)?,
                    false => reduce(Ratio::new(milli, 1000)),
                };
                self.put_steps_per_unit(cfg, ex, places[p as usize], spu)?
            }
        }
        Ok(())
    }

    /// `$10x`: new steps per unit; `$11x` and `$12x` keep their figures in
    /// units, as Grbl's do, so their steps change with it. Checked whole;
    /// nothing changes on an error.
    fn put_steps_per_unit(
        self,
        cfg: &mut MachineConfig,
        ex: &mut Extras,
        axis: Axis,
        spu: StepsPerUnit,
    ) -> Result<(), SetError> {
        let Numbered::StepsPerUnit(p) = self else {
            return Ok(());
        };
        let rate = Numbered::MaxRate(p).get(cfg, ex);
        let accel = Numbered::Accel(p).get(cfg, ex);
        let milli = |v: Value| match v {
            Value::Milli(m) => m.0 as u32,
            _ => 0,
        };
        let (rate, accel) = (milli(rate), milli(accel));
        Setting::Axis(axis, AxisField::StepsPerUnit)
            .check(Value::Ratio(spu))
            .map_err(SetError::refused)?;
        let i = axis.index();
        let old: AxisConfig = cfg.axes[i];
        let a = &mut cfg.axes[i];
        a.steps_per_unit = spu;
        a.max_rate = steps_of(rate, spu, PER_MIN);
        a.accel = steps_of(accel, spu, PER_S);
        let each = [AxisField::MaxRate, AxisField::Accel]
            .into_iter()
            .try_for_each(|f| {
                let s = Setting::Axis(axis, f);
                s.check(s.get(cfg))
            });
        if let Err(e) = each.and_then(|()| check_whole(cfg)) {
            cfg.axes[i] = old;
            return Err(SetError::refused(e));
        }
        ex.typed.max_rate[i] = rate;
        ex.typed.accel[i] = accel;
        Ok(())
    }
}

/// A named setting to `value`, checked with the whole configuration.
fn put(cfg: &mut MachineConfig, s: Setting, value: Value) -> Result<(), SetError> {
    s.put(cfg, value).map_err(SetError::refused)
}

/// Thousandths per minute (`$110`, `$24`, `$25`) and per second² (`$120`).
const PER_MIN: u32 = 60_000;
const PER_S: u32 = 1000;

/// The steps/s (or /s²) of `milli` thousandths of a unit per `scale`.
fn steps_of(milli: u32, spu: StepsPerUnit, scale: u32) -> u32 {
    per(&[milli, spu.num, spu.den], 1, scale) as u32
}

/// The listed figure of a rate of `steps` on `axis`: `typed` when it still
/// makes those steps, else worked out from them.
fn shown(typed: u32, steps: u32, axis: &AxisConfig, scale: u32) -> i32 {
    let spu = axis.steps_per_unit;
    if typed != 0 && steps_of(typed, spu, scale) == steps {
        return typed as i32;
    }
    per(&[steps, spu.den, spu.num], scale, 1)
}

/// `num/den` in lowest terms of ten (`26.500` typed is 26500/1000: 53/2).
fn reduce(r: StepsPerUnit) -> StepsPerUnit {
    let (mut num, mut den) = (r.num, r.den);
    for f in [2, 5] {
        while den > 1 && num % f == 0 && den % f == 0 {
            num /= f;
            den /= f;
        }
    }
    StepsPerUnit::new(num, den)
}

/// `a × (b × scale_b) / (c × scale_c)`, rounded, as an `i32` (the
/// settings' figures are far within it): the products are up to a
/// steps-per-unit part ([`MAX_DEN`](super::MAX_DEN)) times 60 000, so
/// they fit in 64 bits. Out of line, one copy of the 64-bit maths; its
/// figures by reference (on the AVR, arguments past the registers arrived
/// as garbage).
#[inline(never)]
fn per(&[a, b, c]: &[u32; 3], scale_b: u32, scale_c: u32) -> i32 {
    let c = c as u64 * scale_c as u64;
    let v = (a as u64 * (b as u64 * scale_b as u64) + c / 2) / c.max(1);
    v.min(i32::MAX as u64) as i32
}

#[cfg(test)]
mod tests;
