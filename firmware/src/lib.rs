//! The AVR side of taut: the board layer, logging, the runtime, and the
//! tasks' state, which the `app` (src/main.rs) wires together. The special
//! images in examples/ are built on the same pieces.
#![no_std]
// Unsafe code only in the board layer, the runtime and the step engine.
#![deny(unsafe_code)]
#![feature(optimize_attribute)]
#![feature(asm_experimental_arch)]

#[allow(unsafe_code)]
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
#[allow(unsafe_code)]
pub mod rt;
#[allow(unsafe_code)]
pub mod stepper;
pub mod store;
pub mod texts;
pub mod tools;
