//! How long each run of a function lasts, from reaching its entry to
//! returning from it: a task's run (the longest one is how long every other
//! task may wait). A run ends when the stack pointer rises above where it
//! stood at the entry: the `ret` took the return address back. Interrupts
//! inside the run count in it, as they do for the tasks that wait.

/// The runs of the function at `entry` (byte address).
pub(crate) struct CallWatch {
    pub(crate) entry: u32,
    /// The run under way: its first cycle and the stack pointer at entry.
    open: Option<(u64, u16)>,
    /// Each finished run: (first cycle, cycles).
    pub(crate) runs: Vec<(u64, u64)>,
}

impl CallWatch {
    pub(crate) fn new(entry: u32) -> Self {
        CallWatch {
            entry,
            open: None,
            runs: Vec::new(),
        }
    }

    /// After an instruction: execution at `pc` with the stack at `sp`.
    pub(crate) fn observe(&mut self, pc: u32, sp: u16, now: u64) {
        match self.open {
            Some((start, at_entry)) if sp > at_entry => {
                self.runs.push((start, now - start));
                self.open = None;
            }
            Some(_) => {}
            None if pc == self.entry => self.open = Some((now, sp)),
            None => {}
        }
    }
}
