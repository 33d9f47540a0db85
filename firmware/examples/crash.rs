//! A firmware that crashes: it calls through a null function pointer, the
//! usual result of a corrupted or uninitialised callback. On the MCU this
//! jumps to the reset vector without a reset; the simavr harness must report
//! it as `Crashed`.
#![no_std]
#![no_main]
#![feature(asm_experimental_arch)]

use panic_halt as _;

#[avr_device::entry]
fn main() -> ! {
    let dp = avr_device::atmega2560::Peripherals::take().unwrap();
    // Status LED (D13 = PB7) on: the firmware got this far.
    dp.PORTB.ddrb().write(|w| w.pb7().set_bit());
    dp.PORTB.portb().write(|w| w.pb7().set_bit());
    // SAFETY: deliberately wrong: `icall` through Z = 0, the null pointer.
    unsafe { core::arch::asm!("ldi r30, 0", "ldi r31, 0", "icall", options(noreturn)) }
}
