//! Resources shared between tasks and interrupts, RTIC style: the data sits
//! in a `static` and is reached only through `lock`, a critical section.
//! Keep the closure short: it delays the step interrupt by its length (the
//! bound is measured by the HIL tests as the longest interrupts-off span).

use avr_device::interrupt::{self, Mutex};
use core::cell::RefCell;

pub struct Shared<T>(Mutex<RefCell<T>>);

impl<T> Shared<T> {
    pub const fn new(value: T) -> Self {
        Shared(Mutex::new(RefCell::new(value)))
    }

    pub fn lock<R>(&self, f: impl FnOnce(&mut T) -> R) -> R {
        interrupt::free(|cs| f(&mut self.0.borrow(cs).borrow_mut()))
    }
}
