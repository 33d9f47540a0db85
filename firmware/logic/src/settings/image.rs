//! The settings as the EEPROM keeps them: `taut`, a format version, every
//! setting in `$$` order (whole numbers and millis as 4 bytes, ratios as
//! 8, little-endian), then a Fletcher-16 checksum of all that. Read back
//! only whole: a blank EEPROM, another version, a wrong checksum or a value
//! the firmware would refuse gives the defaults (and one warning line)
//! rather than anything half-read.
//!
//! Written by streaming [`bytes`] (no copy in RAM: the firmware compares
//! each byte with the EEPROM and writes only those that differ).

use super::{all, Setting, Value, COUNT};
use crate::axis::AXES;
use crate::config::MachineConfig;
use crate::machine::Machine;
use crate::units::{Milli, StepsPerUnit};

pub const MAGIC: [u8; 4] = *b"taut";
/// Bumped whenever the settings or their kinds change.
pub const VERSION: u8 = 7;
const HEADER: usize = MAGIC.len() + 1;

/// Why the image was not taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unusable {
    /// Never written (erased EEPROM reads 0xFF).
    Blank,
    /// Written by a firmware with another settings format.
    OtherVersion(u8),
    /// Corrupted (a cut in mid-write, a worn cell).
    Checksum,
    /// Consistent, but a value this firmware refuses.
    Refused(Setting),
    /// Values this firmware refuses together (a pulse too long for a rate).
    Inconsistent,
}

fn width(s: Setting) -> usize {
    match s {
        Setting::Axis(_, super::AxisField::StepsPerUnit) => 8,
        Setting::Global(super::GlobalField::Crosstalk) => 8,
        _ => 4,
    }
}

/// Bytes of an image: 4 a setting, 4 more for each ratio ([`width`]: the
/// steps per unit of every axis, the crosstalk), the checksum's 2. A
/// constant: summed over the settings at run time it took 248 bytes of
/// flash on the AVR.
pub const fn len() -> usize {
    HEADER + 4 * COUNT + 4 * (AXES + 1) + 2
}

/// The image of `cfg`, byte by byte.
pub fn bytes(cfg: &MachineConfig) -> impl Iterator<Item = u8> + '_ {
    let body = MAGIC
        .into_iter()
        .chain([VERSION])
        .chain(all().flat_map(move |s| value_bytes(s.get(cfg))));
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

/// A comparison of `cfg`'s image with the EEPROM, resumable: the store
/// task looks for one byte to write per run, and walking the whole image
/// in one run took ~2.3 ms on the AVR (every task waits behind a run).
/// [`Scan::step`] goes on where the last call stopped, with the checksum
/// summed so far. Start a new scan when the settings change.
#[derive(Clone, Copy, Debug)]
pub struct Scan {
    /// The next part: 0 the header, then setting `next - 1` (an index of
    /// [`Setting::at`]) up to [`COUNT`], then the checksum.
    next: u8,
    /// Its first byte in the image.
    at: u16,
    sum: Fletcher,
}

/// What [`Scan::step`] found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// Byte `.0` of the EEPROM must become `.1`; the scan compares it
    /// again next (once written, it goes on).
    Write(usize, u8),
    /// No difference in the parts compared; more to compare.
    More,
    /// The EEPROM holds the image.
    Same,
}

const LAST_SETTING: u8 = COUNT as u8;
const _: () = assert!(COUNT < u8::MAX as usize - 1);

impl Scan {
    pub const fn new() -> Scan {
        Scan {
            next: 0,
            at: 0,
            sum: Fletcher::new(),
        }
    }

    /// Compares up to `parts` parts of the image (the header, a setting,
    /// the checksum) with what `read(i)` holds at byte `i`.
    /// Built for speed: the store task runs it, which every task waits
    /// behind.
    #[cfg_attr(target_arch = "avr", optimize(speed))]
    pub fn step(&mut self, cfg: &MachineConfig, read: impl Fn(usize) -> u8, parts: u8) -> Step {
        for _ in 0..parts {
            let (buf, n, checksum) = match self.next {
                0 => {
                    let m = MAGIC;
                    ([m[0], m[1], m[2], m[3], VERSION, 0, 0, 0], HEADER, false)
                }
                i if i <= LAST_SETTING => match Setting::at(i as usize - 1) {
                    Some(s) => {
                        let (buf, n) = value_array(s.get(cfg));
                        (buf, n, false)
                    }
                    None => ([0; 8], 0, false),
                },
                i if i == LAST_SETTING + 1 => (widen2(self.sum.value().to_le_bytes()), 2, true),
                _ => return Step::Same,
            };
            // The checksum is not summed: its bytes compare plainly.
            let mut sum = self.sum;
            for (k, &b) in buf[..n].iter().enumerate() {
                let i = self.at as usize + k;
                if read(i) != b {
                    return Step::Write(i, b);
                }
                if !checksum {
                    sum.add(b);
                }
            }
            self.sum = sum;
            self.at += n as u16;
            self.next += 1;
        }
        match self.next > LAST_SETTING + 1 {
            true => Step::Same,
            false => Step::More,
        }
    }
}

impl Default for Scan {
    fn default() -> Self {
        Scan::new()
    }
}

fn widen2(b: [u8; 2]) -> [u8; 8] {
    [b[0], b[1], 0, 0, 0, 0, 0, 0]
}

/// Value bytes: up to 8, the unused ones skipped.
fn value_bytes(v: Value) -> impl Iterator<Item = u8> {
    let (buf, n) = value_array(v);
    buf.into_iter().take(n)
}

/// A value's bytes and how many of them count.
fn value_array(v: Value) -> ([u8; 8], usize) {
    match v {
        Value::Number(n) => (widen(n.to_le_bytes()), 4),
        Value::Milli(m) => (widen(m.0.to_le_bytes()), 4),
        Value::Machine(m) => (widen((m as u32).to_le_bytes()), 4),
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

/// Reads an image through `read(i)` (byte `i` of the EEPROM) onto the
/// defaults `base`.
pub fn decode(read: impl Fn(usize) -> u8, base: &MachineConfig) -> Result<MachineConfig, Unusable> {
    let mut cfg = *base;
    decode_into(read, &mut cfg).map(|()| cfg)
}

/// [`decode`] in place, onto `cfg` (the defaults on entry): on the AVR no
/// copy of the settings sits on the stack. Every value is checked before
/// any is taken, so on an error `cfg` is unchanged, except after
/// [`Unusable::Inconsistent`] (each value fine, the set not): the caller
/// loads the defaults again.
// Out of line: at boot its locals would sit under the checkpoint's
// scan and the kinematics' check (the boot's stack peak).
#[inline(never)]
pub fn decode_into(read: impl Fn(usize) -> u8, cfg: &mut MachineConfig) -> Result<(), Unusable> {
    if (0..HEADER).all(|i| read(i) == 0xFF) {
        return Err(Unusable::Blank);
    }
    let magic_ok = (0..MAGIC.len()).all(|i| read(i) == MAGIC[i]);
    if magic_ok && read(MAGIC.len()) != VERSION {
        return Err(Unusable::OtherVersion(read(MAGIC.len())));
    }
    let n = len();
    let mut sum = Fletcher::new();
    (0..n - 2).for_each(|i| sum.add(read(i)));
    if !magic_ok || u16::from_le_bytes([read(n - 2), read(n - 1)]) != sum.value() {
        return Err(Unusable::Checksum);
    }
    for take in [false, true] {
        let mut at = HEADER;
        for s in all() {
            let value = value(&read, s.get(cfg), at).ok_or(Unusable::Refused(s))?;
            at += width(s);
            s.check(value).map_err(|_| Unusable::Refused(s))?;
            if take {
                s.force(cfg, value);
            }
        }
    }
    // Each value in range; now the set as a whole.
    super::check_whole(cfg).map_err(|_| Unusable::Inconsistent)
}

/// The value in the image at byte `at`, of the kind `like` is.
fn value(read: &impl Fn(usize) -> u8, like: Value, at: usize) -> Option<Value> {
    let word = |i: usize| u32::from_le_bytes([read(i), read(i + 1), read(i + 2), read(i + 3)]);
    Some(match like {
        Value::Number(_) => Value::Number(word(at)),
        Value::Milli(_) => Value::Milli(Milli(word(at) as i32)),
        Value::Machine(_) => Value::Machine(Machine::from_index(u8::try_from(word(at)).ok()?)?),
        Value::Ratio(_) => Value::Ratio(StepsPerUnit::new(word(at), word(at + 4))),
    })
}

/// Fletcher-16: two running sums mod 255 (catches swapped and zeroed
/// bytes, which a plain sum misses).
#[derive(Clone, Copy, Debug)]
struct Fletcher {
    a: u16,
    b: u16,
}

impl Fletcher {
    const fn new() -> Self {
        Fletcher { a: 0, b: 0 }
    }

    /// Both sums stay below 255, so one subtraction reduces them (a `%`
    /// is a 16-bit division on the AVR, twice a byte).
    /// Inlined: once a byte of the image each time the store task looks
    /// for a change (at `z` it was a call).
    #[inline(always)]
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

#[cfg(test)]
mod tests;
