//! Table-free single-precision `sin`/`cos`, `atan2` and `sqrt`.
//!
//! On the AVR every constant table lands in SRAM (`.data`), and there are
//! 8 KiB of it: `libm`'s `sinf`/`cosf` pull in the 264-byte `IPIO2` table of
//! their large-argument reduction, `sqrtf` a 256-byte reciprocal square root
//! table and `atan2f` the `atanf` tables. These replacements hold only a
//! handful of scalar constants, which the compiler keeps as immediates.
//!
//! - [`sin_cos`]: reduction by k·π/2 with a two-constant Cody–Waite split of
//!   π/2 (exact for |k| < 2¹⁶), then polynomials on [−π/4, π/4]. Meant for
//!   angles within a few turns: for |x| ≤ 100 the error is within 2·10⁻⁷
//!   plus 10⁻⁷·|x|/π of `libm`; it grows with |x| beyond, and past ~10⁵
//!   the reduction is meaningless. Non-finite x gives NaN.
//! - [`atan2`]: reduced to atan(t), t ∈ [0, 1], then to |u| ≤ tan(π/8) by
//!   atan(t) = π/4 + atan((t − 1)/(t + 1)), one division either way; the
//!   multiple of π/4 is added last, in two parts. Zeros, infinities and signs as `libm`'s `atan2f`;
//!   within 3·10⁻⁷ of it.
//! - [`sqrt`]: bit by bit on the integer mantissa, correctly rounded (equal
//!   to `libm::sqrtf`); √±0 = ±0, negative → NaN.
//!
//! The polynomial coefficients are Cephes' (`sinf.c`, `atanf.c`). No
//! lookup tables, no recursion; the only `libm` call is `roundf`.
//!
//! Cycles on the AVR (simavr, soft float): `sin_cos` ≈ 20 500 (`libm`'s
//! `sinf` + `cosf` ≈ 69 000), `atan2` ≈ 16 300 (17 700), `sqrt` ≈ 3 200
//! (4 800).

use core::f32::consts::FRAC_2_PI;

/// π/2 = `PIO2_HI` + `PIO2_LO`. `PIO2_HI` = 201/128 has 8 significant bits,
/// so k·`PIO2_HI` is exact for |k| < 2¹⁶.
const PIO2_HI: f32 = 201.0 / 128.0;
const PIO2_LO: f32 = 0.000_483_826_8;

/// π/4 = `PIO4_HI` + `PIO4_LO`. `PIO4_HI` has 21 significant bits, so
/// n·`PIO4_HI` is exact for n ≤ 4.
const PIO4_HI: f32 = 1_647_099.0 / 2_097_152.0; // ⌊π/4·2²¹⌋/2²¹
const PIO4_LO: f32 = 1.569_582_4e-7;

/// tan(π/8) = √2 − 1.
const TAN_PI_8: f32 = 0.414_213_57;

/// +∞'s bits; a magnitude's above them are NaN's.
const INF_BITS: u32 = 0x7f80_0000;

/// |x|'s bits: for any two that are not NaN, in the order of the values
/// (a comparison of integers: of floats, it is a call on the AVR).
pub fn magnitude(x: f32) -> u32 {
    x.to_bits() & 0x7fff_ffff
}

/// 2⁴⁰, exactly.
const TWO_POW_40: f32 = (1u64 << 40) as f32;

/// sin x for |x| ≤ π/4 (a little beyond is fine).
fn sin_poly(x: f32) -> f32 {
    const S1: f32 = -0.166_666_55;
    const S2: f32 = 0.008_332_161;
    const S3: f32 = -0.000_195_152_96;
    let z = x * x;
    ((S3 * z + S2) * z + S1) * z * x + x
}

/// cos x for |x| ≤ π/4 (a little beyond is fine).
fn cos_poly(x: f32) -> f32 {
    const C2: f32 = 0.041_666_646;
    const C3: f32 = -0.001_388_731_6;
    const C4: f32 = 2.443_315_7e-5;
    let z = x * x;
    ((C4 * z + C3) * z + C2) * z * z - 0.5 * z + 1.0
}

/// atan x for |x| ≤ tan(π/8) (a little beyond is fine).
fn atan_poly(x: f32) -> f32 {
    const A1: f32 = -0.333_329_5;
    const A2: f32 = 0.199_777_11;
    const A3: f32 = -0.138_776_85;
    const A4: f32 = 0.080_537_446;
    let z = x * x;
    (((A4 * z + A3) * z + A2) * z + A1) * z * x + x
}

/// (sin x, cos x). See the module documentation for the range.
pub fn sin_cos(x: f32) -> (f32, f32) {
    if !x.is_finite() {
        return (f32::NAN, f32::NAN);
    }
    // x = k·π/2 + r, |r| ≤ π/4 (up to the rounding of k).
    let k = libm::roundf(x * FRAC_2_PI);
    if k == 0.0 {
        if x == 0.0 {
            return (x, 1.0); // sin −0 = −0, which the polynomial loses
        }
        return (sin_poly(x), cos_poly(x));
    }
    // x − k·PIO2_HI is exact: k·PIO2_HI is, and it is within a factor of
    // two of x (Sterbenz).
    let r = (x - k * PIO2_HI) - k * PIO2_LO;
    let (s, c) = (sin_poly(r), cos_poly(r));
    // Quadrant k mod 4, without a jump table: +π/2 maps (s, c) to
    // (c, −s), +π to (−s, −c). The cast saturates for huge x.
    let q = k as i32;
    let (s, c) = if q & 1 != 0 { (c, -s) } else { (s, c) };
    if q & 2 != 0 {
        (-s, -c)
    } else {
        (s, c)
    }
}

/// The angle of the point (x, y) from the positive x axis, in [−π, π]:
/// `libm::atan2f`'s conventions for zeros, infinities and NaN.
pub fn atan2(y: f32, x: f32) -> f32 {
    // Magnitudes compared as their bits (in the order of their values, for
    // any that is not NaN): on the AVR a float comparison is a call.
    let (bx, by) = (magnitude(x), magnitude(y));
    if bx > INF_BITS || by > INF_BITS {
        return x + y;
    }
    // Fold the octant: t = num/den ∈ [0, 1].
    let swapped = by > bx;
    let (nb, db) = if swapped { (bx, by) } else { (by, bx) };
    let (mut num, mut den) = (f32::from_bits(nb), f32::from_bits(db));
    if nb == INF_BITS {
        // Both infinite: ±π/4, ±3π/4.
        (num, den) = (1.0, 1.0);
    } else if db > 1e38f32.to_bits() {
        // Keep num + den finite.
        (num, den) = (num * 0.5, den * 0.5);
    } else if db < 1e-30f32.to_bits() {
        // Keep tan(π/8)·den normal, so that the test below is sharp
        // (exact: a power of two, no overflow).
        (num, den) = (num * TWO_POW_40, den * TWO_POW_40);
    }
    // The angle is n·π/4 + p, n ∈ 0..=4, p = ±atan(u), |u| ≤ tan(π/8);
    // for t > tan(π/8), atan t = π/4 + atan((t − 1)/(t + 1)). One division
    // either way.
    let (mut n, mut p) = if db == 0 {
        (0u8, 0.0) // both zero: the sign bits decide below
    } else if magnitude(num) > magnitude(TAN_PI_8 * den) {
        (1u8, atan_poly((num - den) / (num + den)))
    } else {
        (0u8, atan_poly(num / den))
    };
    if swapped {
        // π/2 − angle
        n = 2 - n;
        p = -p;
    }
    if x.is_sign_negative() {
        // π − angle
        n = 4 - n;
        p = -p;
    }
    // n·PIO4_HI is exact: the angle is rounded once, at the end.
    let a = if n == 0 {
        p
    } else {
        let n = n as f32;
        n * PIO4_HI + (n * PIO4_LO + p)
    };
    if y.is_sign_negative() {
        -a
    } else {
        a
    }
}

/// √x, correctly rounded (round to nearest even). √±0 = ±0, √+∞ = +∞;
/// negative x or NaN gives NaN.
pub fn sqrt(x: f32) -> f32 {
    // As bits: see `atan2`.
    let m = magnitude(x);
    if m > INF_BITS || m == 0 || x.to_bits() == INF_BITS {
        return x;
    }
    if x.is_sign_negative() {
        return f32::NAN;
    }
    // fdlibm's e_sqrtf.c: x = m·2^e with m the 24-bit integer mantissa,
    // e made even; the root's bits are found one by one from the top.
    let mut ix = x.to_bits() as i32;
    let mut e = ix >> 23;
    if e == 0 {
        // Subnormal: normalise.
        let mut i = 0;
        while ix & 0x0080_0000 == 0 {
            ix <<= 1;
            i += 1;
        }
        e -= i - 1;
    }
    e -= 127;
    ix = (ix & 0x007f_ffff) | 0x0080_0000;
    if e & 1 != 0 {
        ix += ix;
    }
    e >>= 1;
    // q: the root with one bit past the last (the rounding bit); ix: the
    // remainder, doubled every round.
    ix += ix;
    let (mut q, mut s, mut r) = (0i32, 0i32, 0x0100_0000i32);
    while r != 0 {
        let t = s + r;
        if t <= ix {
            s = t + r;
            ix -= t;
            q += r;
        }
        ix += ix;
        r >>= 1;
    }
    // A non-zero remainder means the root lies strictly beyond the bits
    // found, so a set rounding bit rounds up (a tie cannot happen).
    if ix != 0 {
        q += q & 1;
    }
    f32::from_bits(((q >> 1) + 0x3f00_0000 + (e << 23)) as u32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};
    use proptest::prelude::*;

    /// The allowed sin/cos error at x.
    fn trig_tol(x: f32) -> f32 {
        2e-7 + 1e-7 * x.abs() / PI
    }

    fn trig_err(x: f32) -> (f32, f32) {
        let (s, c) = sin_cos(x);
        ((s - libm::sinf(x)).abs(), (c - libm::cosf(x)).abs())
    }

    fn ulps(a: f32, b: f32) -> u32 {
        (a.to_bits() as i32).abs_diff(b.to_bits() as i32)
    }

    #[test]
    fn sin_cos_special_points() {
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        let (s, c) = sin_cos(-0.0);
        assert!(s == 0.0 && s.is_sign_negative() && c == 1.0);
        for (x, es, ec) in [
            (FRAC_PI_2, 1.0, 0.0),
            (-FRAC_PI_2, -1.0, 0.0),
            (PI, 0.0, -1.0),
            (-PI, 0.0, -1.0),
            (
                FRAC_PI_4,
                core::f32::consts::FRAC_1_SQRT_2,
                core::f32::consts::FRAC_1_SQRT_2,
            ),
            (3.0 * FRAC_PI_2, -1.0, 0.0),
            (2.0 * PI, 0.0, 1.0),
        ] {
            let (s, c) = sin_cos(x);
            assert!(
                (s - es).abs() <= 2e-7 && (c - ec).abs() <= 2e-7,
                "{x}: {s} {c}"
            );
            assert!(trig_err(x).0 <= trig_tol(x) && trig_err(x).1 <= trig_tol(x));
        }
        // The f32 nearest π/2 is 4.37e-8 past it: cos is that, negated,
        // as libm has it (to PIO2_LO's rounding, 2.6e-12); the same at π.
        let (s, c) = sin_cos(FRAC_PI_2);
        assert!(
            s == 1.0 && c < 0.0 && (c - libm::cosf(FRAC_PI_2)).abs() <= 1e-11,
            "{c}"
        );
        let (s, c) = sin_cos(PI);
        assert!(
            c == -1.0 && s < 0.0 && (s - libm::sinf(PI)).abs() <= 1e-11,
            "{s}"
        );
        let (s, c) = sin_cos(f32::NAN);
        assert!(s.is_nan() && c.is_nan());
        assert!(sin_cos(f32::INFINITY).0.is_nan());
    }

    #[test]
    fn sin_cos_sweep() {
        // Every 7th f32 in ±100 would take long; a dense grid does.
        let mut worst = 0.0f32;
        let n = 2_000_000;
        for i in -n..=n {
            let x = 100.0 * i as f32 / n as f32;
            let (es, ec) = trig_err(x);
            assert!(es <= trig_tol(x) && ec <= trig_tol(x), "{x}: {es} {ec}");
            worst = worst.max(es.max(ec) - 1e-7 * x.abs() / PI);
        }
        std::println!("sin_cos: worst error beyond 1e-7·|x|/π: {worst:e}");
    }

    #[test]
    fn atan2_special_points() {
        let pi = PI;
        assert_eq!(atan2(0.0, 1.0), 0.0);
        assert_eq!(atan2(1.0, 0.0), FRAC_PI_2);
        assert_eq!(atan2(-1.0, 0.0), -FRAC_PI_2);
        assert_eq!(atan2(1.0, 1.0), FRAC_PI_4);
        assert_eq!(atan2(0.0, -1.0), pi);
        // The seam: just above and below the negative x axis.
        assert_eq!(atan2(-0.0, -1.0), -pi);
        assert!((atan2(1e-7, -1.0) - pi).abs() <= 3e-7);
        assert!((atan2(-1e-7, -1.0) + pi).abs() <= 3e-7);
        assert!(atan2(1e-7, -1.0) <= pi && atan2(-1e-7, -1.0) >= -pi);
        // Zeros and infinities, as libm.
        let specials = [0.0, -0.0, 1.0, -1.0, f32::INFINITY, f32::NEG_INFINITY];
        for y in specials {
            for x in specials {
                let (a, e) = (atan2(y, x), libm::atan2f(y, x));
                assert!(
                    a.to_bits() == e.to_bits() || (a - e).abs() <= 3e-7,
                    "atan2({y}, {x}) = {a}, libm {e}"
                );
                assert_eq!(
                    a.is_sign_negative(),
                    e.is_sign_negative(),
                    "atan2({y}, {x})"
                );
            }
        }
        assert!(atan2(f32::NAN, 1.0).is_nan() && atan2(1.0, f32::NAN).is_nan());
        // Where num + den would overflow, and where tan(π/8)·den would be
        // subnormal.
        let sub = |n: u32| f32::from_bits(n);
        for (y, x) in [
            (f32::MAX, f32::MAX),
            (f32::MAX, -f32::MAX),
            (-f32::MAX, 0.6 * f32::MAX),
            (sub(3), sub(7)),
            (sub(7), -sub(3)),
            (sub(1), sub(1)),
            (-sub(5), sub(12)),
            (1e-30, 2e-30),
        ] {
            let (a, e) = (atan2(y, x), libm::atan2f(y, x));
            assert!((a - e).abs() <= 3e-7, "atan2({y:e}, {x:e}) = {a}, libm {e}");
        }
    }

    #[test]
    fn atan2_sweep() {
        // Around the circle and both octant seams, at two magnitudes.
        let mut worst = 0.0f32;
        let n = 1_000_000;
        for i in 0..n {
            let a = 2.0 * PI * i as f32 / n as f32;
            for r in [1.0f32, 387.0] {
                let (y, x) = (r * libm::sinf(a), r * libm::cosf(a));
                let e = (atan2(y, x) - libm::atan2f(y, x)).abs();
                assert!(e <= 3e-7, "atan2({y}, {x}): {e}");
                worst = worst.max(e);
            }
        }
        std::println!("atan2: worst error {worst:e}");
    }

    #[test]
    fn sqrt_special_points() {
        assert_eq!(sqrt(0.0).to_bits(), 0.0f32.to_bits());
        assert_eq!(sqrt(-0.0).to_bits(), (-0.0f32).to_bits());
        assert!(sqrt(-1.0).is_nan() && sqrt(-f32::MIN_POSITIVE).is_nan());
        assert!(sqrt(f32::NAN).is_nan() && sqrt(f32::NEG_INFINITY).is_nan());
        assert_eq!(sqrt(f32::INFINITY), f32::INFINITY);
        for i in 1..=4096u32 {
            let f = i as f32;
            assert_eq!(sqrt(f * f), f);
        }
        assert_eq!(sqrt(0.25), 0.5);
        assert_eq!(sqrt(2.0), core::f32::consts::SQRT_2);
        assert_eq!(sqrt(f32::MAX), libm::sqrtf(f32::MAX));
        assert_eq!(sqrt(f32::MIN_POSITIVE), libm::sqrtf(f32::MIN_POSITIVE));
        let tiny = f32::from_bits(1); // the smallest subnormal
        assert_eq!(sqrt(tiny), libm::sqrtf(tiny));
    }

    #[test]
    fn sqrt_sweep_of_all_positive_floats() {
        // Every 257th bit pattern, subnormals to infinity.
        for bits in (1..0x7f80_0000u32).step_by(257) {
            let x = f32::from_bits(bits);
            assert_eq!(sqrt(x).to_bits(), libm::sqrtf(x).to_bits(), "√{x:e}");
        }
    }

    proptest! {
        #[test]
        fn sin_cos_match_libm(x in -100.0f32..100.0) {
            let (es, ec) = trig_err(x);
            prop_assert!(es <= trig_tol(x) && ec <= trig_tol(x), "{} {} {}", x, es, ec);
        }

        #[test]
        fn sin_cos_of_board_angles(k in 0u32..1000, n in 3u32..1000) {
            // The angles geometry takes: TAU·k/n.
            let x = core::f32::consts::TAU * (k % n) as f32 / n as f32;
            let (es, ec) = trig_err(x);
            prop_assert!(es <= trig_tol(x) && ec <= trig_tol(x), "{} {} {}", x, es, ec);
        }

        #[test]
        fn atan2_matches_libm(
            y in prop_oneof![-1e3f32..1e3, proptest::num::f32::NORMAL | proptest::num::f32::SUBNORMAL | proptest::num::f32::ZERO],
            x in prop_oneof![-1e3f32..1e3, proptest::num::f32::NORMAL | proptest::num::f32::SUBNORMAL | proptest::num::f32::ZERO],
        ) {
            let (a, e) = (atan2(y, x), libm::atan2f(y, x));
            prop_assert!((a - e).abs() <= 3e-7, "atan2({}, {}) = {}, libm {}", y, x, a, e);
        }

        #[test]
        fn sqrt_is_correctly_rounded(x in proptest::num::f32::POSITIVE | proptest::num::f32::SUBNORMAL | proptest::num::f32::ZERO) {
            let r = sqrt(x);
            prop_assert_eq!(r.to_bits(), libm::sqrtf(x).to_bits());
            // f64's root rounded to f32 is correctly rounded too (53 ≥ 2·24 + 2).
            prop_assert!(ulps(r, (x as f64).sqrt() as f32) == 0);
        }
    }
}
