//! Blinks the status LED (D13 = PB7) three times, 1 ms on and 1 ms off, then
//! sleeps with interrupts enabled. Harness tests count exactly 6 edges.
#![no_std]
#![no_main]

use panic_halt as _;

/// 1 ms at 16 MHz.
const MS: u32 = 16_000;

#[avr_device::entry]
fn main() -> ! {
    let dp = avr_device::atmega2560::Peripherals::take().unwrap();
    dp.PORTB.ddrb().write(|w| w.pb7().set_bit());
    for _ in 0..3 {
        dp.PORTB.portb().write(|w| w.pb7().set_bit());
        avr_device::asm::delay_cycles(MS);
        dp.PORTB.portb().write(|w| w.pb7().clear_bit());
        avr_device::asm::delay_cycles(MS);
    }
    // SAFETY: no interrupt handlers share state with this code.
    unsafe { avr_device::interrupt::enable() };
    loop {
        avr_device::asm::sleep();
    }
}
