//! The card on simavr's SPI bus. Every byte the MCU clocks through SPDR
//! reaches the card with the chip select level of that moment, and the
//! card's answer is put back into SPDR before the firmware can read it. With
//! no card in the slot MISO floats high: the MCU reads 0xFF.
//!
//! The slot is a simavr I/O module of its own, so it lives exactly as long
//! as the `avr_t`: simavr frees it in `avr_terminate` through `dealloc`.
//!
//! Insertions and removals planned for a later simulated time are applied
//! when the bus next carries a byte, and seen by `sd_card`/`sd_present`
//! as soon as they are due: only SPI traffic can observe the slot.
//!
//! Safety invariants:
//! - `SdIo` is leaked (simavr keeps writing to its `avr_io_t` after
//!   `dealloc`, ~100 bytes per simulation); its `slot` is a `Box<Slot>`
//!   freed in `dealloc`, after which simavr calls nothing of ours.
//! - `Slot::shared` is the simulation's `Shared`, freed after the `avr_t`.
//! - The callback runs only inside simavr calls made by `Sim`'s `&mut self`
//!   methods; no Rust reference into the slot lives across such a call.

use super::{SdCard, SdImage, SdStats};
use crate::clock::cycles_in;
use crate::hooks::Shared;
use crate::sim::{ioctl, Sim};
use simavr_ffi as ffi;
use std::ffi::CStr;
use std::os::raw::c_void;
use std::time::Duration;
use taut_logic::pinmap;

/// Names our I/O module; its address identifies it in simavr's list.
static KIND: &CStr = c"taut-sd";

#[repr(C)]
struct SdIo {
    /// First field: simavr links modules through it.
    io: ffi::avr_io_t,
    slot: *mut Slot,
}

struct Slot {
    shared: *mut Shared,
    cs: *mut ffi::avr_irq_t,
    spi_in: *mut ffi::avr_irq_t,
    card: Option<SdCard>,
    /// Planned insertions (`Some`) and removals (`None`), by cycle.
    plan: Vec<(u64, Option<SdCard>)>,
}

impl Slot {
    fn apply_due(&mut self, now: u64) {
        let due = self.plan.iter().take_while(|(at, _)| *at <= now).count();
        for (_, card) in self.plan.drain(..due) {
            self.card = card;
        }
    }

    /// The card in the slot at cycle `now`, plans included.
    fn card_at(&self, now: u64) -> Option<&SdCard> {
        match self.plan.iter().rev().find(|(at, _)| *at <= now) {
            Some((_, card)) => card.as_ref(),
            None => self.card.as_ref(),
        }
    }
}

impl From<SdImage> for SdCard {
    fn from(image: SdImage) -> SdCard {
        SdCard::new(image)
    }
}

/// # Safety
/// `param` is the live `Slot` of the simulation (module invariants).
unsafe extern "C" fn on_spi_byte(_irq: *mut ffi::avr_irq_t, mosi: u32, param: *mut c_void) {
    let slot = &mut *(param as *mut Slot);
    slot.apply_due((*slot.shared).now());
    let cs_low = (*slot.cs).value & 0xFF == 0;
    let miso = match slot.card.as_mut() {
        Some(card) => card.exchange(mosi as u8, cs_low),
        None => 0xFF,
    };
    // Writes SPDR; the reference into the slot is not used past this call.
    ffi::avr_raise_irq(slot.spi_in, u32::from(miso));
}

/// # Safety
/// Called once by simavr with our `SdIo` while terminating the `avr_t`.
unsafe extern "C" fn dealloc(io: *mut ffi::avr_io_t) {
    let sd = io as *mut SdIo;
    drop(Box::from_raw((*sd).slot));
    (*sd).slot = std::ptr::null_mut();
}

impl Sim {
    /// Puts a card (or a bare image, as a default card) in the slot now,
    /// replacing any card there. It starts powered but uninitialised.
    pub fn insert_sd(&mut self, card: impl Into<SdCard>) {
        self.sd_slot().card = Some(card.into());
    }

    /// Takes the card out now; it keeps what was written to it.
    pub fn remove_sd(&mut self) -> Option<SdCard> {
        let now = self.cycles();
        let slot = self.sd_slot();
        slot.apply_due(now);
        slot.card.take()
    }

    /// Plans an insertion at simulated time `at` since power-on.
    pub fn sd_insert_at(&mut self, at: Duration, card: impl Into<SdCard>) {
        self.plan_sd(at, Some(card.into()));
    }

    /// Plans a removal at simulated time `at` since power-on.
    pub fn sd_remove_at(&mut self, at: Duration) {
        self.plan_sd(at, None);
    }

    /// The card in the slot now (not one that pulled itself out).
    pub fn sd_present(&self) -> bool {
        self.sd_card().is_some_and(|card| !card.is_pulled())
    }

    /// The card in the slot now, even one that pulled itself out.
    pub fn sd_card(&self) -> Option<&SdCard> {
        // SAFETY: module invariants; `&self` rules out a running simavr call.
        let slot = unsafe { self.find_slot()?.as_ref()? };
        slot.card_at(self.cycles())
    }

    /// The card in the slot now, to inject faults or look at its image.
    pub fn sd_card_mut(&mut self) -> Option<&mut SdCard> {
        let now = self.cycles();
        let slot = self.sd_slot();
        slot.apply_due(now);
        slot.card.as_mut()
    }

    /// Counters of the card in the slot now.
    pub fn sd_stats(&self) -> Option<SdStats> {
        self.sd_card().map(|card| *card.stats())
    }

    fn plan_sd(&mut self, at: Duration, card: Option<SdCard>) {
        let at = cycles_in(at);
        let plan = &mut self.sd_slot().plan;
        let index = plan.partition_point(|(when, _)| *when <= at);
        plan.insert(index, (at, card));
    }

    /// Our slot module in simavr's list, if installed.
    fn find_slot(&self) -> Option<*mut Slot> {
        // SAFETY: the avr_t is live; its module list is only changed by
        // simavr during `avr_register_io` and teardown.
        unsafe {
            let mut io = (*self.avr.as_ptr()).io_port;
            while !io.is_null() {
                if (*io).kind == KIND.as_ptr() {
                    return Some((*(io as *mut SdIo)).slot);
                }
                io = (*io).next;
            }
        }
        None
    }

    /// The slot, installed on first use.
    fn sd_slot(&mut self) -> &mut Slot {
        let slot = self.find_slot().unwrap_or_else(|| self.install_slot());
        // SAFETY: module invariants; `&mut self` rules out a running callback.
        unsafe { &mut *slot }
    }

    fn install_slot(&mut self) -> *mut Slot {
        let avr = self.avr.as_ptr();
        let (port, bit) = pinmap::port_bit(pinmap::SD_CS);
        // SAFETY: the avr_t is live; ioctl queries have no side effect; the
        // module and slot outlive every callback (module invariants).
        unsafe {
            let spi = |n: u32| {
                // simavr names the ATmega2560's only SPI 0 (not '0').
                ffi::avr_io_getirq(avr, ioctl(b's', b'p', b'i', 0), n as i32)
            };
            let slot = Box::into_raw(Box::new(Slot {
                shared: self.shared.as_ptr(),
                cs: ffi::avr_io_getirq(
                    avr,
                    ioctl(b'i', b'o', b'g', port.letter() as u8),
                    bit as i32,
                ),
                spi_in: spi(ffi::SPI_IRQ_INPUT),
                card: None,
                plan: Vec::new(),
            }));
            assert!(!(*slot).cs.is_null() && !(*slot).spi_in.is_null());
            let io: &mut SdIo = Box::leak(Box::new(SdIo {
                io: std::mem::zeroed(),
                slot,
            }));
            io.io.kind = KIND.as_ptr();
            io.io.dealloc = Some(dealloc);
            ffi::avr_register_io(avr, &mut io.io);
            ffi::avr_irq_register_notify(
                spi(ffi::SPI_IRQ_OUTPUT),
                Some(on_spi_byte),
                slot as *mut c_void,
            );
            slot
        }
    }
}
