//! The machine's four buttons (RAMPS end-stop inputs, see `pinmap`). The
//! millisecond tick samples the pins — only while a button is down or has
//! just changed — into `SAMPLES`; the buttons task debounces them
//! (`taut_logic::buttons`) and sends the presses to the job through
//! `BUTTONS` (`queues`).

use crate::board::gpio::{Pin, PullUp};
use crate::queues::{SampleButtons, Samples, TellPresses};
use crate::rt::IsrCell;
use embedded_hal::digital::InputPin;
use taut_logic::buttons::{Debouncer, DEBOUNCE_MS};
use taut_logic::pinmap::Button;

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
    /// D18 is TX1 while UART1 is on (a plotter's): no switch then.
    fn raw(&mut self) -> u8 {
        let tx1 = crate::board::usart1::on() as u8 * (1 << Button::ZeroDrill as u8);
        let bit =
            |pressed: Result<bool, _>, b: Button| (pressed == Ok(true)) as u8 * (1 << b as u8);
        bit(self.confirm.is_low(), Button::Confirm)
            | bit(self.zero_base.is_low(), Button::ZeroBase)
            | bit(self.zero_radial.is_low(), Button::ZeroRadial)
            | bit(self.zero_drill.is_low(), Button::ZeroDrill) & !tx1
    }
}

/// The tick's side: the pins, the last sample, how many quiet
/// milliseconds (all released, unchanged) have passed since, and its end
/// of `SAMPLES`.
static SAMPLER: IsrCell<(ButtonPins, u8, u8, SampleButtons)> = IsrCell::new();

/// Hand the pins and the end of `SAMPLES` to the tick; call before
/// interrupts are enabled.
pub fn start(pins: ButtonPins, samples: SampleButtons) {
    SAMPLER.init((pins, 0, u8::MAX, samples));
}

/// The tick's millisecond sample: queued while a button is down and until
/// the levels have been quiet long enough to debounce a release. True when
/// a sample was queued (spawn the buttons task); and the inputs read (bit =
/// button), which are also the homing switches.
pub fn sample() -> (bool, u8) {
    SAMPLER
        .with(|(pins, last, quiet, samples)| {
            let raw = pins.raw();
            *quiet = if raw == 0 && raw == *last {
                quiet.saturating_add(1)
            } else {
                0
            };
            *last = raw;
            (*quiet <= DEBOUNCE_MS && samples.push(raw).is_ok(), raw)
        })
        .unwrap_or((false, 0))
}

/// The buttons task's state: the debouncer, its ends of `SAMPLES` and
/// `BUTTONS`.
pub struct ButtonsTask {
    debouncer: Debouncer,
    samples: Samples,
    presses: TellPresses,
}

impl ButtonsTask {
    pub const fn new(samples: Samples, presses: TellPresses) -> Self {
        ButtonsTask {
            debouncer: Debouncer::new(),
            samples,
            presses,
        }
    }

    /// ButtonsTask every queued sample; true when events went to the job.
    pub fn poll(&mut self) -> bool {
        let mut sent = false;
        while let Some(raw) = self.samples.pop() {
            for e in self.debouncer.tick(raw) {
                sent |= self.presses.push(e).is_ok();
            }
        }
        sent
    }
}
