//! A firmware that hangs: it sleeps with interrupts disabled, so nothing can
//! ever wake it. The simavr harness must report it as `Hung`.
#![no_std]
#![no_main]

use panic_halt as _;

#[avr_device::entry]
fn main() -> ! {
    let dp = avr_device::atmega2560::Peripherals::take().unwrap();
    dp.PORTB.ddrb().write(|w| w.pb7().set_bit());
    dp.PORTB.portb().write(|w| w.pb7().set_bit());
    avr_device::interrupt::disable();
    loop {
        avr_device::asm::sleep();
    }
}
