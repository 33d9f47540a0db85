//! Busy-wait delays for the few places that need microsecond set-up times
//! (driver enable, SD card power-up). Never used for waits a task could yield.

use embedded_hal::delay::DelayNs;

pub struct Delay;

impl DelayNs for Delay {
    fn delay_ns(&mut self, ns: u32) {
        // 16 cycles per µs; round up so a delay is never shorter than asked.
        let cycles = (ns / 1000 + 1) * 16;
        avr_device::asm::delay_cycles(cycles);
    }

    fn delay_us(&mut self, us: u32) {
        avr_device::asm::delay_cycles(us.saturating_mul(16));
    }
}
