//! Grbl 1.1's numbered settings (`$0` … `$132`) over ours: `$$` lists
//! those that mean something here, in Grbl's units, before our named
//! ones; `$<n>=<value>` writes the named settings behind them. Per-axis
//! numbers count Grbl's X, Y, Z places of the status report
//! ([`report_axes`]): on the string-art machine `$100` is the radial
//! carriage (word `X`), `$101` the base (`C`, degrees), `$102` the drill.

use super::{AxisField, GlobalField, Setting, SettingError, Value};
use crate::axis::Axis;
use crate::config::{AxisConfig, MachineConfig};
use crate::machine::Machine;
use crate::text::num::{parse_milli, parse_ratio, parse_u32, trim, NumError};
use crate::text::ErrorKind;
use crate::units::{Milli, StepsPerUnit};
use taut_progmem::text;

/// A Grbl setting taut has, by what it sets. The per-axis ones carry the
/// report place (0 X, 1 Y, 2 Z).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Numbered {
    /// `$0` step pulse, µs.
    StepPulse,
    /// `$1` step idle delay, ms: 255, the drivers always hold.
    IdleDelay,
    /// `$4` step enable invert: 1, ENABLE high switches a driver on.
    EnableInvert,
    /// `$3` direction invert, a bit per place.
    DirInvert,
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
    /// `$21` hard limits: taut has none, 0.
    HardLimits,
    /// `$22` homing cycle.
    Homing,
    /// `$27` homing pull-off, mm.
    HomingPullOff,
    /// `$100…` steps per unit.
    StepsPerUnit(u8),
    /// `$110…` maximum rate, units/min.
    MaxRate(u8),
    /// `$120…` acceleration, units/s².
    Accel(u8),
    /// `$130…` maximum travel, units.
    MaxTravel(u8),
}

/// How many numbered settings `$$` lists.
pub const COUNT: usize = 12 + 4 * 3;

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

impl Numbered {
    /// The setting at `index` in `$$` order: `$0 $1 $3 $4 $10 $11 $12 $13
    /// $20 $21 $22 $27`, then `$100…$132`.
    pub fn at(index: usize) -> Option<Numbered> {
        // Grbl's numbers below 100 as bytes of a flash text: a table would
        // sit in SRAM on the AVR.
        let small = text!("\0\x01\x03\x04\n\x0b\x0c\r\x14\x15\x16\x1b");
        let n = match index {
            i if i < small.len() => small.byte(i),
            i if i < COUNT => {
                let i = (i - small.len()) as u8;
                100 + i / 3 * 10 + i % 3
            }
            _ => return None,
        };
        Numbered::from_number(n)
    }

    /// The setting Grbl numbers `n`, if taut has it.
    pub fn from_number(n: u8) -> Option<Numbered> {
        let place = n % 10;
        Some(match n {
            0 => Numbered::StepPulse,
            1 => Numbered::IdleDelay,
            3 => Numbered::DirInvert,
            4 => Numbered::EnableInvert,
            10 => Numbered::StatusReport,
            11 => Numbered::JunctionDeviation,
            12 => Numbered::ArcTolerance,
            13 => Numbered::ReportInches,
            20 => Numbered::SoftLimits,
            21 => Numbered::HardLimits,
            22 => Numbered::Homing,
            27 => Numbered::HomingPullOff,
            100..=102 => Numbered::StepsPerUnit(place),
            110..=112 => Numbered::MaxRate(place),
            120..=122 => Numbered::Accel(place),
            130..=132 => Numbered::MaxTravel(place),
            _ => return None,
        })
    }

    /// The setting a `$` key names (`10`, `110`), if taut has it.
    pub fn parse(key: &[u8]) -> Option<Numbered> {
        match parse_u32(key) {
            Ok(n) if n <= u8::MAX as u32 => Numbered::from_number(n as u8),
            _ => None,
        }
    }

    pub fn number(self) -> u8 {
        match self {
            Numbered::StepPulse => 0,
            Numbered::IdleDelay => 1,
            Numbered::DirInvert => 3,
            Numbered::EnableInvert => 4,
            Numbered::StatusReport => 10,
            Numbered::JunctionDeviation => 11,
            Numbered::ArcTolerance => 12,
            Numbered::ReportInches => 13,
            Numbered::SoftLimits => 20,
            Numbered::HardLimits => 21,
            Numbered::Homing => 22,
            Numbered::HomingPullOff => 27,
            Numbered::StepsPerUnit(p) => 100 + p,
            Numbered::MaxRate(p) => 110 + p,
            Numbered::Accel(p) => 120 + p,
            Numbered::MaxTravel(p) => 130 + p,
        }
    }

    /// The named setting behind this one and how Grbl counts it; `None`
    /// for those over several fields or none.
    fn behind(self, machine: Machine) -> Option<(Setting, Unit)> {
        let axis = |p: u8, field| Setting::Axis(report_axes(machine)[p as usize], field);
        let global = |g| Setting::Global(g);
        Some(match self {
            Numbered::StepPulse => (global(GlobalField::StepPulseUs), Unit::Same),
            Numbered::IdleDelay => (global(GlobalField::StepIdleDelay), Unit::Same),
            Numbered::StatusReport => (global(GlobalField::StatusReport), Unit::Same),
            Numbered::ReportInches => (global(GlobalField::ReportInches), Unit::Same),
            Numbered::HomingPullOff => (global(GlobalField::HomingPullOff), Unit::Same),
            Numbered::JunctionDeviation => (global(GlobalField::JunctionDeviationUm), Unit::Micro),
            Numbered::ArcTolerance => (global(GlobalField::ArcToleranceUm), Unit::Micro),
            Numbered::StepsPerUnit(p) => (axis(p, AxisField::StepsPerUnit), Unit::Ratio),
            Numbered::MaxRate(p) => (axis(p, AxisField::MaxRate), Unit::PerMinute),
            Numbered::Accel(p) => (axis(p, AxisField::Accel), Unit::PerSecond),
            Numbered::MaxTravel(p) => (axis(p, AxisField::TravelMin), Unit::Span),
            _ => return None,
        })
    }

    /// The value in Grbl's units: whole numbers for switches and masks,
    /// three decimals for lengths and rates.
    #[inline(never)]
    pub fn get(self, cfg: &MachineConfig) -> Value {
        let Some((setting, unit)) = self.behind(cfg.machine) else {
            return Value::Number(self.over_places(cfg));
        };
        let a = axis_of(setting, cfg);
        let StepsPerUnit { num, den } = a.steps_per_unit;
        let value = setting.get(cfg);
        let n = match value {
            Value::Number(n) => n,
            _ => 0,
        };
        Value::Milli(Milli(match unit {
            Unit::Same => return value,
            Unit::Ratio => per(&[num, 1, den], 1000, 1),
            Unit::Micro => n as i32,
            Unit::PerSecond | Unit::PerMinute => per(&[n, den, num], unit.scale(), 1),
            Unit::Span => a.travel.1 .0.wrapping_sub(a.travel.0 .0),
        }))
    }

    /// The value of a switch or mask over the report places.
    fn over_places(self, cfg: &MachineConfig) -> u32 {
        // Bytes: a `u32`'s shifts are four times as long on the AVR.
        let mut mask = [0u8; 3];
        for (p, axis) in report_axes(cfg.machine).iter().enumerate() {
            let a = &cfg.axes[axis.index()];
            mask[0] |= (!a.dir_high_is_positive as u8) << p;
            mask[1] |= (a.soft_limits as u8) << p;
            mask[2] |= (!a.enable_active_high as u8) << p;
        }
        (match self {
            Numbered::DirInvert => mask[0],
            Numbered::SoftLimits => (mask[1] != 0) as u8,
            Numbered::Homing => (cfg.homing.axes != 0) as u8,
            // Grbl's ENABLE is active low unless inverted.
            Numbered::EnableInvert => (mask[2] == 0) as u8,
            _ => 0,
        }) as u32
    }

    /// Sets the settings behind this one from `text` (Grbl's units),
    /// checked with the whole configuration ([`Setting::put`]); nothing
    /// changes on an error.
    #[inline(never)]
    pub fn set(self, cfg: &mut MachineConfig, text: &[u8]) -> Result<(), SettingError> {
        let (lead, text) = trim(text);
        self.put(cfg, text).map_err(|e| NumError {
            at: lead + e.at,
            kind: e.kind,
        })
    }

    fn put(self, cfg: &mut MachineConfig, text: &[u8]) -> Result<(), NumError> {
        let error = |kind| NumError { at: 0, kind };
        // The value listed now keeps the exact figure behind it (a sender
        // writes back what `$$` showed: `$101=26.667` stays 9600/360).
        let listed = self.get(cfg);
        let whole = parse_u32(text);
        let milli = parse_milli(text);
        let same = match listed {
            Value::Milli(m) => matches!(milli, Ok(v) if v == m),
            Value::Number(n) => matches!(whole, Ok(v) if v == n),
            _ => false,
        };
        if same {
            return Ok(());
        }
        let Some((setting, unit)) = self.behind(cfg.machine) else {
            return self.put_over_places(cfg, whole?).map_err(error);
        };
        let a = axis_of(setting, cfg);
        // Lengths and rates are never below zero.
        let milli = milli.map(|m| m.0.max(0));
        let StepsPerUnit { num, den } = a.steps_per_unit;
        let value = match unit {
            Unit::Ratio => Value::Ratio(parse_ratio(text)?),
            Unit::Same => match listed {
                Value::Milli(_) => Value::Milli(Milli(milli?)),
                _ => Value::Number(whole?),
            },
            Unit::Micro => Value::Number(milli? as u32),
            Unit::PerSecond | Unit::PerMinute => {
                Value::Number(per(&[milli? as u32, num, den], 1, unit.scale()) as u32)
            }
            // The travel keeps its upper end.
            Unit::Span => Value::Milli(Milli(a.travel.1 .0.saturating_sub(milli?))),
        };
        setting.put(cfg, value).map_err(error)
    }

    /// Sets a switch or mask over the report places to `n`: no figure at
    /// odds, only its range.
    fn put_over_places(self, cfg: &mut MachineConfig, n: u32) -> Result<(), ErrorKind> {
        let max = match self {
            Numbered::DirInvert => 7,
            Numbered::SoftLimits | Numbered::Homing | Numbered::EnableInvert => 1,
            _ => 0,
        };
        if n > max {
            return Err(ErrorKind::Range { min: 0, max });
        }
        match self {
            // Off, or on with the axes `homing_axes` names, which `$22=1`
            // cannot guess.
            Numbered::Homing if n == 1 => {
                return Err(ErrorKind::Invalid(GlobalField::HomingAxes.name()))
            }
            Numbered::Homing => cfg.homing.axes = 0,
            _ => {
                for (p, axis) in report_axes(cfg.machine).iter().enumerate() {
                    let a = &mut cfg.axes[axis.index()];
                    match self {
                        Numbered::DirInvert => a.dir_high_is_positive = n >> p & 1 == 0,
                        // Every driver alike, as Grbl's one ENABLE pin.
                        Numbered::EnableInvert => a.enable_active_high = n == 1,
                        // On only where a travel is set: the base turns freely.
                        _ => a.soft_limits = n == 1 && a.travel.0 < a.travel.1,
                    }
                }
            }
        }
        Ok(())
    }
}

/// How Grbl counts a setting against ours.
#[derive(Clone, Copy)]
enum Unit {
    /// As ours: a whole number, or thousandths.
    Same,
    /// Steps per unit, with three decimals.
    Ratio,
    /// µm as mm.
    Micro,
    /// Steps/s as units/min (`$110`).
    PerMinute,
    /// Steps/s² as units/s² (`$120`).
    PerSecond,
    /// The travel's length: its lower end below the upper one.
    Span,
}

impl Unit {
    /// Thousandths of a unit per minute or per second.
    fn scale(self) -> u32 {
        match self {
            Unit::PerMinute => 60_000,
            _ => 1000,
        }
    }
}

/// The axis of a per-axis setting (the first for the others).
fn axis_of(setting: Setting, cfg: &MachineConfig) -> &AxisConfig {
    match setting {
        Setting::Axis(a, _) => &cfg.axes[a.index()],
        Setting::Global(_) => &cfg.axes[0],
    }
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
