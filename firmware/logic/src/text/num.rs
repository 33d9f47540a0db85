//! Numbers of the job files and settings, parsed straight into integers
//! and fixed point (no floats between the text and the machine).

use crate::text::ErrorKind;
use crate::units::{Milli, StepsPerUnit};

/// A number that did not parse: what, and at which byte of the text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NumError {
    pub at: usize,
    pub kind: ErrorKind,
}

const fn not_a_number(at: usize) -> NumError {
    NumError {
        at,
        kind: ErrorKind::NotANumber,
    }
}

const TOO_BIG: NumError = NumError {
    at: 0,
    kind: ErrorKind::TooBig,
};

/// `s` without leading and trailing blanks, and the offset of what remains.
pub fn trim(s: &[u8]) -> (usize, &[u8]) {
    let blank = |b: &u8| matches!(b, b' ' | b'\t' | b'\r');
    let start = s.iter().position(|b| !blank(b)).unwrap_or(s.len());
    let end = s.iter().rposition(|b| !blank(b)).map_or(start, |e| e + 1);
    (start, &s[start..end])
}

/// Appends one decimal digit; `None` when `u32` overflows.
pub fn push_digit(value: u32, digit: u8) -> Option<u32> {
    times_ten_plus(value, (digit - b'0') as u32)
}

/// `value × 10 + add`; `None` when `u32` overflows. One copy, out of
/// line, with the overflow tested before the multiply: on the AVR a
/// `checked_mul` is two 32-bit multiplies and a test at every use.
#[inline(never)]
pub fn times_ten_plus(value: u32, add: u32) -> Option<u32> {
    if value > u32::MAX / 10 {
        return None;
    }
    (value * 10).checked_add(add)
}

/// A whole non-negative number: digits only.
pub fn parse_u32(s: &[u8]) -> Result<u32, NumError> {
    if s.is_empty() {
        return Err(not_a_number(0));
    }
    let mut value = 0u32;
    for (i, &b) in s.iter().enumerate() {
        if !b.is_ascii_digit() {
            return Err(not_a_number(i));
        }
        value = push_digit(value, b).ok_or(TOO_BIG)?;
    }
    Ok(value)
}

/// A decimal number `12.345` scaled by `10^decimals` and rounded half up
/// (digits beyond the scale only round): `parse_fixed(b"40.2", 4) == 402000`.
pub fn parse_fixed(s: &[u8], decimals: u32) -> Result<u32, NumError> {
    let mut value = 0u32;
    let mut digits = 0;
    let mut frac_digits: Option<u32> = None;
    let mut round_up = false;
    for (i, &b) in s.iter().enumerate() {
        match (b, frac_digits) {
            (b'.', None) => frac_digits = Some(0),
            (b'0'..=b'9', Some(n)) if n >= decimals => {
                // The first digit beyond the scale decides the rounding.
                if n == decimals {
                    round_up = b >= b'5';
                }
                frac_digits = Some(n + 1);
            }
            (b'0'..=b'9', _) => {
                value = push_digit(value, b).ok_or(TOO_BIG)?;
                frac_digits = frac_digits.map(|n| n + 1);
            }
            _ => return Err(not_a_number(i)),
        }
        digits += b.is_ascii_digit() as u32;
    }
    if digits == 0 {
        return Err(not_a_number(0));
    }
    for _ in frac_digits.unwrap_or(0).min(decimals)..decimals {
        value = times_ten_plus(value, 0).ok_or(TOO_BIG)?;
    }
    value.checked_add(round_up as u32).ok_or(TOO_BIG)
}

/// A signed decimal in thousandths: `-450.5` is `-450_500`.
pub fn parse_milli(s: &[u8]) -> Result<Milli, NumError> {
    let (negative, digits) = match s.split_first() {
        Some((b'-', rest)) => (true, rest),
        _ => (false, s),
    };
    let skip = negative as usize;
    let v = parse_fixed(digits, 3).map_err(|e| NumError {
        at: e.at + skip,
        ..e
    })?;
    let v = i32::try_from(v).map_err(|_| TOO_BIG)?;
    Ok(Milli(if negative { -v } else { v }))
}

/// Steps per unit as `num/den` (`1600/12`) or a decimal (`26.5` = 53/2).
/// Zero in either part is left to the caller's range check.
pub fn parse_ratio(s: &[u8]) -> Result<StepsPerUnit, NumError> {
    if let Some(slash) = s.iter().position(|&b| b == b'/') {
        let part = |from: usize, text: &[u8]| {
            let (lead, digits) = trim(text);
            parse_u32(digits).map_err(|e| NumError {
                at: from + lead + e.at,
                ..e
            })
        };
        let num = part(0, &s[..slash])?;
        let den = part(slash + 1, &s[slash + 1..])?;
        return Ok(StepsPerUnit::new(num, den));
    }
    // A decimal: all its digits over 10^(decimals), then reduced.
    let decimals = s
        .iter()
        .position(|&b| b == b'.')
        .map_or(0, |p| s.len() - p - 1);
    if decimals > 9 {
        return Err(TOO_BIG);
    }
    let num = parse_fixed(s, decimals as u32)?;
    let den = 10u32.pow(decimals as u32);
    let g = gcd(num, den);
    Ok(StepsPerUnit::new(num / g, den / g))
}

fn gcd(mut a: u32, mut b: u32) -> u32 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn nan(at: usize) -> NumError {
        not_a_number(at)
    }

    #[test]
    fn whole_numbers() {
        assert_eq!(parse_u32(b"250"), Ok(250));
        assert_eq!(parse_u32(b"007"), Ok(7));
        assert_eq!(parse_u32(b"4294967295"), Ok(u32::MAX));
        assert_eq!(parse_u32(b"4294967296"), Err(TOO_BIG));
        assert_eq!(parse_u32(b""), Err(nan(0)));
        assert_eq!(parse_u32(b"-3"), Err(nan(0)));
        assert_eq!(parse_u32(b"12a"), Err(nan(2)));
    }

    #[test]
    fn fixed_point_scales_and_rounds() {
        assert_eq!(parse_fixed(b"40.2", 4), Ok(402_000));
        assert_eq!(parse_fixed(b"40", 4), Ok(400_000));
        assert_eq!(parse_fixed(b"40.", 4), Ok(400_000));
        assert_eq!(parse_fixed(b".5", 4), Ok(5_000));
        assert_eq!(parse_fixed(b"3.50004", 4), Ok(35_000));
        assert_eq!(parse_fixed(b"3.50005", 4), Ok(35_001));
        assert_eq!(parse_fixed(b"3.500049999", 4), Ok(35_000));
        assert_eq!(parse_fixed(b"40,2", 4), Err(nan(2)));
        assert_eq!(parse_fixed(b"4.0.2", 4), Err(nan(3)));
        assert_eq!(parse_fixed(b".", 4), Err(nan(0)));
        assert_eq!(parse_fixed(b"", 4), Err(nan(0)));
        assert_eq!(parse_fixed(b"-1", 4), Err(nan(0)));
        assert_eq!(parse_fixed(b"500000", 4), Err(TOO_BIG));
    }

    #[test]
    fn ratios() {
        assert_eq!(parse_ratio(b"1600/12"), Ok(StepsPerUnit::new(1600, 12)));
        assert_eq!(parse_ratio(b"1600 / 12"), Ok(StepsPerUnit::new(1600, 12)));
        assert_eq!(parse_ratio(b"32"), Ok(StepsPerUnit::new(32, 1)));
        assert_eq!(parse_ratio(b"26.5"), Ok(StepsPerUnit::new(53, 2)));
        assert_eq!(parse_ratio(b"32.000"), Ok(StepsPerUnit::new(32, 1)));
        assert_eq!(parse_ratio(b"16/x"), Err(nan(3)));
        assert_eq!(parse_ratio(b"16/ 1x"), Err(nan(5)));
        assert_eq!(parse_ratio(b"1/"), Err(nan(2)));
        assert_eq!(parse_ratio(b"1.0000000001"), Err(TOO_BIG));
    }

    proptest! {
        #[test]
        fn decimal_text_round_trips(whole in 0u32..400_000, frac in 0u32..10_000) {
            let text = std::format!("{}.{:04}", whole, frac);
            prop_assert_eq!(parse_fixed(text.as_bytes(), 4), Ok(whole * 10_000 + frac));
        }
    }
}
