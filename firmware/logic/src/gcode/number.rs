//! Numbers read one character at a time, without floats, as Grbl's
//! `read_float` reads them (an optional sign, digits, one point; no
//! exponent) but exact: the digits are kept as an integer significand
//! and a power of ten, and converted once, when the word ends, to what
//! the word needs — nanometres for an axis word, thousandths for a feed,
//! a whole number and hundredths for a `G`/`M` number. So a move of
//! `X0.0125` or `X0.00049` (inches) is taken as written, not rounded to
//! a µm or a thousandth of an inch.

use crate::units::Milli;

/// A number being read. A `push` error means the character cannot belong
/// to this number (a second point, a late sign).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Number {
    /// The first [`DIGITS_KEPT`] significant digits.
    sig: u32,
    /// Value = `sig` × 10^`exp`: decimals make it negative, integer digits
    /// past the kept ones positive.
    exp: i8,
    /// [`NEGATIVE`], [`SIGNED`], [`DIGITS`], [`POINT`], [`ROUNDED`]: one
    /// byte, as the parser's statics hold several numbers.
    flags: u8,
}

const NEGATIVE: u8 = 1;
const SIGNED: u8 = 2;
const DIGITS: u8 = 4;
const POINT: u8 = 8;
/// The first digit past the kept ones has rounded `sig`; later ones
/// cannot matter.
const ROUNDED: u8 = 16;

/// Significant digits kept: 9 (`999 999 999` fits a `u32`), one more than
/// Grbl's `read_float` and beyond what its `float` holds.
const DIGITS_KEPT: u32 = 100_000_000;
/// Decimal exponents stop here: a value of 10^-60 is nothing, one of
/// 10^60 saturates every conversion.
const EXP_LIMIT: i8 = 60;

/// Whole units and hundredths of a `G`/`M` number, as Grbl splits it:
/// `G38.2` is (38, 20), `G1.005` (1, 1), `G1.001` (1, 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Code {
    pub int: u32,
    pub hundredths: u8,
}

impl Number {
    pub(super) const fn new() -> Number {
        Number {
            sig: 0,
            exp: 0,
            flags: 0,
        }
    }

    fn has(&self, flag: u8) -> bool {
        self.flags & flag != 0
    }

    pub(super) fn has_digits(&self) -> bool {
        self.has(DIGITS)
    }

    pub(super) fn is_negative(&self) -> bool {
        self.has(NEGATIVE) && self.sig != 0
    }

    /// One character of the number; per byte, so no division and no
    /// 64-bit arithmetic.
    #[inline]
    pub(super) fn push(&mut self, c: u8) -> Result<(), ()> {
        match c {
            b'+' | b'-' if !self.has(SIGNED | DIGITS | POINT) => {
                self.flags |= SIGNED | if c == b'-' { NEGATIVE } else { 0 };
                Ok(())
            }
            b'.' if !self.has(POINT) => {
                self.flags |= POINT;
                Ok(())
            }
            b'0'..=b'9' => {
                self.digit(c - b'0');
                Ok(())
            }
            _ => Err(()),
        }
    }

    #[inline]
    fn digit(&mut self, d: u8) {
        self.flags |= DIGITS;
        if self.sig < DIGITS_KEPT {
            // Leading zeros cost nothing: `sig` stays 0. Tenfold as
            // shifts and an add: the AVR's `u32` product is a library call
            // (~70 cycles, and the registers it takes are saved at every
            // digit), which LLVM would fold the shifts back into, were
            // one of them not hidden from it.
            let twice = self.sig << 1;
            self.sig = (core::hint::black_box(twice) << 2) + twice + u32::from(d);
            if self.has(POINT) && self.exp > -EXP_LIMIT {
                self.exp -= 1;
            }
        } else {
            self.digit_past_kept(d);
        }
    }

    /// A digit past the kept ones (a tenth and later significant digit).
    #[cold]
    #[inline(never)]
    fn digit_past_kept(&mut self, d: u8) {
        if !self.has(POINT) {
            // An integer digit past the kept ones: the value grows tenfold.
            self.exp = (self.exp + 1).min(EXP_LIMIT);
        } else if !self.has(ROUNDED) {
            // The first decimal past the kept ones rounds half away from
            // zero; `sig` may become 10^9, which still fits.
            self.flags |= ROUNDED;
            self.sig += (d >= 5) as u32;
        }
    }

    /// `value × 10^shift`, rounded half away from zero to an integer and
    /// saturated to `limit`; per word, not per byte.
    fn scaled(&self, shift: i8, limit: u64) -> u64 {
        let exp = self.exp as i16 + shift as i16;
        let mut v = self.sig as u64;
        if exp >= 0 {
            // Tenfold in 32 bits while it fits (every coordinate under
            // 4 m in nanometres): a `u64` product is a library call of
            // ~350 cycles on the AVR, three a word.
            let mut k = exp;
            let mut narrow = self.sig;
            while k > 0 && narrow <= u32::MAX / 10 {
                narrow *= 10;
                k -= 1;
            }
            v = narrow as u64;
            for _ in 0..k {
                // Below `limit` ≤ 2^60, ×10 cannot overflow.
                if v >= limit {
                    return limit;
                }
                v *= 10;
            }
        } else if exp >= -9 {
            // `sig` ≤ 10^9 and 10^9 + 10^9 / 2 fit 32 bits: a 32-bit
            // division.
            let p = 10u32.pow((-exp) as u32);
            v = ((self.sig + p / 2) / p) as u64;
        } else {
            // At most 9 significant digits: past 10 decimals it is 0.
            let down = (-exp).min(11) as u32;
            let p = 10u64.pow(down);
            v = (v + p / 2) / p;
        }
        v.min(limit)
    }

    /// `value × 10^shift` if it is whole and fits 32 bits (the common
    /// case of every conversion: no 64-bit arithmetic), by tenfolds.
    #[inline]
    fn narrow(&self, shift: i8) -> Option<u32> {
        // `exp` is within ±[`EXP_LIMIT`]: no overflow.
        let mut k = self.exp + shift;
        if k < 0 {
            return None;
        }
        let mut v = self.sig;
        while k > 0 {
            if v > u32::MAX / 10 {
                return None;
            }
            v *= 10;
            k -= 1;
        }
        Some(v)
    }

    /// The value in millionths (nanometres of a mm), saturated at
    /// ±[`NANO_LIMIT`]; `None` without a digit.
    pub(super) fn nano(&self) -> Option<i64> {
        let v = match self.narrow(6) {
            Some(v) => i64::from(v),
            None => self.scaled(6, NANO_LIMIT as u64) as i64,
        };
        self.has_digits()
            .then_some(if self.has(NEGATIVE) { -v } else { v })
    }

    /// The value in thousandths, rounded once and saturated at
    /// ±`i32::MAX`; `None` without a digit.
    pub(super) fn milli(&self) -> Option<Milli> {
        let v = match self.narrow(3) {
            Some(v) => v.min(i32::MAX as u32) as i32,
            None => self.scaled(3, i32::MAX as u64) as i32,
        };
        self.has_digits()
            .then_some(Milli(if self.has(NEGATIVE) { -v } else { v }))
    }

    /// The whole part (truncated, saturated) and the hundredths (rounded)
    /// of a non-negative number, as Grbl's `int_value` and `mantissa`.
    pub(super) fn code(&self) -> Code {
        // A whole number as written (`G1`, `M3`): no conversion.
        if self.exp == 0 {
            return Code {
                int: self.sig,
                hundredths: 0,
            };
        }
        let int = self.whole();
        let all = self.scaled(2, u32::MAX as u64);
        Code {
            int,
            hundredths: all.saturating_sub(int as u64 * 100).min(100) as u8,
        }
    }

    /// The whole part, truncated and saturated (Grbl's `trunc(value)` of
    /// `N`, `T`, `L`).
    pub(super) fn whole(&self) -> u32 {
        let exp = self.exp as i16;
        if exp == 0 {
            return self.sig;
        }
        if exp >= 0 {
            return self.scaled(0, u32::MAX as u64) as u32;
        }
        match (-exp) as u32 {
            // `sig` fits 32 bits, and so do powers of ten up to 10^9.
            down @ 0..=9 => self.sig / 10u32.pow(down),
            _ => 0,
        }
    }
}

/// Largest axis value in nanometres: ±9.2 × 10^15, far past any machine
/// and still summable without overflow.
pub const NANO_LIMIT: i64 = i64::MAX >> 10;
// `scaled` multiplies values below its limit by ten unchecked.
const _: () = assert!(NANO_LIMIT as u64 <= u64::MAX / 10);

/// Reads a whole fixed-point number such as a `$` setting's value
/// (`"-2.5"` → `Milli(-2500)`); `None` if it is not one.
pub fn parse_milli(text: &str) -> Option<Milli> {
    let mut number = Number::new();
    for &c in text.as_bytes() {
        number.push(c).ok()?;
    }
    number.milli()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Number {
        let mut n = Number::new();
        for &c in text.as_bytes() {
            n.push(c).unwrap();
        }
        n
    }

    #[test]
    fn exact_in_nanometres_and_rounded_once_in_thousandths() {
        assert_eq!(read("0.0125").nano(), Some(12_500));
        assert_eq!(read("0.00049").nano(), Some(490));
        assert_eq!(read("-2.5").nano(), Some(-2_500_000));
        assert_eq!(read("0.0125").milli(), Some(Milli(13)));
        assert_eq!(read("-0.0125").milli(), Some(Milli(-13)));
        // Nine significant digits are kept, the tenth rounds.
        assert_eq!(read("123456.789012").nano(), Some(123_456_789_000));
        assert_eq!(read("123456.789512").nano(), Some(123_456_790_000));
        assert_eq!(read(".5").nano(), Some(500_000));
        assert_eq!(read("5.").nano(), Some(5_000_000));
        assert_eq!(read("+7").milli(), Some(Milli(7000)));
        assert_eq!(read("-").nano(), None);
        assert_eq!(read(".").milli(), None);
    }

    #[test]
    fn digits_past_nine_round_once_and_big_numbers_saturate() {
        // 1234.56789 kept; the 6 rounds the last kept digit up.
        assert_eq!(read("1234.567896").nano(), Some(1_234_567_900));
        assert_eq!(read("0.0000004").nano(), Some(0));
        assert_eq!(read("0.0000005").nano(), Some(1));
        assert_eq!(
            read("99999999999999999999999").milli(),
            Some(Milli(i32::MAX))
        );
        assert_eq!(read("-99999999999999999999999").nano(), Some(-NANO_LIMIT));
        assert_eq!(read("0.00000000000000000000000000001").nano(), Some(0));
    }

    #[test]
    fn codes_split_as_grbl_splits_them() {
        assert_eq!(
            read("38.2").code(),
            Code {
                int: 38,
                hundredths: 20
            }
        );
        assert_eq!(
            read("01").code(),
            Code {
                int: 1,
                hundredths: 0
            }
        );
        assert_eq!(
            read("1.001").code(),
            Code {
                int: 1,
                hundredths: 0
            }
        );
        assert_eq!(
            read("1.005").code(),
            Code {
                int: 1,
                hundredths: 1
            }
        );
        // Grbl's `trunc` then `round`: 0.996 is G0 with 100 hundredths.
        assert_eq!(
            read("0.996").code(),
            Code {
                int: 0,
                hundredths: 100
            }
        );
        assert_eq!(
            read("92.1").code(),
            Code {
                int: 92,
                hundredths: 10
            }
        );
        assert_eq!(read("1.5").whole(), 1);
        assert_eq!(read("12345678901").whole(), u32::MAX);
        assert_eq!(read("255.9").whole(), 255);
    }

    /// `value × 10^shift` rounded half away from zero and saturated,
    /// worked out in 128 bits.
    fn scaled_wide(n: &Number, shift: i8, limit: u64) -> u64 {
        let exp = n.exp as i32 + shift as i32;
        let v = n.sig as u128;
        let r = if exp >= 0 {
            v.saturating_mul(10u128.saturating_pow(exp as u32))
        } else if exp < -30 {
            0
        } else {
            let p = 10u128.pow((-exp) as u32);
            (v + p / 2) / p
        };
        r.min(limit as u128) as u64
    }

    proptest::proptest! {
        #[test]
        fn digits_are_kept_exactly_s(digits in "[0-9]{1,9}") {
            let n = read(&digits);
            proptest::prop_assert_eq!(n.sig, digits.parse::<u32>().unwrap());
            proptest::prop_assert_eq!(n.exp, 0);
        }

        #[test]
        fn scaled_is_the_wide_product_s(sig in 0u32..=1_000_000_000, exp in -60i8..=60, shift in 0i8..=6, wide in proptest::bool::ANY) {
            let n = Number { sig, exp, flags: DIGITS };
            let limit = if wide { NANO_LIMIT as u64 } else { u32::MAX as u64 };
            proptest::prop_assert_eq!(n.scaled(shift, limit), scaled_wide(&n, shift, limit));
            if let Some(v) = n.narrow(shift) {
                proptest::prop_assert_eq!(u64::from(v), scaled_wide(&n, shift, u64::MAX));
            } else {
                proptest::prop_assert!(exp + shift < 0 || scaled_wide(&n, shift, u64::MAX) > u64::from(u32::MAX));
            }
            let trunc = if exp >= 0 { scaled_wide(&n, 0, u32::MAX as u64) } else if exp < -10 { 0 } else { (sig as u64 / 10u64.pow((-exp) as u32)).min(u32::MAX as u64) };
            proptest::prop_assert_eq!(n.whole() as u64, trunc);
        }
    }
}
