//! The runtime the `app` is built on: shared resources, interrupt-safe
//! queues, stack measurement. The dispatcher's ordering logic is
//! `taut_logic::sched` (host-tested); the app holds it in `TaskCell` statics.

pub mod byte;
pub mod dispatch;
pub mod flags;
pub mod isr_cell;
pub mod mailbox;
pub mod mul64;
pub mod nested;
pub mod ring;
pub mod stack;
pub mod task_cell;
pub mod tasks;

pub use flags::{Flags, Tally};

/// What a software task wants after a run; the app reschedules it.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Poll<S> {
    /// Nothing until new input spawns it.
    Idle,
    /// Run again, after the tasks already ready (a long job, in pieces).
    Again,
    /// Run again in this many ms.
    After(u16),
    /// Run again when the app signals `S`.
    Wait(S),
}
pub use isr_cell::IsrCell;
pub use mailbox::Mailbox;
pub use ring::Ring;
pub use task_cell::TaskCell;

/// Let the interrupts in: the app's init calls it once, when every handler
/// and the state it touches is ready.
pub fn enable_interrupts() {
    // SAFETY: the caller's init has set up every handler's state.
    unsafe { avr_device::interrupt::enable() };
}
