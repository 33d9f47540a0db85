//! Fixed-point quantities. G-code and job-file numbers are parsed into
//! [`Milli`] (thousandths of a unit: µm or millidegrees) so no float is
//! needed between the text and the step count.

use core::num::NonZeroU32;

/// A length in µm or an angle in millidegrees: thousandths of the axis unit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Milli(pub i32);

impl Milli {
    pub const ZERO: Milli = Milli(0);
    /// Scale of the fixed point: 1 unit = 1000 milli.
    pub const SCALE: i32 = 1000;

    pub const fn from_units(units: i32) -> Milli {
        Milli(units * Self::SCALE)
    }
}

/// An optional [`Milli`] in four bytes where `Option` takes eight: parsed
/// lines wait in SRAM. `i32::MIN`, below any value the parser reads,
/// cannot be held (it reads back as none).
#[derive(Clone, Copy, Default, PartialEq, Eq)]
pub struct MaybeMilli(Option<NonZeroU32>);

impl MaybeMilli {
    pub const NONE: MaybeMilli = MaybeMilli(None);

    pub const fn new(value: Option<Milli>) -> MaybeMilli {
        match value {
            Some(m) => MaybeMilli(NonZeroU32::new(m.0 as u32 ^ SIGN)),
            None => MaybeMilli::NONE,
        }
    }

    pub const fn get(self) -> Option<Milli> {
        match self.0 {
            Some(bits) => Some(Milli((bits.get() ^ SIGN) as i32)),
            None => None,
        }
    }

    pub const fn is_some(self) -> bool {
        self.0.is_some()
    }
}

const SIGN: u32 = 1 << 31;

impl From<Option<Milli>> for MaybeMilli {
    fn from(value: Option<Milli>) -> Self {
        MaybeMilli::new(value)
    }
}

impl core::fmt::Debug for MaybeMilli {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        self.get().fmt(f)
    }
}

/// Steps per axis unit as an exact ratio `num / den` (e.g. the drill's
/// 1600 steps per 12 mm, which is not a whole number per mm).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StepsPerUnit {
    pub num: u32,
    pub den: u32,
}

impl StepsPerUnit {
    pub const fn new(num: u32, den: u32) -> Self {
        StepsPerUnit { num, den }
    }

    /// Absolute step position of an absolute target, rounded once, half
    /// away from zero. Converting from the absolute target (never adding
    /// rounded relative moves) is what keeps positions from drifting.
    pub fn steps(self, target: Milli) -> i32 {
        let n = target.0 as i64 * self.num as i64;
        let d = self.den as i64 * Milli::SCALE as i64;
        div_round(n, d) as i32
    }

    /// The same from a target in millionths of the unit (nanometres),
    /// as the programmed position keeps it: rounded once, half away from
    /// zero; `None` when the count does not fit an `i32`.
    pub fn steps_exact(self, target: i64) -> Option<i32> {
        // Every line's target on a linear machine: within ±2.1 m and a
        // denominator below 4 295, one product and a division with a
        // 32-bit quotient (the checked 64-bit product and the general
        // 64-bit division cost ~3 000 cycles an axis on the AVR).
        let a = target.unsigned_abs();
        if a >> 31 == 0 && self.den <= u32::MAX / 1_000_000 {
            let d = self.den * 1_000_000;
            // Below 2^63 + 2^31: no overflow; even `d`, so `d / 2` exact.
            let n = a * self.num as u64 + (d / 2) as u64;
            if n >> 32 >= d as u64 {
                return None;
            }
            let q = crate::segment::div_to_u32(n, d) as i64;
            return i32::try_from(if target < 0 { -q } else { q }).ok();
        }
        self.steps_exact_wide(target)
    }

    /// [`StepsPerUnit::steps_exact`] of `target` surely fits an `i32`:
    /// within ±2.1 m at under 1 000 steps a unit, some 2 million steps at
    /// most (each line's check on a linear machine, without the division;
    /// false: ask `steps_exact`).
    pub fn surely_fits(self, target: i64) -> bool {
        self.num < 1000 && (-(1 << 31)..1 << 31).contains(&target)
    }

    /// [`StepsPerUnit::steps_exact`] for any target, in 64 bits.
    fn steps_exact_wide(self, target: i64) -> Option<i32> {
        let n = target.checked_mul(self.num as i64)?;
        let d = self.den as i64 * 1_000_000;
        i32::try_from(div_round(n, d)).ok()
    }

    /// The position of a step count, rounded to the nearest milli-unit.
    pub fn milli(self, steps: i32) -> Milli {
        let n = steps as i64 * self.den as i64 * Milli::SCALE as i64;
        Milli(div_round(n, self.num as i64) as i32)
    }

    pub fn as_f32(self) -> f32 {
        self.num as f32 / self.den as f32
    }
}

/// `value / 10^places` with `places` decimals: `Decimal(-12_345, 3)` is
/// `-12.345`, `Decimal(7, 0)` is `7`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Decimal(pub i32, pub u8);

impl ufmt::uDisplay for Decimal {
    /// Each digit by subtracting its power of ten: a `u32` division is a
    /// ~650-cycle call on the AVR, and dividing took ~7 000 cycles a
    /// number (a status report prints three to six).
    fn fmt<W: ufmt::uWrite + ?Sized>(
        &self,
        f: &mut ufmt::Formatter<'_, W>,
    ) -> Result<(), W::Error> {
        let Decimal(v, places) = *self;
        if v < 0 {
            f.write_char('-')?;
        }
        let mut a = v.unsigned_abs();
        let mut shown = false;
        for p in (0..10u8).rev() {
            let power = power_of_ten(p);
            let mut digit = b'0';
            while a >= power {
                a -= power;
                digit += 1;
            }
            // No leading zeros, but the units digit and the decimals.
            shown |= digit != b'0' || p <= places;
            if shown {
                f.write_char(digit as char)?;
            }
            if p == places && p > 0 {
                f.write_char('.')?;
            }
        }
        Ok(())
    }
}

/// 10^`p`, `p` ≤ 9. A match, not a loop of multiplies (a call each on
/// the AVR).
fn power_of_ten(p: u8) -> u32 {
    match p {
        0 => 1,
        1 => 10,
        2 => 100,
        3 => 1_000,
        4 => 10_000,
        5 => 100_000,
        6 => 1_000_000,
        7 => 10_000_000,
        8 => 100_000_000,
        _ => 1_000_000_000,
    }
}

/// `n / d` rounded half away from zero; `d > 0`. Any `n`: where adding
/// the half would overflow, the same quotient is taken a `d` lower (or
/// higher) and one added back.
pub fn div_round(n: i64, d: i64) -> i64 {
    let half = d / 2;
    if n >= 0 {
        match n.checked_add(half) {
            Some(m) => m / d,
            None => (n - (d - half)) / d + 1,
        }
    } else {
        match n.checked_sub(half) {
            Some(m) => m / d,
            None => (n + (d - half)) / d - 1,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn maybe_milli_is_four_bytes_and_holds_zero_and_the_extremes() {
        assert_eq!(core::mem::size_of::<MaybeMilli>(), 4);
        for v in [0, 1, -1, i32::MAX, -i32::MAX] {
            assert_eq!(MaybeMilli::new(Some(Milli(v))).get(), Some(Milli(v)));
        }
        assert_eq!(MaybeMilli::new(None).get(), None);
        assert!(!MaybeMilli::NONE.is_some());
    }

    proptest! {
        #[test]
        fn maybe_milli_reads_back_what_it_was_given(v in -i32::MAX..=i32::MAX) {
            prop_assert_eq!(MaybeMilli::new(Some(Milli(v))).get(), Some(Milli(v)));
        }
    }

    /// What `Decimal` prints, worked out with `std`'s formatting.
    fn decimal_by_std(v: i32, places: u8) -> std::string::String {
        let scale = 10i64.pow(places as u32);
        let a = (v as i64).abs();
        let sign = if v < 0 { "-" } else { "" };
        match places {
            0 => std::format!("{sign}{a}"),
            p => std::format!("{sign}{}.{:0w$}", a / scale, a % scale, w = p as usize),
        }
    }

    fn decimal(v: i32, places: u8) -> std::string::String {
        crate::text::error::tests::show(&Decimal(v, places))
    }

    #[test]
    fn decimals_print_as_std_does() {
        for v in [
            0,
            1,
            -1,
            9,
            10,
            999,
            1000,
            -12_345,
            i32::MAX,
            i32::MIN,
            -i32::MAX,
        ] {
            for places in 0..=9 {
                assert_eq!(
                    decimal(v, places),
                    decimal_by_std(v, places),
                    "{v} {places}"
                );
            }
        }
        assert_eq!(decimal(-12_345, 3), "-12.345");
        assert_eq!(decimal(7, 0), "7");
        assert_eq!(decimal(5, 3), "0.005");
    }

    proptest! {
        #[test]
        fn any_decimal_prints_as_std_does(v in any::<i32>(), places in 0u8..=9) {
            prop_assert_eq!(decimal(v, places), decimal_by_std(v, places));
        }
    }

    proptest! {
        #[test]
        fn exact_steps_are_the_wide_division_s(
            target in prop_oneof![-(1i64 << 31)..(1i64 << 31), any::<i64>()],
            num in prop_oneof![1u32..100_000, any::<u32>()],
            den in prop_oneof![1u32..5000, 1u32..=u32::MAX],
        ) {
            let s = StepsPerUnit::new(num.max(1), den.max(1));
            prop_assert_eq!(s.steps_exact(target), s.steps_exact_wide(target));
            prop_assert!(!s.surely_fits(target) || s.steps_exact_wide(target).is_some());
        }
    }

    #[test]
    fn div_round_is_half_away_from_zero_to_the_extremes() {
        for d in [1, 2, 3, 7, 1_000_000, i64::MAX] {
            for n in [
                0,
                1,
                -1,
                5,
                -5,
                i64::MAX,
                i64::MIN,
                i64::MAX - 1,
                i64::MIN + 1,
            ] {
                let want = (n as i128 * 2 + (n.signum() as i128) * d as i128) / (2 * d as i128);
                assert_eq!(div_round(n, d) as i128, want, "{n} / {d}");
            }
        }
    }

    #[test]
    fn exact_steps_at_the_fast_path_s_edges() {
        for (num, den) in [(80, 1), (1600, 12), (u32::MAX, 1), (1, 4294), (7, 4295)] {
            let s = StepsPerUnit::new(num, den);
            for t in [
                0,
                1,
                -1,
                499_999,
                500_000,
                -500_000,
                (1 << 31) - 1,
                -(1 << 31) + 1,
                1 << 31,
                -(1 << 31),
                i64::MAX,
                i64::MIN,
            ] {
                assert_eq!(s.steps_exact(t), s.steps_exact_wide(t), "{num}/{den} {t}");
                assert!(
                    !s.surely_fits(t) || s.steps_exact(t).is_some(),
                    "{num}/{den} {t}"
                );
            }
        }
    }

    #[test]
    fn one_degree_steps_accumulate_exactly() {
        let base = StepsPerUnit::new(9600, 360);
        let mut target = Milli::ZERO;
        for _ in 0..360 {
            target.0 += 1000;
        }
        assert_eq!(base.steps(target), 9600);
        assert_eq!(base.steps(Milli(1000)), 27); // 26.67 rounds to 27
    }

    #[test]
    fn drill_non_integer_steps_per_mm() {
        let drill = StepsPerUnit::new(1600, 12);
        assert_eq!(drill.steps(Milli(12_000)), 1600);
        assert_eq!(drill.steps(Milli(-10_000)), -1333);
        assert_eq!(drill.steps(Milli(10_386)), 1385); // 1384.8
    }

    proptest! {
        #[test]
        fn round_trip_within_half_step(m in -2_000_000i32..2_000_000, num in 1u32..20000, den in 1u32..400) {
            let s = StepsPerUnit::new(num, den);
            let steps = s.steps(Milli(m));
            let back = s.milli(steps);
            // back is the position of the rounded step: within half a step of m.
            let half_step_milli = (den as f64 * 1000.0) / (2.0 * num as f64) + 1.0;
            prop_assert!(((back.0 - m) as f64).abs() <= half_step_milli);
        }
    }
}
