//! USART0 as the host sees it: bytes the firmware sent, and bytes waiting to
//! be received, fed at the pace of a 115200 8N1 line; USART1 (the second
//! console, `uart1_…`) the same at the rate its UBRR1 makes.

use crate::clock::cycles_in;
use crate::sim::Sim;
use std::time::Duration;

pub use crate::serial::{BAUD, CYCLES_PER_BYTE};

impl Sim {
    /// Bytes USART0 transmitted since the last `take_uart`.
    pub fn uart_bytes(&self) -> &[u8] {
        &self.shared().uart.tx
    }

    /// The transmitted bytes as text (invalid UTF-8 shown as U+FFFD).
    pub fn uart_text(&self) -> String {
        String::from_utf8_lossy(self.uart_bytes()).into_owned()
    }

    /// The bytes transmitted from byte `from` on, as text.
    pub fn uart_text_from(&self, from: usize) -> String {
        String::from_utf8_lossy(&self.uart_bytes()[from..]).into_owned()
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

    /// Plans bytes for USART0 at simulated time `at` since power-on, sent
    /// whatever the firmware says: when due they go on the line ahead of
    /// bytes still queued (even mid-line), as a G-code sender slips in its
    /// real-time commands (`?`, `!`, `~`, Ctrl-X), then one per byte time.
    pub fn uart_send_at(&mut self, at: Duration, bytes: &[u8]) {
        self.shared_mut().uart.plan(cycles_in(at), bytes);
    }

    /// Whether the host side honours the firmware's XOFF and XON (a tty
    /// with `IXON`): bytes waiting to be sent then wait while it is off.
    pub fn set_uart_xonxoff(&mut self, on: bool) {
        self.shared_mut().uart.honour_xoff = on;
    }

    /// Bytes queued by `uart_send` (or planned and due) not yet delivered.
    pub fn uart_pending(&self) -> usize {
        self.shared().uart.rx.len()
    }

    /// Bytes USART1 transmitted since the last `take_uart1`.
    pub fn uart1_bytes(&self) -> &[u8] {
        &self.shared().uart1.tx
    }

    /// USART1's transmitted bytes as text.
    pub fn uart1_text(&self) -> String {
        String::from_utf8_lossy(self.uart1_bytes()).into_owned()
    }

    /// USART1's transmitted text, clearing the capture.
    pub fn take_uart1(&mut self) -> String {
        let bytes = std::mem::take(&mut self.shared_mut().uart1.tx);
        String::from_utf8_lossy(&bytes).into_owned()
    }

    /// Queues bytes for USART1 to receive, one per byte time at the rate
    /// the firmware set (UBRR1), as [`Sim::uart_send`].
    pub fn uart1_send(&mut self, bytes: &[u8]) {
        self.shared_mut().uart1.rx.extend(bytes);
    }

    /// Plans bytes for USART1 at simulated time `at`, as
    /// [`Sim::uart_send_at`].
    pub fn uart1_send_at(&mut self, at: Duration, bytes: &[u8]) {
        self.shared_mut().uart1.plan(cycles_in(at), bytes);
    }

    /// Bytes queued for USART1 not yet delivered.
    pub fn uart1_pending(&self) -> usize {
        self.shared().uart1.rx.len()
    }

    /// USART1's byte time (8N1) at the rate the firmware set, in cycles.
    pub fn uart1_byte_cycles(&self) -> u64 {
        self.uart1_cycles_per_byte()
    }
}
