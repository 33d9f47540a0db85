//! Bits that interrupts set and a task takes: which tasks an interrupt
//! spawned, which real-time commands arrived. Setting is one masked `|=`
//! (a nested handler may be setting another bit), so an interrupt masks
//! the step interrupt for a few cycles only.

use core::cell::UnsafeCell;

pub struct Flags(UnsafeCell<u16>);

// SAFETY: every access is a read-modify-write with interrupts masked, or
// a read with interrupts masked (`is_empty`).
unsafe impl Sync for Flags {}

impl Flags {
    pub const fn new() -> Self {
        Flags(UnsafeCell::new(0))
    }

    /// Set bit `bit` (below 16). From interrupts or tasks.
    #[inline(always)]
    pub fn set(&self, bit: u8) {
        // SAFETY: masked read-modify-write (see `Sync`).
        avr_device::interrupt::free(|_| unsafe { *self.0.get() |= 1 << bit });
    }

    /// Take every bit set so far.
    pub fn take(&self) -> u16 {
        // SAFETY: masked read-modify-write (see `Sync`).
        avr_device::interrupt::free(|_| unsafe { core::mem::take(&mut *self.0.get()) })
    }

    /// No bit set, as far as a read without masking sees: a bit set while
    /// it reads may be missed (a hint for a task deciding whether to end
    /// its run early; the step interrupt is not delayed by it).
    pub fn seems_empty(&self) -> bool {
        // SAFETY: a volatile read of a value only ever changed whole by a
        // masked read-modify-write; a torn read is one of its two values'
        // halves, which may only miss a bit just set.
        unsafe { core::ptr::read_volatile(self.0.get()) == 0 }
    }

    /// [`Flags::seems_empty`] for the bits of `mask` alone.
    pub fn seems_any(&self, mask: u16) -> bool {
        // SAFETY: as `seems_empty`'s.
        unsafe { core::ptr::read_volatile(self.0.get()) & mask != 0 }
    }

    /// With interrupts masked (the dispatcher's idle path): the two bytes
    /// agree.
    pub fn is_empty_masked(&self) -> bool {
        // SAFETY: called with interrupts masked, so no handler writes it.
        unsafe { core::ptr::read_volatile(self.0.get()) == 0 }
    }
}

impl Default for Flags {
    fn default() -> Self {
        Self::new()
    }
}

/// A running sum the receive interrupt adds to and a task takes: presses
/// that come faster than the task runs are counted, not merged.
pub struct Tally(UnsafeCell<i16>);

// SAFETY: as `Flags`: every access is masked.
unsafe impl Sync for Tally {}

impl Default for Tally {
    fn default() -> Self {
        Self::new()
    }
}

impl Tally {
    pub const fn new() -> Self {
        Tally(UnsafeCell::new(0))
    }

    #[inline(always)]
    pub fn add(&self, v: i8) {
        // SAFETY: masked read-modify-write.
        avr_device::interrupt::free(|_| unsafe {
            let t = &mut *self.0.get();
            *t = t.saturating_add(v.into());
        });
    }

    #[inline(always)]
    pub fn clear(&self) {
        // SAFETY: masked write.
        avr_device::interrupt::free(|_| unsafe { *self.0.get() = 0 });
    }

    /// The sum so far, and zero from now on.
    pub fn take(&self) -> i16 {
        // SAFETY: masked read-modify-write.
        avr_device::interrupt::free(|_| unsafe { core::mem::take(&mut *self.0.get()) })
    }
}
