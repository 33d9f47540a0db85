//! The machine's four buttons (RAMPS end-stop inputs, see `pinmap`),
//! sampled by the millisecond tick and debounced by
//! `taut_logic::buttons`. Events go to the job through [`BUTTONS`].

use crate::board::gpio::{Pin, PullUp};
use crate::rt::Ring;
use core::cell::UnsafeCell;
use embedded_hal::digital::InputPin;
use taut_logic::buttons::{ButtonEvent, Buttons};
use taut_logic::pinmap::Button;

/// Tick → job. Full: the event is refused and counted (the job is far
/// behind a human's presses).
pub static BUTTONS: Ring<ButtonEvent, 8> = Ring::new();

/// The end-stop inputs of the RAMPS board: X-MAX (green), X-MIN, Y-MIN,
/// Z-MIN (white).
pub struct ButtonPins {
    pub confirm: Pin<2, PullUp>,
    pub zero_base: Pin<3, PullUp>,
    pub zero_radial: Pin<14, PullUp>,
    pub zero_drill: Pin<18, PullUp>,
}

const _: () = {
    assert!(Button::Confirm.pin() == 2 && Button::ZeroBase.pin() == 3);
    assert!(Button::ZeroRadial.pin() == 14 && Button::ZeroDrill.pin() == 18);
};

impl ButtonPins {
    /// Pressed buttons as a bitmask (bit `Button as u8`); active low.
    fn raw(&mut self) -> u8 {
        let bit =
            |pressed: Result<bool, _>, b: Button| (pressed == Ok(true)) as u8 * (1 << b as u8);
        bit(self.confirm.is_low(), Button::Confirm)
            | bit(self.zero_base.is_low(), Button::ZeroBase)
            | bit(self.zero_radial.is_low(), Button::ZeroRadial)
            | bit(self.zero_drill.is_low(), Button::ZeroDrill)
    }
}

struct Sampler(UnsafeCell<Option<(ButtonPins, Buttons)>>);

// SAFETY: written once by `start` before interrupts are enabled, then used
// only by `sample`, which only the tick interrupt calls (and a tick never
// lasts the millisecond it would take to re-enter).
unsafe impl Sync for Sampler {}

static SAMPLER: Sampler = Sampler(UnsafeCell::new(None));

/// Hand the pins to the tick; call before interrupts are enabled.
pub fn start(pins: ButtonPins) {
    avr_device::interrupt::free(|_| unsafe { *SAMPLER.0.get() = Some((pins, Buttons::new())) });
}

/// The tick's millisecond sample. True when events were queued.
pub fn sample() -> bool {
    // SAFETY: see `Sampler`.
    let Some((pins, debouncer)) = (unsafe { &mut *SAMPLER.0.get() }) else {
        return false;
    };
    let events = debouncer.tick(pins.raw());
    for &e in &events {
        let _ = BUTTONS.push(e);
    }
    !events.is_empty()
}
