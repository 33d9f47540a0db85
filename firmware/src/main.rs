#![no_std]
#![no_main]
#![feature(abi_avr_interrupt)]
use panic_halt as _;
#[avr_device::entry]
fn main() -> ! {
    let dp = avr_device::atmega2560::Peripherals::take().unwrap();
    dp.PORTB.ddrb().write(|w| unsafe { w.bits(0x80) });
    loop { dp.PORTB.portb().modify(|r, w| unsafe { w.bits(r.bits() ^ 0x80) }); }
}
