//! Numbers read one character at a time, without floats: a fixed-point
//! value is kept as its magnitude in thousandths, so `-2.5` becomes
//! `Milli(-2500)` with one multiply-add per digit.

use crate::units::Milli;

/// A number being read. A `push` error means the character cannot belong
/// to this number (a second point, a late sign, too large).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Number {
    /// Magnitude so far: thousandths for fixed-point numbers, else units.
    magnitude: u32,
    /// Largest magnitude accepted.
    limit: u32,
    /// Fixed-point (sign and point allowed) or a plain unsigned integer.
    fixed: bool,
    negative: bool,
    signed: bool,
    digits: bool,
    point: bool,
    decimals: u8,
}

impl Number {
    /// A signed value with up to three decimals kept, e.g. `X-2.5`.
    pub(super) const fn fixed() -> Number {
        Number::new(true, i32::MAX as u32)
    }

    /// An unsigned integer up to `limit`, e.g. `N` or the checksum.
    pub(super) const fn integer(limit: u32) -> Number {
        Number::new(false, limit)
    }

    const fn new(fixed: bool, limit: u32) -> Number {
        Number {
            magnitude: 0,
            limit,
            fixed,
            negative: false,
            signed: false,
            digits: false,
            point: false,
            decimals: 0,
        }
    }

    pub(super) fn has_digits(&self) -> bool {
        self.digits
    }

    pub(super) fn push(&mut self, c: u8) -> Result<(), ()> {
        match c {
            b'+' | b'-' if self.fixed && !self.signed && !self.digits && !self.point => {
                self.signed = true;
                self.negative = c == b'-';
                Ok(())
            }
            b'.' if self.fixed && !self.point => {
                self.point = true;
                Ok(())
            }
            b'0'..=b'9' => self.digit((c - b'0') as u32),
            _ => Err(()),
        }
    }

    fn digit(&mut self, d: u32) -> Result<(), ()> {
        self.digits = true;
        let magnitude = if !self.point {
            let unit = if self.fixed { 1000 } else { 1 };
            self.magnitude
                .checked_mul(10)
                .and_then(|m| m.checked_add(d * unit))
        } else {
            self.decimals = self.decimals.saturating_add(1);
            // Three decimals are kept; the fourth rounds half away from
            // zero (the magnitude rounds up); later ones cannot matter.
            let add = match self.decimals {
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
        self.digits
            .then_some(Milli(if self.negative { -m } else { m }))
    }

    /// The value of an integer; `None` without a digit.
    pub(super) fn value(&self) -> Option<u32> {
        self.digits.then_some(self.magnitude)
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
