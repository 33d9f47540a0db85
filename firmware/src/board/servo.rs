//! Timer1 as the pen servo's PWM on OC1A (D11, RAMPS SERVO0): 50 Hz, the
//! pulse width set in hardware, so no interrupt can make it jitter.

use super::gpio::{Output, Pin};
use avr_device::atmega2560::TC1;

/// Timer ticks per µs at clk/8.
const TICKS_PER_US: u16 = 2;
/// 20 ms between pulses.
const PERIOD_US: u16 = 20_000;

/// Proof that Timer1 drives SERVO0.
pub struct PenServo {
    tc1: TC1,
    _pin: Pin<11, Output>,
}

impl PenServo {
    /// Starts the pulses at `pulse_us` (the pin is already an output).
    pub fn start(tc1: TC1, pin: Pin<11, Output>, pulse_us: u16) -> PenServo {
        // Fast PWM with TOP = ICR1 (mode 14), clk/8; OC1A high from the
        // period's start until the compare. The mode first: the compare
        // registers are written in it.
        tc1.tccr1a()
            .write(|w| w.com1a().match_clear().wgm1().set(0b10));
        tc1.tccr1b()
            .write(|w| w.wgm1().set(0b11).cs1().prescale_8());
        tc1.icr1().write(|w| w.set(PERIOD_US * TICKS_PER_US - 1));
        let mut servo = PenServo { tc1, _pin: pin };
        servo.set_pulse_us(pulse_us);
        servo
    }

    /// The width of the next pulses (the timer takes it at the period's
    /// end: no pulse is ever cut).
    pub fn set_pulse_us(&mut self, us: u16) {
        self.tc1.ocr1a().write(|w| w.set(us * TICKS_PER_US - 1));
    }

    /// The pulse width now set, µs.
    pub fn pulse_us(&self) -> u16 {
        (self.tc1.ocr1a().read().bits() + 1) / TICKS_PER_US
    }
}
