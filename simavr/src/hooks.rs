//! The state simavr's callbacks write into, and the callbacks themselves.
//!
//! Invariants (upheld by `Sim`):
//! - `Shared` lives in one heap allocation that does not move and outlives the
//!   `avr_t` (it is freed after `avr_terminate`), so the `param` pointers
//!   handed to simavr stay valid for every callback.
//! - Callbacks run only inside simavr calls made by `Sim`'s `&mut self`
//!   methods (`avr_run`, `avr_raise_irq`, `avr_ioctl`), on the thread that
//!   owns the `Sim`, and no Rust reference into `Shared` is alive across
//!   such a call, so each callback's `&mut Shared` is the only one.
//! - The raw pointers in `Shared` (the `avr_t`, the SD slot's IRQs) point
//!   into that same `avr_t` and are private here: other modules reach
//!   `Shared`'s plain data only.

use crate::probe::Probe;
use crate::sdcard::slot::Slot;
use crate::serial::SerialLine;
use simavr_ffi::{avr_irq_t, avr_t};
use std::os::raw::c_void;

pub(crate) struct Shared {
    avr: *mut avr_t,
    /// Cycles run before the last reset (simavr zeroes its counter on reset).
    pub cycle_base: u64,
    /// Bumped by every callback: tells the run loop something happened.
    pub events: u64,
    pub probes: Vec<Probe>,
    pub uart: SerialLine,
    /// Address of the first invalid opcode executed.
    pub bad_opcode_pc: Option<u32>,
    /// The SD card slot: what answers the SPI bytes once it is wired.
    pub sd: Slot,
    /// The slot's wires, once connected.
    spi: Option<SpiWires>,
}

/// simavr's IRQs the SD card slot reads and writes.
#[derive(Clone, Copy)]
pub(crate) struct SpiWires {
    /// The chip select pin's level.
    pub cs: *mut avr_irq_t,
    /// SPI input: what the card drives on MISO lands in SPDR.
    pub miso: *mut avr_irq_t,
}

impl Shared {
    pub fn new(avr: *mut avr_t) -> Shared {
        Shared {
            avr,
            cycle_base: 0,
            events: 0,
            probes: Vec::new(),
            uart: SerialLine::default(),
            bad_opcode_pc: None,
            sd: Slot::default(),
            spi: None,
        }
    }

    /// The SD slot is wired to the SPI bus.
    pub fn spi_wired(&self) -> bool {
        self.spi.is_some()
    }

    pub fn wire_spi(&mut self, wires: SpiWires) {
        self.spi = Some(wires);
    }

    /// Cycles since power-on, across resets.
    pub fn now(&self) -> u64 {
        // SAFETY: `avr` is valid while `Shared` is reachable (see module doc).
        self.cycle_base + unsafe { (*self.avr).cycle }
    }
}

/// Parameter of a pin callback: which probe of which `Shared`.
pub(crate) struct PinHook {
    pub shared: *mut Shared,
    pub probe: usize,
}

/// # Safety
/// `param` is a live `PinHook` whose `shared` obeys the module invariants.
pub(crate) unsafe extern "C" fn on_pin(_irq: *mut avr_irq_t, value: u32, param: *mut c_void) {
    let hook = &*(param as *const PinHook);
    let shared = &mut *hook.shared;
    let now = shared.now();
    shared.probes[hook.probe].record(now, value & 0xff != 0);
    shared.events += 1;
}

/// # Safety
/// `param` is the `Shared` of the simulation (module invariants).
pub(crate) unsafe extern "C" fn on_uart_tx(_irq: *mut avr_irq_t, value: u32, param: *mut c_void) {
    let shared = &mut *(param as *mut Shared);
    shared.uart.tx.push(value as u8);
    shared.events += 1;
}

/// # Safety
/// As `on_uart_tx`.
pub(crate) unsafe extern "C" fn on_uart_xon(_irq: *mut avr_irq_t, value: u32, param: *mut c_void) {
    let shared = &mut *(param as *mut Shared);
    if value != 0 && !shared.uart.rx_ready {
        shared.uart.rx_ready = true;
        shared.events += 1;
    }
}

/// # Safety
/// As `on_uart_tx`.
pub(crate) unsafe extern "C" fn on_uart_xoff(_irq: *mut avr_irq_t, value: u32, param: *mut c_void) {
    let shared = &mut *(param as *mut Shared);
    if value != 0 {
        shared.uart.rx_ready = false;
    }
}

/// # Safety
/// As `on_uart_tx`.
pub(crate) unsafe extern "C" fn on_bad_opcode(_irq: *mut avr_irq_t, _op: u32, param: *mut c_void) {
    let shared = &mut *(param as *mut Shared);
    if shared.bad_opcode_pc.is_none() {
        shared.bad_opcode_pc = Some((*shared.avr).pc);
    }
    shared.events += 1;
}

/// A byte the MCU clocked out through SPDR: the card in the slot (if any)
/// sees it with the chip select level of this moment, and its answer is put
/// back into SPDR before the firmware can read it.
///
/// # Safety
/// As `on_uart_tx`, and `spi` is set.
pub(crate) unsafe extern "C" fn on_spi_byte(_irq: *mut avr_irq_t, mosi: u32, param: *mut c_void) {
    let shared = &mut *(param as *mut Shared);
    let Some(wires) = shared.spi else { return };
    let cs_low = (*wires.cs).value & 0xFF == 0;
    let miso = shared.sd.exchange(mosi as u8, cs_low);
    // Writes SPDR; `shared` is not used past this call.
    simavr_ffi::avr_raise_irq(wires.miso, u32::from(miso));
}

/// simavr's default sleeps in real time; the harness wants simulated time
/// to pass as fast as the host can go.
pub(crate) unsafe extern "C" fn no_sleep(_avr: *mut avr_t, _how_long: u64) {}

/// simavr's messages: warnings and errors go to stderr; its chatter (such as
/// "Loaded N bytes", printed whatever the log level) is dropped.
///
/// # Safety
/// Called by simavr with a printf format and its matching argument list.
pub(crate) unsafe extern "C" fn log(
    _avr: *mut avr_t,
    level: std::os::raw::c_int,
    format: *const std::os::raw::c_char,
    args: *mut simavr_ffi::__va_list_tag,
) {
    if level > simavr_ffi::LOG_WARNING as std::os::raw::c_int {
        return;
    }
    let mut buf = [0u8; 256];
    simavr_ffi::vsnprintf(buf.as_mut_ptr() as *mut _, buf.len() as _, format, args);
    let text = std::ffi::CStr::from_bytes_until_nul(&buf).unwrap_or_default();
    eprintln!("simavr: {}", plain(&text.to_string_lossy()).trim_end());
}

/// Text without ANSI colour sequences (`ESC [ ... m`).
fn plain(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut chars = text.chars();
    while let Some(c) = chars.next() {
        if c == '\x1b' {
            chars.by_ref().find(|&c| c == 'm');
        } else {
            out.push(c);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn colour_codes_are_dropped() {
        assert_eq!(super::plain("\x1b[31mCORE: bad\x1b[0m!"), "CORE: bad!");
    }
}
