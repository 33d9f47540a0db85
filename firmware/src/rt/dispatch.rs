//! The dispatcher: runs ready software tasks, highest priority first, each
//! to completion, and sleeps when nothing is ready. The watchdog is fed by
//! `taut_logic::sched::Round` (host-tested): when every task that was
//! ready at the start of a round has run, with tasks still owed going
//! first once a round is 50 ms old. So rounds end under any load, and only
//! a task that never returns lets the watchdog reset the board.
//!
//! Interrupts never touch the ready set: they set the task's bit in
//! `Spawned` (one masked `|=`), and the dispatcher moves flagged tasks into
//! `Ready`, in task order, before each dispatch. So the ready set needs no
//! lock, and a spawn from an interrupt masks the step interrupt for a few
//! cycles. (A task pending already is not queued twice, so a bit per task
//! loses nothing; tasks flagged between two dispatches enter their
//! priority's FIFO in task order.)

use super::{Flags, TaskCell};
use core::arch::asm;
use taut_logic::sched::{Ready, Round, TaskId};

/// Tasks spawned from interrupts and not yet in the ready set: bit = id.
pub type Spawned = Flags;

/// From an interrupt handler: make task `id` (below 16) ready.
#[inline(always)]
pub fn spawn_from_isr(spawned: &Spawned, id: u8) {
    spawned.set(id);
}

/// Moves the interrupts' spawns into `ready` (those that came together in
/// index order); true when there were any. A task that spawns calls it
/// first, so what an interrupt spawned during its run is queued ahead of
/// it, in the order they came (a console byte during a refill run is not
/// overtaken by the refill's next run).
#[inline(always)]
pub fn admit<T: TaskId, const N: usize, const P: usize>(
    spawned: &Spawned,
    ready: &mut Ready<T, N, P>,
    task: fn(u8) -> T,
) -> bool {
    // Most calls find nothing: looked at without masking the step
    // interrupt, taken (masked) only when there is something.
    if spawned.seems_empty() {
        return false;
    }
    let flags = spawned.take();
    let (mut bits, mut id) = (flags, 0);
    while bits != 0 {
        if bits & 1 != 0 {
            ready.spawn(task(id));
        }
        bits >>= 1;
        id += 1;
    }
    true
}

pub fn run<T: TaskId, const N: usize, const P: usize>(
    spawned: &Spawned,
    ready: &TaskCell<Ready<T, N, P>>,
    task: fn(u8) -> T,
    millis: fn() -> u32,
    feed_watchdog: impl Fn(),
    mut dispatch: impl FnMut(T),
) -> ! {
    // SAFETY: SMCR (0x53): sleep enable, idle mode (timers and UART run).
    unsafe { core::ptr::write_volatile(0x53 as *mut u8, 0x01) };
    let mut round = Round::new();
    loop {
        ready.with(|r| admit(spawned, r, task));
        if let Some(t) = ready.with(|r| round.next(r, millis(), &feed_watchdog)) {
            dispatch(t);
            continue;
        }
        // Nothing ready: sleep until an interrupt spawns a task. Woken by
        // one that spawned nothing (each step, each tick), feed the
        // watchdog and sleep again, ~12 cycles: a round's look costs ~370.
        loop {
            avr_device::interrupt::disable();
            if !spawned.is_empty_masked() {
                // SAFETY: re-enables interrupts, as they were before
                // `disable`.
                unsafe { avr_device::interrupt::enable() };
                break;
            }
            feed_watchdog();
            // `sei` takes effect after the next instruction, so an
            // interrupt arriving now still wakes this `sleep`: no lost
            // wake-up.
            // SAFETY: re-enables interrupts, as they were before `disable`.
            unsafe { asm!("sei", "sleep") };
        }
    }
}
