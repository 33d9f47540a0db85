//! How a stretch of simulation ended.

use serde::Serialize;

/// Program counters are byte addresses in flash, as `avr-objdump` shows them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "end")]
pub enum Outcome {
    /// Time ran out with the firmware still running.
    Running,
    /// The awaited condition came true.
    Done,
    /// Execution left the program: past the end of flash, an invalid opcode,
    /// or a jump to the reset vector without a reset (a null function
    /// pointer, or an interrupt without a handler). `pc` is the instruction
    /// that went wrong.
    Crashed { pc: u32 },
    /// `sleep` with interrupts disabled: nothing can ever wake the MCU.
    Hung { pc: u32 },
    /// The watchdog timed out and reset the MCU (`count` resets so far). The
    /// firmware restarts; running on is allowed.
    WatchdogReset { count: u32 },
    /// The stack pointer went below the end of the statics: pushes are
    /// overwriting `.data`/`.bss`.
    StackOverflow { sp: u16, limit: u16 },
}

impl Outcome {
    /// True for the endings after which simulating further means nothing.
    pub fn is_fatal(&self) -> bool {
        matches!(
            self,
            Outcome::Crashed { .. } | Outcome::Hung { .. } | Outcome::StackOverflow { .. }
        )
    }
}
