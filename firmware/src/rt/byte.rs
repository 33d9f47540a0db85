//! A byte shared with an interrupt, loaded and stored as the one
//! instruction it is on the AVR (`ld`, `st`: no access can split it).
//! LLVM brackets every atomic byte load and store with a SREG save,
//! `cli` and restore: three instructions and 6 bytes of flash each, and
//! the rings' indices are read at every inlined push and pop. Orderings
//! are the caller's `compiler_fence`s, as with `Relaxed`.

use core::arch::asm;
use core::sync::atomic::{AtomicBool, AtomicU8};

/// `a`'s value, as `a.load(Relaxed)`.
#[inline(always)]
pub fn load(a: &AtomicU8) -> u8 {
    let v: u8;
    // SAFETY: one `ld` of the byte `a` owns: an atomic load on a core
    // whose byte accesses are never split.
    unsafe {
        asm!(
            "ld {v}, {p}",
            v = out(reg) v,
            p = in(reg_ptr) a.as_ptr(),
            options(nostack, readonly, preserves_flags),
        )
    };
    v
}

/// `a.store(v, Relaxed)`.
#[inline(always)]
pub fn store(a: &AtomicU8, v: u8) {
    // SAFETY: one `st` to the byte `a` owns, as `load`.
    unsafe {
        asm!(
            "st {p}, {v}",
            v = in(reg) v,
            p = in(reg_ptr) a.as_ptr(),
            options(nostack, preserves_flags),
        )
    };
}

/// `a.load(Relaxed)` of a flag.
#[inline(always)]
pub fn load_bool(a: &AtomicBool) -> bool {
    // SAFETY: an `AtomicBool` has the layout of a `u8` holding 0 or 1.
    load(unsafe { &*(a as *const AtomicBool as *const AtomicU8) }) != 0
}

/// `a.store(v, Relaxed)` of a flag.
#[inline(always)]
pub fn store_bool(a: &AtomicBool, v: bool) {
    // SAFETY: as `load_bool`.
    store(
        unsafe { &*(a as *const AtomicBool as *const AtomicU8) },
        v as u8,
    );
}
