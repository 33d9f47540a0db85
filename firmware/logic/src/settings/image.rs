//! The settings as the EEPROM keeps them: the payload of the settings
//! record ([`eeprom::SETTINGS`](super::eeprom::SETTINGS), two copies,
//! cut-safe). A fixed room of [`PAYLOAD`] bytes, so that a setting added
//! later moves no other record:
//!
//! | byte | what |
//! | --- | --- |
//! | 0 | how many named settings follow ([`STORED`] when this firmware wrote it) |
//! | 1 … | Grbl's [`Extras`] ([`EXTRAS_BYTES`]) |
//! | then | the named settings in stored order ([`stored`]): whole numbers and millis as 4 bytes, ratios as 8, little-endian |
//! | rest | zeros (stored inverted: erased cells) |
//!
//! The stored order is the order settings were added in, never `$$`'s:
//! a new setting goes at its end, and a record written before it came
//! holds fewer: it reads back with what the firmware that wrote it did
//! for the ones it lacks ([`before`]: STEP/DIR drivers, always on), or
//! else the stored machine's defaults. Read back only whole: a value the firmware would
//! refuse, or a set of values it refuses together, makes the copy
//! unusable (the other is tried).
//!
//! [`legacy`]: the one-copy image of format version 6 that boards flashed
//! before kept at byte 0 (the first [`V6`] settings of the stored order),
//! read once to carry its settings over.

use super::grbl::{Extras, EXTRAS_BYTES};
use super::record::Part;
use super::{AxisField, GlobalField, Setting, Value};
use crate::axis::{Axis, AXES};
use crate::config::{Driver, MachineConfig, KEEP_DRIVERS_ON};
use crate::machine::Machine;
use crate::units::{Milli, StepsPerUnit};

/// Why stored settings were not taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unusable {
    /// Never written (erased EEPROM reads 0xFF), or never written whole.
    Blank,
    /// Written by a firmware with another settings format.
    OtherVersion(u8),
    /// Corrupted (a worn cell, a stray write).
    Checksum,
    /// Consistent, but a value this firmware refuses.
    Refused(Setting),
    /// Values this firmware refuses together (a pulse too long for a rate).
    Inconsistent,
}

/// Named settings of version 6 (and of the settings record's version 7):
/// the machine, 8 fields an axis, 23 more machine-wide.
pub const V6: usize = 1 + AXES * V6_AXIS_FIELDS + V6_GLOBALS;
const V6_AXIS_FIELDS: usize = 8;
const V6_GLOBALS: usize = 23;

/// Named settings this firmware stores: [`V6`], then those added since.
pub const STORED: usize = V6 + ADDED;
const ADDED: usize = 3 + AXES;

/// Setting `k` of the stored order: version 6's in its order (the
/// machine, each axis's first 8 fields, the machine-wide fields 1…23),
/// then each added one: the pen's top speed and acceleration, each
/// axis's driver, the step idle delay. Worked out: a table would sit in
/// SRAM on the AVR.
pub fn stored(k: usize) -> Option<Setting> {
    let per_axis = AXES * V6_AXIS_FIELDS;
    Some(match k {
        0 => Setting::Global(GlobalField::Machine),
        k if k <= per_axis => {
            let (axis, field) = ((k - 1) / V6_AXIS_FIELDS, (k - 1) % V6_AXIS_FIELDS);
            Setting::Axis(Axis::ALL[axis], AxisField::at(field))
        }
        k if k < V6 => Setting::Global(GlobalField::at(k - per_axis)?),
        // Added since version 6: append only.
        k => match k - V6 {
            0 => Setting::Global(GlobalField::PenMaxFeed),
            1 => Setting::Global(GlobalField::PenAccel),
            k if k < 2 + AXES => Setting::Axis(Axis::ALL[k - 2], AxisField::Driver),
            k if k == 2 + AXES => Setting::Global(GlobalField::StepIdleDelay),
            _ => return None,
        },
    })
}

/// What a firmware before setting `s` did, for a record written without
/// it: drove STEP/DIR drivers and kept them on. `None`: the stored
/// machine's default (the pen's limits, which planned nothing before).
fn before(s: Setting) -> Option<Value> {
    match s {
        Setting::Axis(_, AxisField::Driver) => Some(Value::Driver(Driver::StepDir)),
        Setting::Global(GlobalField::StepIdleDelay) => Some(Value::Number(KEEP_DRIVERS_ON as u32)),
        _ => None,
    }
}

fn width(s: Setting) -> usize {
    match s {
        Setting::Axis(_, AxisField::StepsPerUnit) => 8,
        Setting::Global(GlobalField::Crosstalk) => 8,
        _ => 4,
    }
}

/// Bytes of the first `n` stored settings: 4 a setting, 4 more for each
/// ratio among them ([`width`]: the steps per unit of every axis, the
/// crosstalk, all in version 6's). A constant expression: summed over
/// the settings at run time it took 248 bytes of flash on the AVR.
pub const fn named_bytes(n: usize) -> usize {
    4 * n + 4 * (AXES + 1)
}

/// Where the named settings begin in the payload.
const NAMED_AT: u16 = 1 + EXTRAS_BYTES;

/// Bytes of the settings record's payload: its fixed room, all the
/// EEPROM holds below the checkpoint (what is not used is zeros). The
/// settings added later must fit ([`ROOM`]).
pub const PAYLOAD: u16 = 281;

/// Bytes of the payload still free for settings added later.
pub const ROOM: usize = PAYLOAD as usize - NAMED_AT as usize - named_bytes(STORED);
const _: () = assert!(named_bytes(STORED) + NAMED_AT as usize <= PAYLOAD as usize);

/// Part `k` of the payload: the count, the extras' parts, each stored
/// setting's value, then zeros to [`PAYLOAD`] bytes.
pub fn part(cfg: &MachineConfig, ex: &Extras, k: u8) -> Option<Part> {
    let extras = Extras::PARTS;
    let k = k as usize;
    if k == 0 {
        return Some(([STORED as u8, 0, 0, 0, 0, 0, 0, 0], 1));
    }
    if k <= extras {
        return ex.part((k - 1) as u8);
    }
    let k = k - 1 - extras;
    if let Some(s) = (k < STORED).then(|| stored(k)).flatten() {
        let (b, n) = value_array(s.get(cfg));
        return Some((b, n as u8));
    }
    // Zeros to the room's end, 8 bytes a part.
    let used = NAMED_AT as usize + named_bytes(STORED) + 8 * (k - STORED);
    let left = (PAYLOAD as usize).checked_sub(used).filter(|&n| n > 0)?;
    Some(([0; 8], left.min(8) as u8))
}

/// A value's bytes and how many of them count.
fn value_array(v: Value) -> ([u8; 8], usize) {
    match v {
        Value::Number(n) => (widen(n.to_le_bytes()), 4),
        Value::Milli(m) => (widen(m.0.to_le_bytes()), 4),
        Value::Machine(m) => (widen((m as u32).to_le_bytes()), 4),
        Value::Driver(d) => (widen((d as u32).to_le_bytes()), 4),
        Value::Ratio(r) => {
            let mut b = [0; 8];
            b[..4].copy_from_slice(&r.num.to_le_bytes());
            b[4..].copy_from_slice(&r.den.to_le_bytes());
            (b, 8)
        }
    }
}

fn widen(b: [u8; 4]) -> [u8; 8] {
    [b[0], b[1], b[2], b[3], 0, 0, 0, 0]
}

/// Reads a payload through `byte(i)` (its byte `i`, as given) onto `cfg`
/// (the defaults on entry) and `ex`, in place: on the AVR no copy of the
/// settings sits on the stack. Every value is checked before any is
/// taken, so on an error `cfg` and `ex` are unchanged, except after
/// [`Unusable::Inconsistent`] (each value fine, the set not): the caller
/// loads the defaults again.
// Out of line: at boot its locals would sit under the checkpoint's
// scan and the kinematics' check (the boot's stack peak).
#[inline(never)]
pub fn decode_into(
    byte: impl Fn(u16) -> u8,
    cfg: &mut MachineConfig,
    ex: &mut Extras,
) -> Result<(), Unusable> {
    let n = byte(0) as usize;
    // A count the room cannot hold is corruption (the CRC passed).
    if n == 0 || NAMED_AT as usize + named_bytes(n) > PAYLOAD as usize {
        return Err(Unusable::Checksum);
    }
    take_named(&|i| byte(NAMED_AT + i), n, cfg)?;
    *ex = Extras::decode(|i| byte(1 + i));
    Ok(())
}

/// The first `n` stored settings from bytes 0… of `byte` (a version-6
/// image's from its byte 5), each checked, then the set. Those past `n`
/// (added after `byte` was written) take what the firmware before them
/// did ([`before`]) or else the stored machine's defaults; past
/// [`STORED`] (written by a newer firmware) are left unread.
pub fn take_named(
    byte: &impl Fn(u16) -> u8,
    n: usize,
    cfg: &mut MachineConfig,
) -> Result<(), Unusable> {
    for take in [false, true] {
        let mut at = 0;
        for s in (0..n.min(STORED)).filter_map(stored) {
            let value = value(byte, s.get(cfg), at).ok_or(Unusable::Refused(s))?;
            at += width(s) as u16;
            s.check(value).map_err(|_| Unusable::Refused(s))?;
            if take {
                // The machine comes first: its defaults under the rest.
                if let Value::Machine(m) = value {
                    cfg.load_defaults(m);
                }
                s.force(cfg, value);
            }
        }
        if take {
            for s in (n..STORED).filter_map(stored) {
                if let Some(v) = before(s) {
                    s.force(cfg, v);
                }
            }
        }
    }
    // Each value in range; now the set as a whole.
    super::check_whole(cfg).map_err(|_| Unusable::Inconsistent)
}

/// The value at byte `at`, of the kind `like` is.
fn value(byte: &impl Fn(u16) -> u8, like: Value, at: u16) -> Option<Value> {
    let word = |i: u16| u32::from_le_bytes([byte(i), byte(i + 1), byte(i + 2), byte(i + 3)]);
    Some(match like {
        Value::Number(_) => Value::Number(word(at)),
        Value::Milli(_) => Value::Milli(Milli(word(at) as i32)),
        Value::Machine(_) => Value::Machine(Machine::from_index(u8::try_from(word(at)).ok()?)?),
        Value::Driver(_) => Value::Driver(Driver::from_index(word(at))?),
        Value::Ratio(_) => Value::Ratio(StepsPerUnit::new(word(at), word(at + 4))),
    })
}

/// The one-copy image of format version 6 at byte 0: `taut`, the version,
/// the named settings as [`decode_into`] reads them (not inverted), a
/// Fletcher-16 checksum. Read once, when no settings record is usable,
/// to carry a board's settings over; its header then becomes the layout
/// marker ([`MARKER`](super::eeprom::MARKER)).
pub mod legacy {
    use super::*;

    pub const MAGIC: [u8; 4] = *b"taut";
    pub const VERSION: u8 = 6;
    const HEADER: usize = MAGIC.len() + 1;

    /// Bytes of a version-6 image: its [`V6`] settings.
    pub const fn len() -> usize {
        HEADER + named_bytes(V6) + 2
    }

    /// The version byte at byte 4 when bytes 0…3 are `taut`.
    pub fn version(read: &impl Fn(u16) -> u8) -> Option<u8> {
        (0..MAGIC.len())
            .all(|i| read(i as u16) == MAGIC[i])
            .then(|| read(4))
    }

    /// A version-6 image of `cfg` (boards flashed before held these).
    pub fn bytes(cfg: &MachineConfig) -> impl Iterator<Item = u8> + '_ {
        let body = MAGIC
            .into_iter()
            .chain([VERSION])
            .chain((0..V6).filter_map(stored).flat_map(move |s| {
                let (b, n) = value_array(s.get(cfg));
                b.into_iter().take(n)
            }));
        let mut sum = Fletcher::new();
        let mut tail = 0;
        body.map(Some).chain([None, None]).map(move |b| match b {
            Some(b) => {
                sum.add(b);
                b
            }
            None => {
                tail += 1;
                sum.value().to_le_bytes()[tail - 1]
            }
        })
    }

    /// Whether `read` (byte `i` of the EEPROM) holds a whole version-6
    /// image; its [`V6`] settings are then [`super::take_named`] from
    /// byte [`BODY`].
    pub fn check(read: &impl Fn(u16) -> u8) -> Result<(), Unusable> {
        match version(read) {
            Some(VERSION) => {}
            Some(v) => return Err(Unusable::OtherVersion(v)),
            None if (0..HEADER as u16).all(|i| read(i) == 0xFF) => return Err(Unusable::Blank),
            None => return Err(Unusable::Checksum),
        }
        let n = len() as u16;
        let mut sum = Fletcher::new();
        (0..n - 2).for_each(|i| sum.add(read(i)));
        match u16::from_le_bytes([read(n - 2), read(n - 1)]) == sum.value() {
            true => Ok(()),
            false => Err(Unusable::Checksum),
        }
    }

    /// Where a version-6 image's settings begin.
    pub const BODY: u16 = HEADER as u16;

    /// The settings of a version-6 image onto `cfg` (the defaults on
    /// entry), as [`super::decode_into`].
    pub fn decode_into(read: impl Fn(u16) -> u8, cfg: &mut MachineConfig) -> Result<(), Unusable> {
        check(&read)?;
        take_named(&|i| read(BODY + i), V6, cfg)
    }

    /// Fletcher-16: two running sums mod 255.
    #[derive(Clone, Copy, Debug)]
    struct Fletcher {
        a: u16,
        b: u16,
    }

    impl Fletcher {
        const fn new() -> Self {
            Fletcher { a: 0, b: 0 }
        }

        fn add(&mut self, x: u8) {
            self.a += x as u16;
            if self.a >= 255 {
                self.a -= 255;
            }
            self.b += self.a;
            if self.b >= 255 {
                self.b -= 255;
            }
        }

        fn value(&self) -> u16 {
            self.b << 8 | self.a
        }
    }
}

/// Bytes a version-6 image takes.
pub const LEGACY_LEN: usize = legacy::len();

#[cfg(test)]
mod tests;
