//! A virtual microSD card on the simulated SPI bus (Mega pins 50–53, chip
//! select D53 = PB0, active low), in SPI mode as the SD Physical Layer
//! Simplified Specification describes it.
//!
//! `SdCard` is the card alone, a pure byte-exchange state machine usable
//! without a simulator; `slot::Slot` holds it where simavr's SPI bus
//! reaches it (wired in `sim`), with the changes planned for later.
//! Nothing here depends on the simulator: `card_slot` gives `Sim` its
//! card methods.

mod card;
pub mod crc;
mod fault;
mod image;
mod registers;
pub(crate) mod slot;
mod stats;
#[cfg(test)]
mod tests;

pub use card::{
    CardKind, SdCard, SdConfig, DATA_ACCEPTED, DATA_CRC_ERROR, DATA_WRITE_ERROR, R1_ADDRESS,
    R1_CRC, R1_IDLE, R1_ILLEGAL, R1_PARAMETER, TOKEN_MULTI_WRITE, TOKEN_START, TOKEN_STOP_TRAN,
};
pub use fault::{CardFault, ReadFault};
pub use image::{SdImage, BLOCK};
pub use stats::SdStats;
