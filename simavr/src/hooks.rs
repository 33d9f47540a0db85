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

use crate::compare_fix::Timers;
use crate::probe::Probe;
use crate::sdcard::slot::Slot;
use crate::serial::SerialLine;
use simavr_ffi as ffi;
use simavr_ffi::{avr_irq_t, avr_t};
use std::os::raw::{c_int, c_void};

pub(crate) struct Shared {
    avr: *mut avr_t,
    /// Cycles run before the last reset (simavr zeroes its counter on reset).
    pub cycle_base: u64,
    /// Bumped by every callback: tells the run loop something happened.
    pub events: u64,
    pub probes: Vec<Probe>,
    pub uart: SerialLine,
    /// USART1's line (the firmware's second console).
    pub uart1: SerialLine,
    /// Address of the first invalid opcode executed.
    pub bad_opcode_pc: Option<u32>,
    /// The SD card slot: what answers the SPI bytes once it is wired.
    pub sd: Slot,
    /// The slot's wires, once connected.
    spi: Option<SpiWires>,
    /// A stack pointer write below this ends the batch, so the run sees
    /// the new depth at the instruction boundary (the lowest seen so far).
    pub sp_floor: u16,
    /// Program counter and simavr cycle of the last stack pointer write.
    pub last_sp_write: (u32, u64),
    /// The last stack pointer write was of SPH: a 16-bit update may be
    /// half done (its SPL write still to come).
    pub sph_alone: bool,
    /// Cycles the core has slept.
    pub asleep: u64,
    /// Where the core was when simavr declared it crashed (a program
    /// counter past the flash).
    pub crash_pc: Option<u32>,
    /// The `cli` instructions trapped: a bit per flash word.
    pub cli_sites: Vec<u64>,
    /// Address 0 holds a trap: reaching it (but from reset) is a crash.
    pub zero_trap: bool,
    /// simavr cycle the run loop's deadline timer is set for, while set.
    pub deadline_at: Option<u64>,
    /// simavr's cycle count when a timer (the watchdog's) reset the MCU.
    pub reset_at: Option<u64>,
    /// A batch saw the interrupts unmasked that began with them on and
    /// never saw them masked: code the traps missed masked them.
    pub unseen_mask: bool,
    /// SPMs the part refused (`boot`).
    pub spm_refused: u32,
    /// A sleep keeps the run loop's deadline (`Sim::run_to`).
    pub hard_deadline: bool,
    /// The deadline fired in the timers just processed: a sleep ends
    /// there, not at the timer after it.
    deadline_fired: bool,
    /// The I flag before the last SREG write (simavr has unpacked the new
    /// value by the time the write hook runs).
    i_on: bool,
    /// The compares simavr would skip after a late overflow.
    timers: Timers,
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
            uart1: SerialLine::default(),
            bad_opcode_pc: None,
            sd: Slot::default(),
            spi: None,
            sp_floor: crate::elf::RAM_END,
            last_sp_write: (0, 0),
            sph_alone: false,
            asleep: 0,
            crash_pc: None,
            cli_sites: Vec::new(),
            zero_trap: false,
            deadline_at: None,
            reset_at: None,
            unseen_mask: false,
            spm_refused: 0,
            hard_deadline: false,
            deadline_fired: false,
            i_on: false,
            // SAFETY: `avr` is live and initialised (module invariants).
            timers: unsafe { Timers::of(avr) },
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

    /// Something the run loop must see happened: simavr finishes the
    /// instruction under way and returns from `avr_run`.
    fn end_batch(&mut self) {
        // SAFETY: `avr` is valid while `Shared` is reachable (see module doc).
        unsafe { end_batch(self.avr) }
    }
}

/// Ends simavr's run of instructions after the current one: `avr_run_one`
/// goes on only while its cycle budget exceeds the instruction's cycles.
///
/// # Safety
/// `avr` is live.
unsafe fn end_batch(avr: *mut avr_t) {
    (*avr).run_cycle_count = 0;
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
    shared.end_batch();
}

/// # Safety
/// `param` is the `Shared` of the simulation (module invariants).
pub(crate) unsafe extern "C" fn on_uart_tx(_irq: *mut avr_irq_t, value: u32, param: *mut c_void) {
    let shared = &mut *(param as *mut Shared);
    transmitted(shared, |s| &mut s.uart, value);
}

/// # Safety
/// As `on_uart_tx`.
pub(crate) unsafe extern "C" fn on_uart_xon(_irq: *mut avr_irq_t, value: u32, param: *mut c_void) {
    let shared = &mut *(param as *mut Shared);
    fifo_ready(shared, |s| &mut s.uart, value);
}

/// # Safety
/// As `on_uart_tx`.
pub(crate) unsafe extern "C" fn on_uart_xoff(_irq: *mut avr_irq_t, value: u32, param: *mut c_void) {
    let shared = &mut *(param as *mut Shared);
    if value != 0 {
        shared.uart.rx_ready = false;
    }
}

/// USART1's `on_uart_tx`.
///
/// # Safety
/// As `on_uart_tx`.
pub(crate) unsafe extern "C" fn on_uart1_tx(_irq: *mut avr_irq_t, value: u32, param: *mut c_void) {
    let shared = &mut *(param as *mut Shared);
    transmitted(shared, |s| &mut s.uart1, value);
}

/// # Safety
/// As `on_uart_tx`.
pub(crate) unsafe extern "C" fn on_uart1_xon(_irq: *mut avr_irq_t, value: u32, param: *mut c_void) {
    let shared = &mut *(param as *mut Shared);
    fifo_ready(shared, |s| &mut s.uart1, value);
}

/// # Safety
/// As `on_uart_tx`.
pub(crate) unsafe extern "C" fn on_uart1_xoff(
    _irq: *mut avr_irq_t,
    value: u32,
    param: *mut c_void,
) {
    let shared = &mut *(param as *mut Shared);
    if value != 0 {
        shared.uart1.rx_ready = false;
    }
}

/// A byte the firmware sent on `line`.
fn transmitted(shared: &mut Shared, line: fn(&mut Shared) -> &mut SerialLine, value: u32) {
    let l = line(shared);
    match value as u8 {
        crate::serial::XOFF => l.xoff = true,
        crate::serial::XON => l.xoff = false,
        _ => {}
    }
    l.tx.push(value as u8);
    shared.events += 1;
    shared.end_batch();
}

/// simavr's receive FIFO of `line` has room (raised when read empty).
fn fifo_ready(shared: &mut Shared, line: fn(&mut Shared) -> &mut SerialLine, value: u32) {
    let l = line(shared);
    if value != 0 {
        l.in_fifo = 0;
    }
    if value != 0 && !l.rx_ready {
        l.rx_ready = true;
        shared.events += 1;
        shared.end_batch();
    }
}

/// # Safety
/// As `on_uart_tx`.
pub(crate) unsafe extern "C" fn on_bad_opcode(_irq: *mut avr_irq_t, _op: u32, param: *mut c_void) {
    let shared = &mut *(param as *mut Shared);
    let avr = shared.avr;
    let pc = (*avr).pc;
    // simavr's decoder: a state other than running on return means the
    // IRQ served the opcode (`cpu_StepDone`: resume at `avr->pc`); the
    // instruction's one cycle is added after.
    let word = pc as usize / 2;
    if shared
        .cli_sites
        .get(word / 64)
        .is_some_and(|w| w >> (word % 64) & 1 != 0)
    {
        // `cli` as simavr runs it (`avr_sreg_set(avr, S_I, 0)`); the run
        // loop must see it only if it masked the interrupts.
        if (*avr).sreg[7] != 0 {
            end_batch(avr);
        }
        (*avr).sreg[7] = 0;
        (*avr).interrupt_state = 0;
        (*avr).pc = pc + 2;
        (*avr).state = simavr_ffi::cpu_StepDone as _;
        shared.i_on = false;
        return;
    }
    if pc == 0 && shared.zero_trap {
        // Execution reached the reset vector: stop there, the trap taking
        // no cycle, as if the run had ended on the jump.
        (*avr).cycle = (*avr).cycle.wrapping_sub(1);
        (*avr).state = simavr_ffi::cpu_StepDone as _;
        end_batch(avr);
        return;
    }
    if shared.bad_opcode_pc.is_none() {
        shared.bad_opcode_pc = Some(pc);
    }
    shared.events += 1;
    end_batch(avr);
}

/// Stack pointer registers in data space.
pub(crate) const SPL: usize = 0x5D;
pub(crate) const SPH: usize = 0x5E;

/// A write of SPL or SPH (pushes, pops, calls, returns, interrupt entries
/// and the firmware's own `out`s all come here): stores it, notes where it
/// happened, and ends the batch when the stack may be deeper than ever.
///
/// # Safety
/// As `on_uart_tx`; `avr` is the live avr_t.
pub(crate) unsafe extern "C" fn on_sp_write(
    avr: *mut avr_t,
    addr: simavr_ffi::avr_io_addr_t,
    v: u8,
    param: *mut c_void,
) {
    let shared = &mut *(param as *mut Shared);
    let data = (*avr).data;
    *data.add(usize::from(addr)) = v;
    shared.last_sp_write = ((*avr).pc, (*avr).cycle);
    // An `out SPH` (a push or call writes SPL then SPH in one go).
    shared.sph_alone = usize::from(addr) == SPH && out_to((*avr).flash, (*avr).pc) == Some(SPH);
    // Between the two bytes of a 16-bit update this may be a value the
    // stack never held; the run loop checks the real one after the
    // instruction, or after the SPL write that completes a frame set-up
    // (`Sim::sp_half_written`).
    // (The byte just stored is not read back: a wider load over a fresh
    // narrow store stalls the host for longer than the rest of this.)
    let sp = if usize::from(addr) == SPL {
        u16::from_le_bytes([v, *data.add(SPH)])
    } else {
        u16::from_le_bytes([*data.add(SPL), v])
    };
    if sp < shared.sp_floor {
        end_batch(avr);
    }
}

/// The data address an `out` instruction at byte address `pc` of `flash`
/// writes, if it is one.
///
/// # Safety
/// `flash` holds at least `pc + 2` bytes.
pub(crate) unsafe fn out_to(flash: *const u8, pc: u32) -> Option<usize> {
    let w = u16::from_le_bytes([*flash.add(pc as usize), *flash.add(pc as usize + 1)]);
    // OUT A, Rr: 1011 1AAr rrrr AAAA; A is an I/O address (data - 0x20).
    (w & 0xF800 == 0xB800).then(|| usize::from(((w >> 5) & 0x30) | (w & 0x0F)) + 0x20)
}

/// A write of SREG (simavr has stored and unpacked it already): if it
/// masked the interrupts, the run loop must see it.
///
/// # Safety
/// As `on_uart_tx`; `avr` is the live avr_t.
pub(crate) unsafe extern "C" fn on_sreg_write(
    avr: *mut avr_t,
    _addr: simavr_ffi::avr_io_addr_t,
    v: u8,
    param: *mut c_void,
) {
    let shared = &mut *(param as *mut Shared);
    let was_on = std::mem::replace(&mut shared.i_on, v & 0x80 != 0);
    if was_on && !shared.i_on {
        end_batch(avr);
    }
}

/// The run loop's own deadline: a cycle timer, so simavr ends its run of
/// instructions on the first boundary at or past it, as it does for the
/// MCU's timers. It does nothing when it fires.
///
/// # Safety
/// As `on_uart_tx`.
unsafe extern "C" fn deadline(
    _avr: *mut avr_t,
    _when: simavr_ffi::avr_cycle_count_t,
    param: *mut c_void,
) -> simavr_ffi::avr_cycle_count_t {
    (*(param as *mut Shared)).deadline_at = None;
    (*(param as *mut Shared)).deadline_fired = true;
    0
}

/// The one pointer to `deadline` that registers and cancels it: simavr
/// finds a timer by its function's address, and Rust does not promise one
/// address per function.
pub(crate) static DEADLINE: simavr_ffi::avr_cycle_timer_t = Some(deadline);

extern "C" {
    /// simavr's decoder (sim_core.h, left out of the bindings): runs
    /// instructions from `avr->pc` while `run_cycle_count` lasts and no
    /// interrupt is due; returns the next program counter.
    fn avr_run_one(avr: *mut avr_t) -> simavr_ffi::avr_flashaddr_t;
}

/// `avr->run`: simavr's `avr_callback_run_raw` (a run of instructions,
/// the cycle timers, a sleep stretch to the next timer, interrupt entry),
/// besides noting the cycles slept and where a crash happened, and taking
/// the run loop's deadline out of the timers before a sleep so the stretch
/// ends where it would without it.
///
/// # Safety
/// Called by `avr_run` on a live avr_t whose `custom.data` is its `Shared`
/// (module invariants).
pub(crate) unsafe extern "C" fn run(avr: *mut avr_t) {
    use simavr_ffi::{cpu_Crashed, cpu_Done, cpu_Running, cpu_Sleeping};
    let shared = (*avr).custom.data as *mut Shared;
    let state = |avr: *mut avr_t| (*avr).state as u32;
    // The I flag changes within a batch only where the hooks see it.
    (*shared).i_on = (*avr).sreg[7] != 0;
    if state(avr) == cpu_Running {
        let masked_before = (*avr).sreg[7] == 0;
        let pc = avr_run_one(avr);
        // simavr stops right after the I flag rises (`interrupt_state` < 0);
        // every way it can fall ends the batch too, so a rise in a batch
        // that began unmasked means a fall went unseen.
        if !masked_before && (*avr).interrupt_state < 0 {
            (*shared).unseen_mask = true;
        }
        if state(avr) == cpu_Crashed {
            (*shared).crash_pc = Some((*avr).pc);
        }
        (*avr).pc = pc;
    }
    if state(avr) == cpu_Sleeping && !(*shared).hard_deadline {
        simavr_ffi::avr_cycle_timer_cancel(avr, DEADLINE, shared as *mut c_void);
        (*shared).deadline_at = None;
    }
    let before = (*avr).cycle;
    (*shared).deadline_fired = false;
    let mut sleep = simavr_ffi::avr_cycle_timer_process(avr);
    // A kept deadline due now ends the stretch here: the next timer may
    // lie a byte's time later (a cut asked at this cycle would come late).
    if (*shared).deadline_fired && (*shared).hard_deadline {
        sleep = 0;
    }
    (*shared).timers.catch_up(avr);
    if (*avr).cycle < before {
        (*shared).reset_at = Some(before);
    }
    if state(avr) == cpu_Sleeping {
        if (*avr).sreg[7] == 0 {
            (*avr).state = cpu_Done as _;
            return;
        }
        (*avr).cycle += 1 + sleep;
        (*shared).asleep += 1 + sleep;
    }
    let awake_or_asleep = state(avr) == cpu_Running || state(avr) == cpu_Sleeping;
    if awake_or_asleep && (*avr).interrupt_state != 0 {
        simavr_ffi::avr_service_interrupts(avr);
    }
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
/// Called by simavr with a printf format and its matching argument list,
/// and `avr` null or live, its `custom.data` null or its `Shared`.
pub(crate) unsafe extern "C" fn log(
    avr: *mut avr_t,
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
    // After an SPM the part refused (`boot`), simavr's flash module says
    // the SPM never came: it did, and was refused on purpose.
    let shared = match avr.is_null() {
        true => std::ptr::null_mut(),
        false => (*avr).custom.data as *mut Shared,
    };
    let refused = !shared.is_null() && (*shared).spm_refused > 0;
    if refused && text.to_bytes().starts_with(b"FLASH: avr_progen_clear") {
        return;
    }
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

// The EEPROM watch of `power`.

/// EEAR's data address.
const EEARL: usize = 0x41;
const EEARH: usize = 0x42;
/// EECR: EEMPE and EEPE together start a byte's write.
const START_WRITE: u8 = 0b110;

/// What the EECR hook saw.
#[derive(Default)]
pub(crate) struct EepromWatch {
    /// Byte writes started.
    pub writes: u64,
    /// The last one: address, and simavr's cycle counter then.
    pub last: Option<(u16, u64)>,
}

/// Called after simavr's own EEPROM module for every write to EECR.
///
/// # Safety
/// `param` is the `EepromWatch` boxed in the `Sim` that owns `avr`, which
/// outlives the avr_t's callbacks; `avr` is that live avr_t.
pub(crate) unsafe extern "C" fn on_eecr(
    avr: *mut ffi::avr_t,
    _addr: u16,
    v: u8,
    param: *mut c_void,
) {
    if v & START_WRITE != START_WRITE {
        return;
    }
    // SAFETY: see the function's contract; `data` spans the I/O space.
    unsafe {
        let w = &mut *(param as *mut EepromWatch);
        let data = (*avr).data;
        let at = u16::from_le_bytes([*data.add(EEARL), *data.add(EEARH)]) & 0x0FFF;
        w.writes += 1;
        w.last = Some((at, (*avr).cycle));
    }
}

// The SPM guard of `boot`.

/// SPMCSR in data space, and its bits.
const SPMCSR: usize = 0x57;
const SPMEN: u8 = 1 << 0;
const PGERS: u8 = 1 << 1;
const PGWRT: u8 = 1 << 2;
/// RAMPZ and Z in data space.
const RAMPZ: usize = 0x5B;
const ZL: usize = 30;

/// The simavr I/O module that sees each SPM before simavr's flash module.
/// `repr(C)` with the module first: simavr hands its ioctl a pointer to it.
#[repr(C)]
pub(crate) struct SpmGuard {
    pub(crate) io: ffi::avr_io_t,
    boot_start: u32,
    locked: bool,
}

/// simavr's ioctl code of an SPM (`AVR_IOCTL_DEF('f','s','p','m')`).
const IOCTL_SPM: u32 = u32::from_be_bytes(*b"fspm");

/// # Safety
/// Called by simavr's `avr_ioctl` with `port` the `io` of a live,
/// boxed `SpmGuard` attached to a live avr_t whose `custom.data` is its
/// `Shared` (the `hooks` invariants).
unsafe extern "C" fn guard_ioctl(port: *mut ffi::avr_io_t, ctl: u32, _p: *mut c_void) -> c_int {
    if ctl != IOCTL_SPM {
        return -1;
    }
    let guard = &mut *(port as *mut SpmGuard);
    let avr = (*port).avr;
    let data = (*avr).data;
    let spmcsr = *data.add(SPMCSR);
    if spmcsr & SPMEN == 0 {
        // Not enabled: simavr's module does nothing either.
        return -1;
    }
    let z = u32::from_le_bytes([*data.add(ZL), *data.add(ZL + 1), *data.add(RAMPZ), 0]);
    let from_application = (*avr).pc < guard.boot_start;
    let writes_boot = spmcsr & (PGERS | PGWRT) != 0 && z >= guard.boot_start;
    if from_application || (guard.locked && writes_boot) {
        // As the part: the SPM does nothing (SPMEN then clears itself; the
        // flash module's own 4-cycle timer clears it too, and says so).
        *data.add(SPMCSR) = spmcsr & !SPMEN;
        (*((*avr).custom.data as *mut Shared)).spm_refused += 1;
        return 0;
    }
    -1
}

impl SpmGuard {
    /// Refuses an SPM from below `boot_start`, and (when `locked`) one
    /// that erases or writes a page at or above it.
    pub(crate) fn new(boot_start: u32, locked: bool) -> Box<SpmGuard> {
        // SAFETY: avr_io_t is plain C data: null pointers and no callbacks
        // are valid, and simavr fills `next` and `avr` when it is attached.
        let mut io: ffi::avr_io_t = unsafe { std::mem::zeroed() };
        io.kind = c"spm-guard".as_ptr();
        io.ioctl = Some(guard_ioctl);
        Box::new(SpmGuard {
            io,
            boot_start,
            locked,
        })
    }
}

/// USART0's and USART1's control register A (U2X is its bit 1); each one's
/// UBRRnL lies four bytes above it.
pub(crate) const UCSR_A: [u16; 2] = [0xC0, 0xC8];

/// A write of UCSRnA: simavr works out the USART's byte time only when
/// UBRRnL is written, with the U2X bit it holds then, so a firmware that
/// sets U2X after the rate (the silicon does not mind the order) would
/// get a line of half its rate. Here the rate is worked out again, by
/// simavr's own UBRRnL handler with the value UBRRnL holds.
///
/// # Safety
/// `avr` is the live avr_t and `addr` one of [`UCSR_A`] (simavr's own
/// handler of the register ran before: it was registered first).
pub(crate) unsafe extern "C" fn on_ucsra_write(
    avr: *mut avr_t,
    addr: simavr_ffi::avr_io_addr_t,
    _v: u8,
    _param: *mut c_void,
) {
    let ubrrl = addr + 4;
    // simavr's I/O table starts at data address 0x20 (AVR_DATA_TO_IO).
    let io = &(*avr).io[usize::from(ubrrl) - 0x20].w;
    if let Some(write) = io.c {
        write(avr, ubrrl, *(*avr).data.add(usize::from(ubrrl)), io.param);
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn colour_codes_are_dropped() {
        assert_eq!(super::plain("\x1b[31mCORE: bad\x1b[0m!"), "CORE: bad!");
    }
}
