//! Numbers read one character at a time, without floats: a fixed-point
//! value is kept as its magnitude in thousandths, so `-2.5` becomes
//! `Milli(-2500)` with one multiply-add per digit.

use crate::text::num::times_ten_plus;
use crate::units::Milli;

/// A number being read. A `push` error means the character cannot belong
/// to this number (a second point, a late sign, too large).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Number {
    /// Magnitude so far: thousandths for fixed-point numbers, else units.
    magnitude: u32,
    /// Largest magnitude accepted.
    limit: u32,
    /// [`FIXED`], [`NEGATIVE`], [`SIGNED`], [`DIGITS`], [`POINT`], and the
    /// decimals read (saturating at 7) above [`DECIMALS_SHIFT`]: one byte,
    /// as the parser's statics and frames hold several numbers.
    flags: u8,
}

/// Fixed-point (sign and point allowed), else a plain unsigned integer.
const FIXED: u8 = 1;
const NEGATIVE: u8 = 2;
const SIGNED: u8 = 4;
const DIGITS: u8 = 8;
const POINT: u8 = 16;
const DECIMALS_SHIFT: u8 = 5;

impl Number {
    /// A signed value with up to three decimals kept, e.g. `X-2.5`.
    pub(super) const fn fixed() -> Number {
        Number::new(FIXED, i32::MAX as u32)
    }

    /// An unsigned integer up to `limit`, e.g. `N` or the checksum.
    pub(super) const fn integer(limit: u32) -> Number {
        Number::new(0, limit)
    }

    const fn new(flags: u8, limit: u32) -> Number {
        Number {
            magnitude: 0,
            limit,
            flags,
        }
    }

    fn has(&self, flag: u8) -> bool {
        self.flags & flag != 0
    }

    pub(super) fn has_digits(&self) -> bool {
        self.has(DIGITS)
    }

    pub(super) fn push(&mut self, c: u8) -> Result<(), ()> {
        let fixed = self.has(FIXED);
        match c {
            b'+' | b'-' if fixed && !self.has(SIGNED | DIGITS | POINT) => {
                self.flags |= SIGNED | if c == b'-' { NEGATIVE } else { 0 };
                Ok(())
            }
            b'.' if fixed && !self.has(POINT) => {
                self.flags |= POINT;
                Ok(())
            }
            b'0'..=b'9' => self.digit((c - b'0') as u32),
            _ => Err(()),
        }
    }

    fn digit(&mut self, d: u32) -> Result<(), ()> {
        self.flags |= DIGITS;
        let magnitude = if !self.has(POINT) {
            let unit = if self.has(FIXED) { 1000 } else { 1 };
            times_ten_plus(self.magnitude, d * unit)
        } else {
            let decimals = (self.flags >> DECIMALS_SHIFT).saturating_add(1).min(7);
            self.flags = (self.flags & ((1 << DECIMALS_SHIFT) - 1)) | decimals << DECIMALS_SHIFT;
            // Three decimals are kept; the fourth rounds half away from
            // zero (the magnitude rounds up); later ones cannot matter.
            let add = match decimals {
                1 => d * 100,
                2 => d * 10,
                3 => d,
                4 => (d >= 5) as u32,
                _ => 0,
            };
            self.magnitude.checked_add(add)
        };
        match magnitude {
            Some(m) if m <= self.limit => {
                self.magnitude = m;
                Ok(())
            }
            _ => Err(()),
        }
    }

    /// The value of a fixed-point number; `None` without a digit.
    pub(super) fn milli(&self) -> Option<Milli> {
        let m = self.magnitude as i32; // limit is i32::MAX
        self.has_digits()
            .then_some(Milli(if self.has(NEGATIVE) { -m } else { m }))
    }

    /// The value of an integer; `None` without a digit.
    pub(super) fn value(&self) -> Option<u32> {
        self.has_digits().then_some(self.magnitude)
    }
}

/// Reads a whole fixed-point number such as a `$` setting's value
/// (`"-2.5"` → `Milli(-2500)`); `None` if it is not one.
pub fn parse_milli(text: &str) -> Option<Milli> {
    let mut number = Number::fixed();
    for &c in text.as_bytes() {
        number.push(c).ok()?;
    }
    number.milli()
}
