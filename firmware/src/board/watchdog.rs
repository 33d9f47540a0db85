//! The watchdog: resets the board when the idle loop has not fed it within
//! its period, i.e. when some task never returned.

use avr_device::atmega2560::WDT;

pub struct Watchdog {
    wdt: WDT,
}

impl Watchdog {
    /// Period ≈ 500 ms (the longest task is far shorter; a wedged one is caught).
    pub fn start(wdt: WDT) -> Watchdog {
        avr_device::asm::wdr();
        avr_device::interrupt::free(|_| {
            // Timed sequence: WDCE|WDE, then the new setting within 4 cycles.
            wdt.wdtcsr().write(|w| w.wdce().set_bit().wde().set_bit());
            wdt.wdtcsr()
                .write(|w| w.wde().set_bit().wdpl().cycles_64k());
        });
        Watchdog { wdt }
    }

    pub fn feed(&self) {
        avr_device::asm::wdr();
    }

    /// Switch off (needs MCUSR.WDRF cleared first, which the start-up does:
    /// `board::early`).
    pub fn stop(self) -> WDT {
        avr_device::interrupt::free(|_| {
            avr_device::asm::wdr();
            self.wdt
                .wdtcsr()
                .write(|w| w.wdce().set_bit().wde().set_bit());
            // SAFETY: 0 is a valid WDTCSR value: watchdog off, no interrupt.
            self.wdt.wdtcsr().write(|w| unsafe { w.bits(0) });
        });
        self.wdt
    }
}
