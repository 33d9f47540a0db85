//! The dispatcher: runs ready software tasks, highest priority first, each
//! to completion; feeds the watchdog only when every task that was ready at
//! the start of a round has run (when nothing is ready, on the idle path);
//! sleeps when nothing is ready. A task that never returns ends every
//! round, so the watchdog resets the board; a busy but healthy machine,
//! whose tasks keep spawning each other, still completes rounds.
//!
//! Interrupts never touch the ready set: they push task ids into `spawned`
//! (a short masked push), and the dispatcher moves them into `Ready` in
//! arrival order. So the ready set needs no lock, and nothing in the main
//! loop masks the step interrupt for longer than a ring push.

use super::{Ring, TaskCell};
use crate::board::watchdog::Watchdog;
use core::arch::asm;
use taut_logic::sched::{Ready, TaskId};

/// Task ids spawned from interrupts, in arrival order.
pub type Spawned = Ring<u8, 16>;

/// From an interrupt handler: make task `id` ready. A full ring is counted
/// in its stats (it holds more slots than there are tasks, so it cannot
/// fill unless the dispatcher is stuck, which the watchdog handles).
#[inline(always)]
pub fn spawn_from_isr(spawned: &Spawned, id: u8) {
    // Masked: a nested handler may also be pushing.
    avr_device::interrupt::free(|_| {
        let _ = spawned.push(id);
    });
}

pub fn run<T: TaskId, const N: usize, const P: usize>(
    spawned: &Spawned,
    ready: &TaskCell<Ready<T, N, P>>,
    task: fn(u8) -> T,
    watchdog: &Watchdog,
    mut dispatch: impl FnMut(T),
) -> ! {
    // SAFETY: SMCR (0x53): sleep enable, idle mode (timers and UART run).
    unsafe { core::ptr::write_volatile(0x53 as *mut u8, 0x01) };
    // Tasks (bit = index) still owed a run in this round.
    let mut round: u32 = 0;
    loop {
        while let Some(id) = spawned.pop() {
            ready.with(|r| r.spawn(task(id)));
        }
        if round == 0 {
            // Every task of the last round ran: feed, and start a new one.
            watchdog.feed();
            round = ready.with(|r| {
                (0..T::COUNT as u8)
                    .filter(|&i| r.is_pending(task(i)))
                    .fold(0, |m, i| m | 1 << i)
            });
        }
        if let Some(t) = ready.with(|r| r.pop()) {
            round &= !(1 << t.index());
            dispatch(t);
            continue;
        }
        avr_device::interrupt::disable();
        if spawned.is_empty() {
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
