//! The runtime the `app` is built on: shared resources, interrupt-safe
//! queues, stack measurement. The dispatcher's ordering logic is
//! `taut_logic::sched` (host-tested); the app holds it in `Shared` statics.

pub mod dispatch;
pub mod nested;
pub mod ring;
pub mod shared;
pub mod stack;
pub mod task_cell;

pub use ring::Ring;
pub use shared::Shared;
pub use task_cell::TaskCell;
