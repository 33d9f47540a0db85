//! USART0, the serial console: 115200 8N1. Transmit goes through a 256-byte
//! ring drained by the data-register-empty interrupt, so writing never waits
//! for the wire; received bytes go into a 64-byte ring filled by the receive
//! interrupt. Each ring has one producer and one consumer and byte-sized
//! indices, which the AVR loads and stores atomically: no locking needed.

use avr_device::atmega2560::USART0;
use core::cell::UnsafeCell;
use core::sync::atomic::{AtomicU16, AtomicU8, Ordering::Relaxed};

/// A single-producer single-consumer byte ring of 2^k ≤ 256 bytes.
pub struct ByteRing<const N: usize> {
    buf: UnsafeCell<[u8; N]>,
    head: AtomicU8,
    tail: AtomicU8,
}

// SAFETY: the producer only writes `buf[head]` then publishes `head`; the
// consumer only reads `buf[tail]` then publishes `tail`; the slots they touch
// never overlap, and index stores are single-byte (atomic on AVR).
unsafe impl<const N: usize> Sync for ByteRing<N> {}

impl<const N: usize> ByteRing<N> {
    const MASK: u8 = (N - 1) as u8;

    pub const fn new() -> Self {
        assert!(N.is_power_of_two() && N <= 256);
        ByteRing { buf: UnsafeCell::new([0; N]), head: AtomicU8::new(0), tail: AtomicU8::new(0) }
    }

    pub fn len(&self) -> usize {
        let used = self.head.load(Relaxed).wrapping_sub(self.tail.load(Relaxed)) & Self::MASK;
        used as usize
    }

    /// Free slots (one slot stays empty to tell full from empty).
    pub fn free(&self) -> usize {
        N - 1 - self.len()
    }

    /// Producer side: append all of `bytes` or nothing.
    pub fn push_all(&self, bytes: &[u8]) -> bool {
        if bytes.len() > self.free() {
            return false;
        }
        let mut h = self.head.load(Relaxed);
        for &b in bytes {
            // SAFETY: slot `h` is free (checked above), owned by the producer.
            unsafe { (*self.buf.get())[(h & Self::MASK) as usize] = b };
            h = h.wrapping_add(1) & Self::MASK;
        }
        core::sync::atomic::compiler_fence(core::sync::atomic::Ordering::Release);
        self.head.store(h, Relaxed);
        true
    }

    /// Consumer side.
    pub fn pop(&self) -> Option<u8> {
        let t = self.tail.load(Relaxed);
        if t == self.head.load(Relaxed) {
            return None;
        }
        core::sync::atomic::compiler_fence(core::sync::atomic::Ordering::Acquire);
        // SAFETY: slot `t` was published by the producer and is ours to read.
        let b = unsafe { (*self.buf.get())[t as usize] };
        self.tail.store(t.wrapping_add(1) & Self::MASK, Relaxed);
        Some(b)
    }
}

pub static TX: ByteRing<256> = ByteRing::new();
pub static RX: ByteRing<64> = ByteRing::new();
/// Received bytes lost because RX was full (reported by `$Q`).
pub static RX_OVERRUNS: AtomicU16 = AtomicU16::new(0);

pub struct Usart0;

impl Usart0 {
    /// 115200 baud with U2X: UBRR = 16 gives 117 647 baud (+2.1 %), the
    /// Arduino core's choice, which every USB-serial bridge accepts.
    pub fn start(usart: USART0) -> Usart0 {
        usart.ubrr0().write(|w| w.set(16));
        usart.ucsr0a().write(|w| w.u2x0().set_bit());
        usart.ucsr0c().write(|w| w.ucsz0().chr8());
        usart.ucsr0b().write(|w| w.txen0().set_bit().rxen0().set_bit().rxcie0().set_bit());
        Usart0
    }
}

fn regs() -> &'static avr_device::atmega2560::usart0::RegisterBlock {
    // SAFETY: USART0 is configured once by `Usart0::start`; afterwards only
    // these interrupt-safe single-register accesses touch it.
    unsafe { &*USART0::ptr() }
}

/// Queue bytes for sending; all or nothing. Returns false when the ring is full.
pub fn send(bytes: &[u8]) -> bool {
    let ok = TX.push_all(bytes);
    if ok {
        // Data-register-empty interrupt on: it drains the ring and turns
        // itself off when the ring is empty. Set atomically with the ISR.
        avr_device::interrupt::free(|_| regs().ucsr0b().modify(|_, w| w.udrie0().set_bit()));
    }
    ok
}

/// Bytes queued for sending and not yet on the wire.
pub fn tx_pending() -> usize {
    TX.len()
}

/// Called by `USART0_UDRE`.
pub fn on_data_register_empty() {
    match TX.pop() {
        Some(b) => {
            regs().udr0().write(|w| unsafe { w.bits(b) });
        }
        None => {
            regs().ucsr0b().modify(|_, w| w.udrie0().clear_bit());
        }
    }
}

/// Called by `USART0_RX`.
pub fn on_receive() {
    let b = regs().udr0().read().bits();
    if !RX.push_all(&[b]) {
        RX_OVERRUNS.store(RX_OVERRUNS.load(Relaxed).saturating_add(1), Relaxed);
    }
}
