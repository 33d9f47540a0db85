//! Safe harness over simavr for the Arduino Mega 2560 (ATmega2560, 16 MHz):
//! load a firmware ELF, run it for a simulated time or until a condition
//! holds, watch its pins and its serial port, drive its inputs, and learn
//! whether it crashed, hung, was reset by its watchdog or overflowed its
//! stack. Every `unsafe` call into simavr, and every raw pointer to its
//! objects, stays in `sim` and `hooks`.

pub mod boot;
mod calls;
mod card_slot;
pub mod clock;
mod compare_fix;
pub mod console;
pub mod elf;
mod endstop;
mod error;
pub mod fitting;
mod gpio;
mod hooks;
mod input;
mod masked;
pub mod operator;
mod outcome;
pub mod power;
pub mod probe;
pub mod profile;
pub mod pty;
pub mod report;
mod run;
pub mod scenario;
pub mod sdcard;
pub mod sdimage;
mod serial;
pub mod session;
mod sim;
pub mod stack_chain;
mod traps;
pub mod uart;

pub use console::{Reply, SendError};
pub use elf::ElfInfo;
pub use error::{Error, Result};
pub use outcome::Outcome;
pub use probe::{Edge, Probe};
pub use report::{PinReport, Report};
pub use sim::Sim;
/// The trace code (VCD, pulse replay, pictures) lives in `taut-trace`,
/// free of simavr: re-exported here for the harness's users.
pub use taut_trace::{coils, picture, replay, vcd};
