//! USART1 (D19 RX1, D18 TX1), the second console, for an HC-05/HC-06
//! Bluetooth module: 8N1 at `$uart1_baud` (9600, the modules' factory
//! rate, by default). The same rings and rules as USART0's (`usart`):
//! `RX1` filled by the receive interrupt, its last slot kept for a line's
//! end; `TX1` drained by the data-register-empty interrupt. No XON/XOFF:
//! a module has no use for it. Off on the string-art machine, whose
//! `zero_drill` button is on D18.

use super::usart::{keep, Outbox};
use crate::rt::byte;
use crate::rt::Ring;
use avr_device::atmega2560::USART1;
use core::sync::atomic::{AtomicBool, AtomicU8};
use taut_logic::settings::grbl::Uart1Baud;

/// Receive interrupt → console, as `usart::RX`: 64 bytes, the longest
/// line a sender types by hand or a job's, its last slot kept for a
/// line's end.
pub(super) static RX1: Ring<u8, 64, true> = Ring::new();
/// Tasks (through [`OUTBOX`]) → transmit interrupt: room for the longest
/// reply (`reply::ROOM`).
pub(super) static TX1: Ring<u8, 128> = Ring::new();

fn regs() -> &'static avr_device::atmega2560::usart1::RegisterBlock {
    // SAFETY: USART1 is configured by `configure` only, from a task;
    // otherwise only these interrupt-safe single-register accesses touch
    // it.
    unsafe { &*USART1::ptr() }
}

/// The port is on: its interrupts run and the console reads it.
static ON: AtomicBool = AtomicBool::new(false);

pub fn on() -> bool {
    byte::load_bool(&ON)
}

/// The rate set (a [`Uart1Baud`] code).
static RATE: AtomicU8 = AtomicU8::new(Uart1Baud::Off as u8);

/// At `baud` (with U2X, from the 16 MHz clock: 9600 −0.2 %, 38400
/// +0.2 %, 115200 +2.1 %), or off: the pins back to plain I/O (D18 is
/// the string-art machine's `zero_drill` button). At power-on and on
/// Ctrl-X. A new rate drops the bytes not yet read or sent.
pub fn configure(baud: Uart1Baud) {
    // Tasks only (no swap on the AVR).
    if byte::load(&RATE) == baud as u8 {
        return;
    }
    byte::store(&RATE, baud as u8);
    let ubrr = match baud {
        Uart1Baud::Off => None,
        Uart1Baud::B9600 => Some(207),
        Uart1Baud::B38400 => Some(51),
        Uart1Baud::B115200 => Some(16),
    };
    let r = regs();
    avr_device::interrupt::free(|_| {
        r.ucsr1b().write(|w| w);
        RX1.clear();
        TX1.clear();
        byte::store_bool(&CUT, false);
        byte::store_bool(&ON, ubrr.is_some());
        if let Some(ubrr) = ubrr {
            r.ubrr1().write(|w| w.set(ubrr));
            r.ucsr1a().write(|w| w.u2x1().set_bit());
            r.ucsr1c().write(|w| w.ucsz1().chr8());
            r.ucsr1b()
                .write(|w| w.txen1().set_bit().rxen1().set_bit().rxcie1().set_bit());
        }
    });
}

/// Queue bytes for sending; all or nothing (false: no room, or the port
/// is off).
#[inline(never)]
pub fn send(bytes: &[u8]) -> bool {
    let ok = on() && OUTBOX.send(bytes);
    if ok {
        wake();
    }
    ok
}

/// The next received byte for the console.
pub fn receive() -> Option<u8> {
    RX1.pop()
}

fn wake() {
    avr_device::interrupt::free(|_| regs().ucsr1b().modify(|_, w| w.udrie1().set_bit()));
}

/// `TX1`'s staging (`usart::Outbox`).
pub static OUTBOX: Outbox = Outbox::new(&TX1);

/// Queue what line `owner` staged in `TX1`, unless the port is off.
#[inline(never)]
pub fn publish(owner: u8, n: usize, lost: bool) -> bool {
    let ok = OUTBOX.publish(owner, n, lost || !on());
    if ok {
        wake();
    }
    ok
}

/// USART1 control register B and its interrupt-enable bits (`rt::nested`).
pub const UCSR1B: u16 = 0xC9;
pub const RXCIE1: u8 = 7;
pub const UDRIE1: u8 = 5;

/// The `USART1_UDRE` handler, entered with its interrupt switched off.
pub fn on_data_register_empty() {
    if let Some(b) = TX1.pop() {
        // SAFETY: UDR1 takes any byte.
        regs().udr1().write(|w| unsafe { w.bits(b) });
        if !TX1.is_empty() {
            avr_device::interrupt::free(|_| regs().ucsr1b().modify(|_, w| w.udrie1().set_bit()));
        }
    }
}

/// A line lost bytes to a full `RX1` (`usart::keep`).
static CUT: AtomicBool = AtomicBool::new(false);

/// The `USART1_RX` handler, entered with its interrupt switched off: the
/// byte goes to `take` (real-time commands), or when it declines, into
/// `RX1`. Returns what `take` said.
pub fn on_receive(take: impl FnOnce(u8) -> bool) -> bool {
    let b = regs().udr1().read().bits();
    let taken = take(b);
    if !taken {
        keep(&RX1, &CUT, b);
    }
    avr_device::interrupt::free(|_| regs().ucsr1b().modify(|_, w| w.rxcie1().set_bit()));
    taken
}
