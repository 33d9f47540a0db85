//! USART0, the serial console: 115200 8N1. Transmit goes through the `TX`
//! ring drained by the data-register-empty interrupt, so writing never waits
//! for the wire; received bytes go into the `RX` ring, filled by the receive
//! interrupt (`queues`). With `$flow=xonxoff` the receive side sends XOFF
//! when `RX` holds [`XOFF_AT`] bytes and XON once it is down to
//! [`XON_AT`], each ahead of the bytes waiting in `TX`.

use crate::rt::byte;
use crate::rt::Ring;
use avr_device::atmega2560::USART0;
use core::sync::atomic::{AtomicBool, AtomicU8};
use taut_logic::gcode::LINE_CUT;

/// Receive interrupt → console: line bytes (real-time commands are taken
/// out before). 128 bytes, Grbl's buffer, every one usable: what senders
/// count characters against (CNCjs 120, UGS and grbl-streamer 128, all of
/// it unread when the console has not begun the next line). Full: the
/// byte is lost and counted (the sender ignored flow control). The board's
/// only: the console reads it through `Port`.
pub(super) static RX: Ring<u8, 128, true> = Ring::new();
/// Tasks (through [`OUTBOX`]) → transmit interrupt. Replies wait for room;
/// a log line without room is dropped whole and counted.
pub(super) static TX: Ring<u8, 128> = Ring::new();

pub struct Usart0;

impl Usart0 {
    /// 115200 baud with U2X: UBRR = 16 gives 117 647 baud (+2.1 %), the
    /// Arduino core's choice, which every USB-serial bridge accepts.
    pub fn start(usart: USART0) -> Usart0 {
        usart.ubrr0().write(|w| w.set(16));
        usart.ucsr0a().write(|w| w.u2x0().set_bit());
        usart.ucsr0c().write(|w| w.ucsz0().chr8());
        usart
            .ucsr0b()
            .write(|w| w.txen0().set_bit().rxen0().set_bit().rxcie0().set_bit());
        Usart0
    }
}

fn regs() -> &'static avr_device::atmega2560::usart0::RegisterBlock {
    // SAFETY: USART0 is configured once by `Usart0::start`; afterwards only
    // these interrupt-safe single-register accesses touch it.
    unsafe { &*USART0::ptr() }
}

/// Queue bytes for sending; all or nothing. Returns false when the ring is
/// full. A line being staged loses its slots (`Outbox::stage`).
#[inline(never)]
pub fn send(bytes: &[u8]) -> bool {
    let ok = OUTBOX.send(bytes);
    if ok {
        wake();
    }
    ok
}

/// XON/XOFF flow control (`$flow=xonxoff`): the [`FLOW_ON`],
/// [`FLOW_STOPPED`] and [`FLOW_DUE`] bits.
static FLOW: AtomicU8 = AtomicU8::new(0);
/// Flow control is on.
const FLOW_ON: u8 = 1;
/// XOFF is sent or due: the sender is to pause.
const FLOW_STOPPED: u8 = 2;
/// The byte of the state (XOFF when stopped, else XON) goes out next,
/// ahead of `TX`'s.
const FLOW_DUE: u8 = 4;
pub const XON: u8 = 0x11;
pub const XOFF: u8 = 0x13;
/// `RX` bytes at which XOFF goes out: the 32 still free take the bytes
/// already on the wire (2.8 ms at 115200 baud: the byte being sent
/// before the XOFF, the XOFF itself, the sender's reaction).
pub const XOFF_AT: usize = 96;
/// `RX` bytes at which XON goes out again (Grbl 0.8's figures, 96 and
/// 64 of 128).
pub const XON_AT: usize = 64;

/// `$flow`: XON/XOFF on or off; switched off while the sender is
/// paused, XON releases it.
pub fn set_xonxoff(on: bool) {
    avr_device::interrupt::free(|_| {
        let f = byte::load(&FLOW);
        let f = match on {
            true => f | FLOW_ON,
            false if f & FLOW_STOPPED != 0 => FLOW_DUE,
            false => f & FLOW_DUE,
        };
        byte::store(&FLOW, f);
    });
    wake();
}

/// At power-on with flow control on: XON, which lets a sender go on
/// that the board paused before it was reset.
pub fn release_sender() {
    if byte::load(&FLOW) & FLOW_ON != 0 {
        byte::store(&FLOW, FLOW_ON | FLOW_DUE);
        wake();
    }
}

/// Pause the sender (`stop`) or let it go on, if flow control is on and
/// it is not so already.
fn flow_to(stop: bool) {
    let changed = avr_device::interrupt::free(|_| {
        let f = byte::load(&FLOW);
        if f & FLOW_ON == 0 || (f & FLOW_STOPPED != 0) == stop {
            return false;
        }
        let stopped = if stop { FLOW_STOPPED } else { 0 };
        byte::store(&FLOW, f & !FLOW_STOPPED | stopped | FLOW_DUE);
        true
    });
    if changed {
        wake();
    }
}

/// The next received byte for the console; XON once `RX` has room again.
pub fn receive() -> Option<u8> {
    let b = RX.pop();
    if byte::load(&FLOW) & FLOW_STOPPED != 0 && RX.len() <= XON_AT {
        flow_to(false);
    }
    b
}

/// Ctrl-X: the bytes not yet read are dropped; a paused sender goes on.
/// A line being cut stays so: its rest never runs as a line of its own.
pub fn clear_input() {
    RX.clear();
    flow_to(false);
}

/// The flow byte due, taken.
fn flow_byte() -> Option<u8> {
    avr_device::interrupt::free(|_| {
        let f = byte::load(&FLOW);
        if f & FLOW_DUE == 0 {
            return None;
        }
        byte::store(&FLOW, f & !FLOW_DUE);
        Some(if f & FLOW_STOPPED != 0 { XOFF } else { XON })
    })
}

/// Data-register-empty interrupt on: it drains the ring and turns itself
/// off when the ring is empty. Set atomically with the ISR.
fn wake() {
    avr_device::interrupt::free(|_| regs().ucsr0b().modify(|_, w| w.udrie0().set_bit()));
}

/// A transmit ring and the number of the line staged in its free slots:
/// bumped by every line begun, sent or queued. Tasks only.
pub struct Outbox {
    ring: &'static Ring<u8, 128>,
    staging: AtomicU8,
}

/// `TX`'s.
pub static OUTBOX: Outbox = Outbox::new(&TX);

impl Outbox {
    pub const fn new(ring: &'static Ring<u8, 128>) -> Outbox {
        Outbox {
            ring,
            staging: AtomicU8::new(0),
        }
    }

    /// The ring's free slots are now the new line's: its number.
    pub fn begin_staging(&self) -> u8 {
        let n = byte::load(&self.staging).wrapping_add(1);
        byte::store(&self.staging, n);
        n
    }

    /// Stage the `n` bytes of `bytes` as bytes `k`… of line `owner`
    /// (`Ring::stage`): false if not all fit (those that do are written)
    /// or the slots are no longer the line's (none is).
    #[inline(always)]
    pub fn stage(&self, owner: u8, k: u8, n: u8, bytes: impl Iterator<Item = u8>) -> bool {
        owner == byte::load(&self.staging) && self.ring.stage(k, n, bytes)
    }

    /// Queue the `n` bytes line `owner` staged, unless it `lost` some or
    /// its slots (refused, then): whether it did (the caller wakes its
    /// transmitter).
    pub fn publish(&self, owner: u8, n: usize, lost: bool) -> bool {
        let current = byte::load(&self.staging);
        // Queued, the slots are no longer the line's.
        self.begin_staging();
        if lost || owner != current {
            self.ring.refuse();
            return false;
        }
        self.ring.publish(n);
        true
    }

    /// Queue bytes, all or nothing; a line being staged loses its slots.
    pub fn send(&self, bytes: &[u8]) -> bool {
        self.begin_staging();
        self.ring.push_all(bytes)
    }
}

/// Queue what line `owner` staged in `TX` (`Outbox::publish`).
#[inline(never)]
pub fn publish(owner: u8, n: usize, lost: bool) -> bool {
    let ok = OUTBOX.publish(owner, n, lost);
    if ok {
        wake();
    }
    ok
}

/// USART0 control register B and its interrupt-enable bits, for the
/// nestable entry (`rt::nested`), which clears the enable before `sei`.
pub const UCSR0B: u16 = 0xC1;
pub const RXCIE0: u8 = 7;
pub const UDRIE0: u8 = 5;

/// The `USART0_UDRE` handler, entered with its interrupt switched off:
/// send one byte, and switch it back on while more are waiting.
pub fn on_data_register_empty() {
    if let Some(b) = flow_byte().or_else(|| TX.pop()) {
        // SAFETY: UDR0 takes any byte.
        regs().udr0().write(|w| unsafe { w.bits(b) });
        if !TX.is_empty() || byte::load(&FLOW) & FLOW_DUE != 0 {
            avr_device::interrupt::free(|_| regs().ucsr0b().modify(|_, w| w.udrie0().set_bit()));
        }
    }
}

/// A line lost bytes to a full `RX`: the rest of it is dropped, and its
/// end goes in as [`LINE_CUT`]. Written by the receive interrupt only.
static CUT: AtomicBool = AtomicBool::new(false);

/// A received byte into `rx`, `cut` its line's state (each port's own).
/// The last slot is kept for a line's end, so however long a line,
/// however late the console reads (power-on homing), every line ends in
/// the ring and gets its reply: a line that lost bytes (a sender
/// ignoring the count or the flow control) ends in [`LINE_CUT`],
/// answered `error:11`. Each lost byte is counted.
pub(super) fn keep<const N: usize>(rx: &Ring<u8, N, true>, cut: &AtomicBool, b: u8) {
    let was_cut = byte::load_bool(cut);
    if b == b'\n' || b == b'\r' {
        // While the console is behind by a whole line the end finds no
        // room: the next line is then dropped with this one.
        if rx.push_inlined(if was_cut { LINE_CUT } else { b }).is_ok() {
            byte::store_bool(cut, false);
        }
        return;
    }
    // No 0xFF from the wire is taken for the marker (Grbl drops every
    // extended byte that is no real-time command).
    if was_cut || b == LINE_CUT || rx.free() <= 1 {
        byte::store_bool(cut, was_cut || b != LINE_CUT);
        rx.refuse();
        return;
    }
    let _ = rx.push_inlined(b);
}

/// The `USART0_RX` handler, entered with its interrupt switched off: the
/// byte goes to `take` (real-time commands), or when it declines, into
/// `RX`. Returns what `take` said.
pub fn on_receive(take: impl FnOnce(u8) -> bool) -> bool {
    let b = regs().udr0().read().bits();
    let taken = take(b);
    if !taken {
        keep(&RX, &CUT, b);
        if byte::load(&FLOW) & FLOW_ON != 0 && RX.len() >= XOFF_AT {
            flow_to(true);
        }
    }
    avr_device::interrupt::free(|_| regs().ucsr0b().modify(|_, w| w.rxcie0().set_bit()));
    taken
}
