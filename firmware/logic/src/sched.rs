//! The task dispatcher's logic: which software task runs next, when timed
//! tasks fall due, and how full the message queues got.
//!
//! The firmware keeps each of these in a `static` that only software tasks
//! touch (interrupts only set a task's bit, which the dispatcher moves into
//! [`Ready`]); the main loop dispatches, and [`Round`] decides when the
//! watchdog is fed. Everything here is `const`-constructible and heap-free.
//!
//! # Ordering guarantees of [`Ready`]
//! - **Priority first**: [`Ready::pop`] returns a ready task of the highest
//!   priority level; a lower level runs only when every higher one is empty.
//! - **FIFO within a priority**: tasks of the same level come out in the
//!   order they were spawned, whether the spawns came from the main loop or
//!   from interrupts interleaved between `pop()` calls.
//! - **At most once**: spawning a task that is already pending is a no-op
//!   (`spawn` returns `false`) and does not move it in the queue. Its work is
//!   carried by its input queue, so nothing is lost: the task drains its
//!   queue when it runs.
//! - **Run to completion**: a task is taken off the ready set when `pop()`
//!   returns it, so it may be spawned again (even by itself) while running
//!   and will then run once more after the tasks already queued at its level.
//!
//! # Timers
//! [`Timers`] holds one-shot and periodic deadlines on the wrapping `u32`
//! millisecond clock; due timers are handed to [`Ready`] in deadline order.
//! Deadlines are compared by signed distance, so the clock may wrap freely as
//! long as no delay exceeds `i32::MAX` ms (about 24.8 days).

mod queue_stats;
mod ready;
mod round;
mod timers;

pub use queue_stats::QueueStats;
pub use ready::Ready;
pub use round::Round;
pub use timers::{Full, Timers};

/// A software task's identity: the firmware's task enum implements this.
///
/// `index` must be unique per task and below `COUNT`; `priority` is the
/// task's fixed level, higher runs first, below the dispatcher's level count.
pub trait TaskId: Copy {
    /// Number of tasks (indices `0..COUNT`).
    const COUNT: usize;
    fn index(self) -> usize;
    fn priority(self) -> u8;
}

#[cfg(test)]
mod test_task {
    use super::TaskId;

    /// A task for tests: its priority travels with it, so a test can pick
    /// any priority table.
    #[derive(Clone, Copy, Debug, PartialEq, Eq)]
    pub struct Tk {
        pub id: u8,
        pub prio: u8,
    }

    pub const fn tk(id: u8, prio: u8) -> Tk {
        Tk { id, prio }
    }

    impl TaskId for Tk {
        const COUNT: usize = 8;
        fn index(self) -> usize {
            self.id as usize
        }
        fn priority(self) -> u8 {
            self.prio
        }
    }
}
