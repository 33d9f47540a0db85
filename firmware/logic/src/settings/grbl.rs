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
/// every machine. (`$1` is the named `step_idle_delay_ms`: the drivers
/// task reads it, and each machine has its own.)
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Extras {
    /// `$2` step invert mask, the `FLAG_` bits (`$5`, `$6`, `$21`, `$22`
    /// off, `$32`), `$23` homing direction invert mask, `$26` homing
    /// debounce (ms): by the `BYTE_` indices.
    pub bytes: [u8; BYTES],
    /// `$30`, `$31`: rpm at the spindle output's top and bottom.
    pub spindle: [u32; 2],
    /// The rates as last typed in Grbl's units, thousandths of a unit per
    /// minute (`$110`…, `$24`, `$25`) or per second² (`$120`…), by the
    /// `TYPED_` indices (per channel for the axes'); 0: never typed so.
    /// Listed while the steps figure is still the one they make: a rate
    /// set by name since shows as its steps make it.
    pub typed: [u32; TYPED],
}

pub const BYTE_STEP_INVERT: usize = 0;
pub const BYTE_FLAGS: usize = 1;
pub const BYTE_HOMING_DIR: usize = 2;
pub const BYTE_DEBOUNCE: usize = 3;
pub const BYTES: usize = 4;

/// `typed[TYPED_MAX_RATE + channel]`, `typed[TYPED_ACCEL + channel]`.
pub const TYPED_MAX_RATE: usize = 0;
pub const TYPED_ACCEL: usize = AXES;
pub const TYPED_HOMING_FEED: usize = 2 * AXES;
pub const TYPED_HOMING_SEEK: usize = 2 * AXES + 1;
pub const TYPED: usize = 2 * AXES + 2;

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
/// `$flow=xonxoff`: the console sends XOFF and XON (taut's, by name: a
/// record from before it has the bit clear, flow control off).
pub const FLAG_XONXOFF: u8 = 32;
/// `$uart1_baud`: the second console's rate, a [`Uart1Baud`] code in
/// these two bits (a record from before it has them clear: 9600).
pub const FLAGS_UART1: u8 = 0b1100_0000;
const UART1_SHIFT: u8 = 6;

/// `$uart1_baud=`: the second console's rate (an HC-05/HC-06's), or 0:
/// off. The rates a Bluetooth module is set to most, exact enough from
/// the Mega's 16 MHz clock.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Uart1Baud {
    /// The modules' factory rate.
    B9600 = 0,
    B38400 = 1,
    B115200 = 2,
    Off = 3,
}

impl Uart1Baud {
    /// Bits per second (0: off).
    pub fn bps(self) -> u32 {
        match self {
            Uart1Baud::B9600 => 9600,
            Uart1Baud::B38400 => 38400,
            Uart1Baud::B115200 => 115_200,
            Uart1Baud::Off => 0,
        }
    }

    pub fn from_bps(bps: u32) -> Option<Uart1Baud> {
        Some(match bps {
            9600 => Uart1Baud::B9600,
            38400 => Uart1Baud::B38400,
            115_200 => Uart1Baud::B115200,
            0 => Uart1Baud::Off,
            _ => return None,
        })
    }
}

/// Bytes of [`Extras`] in EEPROM.
pub const EXTRAS_BYTES: u16 = BYTES as u16 + 2 * 4 + TYPED as u16 * 4;

impl Extras {
    /// Grbl's defaults (`defaults.h`).
    pub const DEFAULT: Extras = Extras {
        bytes: [0, 0, 0, 250],
        spindle: [1000, 0],
        typed: [0; TYPED],
    };

    /// [`Extras::DEFAULT`] in place, a field at a time: a copy of the
    /// constant would sit in the AVR's SRAM.
    pub fn reset(&mut self) {
        self.bytes = [0; BYTES];
        self.bytes[BYTE_DEBOUNCE] = 250;
        self.spindle = [0; 2];
        self.spindle[0] = 1000;
        self.typed = [0; TYPED];
    }

    pub fn flags(&self) -> u8 {
        self.bytes[BYTE_FLAGS]
    }

    /// `$flow=xonxoff`: the console's XON/XOFF flow control is on.
    pub fn xonxoff(&self) -> bool {
        self.flags() & FLAG_XONXOFF != 0
    }

    /// `$flow=`: `xonxoff` or `off` (any case); else the value's error.
    pub fn set_flow(&mut self, value: &[u8]) -> Result<(), NumError> {
        // Flash texts: literals would sit in the AVR's SRAM.
        let on = match value {
            v if text!("xonxoff").eq_ignore_ascii_case(v) => true,
            v if text!("off").eq_ignore_ascii_case(v) => false,
            _ => {
                return Err(NumError {
                    at: 0,
                    kind: ErrorKind::Invalid(text!("flow")),
                })
            }
        };
        let flags = &mut self.bytes[BYTE_FLAGS];
        *flags = *flags & !FLAG_XONXOFF | if on { FLAG_XONXOFF } else { 0 };
        Ok(())
    }

    /// `$uart1_baud`: the second console's rate.
    pub fn uart1_baud(&self) -> Uart1Baud {
        match (self.flags() & FLAGS_UART1) >> UART1_SHIFT {
            0 => Uart1Baud::B9600,
            1 => Uart1Baud::B38400,
            2 => Uart1Baud::B115200,
            _ => Uart1Baud::Off,
        }
    }

    /// UART1's rate on `machine`: off on the string-art machine, whose
    /// `zero_drill` button is on D18 (TX1).
    pub fn uart1(&self, machine: Machine) -> Uart1Baud {
        match machine.is_string_art() {
            true => Uart1Baud::Off,
            false => self.uart1_baud(),
        }
    }

    /// `$uart1_baud=`: 9600, 38400, 115200, or 0 (off); else the value's
    /// error.
    pub fn set_uart1_baud(&mut self, value: &[u8]) -> Result<(), NumError> {
        let bad = NumError {
            at: 0,
            kind: ErrorKind::Invalid(text!("uart1_baud: 9600, 38400, 115200 or 0")),
        };
        // By hand: `str::parse` would bring a 256-byte table into SRAM.
        let digits = !value.is_empty() && value.len() <= 6 && value.iter().all(u8::is_ascii_digit);
        let bps = value
            .iter()
            .fold(0u32, |n, &d| n * 10 + u32::from(d.wrapping_sub(b'0')));
        let baud = Uart1Baud::from_bps(bps).filter(|_| digits).ok_or(bad)?;
        let flags = &mut self.bytes[BYTE_FLAGS];
        *flags = *flags & !FLAGS_UART1 | (baud as u8) << UART1_SHIFT;
        Ok(())
    }

    /// Whether `$H` may home: `$22` on and a channel to home.
    pub fn homing_enabled(&self, cfg: &MachineConfig) -> bool {
        self.flags() & FLAG_HOMING_OFF == 0 && cfg.homing.axes != 0
    }

    /// Parts [`Extras::part`] gives: the bytes, then two words a part.
    pub const PARTS: usize = 1 + (2 + TYPED) / 2;

    /// Part `k` of the EEPROM bytes: the bytes, then the two rpm figures,
    /// then the typed rates, little-endian.
    pub fn part(&self, k: u8) -> Option<Part> {
        let k = k as usize;
        if k == 0 {
            let b = self.bytes;
            return Some(([b[0], b[1], b[2], b[3], 0, 0, 0, 0], BYTES as u8));
        }
        let word = |i: usize| match i {
            0 | 1 => self.spindle.get(i).copied(),
            _ => self.typed.get(i - 2).copied(),
        };
        let (a, b) = (
            word(2 * k - 2)?.to_le_bytes(),
            word(2 * k - 1)?.to_le_bytes(),
        );
        Some(([a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3]], 8))
    }

    /// The extras from their bytes through `byte(i)`. Any value is taken:
    /// none is refused by the machine.
    pub fn decode(byte: impl Fn(u16) -> u8) -> Extras {
        let word = |n: usize| {
            let i = (BYTES + 4 * n) as u16;
            u32::from_le_bytes([byte(i), byte(i + 1), byte(i + 2), byte(i + 3)])
        };
        Extras {
            bytes: core::array::from_fn(|i| byte(i as u16)),
            spindle: [word(0), word(1)],
            typed: core::array::from_fn(|i| word(i + 2)),
        }
    }
}

impl Default for Extras {
    fn default() -> Self {
        Extras::DEFAULT
    }
}

// The words pair up into parts.
const _: () = assert!(TYPED.is_multiple_of(2));

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

    /// Where this setting's value lives on `cfg`'s machine.
    fn held(self, cfg: &MachineConfig) -> Held {
        use Numbered::*;
        let places = report_axes(cfg.machine);
        let global = |g| Setting::Global(g);
        let axis = |p: u8| places[p as usize];
        match self {
            IdleDelay => Held::Named(global(GlobalField::StepIdleDelay)),
            StepInvert => Held::Byte(BYTE_STEP_INVERT),
            HomingDirInvert => Held::Byte(BYTE_HOMING_DIR),
            HomingDebounce => Held::Byte(BYTE_DEBOUNCE),
            SpindleMax => Held::Rpm(0),
            SpindleMin => Held::Rpm(1),
            LimitInvert => Held::Flag(FLAG_LIMIT_INVERT),
            ProbeInvert => Held::Flag(FLAG_PROBE_INVERT),
            HardLimits => Held::Flag(FLAG_HARD_LIMITS),
            LaserMode => Held::Flag(FLAG_LASER),
            Homing => Held::HomingOn,
            DirInvert | EnableInvert | SoftLimits => Held::Places,
            StepPulse => Held::Named(global(GlobalField::StepPulseUs)),
            StatusReport => Held::Named(global(GlobalField::StatusReport)),
            ReportInches => Held::Named(global(GlobalField::ReportInches)),
            JunctionDeviation => Held::Micro(global(GlobalField::JunctionDeviationUm)),
            ArcTolerance => Held::Micro(global(GlobalField::ArcToleranceUm)),
            HomingPullOff => Held::Named(global(GlobalField::HomingPullOff)),
            HomingFeed => Held::Rate(
                TYPED_HOMING_FEED,
                global(GlobalField::HomingLocate),
                axis(0),
            ),
            HomingSeek => Held::Rate(TYPED_HOMING_SEEK, global(GlobalField::HomingSeek), axis(0)),
            MaxRate(p) => Held::Rate(
                TYPED_MAX_RATE + axis(p).index(),
                Setting::Axis(axis(p), AxisField::MaxRate),
                axis(p),
            ),
            Accel(p) => Held::Rate(
                TYPED_ACCEL + axis(p).index(),
                Setting::Axis(axis(p), AxisField::Accel),
                axis(p),
            ),
            StepsPerUnit(p) => Held::StepsPerUnit(axis(p), p),
            MaxTravel(p) => Held::Travel(axis(p)),
        }
    }

    /// The value in Grbl's units: whole numbers for switches, masks, times
    /// and rpm, three decimals for lengths and rates.
    #[inline(never)]
    pub fn get(self, cfg: &MachineConfig, ex: &Extras) -> Value {
        let milli = |m: i32| Value::Milli(Milli(m));
        let n = |v: u32| Value::Number(v);
        match self.held(cfg) {
            Held::Byte(i) => n(ex.bytes[i] as u32),
            Held::Flag(f) => n((ex.flags() & f != 0) as u32),
            Held::Rpm(i) => n(ex.spindle[i]),
            Held::HomingOn => n(ex.homing_enabled(cfg) as u32),
            Held::Places => n(self.over_places(cfg) as u32),
            Held::Named(s) => s.get(cfg),
            Held::Micro(s) => match s.get(cfg) {
                Value::Number(um) => milli(um as i32),
                v => v,
            },
            Held::Rate(t, s, axis) => {
                let steps = match s.get(cfg) {
                    Value::Number(v) => v,
                    _ => 0,
                };
                milli(shown(
                    ex.typed[t],
                    steps,
                    &cfg.axes[axis.index()],
                    self.scale(),
                ))
            }
            Held::StepsPerUnit(axis, _) => {
                let Ratio { num, den } = cfg.axes[axis.index()].steps_per_unit;
                milli(per(&[num, 1, den], 1000, 1))
            }
            Held::Travel(axis) => {
                let (lo, hi) = cfg.axes[axis.index()].travel;
                milli(hi.0.wrapping_sub(lo.0))
            }
        }
    }

    /// A rate's thousandths: per minute, or per second² (`$12x`).
    fn scale(self) -> u32 {
        match self {
            Numbered::Accel(_) => PER_S,
            _ => PER_MIN,
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
        let held = self.held(cfg);
        // `$100` may be a ratio (`1600/12`); anything else a number.
        // A loop, not `contains`: that brings core's memchr (~480 B of AVR
        // flash) for a line of a few bytes.
        #[allow(clippy::manual_contains)]
        let ratio = matches!(held, Held::StepsPerUnit(..)) && text.iter().any(|&b| b == b'/');
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
        // Grbl truncates a whole-number setting's value.
        let whole = milli / 1000;
        // The value listed now keeps the exact figure behind it (a sender
        // writes back what `$$` showed: `$101=26.667` stays 9600/360).
        let same = match self.get(cfg, ex) {
            Value::Milli(m) => m == value,
            Value::Number(n) => n == whole,
            _ => false,
        };
        if same && !ratio {
            return Ok(());
        }
        let byte = |max: u8| match whole <= max as u32 {
            true => Ok(whole as u8),
            false => Err(SetError::refused(ErrorKind::Range {
                min: 0,
                max: max as u32,
            })),
        };
        match held {
            Held::Byte(i) => ex.bytes[i] = byte(255)?,
            Held::Rpm(i) => ex.spindle[i] = whole,
            Held::Flag(f) => {
                let on = byte(1)? == 1;
                let flags = &mut ex.bytes[BYTE_FLAGS];
                *flags = (*flags & !f) | if on { f } else { 0 };
            }
            // Off, or on with the channels `homing_axes` names, which
            // `$22=1` cannot guess.
            Held::HomingOn => match byte(1)? {
                0 => ex.bytes[BYTE_FLAGS] |= FLAG_HOMING_OFF,
                _ if cfg.homing.axes == 0 => {
                    return Err(SetError::refused(ErrorKind::Invalid(
                        GlobalField::HomingAxes.name(),
                    )))
                }
                _ => ex.bytes[BYTE_FLAGS] &= !FLAG_HOMING_OFF,
            },
            Held::Places => {
                let max = match self {
                    Numbered::DirInvert => 7,
                    _ => 1,
                };
                self.put_over_places(cfg, byte(max)?)
            }
            Held::Named(s) => {
                let v = match s.get(cfg) {
                    Value::Milli(_) => Value::Milli(value),
                    _ => Value::Number(whole),
                };
                put(cfg, s, v)?
            }
            Held::Micro(s) => put(cfg, s, Value::Number(milli))?,
            Held::Rate(t, s, axis) => {
                let spu = cfg.axes[axis.index()].steps_per_unit;
                put(cfg, s, Value::Number(steps_of(milli, spu, self.scale())))?;
                ex.typed[t] = milli;
            }
            // The travel keeps its upper end.
            Held::Travel(axis) => {
                let end = cfg.axes[axis.index()].travel.1 .0;
                let min = Value::Milli(Milli(end.saturating_sub(value.0)));
                put(cfg, Setting::Axis(axis, AxisField::TravelMin), min)?;
            }
            Held::StepsPerUnit(axis, p) => {
                // A ratio as typed; a decimal in lowest terms.
                let spu = match ratio {
                    true => parse_ratio(text)?,
                    false => reduce(Ratio::new(milli, 1000)),
                };
                put_steps_per_unit(cfg, ex, axis, p, spu)?
            }
        }
        Ok(())
    }

    /// `$3` (a bit per place), `$4`, `$20` to `n` over the report places.
    #[inline(never)]
    fn put_over_places(self, cfg: &mut MachineConfig, n: u8) {
        for (p, axis) in report_axes(cfg.machine).iter().enumerate() {
            let a = &mut cfg.axes[axis.index()];
            match self {
                Numbered::DirInvert => a.dir_high_is_positive = n >> p & 1 == 0,
                Numbered::EnableInvert => a.enable_active_high = n == 1,
                // On only where a travel is set: the base turns freely.
                _ => a.soft_limits = n == 1 && a.travel.0 < a.travel.1,
            }
        }
    }
}

/// Where a numbered setting's value lives.
#[derive(Clone, Copy)]
enum Held {
    /// [`Extras::bytes`]`[i]`.
    Byte(usize),
    /// A bit of the extras' flags.
    Flag(u8),
    /// [`Extras::spindle`]`[i]`.
    Rpm(usize),
    /// `$22`: the flag and `homing_axes`.
    HomingOn,
    /// `$3`, `$4`, `$20`: a field of every report place.
    Places,
    /// A named setting in Grbl's unit (a whole number or thousandths).
    Named(Setting),
    /// A named setting in µm, which Grbl counts in mm.
    Micro(Setting),
    /// A rate in Grbl's units: its typed figure, the named setting of its
    /// steps, the channel whose steps per unit convert it.
    Rate(usize, Setting, Axis),
    /// `$10x`: the channel, its report place.
    StepsPerUnit(Axis, u8),
    /// `$13x`: the travel's length.
    Travel(Axis),
}

/// `$10x`: new steps per unit; `$11x` and `$12x` keep their figures in
/// units, as Grbl's do, so their steps change with it. Checked whole;
/// nothing changes on an error.
#[inline(never)]
fn put_steps_per_unit(
    cfg: &mut MachineConfig,
    ex: &mut Extras,
    axis: Axis,
    p: u8,
    spu: Ratio,
) -> Result<(), SetError> {
    let milli = |v: Value| match v {
        Value::Milli(m) => m.0 as u32,
        _ => 0,
    };
    let rate = milli(Numbered::MaxRate(p).get(cfg, ex));
    let accel = milli(Numbered::Accel(p).get(cfg, ex));
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
    ex.typed[TYPED_MAX_RATE + i] = rate;
    ex.typed[TYPED_ACCEL + i] = accel;
    Ok(())
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
