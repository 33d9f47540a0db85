//! USART0's line as the host holds it: what the firmware sent, what waits to
//! be received, and the pace of a 115200 8N1 line. Plain data, written by
//! simavr's callbacks and by the run loop alike.

use crate::clock::FREQ_HZ;
use std::collections::VecDeque;

/// Line rate of the host side.
pub const BAUD: u64 = 115_200;
/// One byte on an 8N1 line is 10 bits: ~1389 cycles at 115200 baud.
pub const CYCLES_PER_BYTE: u64 = FREQ_HZ * 10 / BAUD;

#[derive(Default)]
pub(crate) struct SerialLine {
    /// Everything transmitted since the last `take`.
    pub tx: Vec<u8>,
    /// Bytes for the firmware, not yet on the line.
    pub rx: VecDeque<u8>,
    /// simavr's receive FIFO has room and the receiver is on (XON seen, no
    /// XOFF since): bytes raised now are not lost.
    pub rx_ready: bool,
    /// Earliest cycle the next byte may start, one byte time after the last.
    pub next_rx_cycle: u64,
}

/// Start of the window to search after `seen` bytes were already searched
/// for a needle of `len` bytes: a match may straddle the old end.
pub(crate) fn resume_from(seen: usize, len: usize) -> usize {
    seen.saturating_sub(len.saturating_sub(1))
}

pub(crate) fn contains(hay: &[u8], needle: &[u8]) -> bool {
    needle.is_empty() || hay.windows(needle.len()).any(|w| w == needle)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_time() {
        assert_eq!(CYCLES_PER_BYTE, 1388);
    }

    #[test]
    fn incremental_search_finds_straddling_match() {
        let text = b"boot ok\r\n";
        let seen = 6; // "boot o" was searched already
        let from = resume_from(seen, 2);
        assert!(contains(&text[from..], b"ok"));
        assert!(!contains(&text[resume_from(9, 4)..], b"boot"));
    }
}
