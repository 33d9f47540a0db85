//! A firmware whose stack runs into its statics: unbounded recursion with a
//! 16-byte frame. The simavr harness must report `StackOverflow` as soon as
//! the stack pointer drops below the end of `.data`/`.bss`.
#![no_std]
#![no_main]

use core::hint::black_box;
use panic_halt as _;

/// A static in `.bss` for the stack to run into.
static mut SENTRY: [u8; 32] = [0; 32];

#[inline(never)]
fn dive(depth: u16) -> u16 {
    let frame = black_box([depth as u8; 16]);
    // `black_box(true)`: the compiler cannot see that this never ends.
    if black_box(true) {
        dive(depth.wrapping_add(1)).wrapping_add(frame[0] as u16)
    } else {
        frame[15] as u16
    }
}

#[avr_device::entry]
fn main() -> ! {
    // SAFETY: single-threaded, no interrupts enabled.
    black_box(unsafe { &mut *core::ptr::addr_of_mut!(SENTRY) });
    let depth = dive(0);
    black_box(depth);
    loop {}
}
