//! Timer1, the step timer: free-running at the CPU clock (62.5 ns ticks).
//! The stepper schedules events as absolute compare times, so an interrupt
//! that starts late never shifts the events after it.

use avr_device::atmega2560::TC1;

/// Proof that Timer1 runs at clk/1 for the stepper, which drives its
/// compare registers directly from the interrupt.
pub struct StepTimer {
    _tc1: TC1,
}

impl StepTimer {
    pub fn start(tc1: TC1) -> StepTimer {
        // SAFETY: 0 is a valid TCCR1A value: normal mode, compare outputs
        // disconnected (the stepper drives its pins itself).
        tc1.tccr1a().write(|w| unsafe { w.bits(0) });
        tc1.tccr1b().write(|w| w.cs1().direct());
        StepTimer { _tc1: tc1 }
    }
}
