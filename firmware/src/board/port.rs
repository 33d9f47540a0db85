//! The two consoles' serial ports: USB (USART0) and UART1 (a Bluetooth
//! module). A line is answered on the port it came from; log lines go to
//! USB only.

use super::usart::{self, Outbox, RX, TX};
use super::usart1::{self, RX1, TX1};
use crate::rt::byte;
use core::sync::atomic::AtomicU8;
use taut_logic::gcode::LINE_CUT;
use taut_logic::sched::QueueStats;

#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Port {
    Usb = 0,
    Uart1 = 1,
}

/// The port the console reads its line from and answers on: set when a
/// line begins (tasks only; they never preempt each other).
static ANSWER: AtomicU8 = AtomicU8::new(Port::Usb as u8);

/// The port of the line being read or answered.
pub fn answer() -> Port {
    match byte::load(&ANSWER) {
        0 => Port::Usb,
        _ => Port::Uart1,
    }
}

/// USB starts a line before its end has come once its ring is this full:
/// a line longer than the ring (a long comment) is read as it comes.
const USB_EARLY: usize = 64;

/// Between lines: the port whose line is read next, now the one
/// answered. A port whose whole line waits (its end, or `LINE_CUT`, is
/// in the ring), taking turns when both have one: a line half typed on
/// one port never mixes with the other's. With UART1 off, USB's bytes
/// are read as they come.
pub fn next_line() -> Option<Port> {
    let bt = usart1::on() && line_waits(&RX1);
    let usb = match usart1::on() {
        true => line_waits(&RX) || RX.len() >= USB_EARLY,
        false => !RX.is_empty(),
    };
    let port = match (usb, bt) {
        (true, true) if answer() == Port::Usb => Port::Uart1,
        (true, _) => Port::Usb,
        (false, true) => Port::Uart1,
        (false, false) => return None,
    };
    byte::store(&ANSWER, port as u8);
    Some(port)
}

/// A whole line waits on either port.
pub fn any_line_waits() -> bool {
    line_waits(&RX) || usart1::on() && line_waits(&RX1)
}

fn line_waits<const N: usize>(rx: &crate::rt::Ring<u8, N, true>) -> bool {
    rx.any(|&b| b == b'\n' || b == b'\r' || b == LINE_CUT)
}

impl Port {
    /// The ports on: USB, and UART1 if it is.
    pub fn each(mut f: impl FnMut(Port)) {
        f(Port::Usb);
        if usart1::on() {
            f(Port::Uart1);
        }
    }

    /// The next byte of the line being read from this port.
    pub fn receive(self) -> Option<u8> {
        match self {
            Port::Usb => usart::receive(),
            Port::Uart1 => usart1::receive(),
        }
    }

    /// Its receive ring's size (`$I`'s `[OPT:…]`: what a sender counts
    /// characters against).
    pub fn rx_capacity(self) -> usize {
        match self {
            Port::Usb => RX.capacity(),
            Port::Uart1 => RX1.capacity(),
        }
    }

    /// Bytes waiting in its receive ring.
    pub fn rx_len(self) -> usize {
        match self {
            Port::Usb => RX.len(),
            Port::Uart1 => RX1.len(),
        }
    }

    /// Free bytes of its receive ring (the status report's `Bf:`).
    pub fn rx_free(self) -> usize {
        match self {
            Port::Usb => RX.free(),
            Port::Uart1 => RX1.free(),
        }
    }

    /// Its receive ring's counts (`$Q`).
    pub fn rx_stats(self) -> QueueStats {
        match self {
            Port::Usb => RX.stats(),
            Port::Uart1 => RX1.stats(),
        }
    }

    /// Its transmit ring's counts and size (`$Q`).
    pub fn tx_stats(self) -> (QueueStats, usize) {
        match self {
            Port::Usb => (TX.stats(), TX.capacity()),
            Port::Uart1 => (TX1.stats(), TX1.capacity()),
        }
    }

    /// Free bytes of its transmit ring.
    pub fn tx_free(self) -> usize {
        match self {
            Port::Usb => TX.free(),
            Port::Uart1 => TX1.free(),
        }
    }

    /// Queue bytes; all or nothing (`usart::send`).
    pub fn send(self, bytes: &[u8]) -> bool {
        match self {
            Port::Usb => usart::send(bytes),
            Port::Uart1 => usart1::send(bytes),
        }
    }

    /// Its transmit ring and the line staged there (`Line`). Inlined: a
    /// choice of two addresses at each byte a line stages.
    #[inline(always)]
    pub fn outbox(self) -> &'static Outbox {
        match self {
            Port::Usb => &usart::OUTBOX,
            Port::Uart1 => &usart1::OUTBOX,
        }
    }

    pub fn publish(self, owner: u8, n: usize, lost: bool) -> bool {
        match self {
            Port::Usb => usart::publish(owner, n, lost),
            Port::Uart1 => usart1::publish(owner, n, lost),
        }
    }
}

/// Ctrl-X: the bytes not yet read on both ports are dropped.
pub fn clear_input() {
    usart::clear_input();
    RX1.clear();
}
