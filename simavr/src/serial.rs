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
    /// Bytes raised into simavr's receive FIFO since it was last empty: at
    /// most [`FIFO_BYTES`], the AVR's own receive buffer. simavr's FIFO
    /// (64 bytes) is drained at 11 bits a byte (it counts a parity bit
    /// that 8N1 has not), slower than the line's 10: left to fill, it
    /// would hold bytes a real line never holds, which a flow control
    /// stop (XOFF) could not hold back.
    pub in_fifo: u8,
    /// Earliest cycle the next byte may start, one byte time after the last.
    pub next_rx_cycle: u64,
    /// Bytes planned for later cycles, earliest first.
    planned: Vec<(u64, Vec<u8>)>,
    /// The host side honours XON/XOFF (software flow control: a tty with
    /// `IXON` behind a USB-serial chip that stops at once, as an FTDI
    /// does once its driver is told): after an XOFF from the firmware no
    /// byte starts until an XON.
    pub honour_xoff: bool,
    /// The firmware's last flow byte was XOFF.
    pub xoff: bool,
}

/// Bytes of simavr's receive FIFO in use at most: UDR and the byte
/// behind it, as an ATmega's USART holds.
pub const FIFO_BYTES: u8 = 2;

/// Software flow control's bytes (DC1, DC3).
pub const XON: u8 = 0x11;
pub const XOFF: u8 = 0x13;

impl SerialLine {
    /// Whether a byte for the firmware may start now: the host is not
    /// paused by an XOFF it honours.
    pub fn flowing(&self) -> bool {
        !(self.honour_xoff && self.xoff)
    }
}

impl SerialLine {
    /// Plans `bytes` for cycle `at`, after bytes already planned for then.
    pub fn plan(&mut self, at: u64, bytes: &[u8]) {
        let index = self.planned.partition_point(|(when, _)| *when <= at);
        self.planned.insert(index, (at, bytes.to_vec()));
    }

    /// Puts the planned bytes due by `now` on the line ahead of the bytes
    /// still queued, as a sender slips its real-time commands into a
    /// stream; returns the cycle of the next planned bytes.
    pub fn release_due(&mut self, now: u64) -> Option<u64> {
        let due = self.planned.partition_point(|(at, _)| *at <= now);
        for (_, bytes) in self.planned.drain(..due).rev() {
            for &b in bytes.iter().rev() {
                self.rx.push_front(b);
            }
        }
        self.planned.first().map(|(at, _)| *at)
    }
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
    fn planned_bytes_go_ahead_of_queued_ones_when_due() {
        let mut line = SerialLine::default();
        line.rx.extend(b"G1 X5\n");
        line.plan(200, b"~");
        line.plan(100, b"!");
        line.plan(100, b"?");
        assert_eq!(line.release_due(99), Some(100));
        assert_eq!(line.rx, b"G1 X5\n");
        line.rx.pop_front();
        assert_eq!(line.release_due(150), Some(200));
        assert_eq!(line.rx, b"!?1 X5\n");
        assert_eq!(line.release_due(200), None);
        assert_eq!(line.rx, b"~!?1 X5\n");
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
