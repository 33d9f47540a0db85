//! What a ramp costs segment preparation on the AVR, for `cargo xtask bench`:
//! the status LED (D13) is high while each batch runs, so the harness
//! reads the cycles from its edges. In turn: 64 square roots of 64-bit
//! speeds², 64 trapezoids made, 64 event times read off one, and every
//! segment of a default-speed base move (`G0 C360`: 9600 steps at 500
//! steps/s², 2000 steps/s) cut; D12 is toggled once per segment of that
//! last batch, so the harness counts them. First, D11 goes high if the
//! assembly division behind the square root agrees with the compiler's
//! `u64` division on every case tried, and the assembly square root's
//! results are floor roots (it stays low otherwise).
#![no_std]
#![no_main]

use core::hint::black_box;
use panic_halt as _;
use taut_logic::segment::{div_to_u32, isqrt, Preparer, Speeds, Trapezoid};

const N: u32 = 64;

#[avr_device::entry]
fn main() -> ! {
    let dp = avr_device::atmega2560::Peripherals::take().unwrap();
    dp.PORTB
        .ddrb()
        .write(|w| w.pb7().set_bit().pb6().set_bit().pb5().set_bit());
    // Quotients with every bit pattern, remainders up to the divisor.
    let mut x: u32 = 0x9E37_79B9;
    let mut agree = true;
    for _ in 0..200 {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        let d = black_box(x | 1);
        let q = x.rotate_left(7);
        let n = q as u64 * d as u64 + (x % d) as u64;
        agree &= div_to_u32(black_box(n), d) as u64 == black_box(n) / d as u64;
        agree &= div_to_u32(black_box(n), d) == q;
        // Square roots of 32 bits (the assembly one) and of 64.
        for v in [x as u64, n] {
            let r = isqrt(black_box(v));
            agree &= r * r <= v && (r + 1).checked_mul(r + 1).is_none_or(|s| s > v);
        }
    }
    // The largest dividend whose quotient fits: 2^32 - 1 with the
    // largest remainder.
    let n = (u32::MAX as u64) * (u32::MAX as u64) + (u32::MAX - 1) as u64;
    agree &= div_to_u32(black_box(n), black_box(u32::MAX)) == u32::MAX;
    dp.PORTB.portb().write(|w| w.pb5().bit(agree));
    let led = |on: bool| dp.PORTB.portb().modify(|_, w| w.pb7().bit(on));
    let toggle = || dp.PORTB.pinb().write(|w| w.pb6().set_bit());
    led(true);
    for i in 0..N {
        black_box(isqrt(black_box(
            0x3FFF_0000_0000_0000 - (i as u64) * 0x1234_5678_9ABC,
        )));
    }
    led(false);
    let speeds = Speeds {
        entry_sqr: 0,
        cruise_sqr: 2000 * 2000,
        exit_sqr: 0,
    };
    led(true);
    for i in 0..N {
        black_box(Trapezoid::new(black_box(9600 - i), 500, black_box(&speeds)));
    }
    led(false);
    let t = Trapezoid::new(9600, 500, &speeds);
    led(true);
    for i in 0..N {
        black_box(t.time(black_box(i * 60)));
    }
    led(false);
    let mut p = Preparer::new();
    p.start(t);
    led(true);
    while let Some(s) = p.next_segment() {
        black_box(s);
        toggle();
    }
    led(false);
    loop {
        avr_device::asm::sleep();
    }
}
