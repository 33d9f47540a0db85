//! The pure logic of taut: everything that can be computed without touching
//! hardware. `no_std`, no heap; unit- and property-tested on the host.
//!
//! The data's path, Grbl-style: text (`gcode`, `files`) → targets in steps
//! (`kinematics`, `units`) → `planner` (look-ahead) → `segment` (timed step
//! runs the step interrupt executes). `sched` is the task dispatcher's logic;
//! `stringart` the string-art job; `fat` reads its files from the SD card.
#![no_std]
// The AVR build (nightly) compiles the hot arithmetic for speed.
#![cfg_attr(
    target_arch = "avr",
    feature(optimize_attribute, asm_experimental_arch)
)]
// No unsafe code, but for the AVR assembly of `segment`'s 64-by-32-bit
// division (allowed there alone).
#![deny(unsafe_code)]

#[cfg(test)]
extern crate std;

pub mod arc;
pub mod axis;
pub mod buttons;
pub mod checkpoint;
/// A 28BYJ-48's half-step coil sequence.
pub mod coil;
pub mod config;
pub mod coords;
pub mod fat;
pub mod files;
/// Table-free `sin_cos`, `atan2` and `sqrt`: no constant tables in the AVR's SRAM.
pub mod fmath;
pub mod gcode;
pub mod geometry;
pub mod homing;
pub mod interp;
pub mod kinematics;
pub mod machine;
pub mod patterns;
pub mod pinmap;
pub mod planner;
pub mod prep;
pub mod sched;
pub mod seed;
pub mod segment;
pub mod settings;
pub mod stringart;
pub mod text;
pub mod units;
