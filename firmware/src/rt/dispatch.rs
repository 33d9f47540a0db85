//! The dispatcher: runs ready software tasks, highest priority first, each
//! to completion; feeds the watchdog only when every ready task has run;
//! sleeps when nothing is ready.

use super::Shared;
use crate::board::watchdog::Watchdog;
use core::arch::asm;
use taut_logic::sched::{Ready, TaskId};

pub fn run<T: TaskId, const N: usize, const P: usize>(
    ready: &Shared<Ready<T, N, P>>,
    watchdog: &Watchdog,
    mut dispatch: impl FnMut(T),
) -> ! {
    // SAFETY: SMCR (0x53): sleep enable, idle mode (timers and UART run).
    unsafe { core::ptr::write_volatile(0x53 as *mut u8, 0x01) };
    loop {
        while let Some(task) = pop(ready) {
            dispatch(task);
        }
        // A task that never returns never gets here: the watchdog resets.
        watchdog.feed();
        avr_device::interrupt::disable();
        if is_idle(ready) {
            // `sei` takes effect after the next instruction, so an interrupt
            // arriving now still wakes this `sleep`: no lost wake-up.
            // SAFETY: re-enables interrupts, as they were before `disable`.
            unsafe { asm!("sei", "sleep") };
        } else {
            // SAFETY: as above.
            unsafe { avr_device::interrupt::enable() };
        }
    }
}

// Out of line, so the compiler cannot pull unrelated work into the short
// critical sections (each one delays the step interrupt by its length).
#[inline(never)]
fn pop<T: TaskId, const N: usize, const P: usize>(ready: &Shared<Ready<T, N, P>>) -> Option<T> {
    ready.lock(|r| r.pop())
}

#[inline(never)]
fn is_idle<T: TaskId, const N: usize, const P: usize>(ready: &Shared<Ready<T, N, P>>) -> bool {
    ready.lock(|r| r.is_idle())
}
