//! Timer1, the step timer: free-running at the CPU clock (62.5 ns ticks).
//! Step events are scheduled as absolute compare times, so an interrupt that
//! starts late never shifts the events after it.

use avr_device::atmega2560::TC1;

pub struct StepTimer {
    tc1: TC1,
}

impl StepTimer {
    pub fn start(tc1: TC1) -> StepTimer {
        tc1.tccr1a().write(|w| unsafe { w.bits(0) });
        tc1.tccr1b().write(|w| w.cs1().direct());
        StepTimer { tc1 }
    }

    pub fn now(&self) -> u16 {
        self.tc1.tcnt1().read().bits()
    }

    /// Fire `TIMER1_COMPA` when the counter reaches `at`.
    pub fn schedule(&self, at: u16) {
        self.tc1.ocr1a().write(|w| w.set(at));
        self.tc1.tifr1().write(|w| w.ocf1a().set_bit());
        self.tc1.timsk1().modify(|_, w| w.ocie1a().set_bit());
    }

    pub fn stop_events(&self) {
        self.tc1.timsk1().modify(|_, w| w.ocie1a().clear_bit());
    }
}
