//! The runtime the `app` is built on: shared resources, interrupt-safe
//! queues, stack measurement. The dispatcher's ordering logic is
//! `taut_logic::sched` (host-tested); the app holds it in `TaskCell` statics.

pub mod dispatch;
pub mod nested;
pub mod ring;
pub mod stack;
pub mod task_cell;

pub use ring::Ring;
pub use task_cell::TaskCell;
