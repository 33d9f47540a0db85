//! Timer3, the step timer: free-running at the CPU clock (62.5 ns ticks).
//! The stepper schedules events as absolute compare times, so an interrupt
//! that starts late never shifts the events after it.

use avr_device::atmega2560::TC3;

/// Proof that Timer3 runs at clk/1 for the stepper, which drives its
/// compare registers directly from the interrupt.
pub struct StepTimer {
    _tc3: TC3,
}

impl StepTimer {
    pub fn start(tc3: TC3) -> StepTimer {
        // SAFETY: 0 is a valid TCCR3A value: normal mode, compare outputs
        // disconnected (the stepper drives its pins itself).
        tc3.tccr3a().write(|w| unsafe { w.bits(0) });
        tc3.tccr3b().write(|w| w.cs3().direct());
        StepTimer { _tc3: tc3 }
    }
}
