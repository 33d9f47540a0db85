//! Faults a test can inject into a virtual card.

use std::collections::{BTreeMap, BTreeSet};

/// A fault for a card: injected at once (`SdCard::inject`) or at a planned
/// simulated time (`Sim::sd_fault_at`). Blocks are numbered as LBAs (block
/// 0 is the card's first), whatever the card's addressing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CardFault {
    /// The next data block the card sends (a read block, or a register
    /// while the host initialises it) carries a wrong CRC16.
    CrcNext,
    /// The next read of this block carries a wrong CRC16; later reads are
    /// fine.
    CrcOnce(u32),
    /// Every read of this block fails as a worn-out block does: R1 is fine,
    /// then error token 0x04 (card ECC failed) instead of the data.
    BadBlock(u32),
}

/// How a read of a failing block goes wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReadFault {
    /// R1 is fine, then this data error token comes instead of 0xFE
    /// (0x01 error, 0x02 CC error, 0x04 card ECC failed, 0x08 out of range).
    ErrorToken(u8),
    /// R1 is fine, then no token ever: the host times out.
    NoToken,
}

#[derive(Default)]
pub(crate) struct Faults {
    /// Blocks whose every read fails.
    pub bad_blocks: BTreeMap<u32, ReadFault>,
    /// Blocks whose next read carries a wrong CRC16.
    pub crc_once: BTreeSet<u32>,
    /// Commands still to be ignored (no response at all).
    pub mute_commands: u32,
    /// The next data block the card sends carries a wrong CRC16.
    pub corrupt_crc: bool,
    /// The card is pulled out halfway through the next data block.
    pub pull_in_transfer: bool,
    /// Bytes left before the card is pulled, once a transfer started.
    pub pull_countdown: Option<u32>,
}

/// Bytes of a data block after which an armed removal happens: after the
/// token and half the data.
pub(crate) const PULL_AFTER: u32 = 1 + 256;
