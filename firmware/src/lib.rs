//! The AVR side of taut: the board layer, logging, the runtime, and the
//! tasks' state, which the `app` (src/main.rs) wires together. The special
//! images in examples/ are built on the same pieces.
#![no_std]
#![feature(optimize_attribute)]
#![feature(asm_experimental_arch)]

pub mod board;
pub mod buttons;
pub mod card;
pub mod checkpoint;
pub mod console;
pub mod drivers;
pub mod endstop;
pub mod job;
pub mod log;
pub mod machine_io;
pub mod motion;
pub mod print;
pub mod queues;
pub mod realtime;
pub mod reply;
pub mod report;
pub mod rt;
pub mod stepper;
pub mod store;
pub mod texts;
pub mod tools;
