//! USART0 as the host sees it: bytes the firmware sent, and bytes waiting to
//! be received, fed at the pace of a 115200 8N1 line.

use crate::clock::FREQ_HZ;
use crate::sim::Sim;
use std::collections::VecDeque;

/// Line rate of the host side.
pub const BAUD: u64 = 115_200;
/// One byte on an 8N1 line is 10 bits: ~1389 cycles at 115200 baud.
pub const CYCLES_PER_BYTE: u64 = FREQ_HZ * 10 / BAUD;

#[derive(Default)]
pub(crate) struct Uart {
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

impl Sim {
    /// Bytes USART0 transmitted since the last `take_uart`.
    pub fn uart_bytes(&self) -> &[u8] {
        &self.shared().uart.tx
    }

    /// The transmitted bytes as text (invalid UTF-8 shown as U+FFFD).
    pub fn uart_text(&self) -> String {
        String::from_utf8_lossy(self.uart_bytes()).into_owned()
    }

    /// The transmitted text, clearing the capture.
    pub fn take_uart(&mut self) -> String {
        let bytes = std::mem::take(&mut self.shared_mut().uart.tx);
        String::from_utf8_lossy(&bytes).into_owned()
    }

    /// Queues bytes for USART0 to receive, one per byte time of a 115200 8N1
    /// line, each only while the receiver is on and its FIFO has room.
    pub fn uart_send(&mut self, bytes: &[u8]) {
        self.shared_mut().uart.rx.extend(bytes);
    }

    /// Bytes queued by `uart_send` not yet delivered.
    pub fn uart_pending(&self) -> usize {
        self.shared().uart.rx.len()
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
    fn incremental_search_finds_straddling_match() {
        let text = b"boot ok\r\n";
        let seen = 6; // "boot o" was searched already
        let from = resume_from(seen, 2);
        assert!(contains(&text[from..], b"ok"));
        assert!(!contains(&text[resume_from(9, 4)..], b"boot"));
    }
}
