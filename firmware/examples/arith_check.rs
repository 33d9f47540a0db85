//! The image's wide arithmetic in assembly against plain versions: its
//! `__muldi3` (`src/rt/mul64.rs`) against a product built from 16-bit
//! pieces with 32-bit multiplications only (factors of every size, signs
//! and edges), and the segment maths' `div_to_u32` against the compiler's
//! `u64` division (quotients of every length, remainders up to the
//! divisor), and the square root built on both: floor roots at every
//! length; its `memcpy` and `memset` (`src/rt/mem.S`) against byte-by-
//! byte volatile copies and clears, every length to 70 at every offset
//! mod 4, the bytes around untouched. D11 goes high if every result
//! agrees, then D12 when the check is over. The status LED (D13) is high
//! while 256 products of two 32-bit factors run, D10 while 64 copies of
//! 64 bytes run, so the harness reads their cycles.
#![no_std]
#![no_main]

use core::hint::black_box;
use panic_halt as _;
use taut_firmware::rt::mul64::mul as __muldi3;
use taut_logic::segment::{div_to_u32, isqrt};

/// `a · b` modulo 2^64 from 16-bit pieces: no 64-bit multiplication.
fn reference(a: u64, b: u64) -> u64 {
    let piece = |x: u64, i: usize| (x >> (16 * i)) as u16 as u32;
    let mut r = 0u64;
    for i in 0..4 {
        for j in 0..4 - i {
            let p = black_box(piece(a, i)) * black_box(piece(b, j));
            r = r.wrapping_add((p as u64) << (16 * (i + j)));
        }
    }
    r
}

/// `memcpy` and `memset` (the compiler's calls for a length known only
/// at run time) against volatile byte loops, which it cannot make calls
/// of: every length to 70 from and to every offset mod 4, with guard
/// bytes on both sides.
fn copies_and_clears_agree() -> bool {
    let mut agree = true;
    let mut src = [0u8; 80];
    for (i, b) in src.iter_mut().enumerate() {
        *b = (i as u8).wrapping_mul(37) ^ 0xA5;
    }
    let (mut got, mut want) = ([0u8; 80], [0u8; 80]);
    for len in 0..=70usize {
        for (from, to) in [(0, 0), (1, 3), (2, 1), (3, 2), (5, 4)] {
            for buf in [&mut got, &mut want] {
                for (i, b) in buf.iter_mut().enumerate() {
                    // SAFETY: a byte of a local array.
                    unsafe { core::ptr::write_volatile(b, i as u8) };
                }
            }
            // SAFETY: `from + len` and `to + len` are within the 80-byte
            // arrays, which are distinct.
            unsafe {
                core::ptr::copy_nonoverlapping(
                    black_box(src.as_ptr().add(from)),
                    got.as_mut_ptr().add(to),
                    black_box(len),
                );
            }
            for k in 0..len {
                // SAFETY: bytes of local arrays, within their lengths.
                unsafe {
                    core::ptr::write_volatile(
                        &mut want[to + k],
                        core::ptr::read_volatile(&src[from + k]),
                    )
                };
            }
            agree &= got == want;
            let value = black_box(len as u8 ^ 0x3C);
            // SAFETY: `to + len` is within the 80-byte array.
            unsafe { core::ptr::write_bytes(got.as_mut_ptr().add(to), value, black_box(len)) };
            for k in 0..len {
                // SAFETY: a byte of a local array, within its length.
                unsafe { core::ptr::write_volatile(&mut want[to + k], value) };
            }
            agree &= got == want;
        }
    }
    agree
}

#[avr_device::entry]
fn main() -> ! {
    let dp = avr_device::atmega2560::Peripherals::take().unwrap();
    dp.PORTB.ddrb().write(|w| {
        w.pb7()
            .set_bit()
            .pb6()
            .set_bit()
            .pb5()
            .set_bit()
            .pb4()
            .set_bit()
    });
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut agree = true;
    let edges = [0, 1, 0xFF, 0xFFFF_FFFF, 1 << 32, u64::MAX, 1 << 63];
    for a in edges {
        for b in edges {
            agree &= __muldi3(black_box(a), black_box(b)) == reference(a, b);
        }
    }
    for k in 0..600u32 {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        // Both below 2^32, one above, both above, and negative ones.
        let (a, b) = match k % 4 {
            0 => (x >> 32, x & 0xFFFF_FFFF),
            1 => (x >> (k % 32), x.rotate_left(9) >> 40),
            2 => (x, x.rotate_left(23)),
            _ => ((-((x >> 40) as i64)) as u64, x >> 45),
        };
        agree &= __muldi3(black_box(a), black_box(b)) == reference(a, b);
        // The compiler's own `*` reaches the same function.
        agree &= black_box(a).wrapping_mul(black_box(b)) == reference(a, b);
    }
    let mut y: u32 = 0x9E37_79B9;
    for k in 0..400u32 {
        y ^= y << 13;
        y ^= y >> 17;
        y ^= y << 5;
        let d = black_box(y | 1) >> (k % 29);
        let d = d.max(1);
        // Quotients of 0 to 32 bits.
        let q = y.rotate_left(7) >> (k % 33).min(31) >> u32::from(k % 33 == 32);
        let n = q as u64 * d as u64 + (y.rotate_left(3) % d) as u64;
        agree &= div_to_u32(black_box(n), black_box(d)) == q;
        agree &= q as u64 == black_box(n) / black_box(d as u64);
    }
    // Square roots of every length: floor roots.
    for k in 0..640u32 {
        y ^= y << 13;
        y ^= y >> 17;
        y ^= y << 5;
        let v = ((y as u64) << 32 | y.rotate_left(11) as u64) >> (k % 64);
        let r = isqrt(black_box(v));
        agree &= r * r <= v && (r + 1).checked_mul(r + 1).is_none_or(|s| s > v);
    }
    // The largest dividend whose quotient fits, and the smallest.
    let n = (u32::MAX as u64) * (u32::MAX as u64) + (u32::MAX - 1) as u64;
    agree &= div_to_u32(black_box(n), black_box(u32::MAX)) == u32::MAX;
    agree &= div_to_u32(black_box(0), black_box(7)) == 0;
    agree &= copies_and_clears_agree();
    dp.PORTB.portb().write(|w| w.pb5().bit(agree));
    dp.PORTB.portb().modify(|_, w| w.pb7().set_bit());
    for i in 0..256u32 {
        black_box(__muldi3(
            black_box(0x8765_4321 ^ i as u64),
            black_box(0xFEDC_BA98),
        ));
    }
    dp.PORTB
        .portb()
        .modify(|_, w| w.pb7().clear_bit().pb4().set_bit());
    let (mut from, mut to) = ([0x5Au8; 64], [0u8; 64]);
    for _ in 0..64 {
        // SAFETY: two distinct 64-byte arrays.
        unsafe {
            core::ptr::copy_nonoverlapping(
                black_box(&from).as_ptr(),
                to.as_mut_ptr(),
                black_box(64),
            )
        };
        black_box(&mut to);
        from[0] = to[1];
    }
    dp.PORTB
        .portb()
        .modify(|_, w| w.pb4().clear_bit().pb6().set_bit());
    loop {
        avr_device::asm::sleep();
    }
}
