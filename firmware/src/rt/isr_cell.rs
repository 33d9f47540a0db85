//! State owned by one interrupt handler: given its value by the app's init
//! before interrupts are enabled, then used by that handler alone (the
//! buttons' sampler in the millisecond tick).

use core::cell::UnsafeCell;

pub struct IsrCell<T>(UnsafeCell<Option<T>>);

// SAFETY: `init` runs with interrupts masked before the owner can run;
// after it only the owning handler calls `with`, and a handler does not
// re-enter itself (the tick never lasts the millisecond it would take).
unsafe impl<T> Sync for IsrCell<T> {}

impl<T> Default for IsrCell<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T> IsrCell<T> {
    pub const fn new() -> Self {
        IsrCell(UnsafeCell::new(None))
    }

    /// The value; call before interrupts are enabled.
    pub fn init(&self, value: T) {
        // SAFETY: see `Sync`; interrupts are masked besides.
        avr_device::interrupt::free(|_| unsafe { *self.0.get() = Some(value) });
    }

    /// Run `f` with the value, if `init` gave one. Only the owning
    /// handler may call this.
    pub fn with<R>(&self, f: impl FnOnce(&mut T) -> R) -> Option<R> {
        // SAFETY: see `Sync`: the one handler that calls this is not
        // re-entered, so this borrow is the only one.
        unsafe { &mut *self.0.get() }.as_mut().map(f)
    }
}
