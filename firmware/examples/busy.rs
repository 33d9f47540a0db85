//! A firmware that never sleeps: the simulator-speed benchmark's busy load
//! (`sim_mhz_busy`). Counts in a loop and toggles the status LED (D13 = PB7).
#![no_std]
#![no_main]

use panic_halt as _;

#[avr_device::entry]
fn main() -> ! {
    let dp = avr_device::atmega2560::Peripherals::take().unwrap();
    dp.PORTB.ddrb().write(|w| w.pb7().set_bit());
    let mut n: u32 = 0;
    loop {
        n = core::hint::black_box(n.wrapping_add(1));
        if n & 0xFFF == 0 {
            dp.PORTB.pinb().write(|w| w.pb7().set_bit());
        }
    }
}
