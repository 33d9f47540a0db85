//! State shared by software tasks only. Software tasks run to completion
//! one at a time from the dispatcher, so they never preempt each other and
//! need no critical section: the planner's look-ahead can run for
//! milliseconds without ever masking the step interrupt. Interrupt handlers
//! must not touch a `TaskCell` (they use a `Ring` or `Flags`).

use core::cell::{Cell, UnsafeCell};
use core::mem::MaybeUninit;

pub struct TaskCell<T> {
    value: UnsafeCell<MaybeUninit<T>>,
    borrowed: Cell<bool>,
}

// SAFETY: only software tasks access it (contract above), and they run one
// at a time on the single core; `borrowed` catches re-entrant use.
unsafe impl<T> Sync for TaskCell<T> {}

impl<T> TaskCell<T> {
    pub const fn new(value: T) -> Self {
        TaskCell {
            value: UnsafeCell::new(MaybeUninit::new(value)),
            borrowed: Cell::new(false),
        }
    }

    /// A cell of zeros, given its value by [`TaskCell::init`] at boot
    /// before any [`TaskCell::with`]. For big state whose starting value
    /// is nearly all zeros: a `new` cell's value is in `.data`, whose
    /// every byte is also a byte of flash; this one is in `.bss` (same
    /// SRAM, no flash).
    pub const fn zeroed() -> Self {
        TaskCell {
            value: UnsafeCell::new(MaybeUninit::zeroed()),
            borrowed: Cell::new(false),
        }
    }

    /// The starting value of a [`TaskCell::zeroed`] cell (at boot, before
    /// any task runs).
    pub fn init(&self, value: T) {
        assert!(!self.borrowed.get());
        // SAFETY: exclusive as in `with`; the old value (zeros) is not
        // dropped, only overwritten.
        unsafe { (*self.value.get()).write(value) };
    }

    /// [`TaskCell::init`] by `f`, which writes the value in place (a big
    /// one, built on the stack and copied, would deepen it) and returns it
    /// initialised.
    pub fn init_with(&self, f: impl for<'a> FnOnce(&'a mut MaybeUninit<T>) -> &'a mut T) {
        assert!(!self.borrowed.get());
        // SAFETY: exclusive as in `with`.
        f(unsafe { &mut *self.value.get() });
    }

    /// Run `f` with the state. Panics if a task re-enters it.
    pub fn with<R>(&self, f: impl FnOnce(&mut T) -> R) -> R {
        assert!(!self.borrowed.replace(true));
        // SAFETY: exclusive by the flag and the task-only contract.
        // Initialised: by `new`, or by `init` at boot for a `zeroed` cell.
        let r = f(unsafe { (*self.value.get()).assume_init_mut() });
        self.borrowed.set(false);
        r
    }
}
