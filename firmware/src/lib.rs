//! The AVR side of taut: the board layer, logging and the runtime the `app`
//! (src/main.rs) and the special-purpose images in examples/ are built on.
#![no_std]
#![feature(asm_experimental_arch)]

pub mod board;
pub mod log;
pub mod rt;
