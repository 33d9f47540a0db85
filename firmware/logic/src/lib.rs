//! The pure logic of taut: everything that can be computed without touching
//! hardware. `no_std`, no heap; unit- and property-tested on the host.
#![no_std]
#![forbid(unsafe_code)]

#[cfg(test)]
extern crate std;

pub mod axis;
pub mod config;
pub mod units;
