//! Pulse traces as plain data: the VCD reader and writer ([`vcd`]), the
//! machine's motion rebuilt from its STEP/DIR/EN pulses ([`replay`]) and
//! pictures drawn from them ([`picture`]). No simulator inside: the
//! harness (`taut-simavr`) writes the traces, the host tools (`taut
//! preview`) and the tests read them.

pub mod picture;
pub mod replay;
pub mod vcd;
