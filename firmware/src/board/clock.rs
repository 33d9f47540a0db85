//! The monotonic clock: Timer0 in CTC mode ticks every millisecond
//! (16 MHz / 64 / 250); microseconds come from the counter between ticks.

use avr_device::atmega2560::TC0;
use avr_device::interrupt::{self, Mutex};
use core::cell::Cell;

static MILLIS: Mutex<Cell<u32>> = Mutex::new(Cell::new(0));
/// The millisecond at which `tick` reports the alarm (None: not armed).
static ALARM: Mutex<Cell<Option<u32>>> = Mutex::new(Cell::new(None));

pub struct Clock;

impl Clock {
    pub fn start(tc0: TC0) -> Clock {
        tc0.tccr0a().write(|w| w.wgm0().ctc());
        tc0.tccr0b().write(|w| w.cs0().prescale_64());
        // After the mode is complete (simavr checks it on OCR writes).
        // SAFETY: OCR0A takes any 8-bit compare value.
        tc0.ocr0a().write(|w| unsafe { w.bits(249) });
        tc0.timsk0().write(|w| w.ocie0a().set_bit());
        Clock
    }
}

/// Milliseconds since boot (wraps after 49 days).
pub fn millis() -> u32 {
    interrupt::free(|cs| MILLIS.borrow(cs).get())
}

/// Microseconds since boot, 4 µs resolution.
pub fn micros() -> u32 {
    // SAFETY: read-only access to Timer0 registers owned by `Clock`.
    let tc0 = unsafe { &*TC0::ptr() };
    interrupt::free(|cs| {
        let ms = MILLIS.borrow(cs).get();
        let mut t = tc0.tcnt0().read().bits() as u32;
        // A compare match not yet serviced: the millisecond has passed.
        if tc0.tifr0().read().ocf0a().bit_is_set() {
            t = tc0.tcnt0().read().bits() as u32 + 250;
        }
        ms * 1000 + t * 4
    })
}

/// Arm the alarm for millisecond `at` (replacing any earlier one).
pub fn set_alarm(at: u32) {
    interrupt::free(|cs| ALARM.borrow(cs).set(Some(at)));
}

/// Called by the `TIMER0_COMPA` interrupt. True when the alarm fell due
/// (it is then disarmed): the app runs its timers.
pub fn tick() -> bool {
    interrupt::free(|cs| {
        let m = MILLIS.borrow(cs);
        let now = m.get().wrapping_add(1);
        m.set(now);
        let alarm = ALARM.borrow(cs);
        match alarm.get() {
            Some(at) if now.wrapping_sub(at) as i32 >= 0 => {
                alarm.set(None);
                true
            }
            _ => false,
        }
    })
}
