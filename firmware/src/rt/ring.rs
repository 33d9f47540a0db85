//! A lock-free single-producer single-consumer ring for queues that cross
//! an interrupt boundary (UART bytes, step segments). Indices are single
//! bytes, which the AVR loads and stores atomically (`byte`), so neither
//! side ever masks interrupts. Each ring counts what it accepted and
//! refused and how full it got: a full ring is back-pressure to the
//! producer, never a silent loss.

use super::byte;
use core::cell::UnsafeCell;
use core::mem::MaybeUninit;
use core::ptr::read_volatile;
use core::sync::atomic::{compiler_fence, AtomicU8, Ordering::*};
use taut_logic::sched::QueueStats;

/// `WHOLE`: all `N` slots usable (indices run free and are masked when
/// used, so full and empty differ by the count: `N` ≤ 128). Otherwise one
/// slot stays empty and the indices are kept masked, as the step
/// interrupt's assembly consumer of the segment ring expects.
#[repr(C)]
pub struct Ring<T: Copy, const N: usize, const WHOLE: bool = false> {
    buf: UnsafeCell<[MaybeUninit<T>; N]>,
    head: AtomicU8,
    tail: AtomicU8,
    /// Written by the producer only.
    stats: UnsafeCell<QueueStats>,
}

// SAFETY: the producer writes only `buf[head]` before publishing `head`, the
// consumer reads only `buf[tail]` before publishing `tail`: their slots never
// overlap. `stats` is written by the producer only; readers take a copy
// inside a critical section (see `stats`).
unsafe impl<T: Copy + Send, const N: usize, const WHOLE: bool> Sync for Ring<T, N, WHOLE> {}

impl<T: Copy, const N: usize, const WHOLE: bool> Default for Ring<T, N, WHOLE> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Copy, const N: usize, const WHOLE: bool> Ring<T, N, WHOLE> {
    const MASK: u8 = (N - 1) as u8;

    /// The index after `i`.
    fn next(i: u8) -> u8 {
        match WHOLE {
            true => i.wrapping_add(1),
            false => i.wrapping_add(1) & Self::MASK,
        }
    }

    pub const fn new() -> Self {
        assert!(N.is_power_of_two() && N <= 256 && (!WHOLE || N <= 128));
        Ring {
            buf: UnsafeCell::new([MaybeUninit::uninit(); N]),
            head: AtomicU8::new(0),
            tail: AtomicU8::new(0),
            stats: UnsafeCell::new(QueueStats::new()),
        }
    }

    /// Messages waiting. Two loads and a subtraction: inlined (a call
    /// from an interrupt handler costs the saving of every register a
    /// callee may clobber).
    #[inline(always)]
    pub fn len(&self) -> usize {
        let n = byte::load(&self.head).wrapping_sub(byte::load(&self.tail));
        match WHOLE {
            true => n as usize,
            false => (n & Self::MASK) as usize,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Consumer: drop everything queued (its producer must be quiet, or
    /// its new items may go too).
    pub fn clear(&self) {
        byte::store(&self.tail, byte::load(&self.head));
    }

    /// Free slots (unless `WHOLE`, one stays empty to tell full from empty).
    #[inline(always)]
    pub fn free(&self) -> usize {
        self.capacity() - self.len()
    }

    /// Producer: append all of `items` or none (refusal is counted once).
    pub fn push_all(&self, items: &[T]) -> bool {
        // SAFETY: only the producer touches `stats` mutably.
        let stats = unsafe { &mut *self.stats.get() };
        if items.len() > self.free() {
            stats.on_refused();
            return false;
        }
        let mut h = byte::load(&self.head);
        for &item in items {
            // SAFETY: slot `h` is free (checked above) and the producer's.
            unsafe { (*self.buf.get())[(h & Self::MASK) as usize] = MaybeUninit::new(item) };
            h = Self::next(h);
        }
        compiler_fence(Release);
        byte::store(&self.head, h);
        stats.on_send(self.len());
        true
    }

    /// Producer: write the `n` items of `items` from `k` slots past the
    /// last one queued, as many as there are free slots for; the consumer
    /// sees them once [`Ring::publish`] counts them in. A message built in
    /// the ring itself (a log line): no copy of it elsewhere. Nothing else
    /// may be pushed meanwhile. The free slots are counted once, before
    /// the first: the consumer only frees more. Whether all fit.
    #[inline(always)]
    pub fn stage(&self, k: u8, n: u8, items: impl Iterator<Item = T>) -> bool {
        // At most 255 free: `N` ≤ 256 and one stays empty, or `N` ≤ 128.
        let fit = (self.free() as u8).saturating_sub(k).min(n);
        let mut h = byte::load(&self.head).wrapping_add(k);
        for item in items.take(usize::from(fit)) {
            // SAFETY: slot `h` is free (counted above) and the producer's.
            unsafe { (*self.buf.get())[(h & Self::MASK) as usize] = MaybeUninit::new(item) };
            h = h.wrapping_add(1);
        }
        fit == n
    }

    /// Producer: queue the first `n` items staged (all written).
    pub fn publish(&self, n: usize) {
        // SAFETY: only the producer touches `stats` mutably.
        let stats = unsafe { &mut *self.stats.get() };
        let h = byte::load(&self.head).wrapping_add(n as u8);
        compiler_fence(Release);
        byte::store(&self.head, if WHOLE { h } else { h & Self::MASK });
        stats.on_send(self.len());
    }

    /// Producer: count a message refused (a staged one that did not fit).
    pub fn refuse(&self) {
        // SAFETY: only the producer touches `stats` mutably.
        unsafe { (*self.stats.get()).on_refused() };
    }

    /// [`Ring::push`] inlined, for an interrupt handler: a call there
    /// costs the saving of every register a callee may clobber (the UART's
    /// byte went from ~350 cycles to ~310).
    #[inline(always)]
    pub fn push_inlined(&self, item: T) -> Result<(), T> {
        // SAFETY: only the producer touches `stats` mutably.
        let stats = unsafe { &mut *self.stats.get() };
        if self.free() == 0 {
            stats.on_refused();
            return Err(item);
        }
        let h = byte::load(&self.head);
        // SAFETY: slot `h` is free (checked above) and the producer's.
        unsafe { (*self.buf.get())[(h & Self::MASK) as usize] = MaybeUninit::new(item) };
        compiler_fence(Release);
        byte::store(&self.head, Self::next(h));
        stats.on_send(self.len());
        Ok(())
    }

    /// Producer: append `item` (a refusal is counted).
    pub fn push(&self, item: T) -> Result<(), T> {
        self.push_inlined(item)
    }

    /// Consumer: the oldest message, if any. Inlined: the step interrupt
    /// takes its blocks with it, and a call there deepens the stack peak.
    #[inline(always)]
    pub fn pop(&self) -> Option<T> {
        let t = byte::load(&self.tail);
        if t == byte::load(&self.head) {
            return None;
        }
        compiler_fence(Acquire);
        // SAFETY: slot `t` was published by the producer and not yet consumed.
        let item = unsafe { (*self.buf.get())[(t & Self::MASK) as usize].assume_init() };
        compiler_fence(Release);
        byte::store(&self.tail, Self::next(t));
        Some(item)
    }

    /// Consumer: the oldest message without taking it.
    pub fn peek(&self) -> Option<T> {
        let t = byte::load(&self.tail);
        if t == byte::load(&self.head) {
            return None;
        }
        compiler_fence(Acquire);
        // SAFETY: as in `pop`.
        Some(unsafe { (*self.buf.get())[(t & Self::MASK) as usize].assume_init() })
    }

    /// Consumer: `f` of the oldest message, read in place. Inlined, as
    /// [`Ring::pop`].
    #[inline(always)]
    pub fn peek_with<R>(&self, f: impl FnOnce(&T) -> R) -> Option<R> {
        let t = byte::load(&self.tail);
        if t == byte::load(&self.head) {
            return None;
        }
        compiler_fence(Acquire);
        // SAFETY: as in `pop`.
        Some(f(unsafe {
            (*self.buf.get())[(t & Self::MASK) as usize].assume_init_ref()
        }))
    }

    /// Consumer: whether any waiting message is `f`'s.
    pub fn any(&self, f: impl Fn(&T) -> bool) -> bool {
        let (mut t, h) = (byte::load(&self.tail), byte::load(&self.head));
        compiler_fence(Acquire);
        while t != h {
            // SAFETY: slots from tail to head are published and not consumed.
            if f(unsafe { (*self.buf.get())[(t & Self::MASK) as usize].assume_init_ref() }) {
                return true;
            }
            t = Self::next(t);
        }
        false
    }

    /// Byte offsets of the indices, for the step interrupt's assembly
    /// consumer (`stepper::fast`); the slots start at offset 0.
    #[doc(hidden)]
    pub const HEAD: usize = core::mem::offset_of!(Self, head);
    #[doc(hidden)]
    pub const TAIL: usize = core::mem::offset_of!(Self, tail);

    /// Usable capacity.
    pub const fn capacity(&self) -> usize {
        match WHOLE {
            true => N,
            false => N - 1,
        }
    }

    /// A consistent copy of the counters (the producer may be an interrupt).
    pub fn stats(&self) -> QueueStats {
        let p = self.stats.get();
        // SAFETY: interrupts are off, so the producer cannot be mid-update.
        // Field by field and volatile: a plain copy may become a call to
        // `memcpy`, 269 cycles with the step interrupt masked.
        avr_device::interrupt::free(|_| unsafe {
            QueueStats {
                sent: read_volatile(&raw const (*p).sent),
                refused: read_volatile(&raw const (*p).refused),
                high_water: read_volatile(&raw const (*p).high_water),
            }
        })
    }
}
