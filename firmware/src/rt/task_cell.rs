//! State shared by software tasks only. Software tasks run to completion
//! one at a time from the dispatcher, so they never preempt each other and
//! need no critical section: the planner's look-ahead can run for
//! milliseconds without ever masking the step interrupt. Interrupt handlers
//! must not touch a `TaskCell` (they use a `Ring` or `Flags`).

use core::cell::{Cell, UnsafeCell};

pub struct TaskCell<T> {
    value: UnsafeCell<T>,
    borrowed: Cell<bool>,
}

// SAFETY: only software tasks access it (contract above), and they run one
// at a time on the single core; `borrowed` catches re-entrant use.
unsafe impl<T> Sync for TaskCell<T> {}

impl<T> TaskCell<T> {
    pub const fn new(value: T) -> Self {
        TaskCell {
            value: UnsafeCell::new(value),
            borrowed: Cell::new(false),
        }
    }

    /// Run `f` with the state. Panics if a task re-enters it.
    pub fn with<R>(&self, f: impl FnOnce(&mut T) -> R) -> R {
        assert!(!self.borrowed.replace(true));
        // SAFETY: exclusive by the flag and the task-only contract.
        let r = f(unsafe { &mut *self.value.get() });
        self.borrowed.set(false);
        r
    }
}
