//! A simulated ATmega2560 at 16 MHz: setting it up from an ELF or from raw
//! machine code, tearing it down, its clock and stack figures, and every
//! touch of simavr's own objects (the `avr_t`, its IRQs, `avr_run`): the
//! other modules see safe methods only.
//!
//! Safety invariants of `Sim` (every `unsafe` block below relies on them):
//! - `avr` points to the `avr_t` simavr allocated for this `Sim` alone; it is
//!   initialised before `Sim` exists and freed only in `Drop`.
//! - `shared` is a `Box<Shared>` turned into a raw pointer; simavr callbacks
//!   hold it as their `param` (see `hooks`). It is freed after the `avr_t` is
//!   terminated, so no callback can outlive it. All access goes through the
//!   raw pointer, in short scopes that never span a simavr call.
//! - `uart_input`, the IRQs `pin_irq` returns and the SD slot's wires belong
//!   to that `avr_t` and live exactly as long as it.
//! - `Sim` is neither `Send` nor `Sync` (raw pointers): callbacks always run
//!   on the owning thread.

use crate::clock::{self, FREQ_HZ};
use crate::elf::{self, ElfInfo, RAM_END, RAM_START};
use crate::hooks::{self, PinHook, Shared, SpiWires};
use crate::input::PinSchedule;
use crate::masked::MaskedSpans;
use crate::outcome::Outcome;
use crate::probe::StepDir;
use crate::sdcard::slot::Slot;
use crate::{Error, Result};
use simavr_ffi as ffi;
use std::ffi::CString;
use std::os::raw::c_void;
use std::path::Path;
use std::ptr::NonNull;
use std::time::Duration;
use taut_logic::pinmap::{self, Port, PIN_COUNT};

extern "C" {
    /// simavr allocates the `avr_t` with `malloc`; `avr_terminate` does not
    /// free it.
    fn free(ptr: *mut c_void);
}

use crate::hooks::{SPH, SPL};
/// SREG in data space.
const SREG: u16 = 0x5F;

/// The number simavr builds an ioctl code from four characters with.
/// EEPROM bytes of the ATmega2560.
pub const EEPROM_BYTES: usize = 4096;

const fn ioctl(a: u8, b: u8, c: u8, d: u8) -> u32 {
    (a as u32) << 24 | (b as u32) << 16 | (c as u32) << 8 | d as u32
}

pub struct Sim {
    pub(crate) avr: NonNull<ffi::avr_t>,
    shared: NonNull<Shared>,
    /// Boxed: simavr holds their addresses, which must survive the Vec growing.
    #[allow(clippy::vec_box)]
    pin_hooks: Vec<Box<PinHook>>,
    uart_input: *mut ffi::avr_irq_t,
    uart1_input: *mut ffi::avr_irq_t,
    pub(crate) elf: Option<ElfInfo>,
    pub(crate) ram_limit: u16,
    pub(crate) min_sp: u16,
    /// Where the program was when the stack was deepest (byte address).
    pub(crate) min_sp_pc: u32,
    /// The stack's bytes at its deepest, once asked for
    /// ([`Sim::keep_peak_stack`]).
    pub(crate) peak_stack: Option<Vec<u8>>,
    /// Watched program addresses and the cycles execution reached them.
    pub(crate) pc_watches: Vec<(u32, Vec<u64>)>,
    pub(crate) resets: u32,
    /// simavr's own cycle counter after the last step: it drops on reset.
    pub(crate) last_avr_cycle: u64,
    /// A fatal ending, repeated by every later run.
    pub(crate) ended: Option<Outcome>,
    pub(crate) schedule: PinSchedule,
    pub(crate) endstops: Vec<crate::endstop::Endstop>,
    /// Externally driven pins per port, in `Port` order: (mask, levels).
    external: [(u8, u8); 11],
    pub(crate) step_dir: Vec<StepDir>,
    /// Simulated cycles and host time of the last run.
    pub(crate) last_speed: Option<(u64, Duration)>,
    /// Interrupts-masked spans: the open one, and the longest so far.
    pub(crate) masked: MaskedSpans,
    /// Functions whose runs are timed ([`Sim::watch_calls`]).
    pub(crate) call_watches: Vec<crate::calls::CallWatch>,
    /// Cycles per program word, when asked for ([`Sim::enable_profile`]).
    pub(crate) profile: Option<crate::profile::Profile>,
    /// EEPROM byte writes, when watched (`power`).
    pub(crate) eeprom_watch: Option<Box<crate::hooks::EepromWatch>>,
    /// The code as loaded (flash words from address 0, before any trap)
    /// and its function ranges: where a jump to 0 is traced back to.
    pub(crate) code: Vec<u16>,
    pub(crate) code_ranges: Vec<(u32, u32)>,
    /// `unseen_mask` was reported once.
    pub(crate) warned_unseen_mask: bool,
    /// Run on the whole record when the simulation ends ([`Sim::check_at_end`]).
    end_checks: Vec<fn(&Sim)>,
    /// The lock bits' and the boot section's rules on SPM, on a board with
    /// a bootloader (`boot`).
    pub(crate) spm_guard: Option<Box<crate::hooks::SpmGuard>>,
    /// RESET pin pulses so far (`Sim::reset_external`).
    pub(crate) external_resets: u32,
}

impl Sim {
    /// Loads a firmware ELF built for the ATmega2560.
    pub fn load(elf_path: &Path) -> Result<Sim> {
        let info = elf::read(elf_path)?;
        let avr = flashed_mcu(elf_path)?;
        let ranges = elf::code_ranges(elf_path)?;
        let mut sim = Sim::attach(avr, Some(info), info.static_ram_end);
        sim.set_traps(ranges);
        Ok(sim)
    }

    /// Loads a firmware ELF's flash bytes as they are, without the
    /// harness's traps (a board flashed with it: `boot`).
    pub(crate) fn load_plain(elf_path: &Path) -> Result<Sim> {
        Ok(Sim::attach(flashed_mcu(elf_path)?, None, RAM_START))
    }

    /// A part with its flash erased.
    pub(crate) fn blank() -> Result<Sim> {
        Ok(Sim::attach(new_mcu()?, None, RAM_START))
    }

    /// Puts `bytes` into flash at byte address `at`.
    pub(crate) fn load_flash(&mut self, at: u32, bytes: &mut [u8]) {
        let avr = self.avr.as_ptr();
        // SAFETY: `avr` is live; simavr checks the range against the
        // flash's size (callers pass ranges `boot::read_hex` checked).
        unsafe { ffi::avr_loadcode(avr, bytes.as_mut_ptr(), bytes.len() as u32, at) };
    }

    /// The harness's books after simavr reset the MCU (its cycle counter
    /// back to 0 from `before`).
    pub(crate) fn after_reset(&mut self, before: u64) {
        let shared = self.shared_mut();
        shared.cycle_base += before;
        shared.uart.rx_ready = false;
        shared.uart1.rx_ready = false;
        // The reset emptied simavr's timers.
        shared.deadline_at = None;
        self.last_avr_cycle = self.avr_cycle();
    }

    /// Loads the firmware, probes the string-art axes' STEP and DIR pins
    /// (`base`, `radial`, `drill`) and runs it to its greeting's `reset:`
    /// line: how the bench and the examples start. Panics if it cannot.
    pub fn boot(elf_path: &Path) -> Sim {
        use taut_logic::axis::Axis;
        let mut sim = Sim::load(elf_path).expect("firmware loads");
        for axis in [Axis::Base, Axis::Radial, Axis::Drill] {
            let d = pinmap::driver(axis);
            sim.probe_step_dir(axis.name(), d.step, d.dir, true);
        }
        assert_eq!(
            sim.run_until_uart_contains("reset:", Duration::from_millis(50)),
            Outcome::Done
        );
        sim
    }

    /// Loads raw machine code (little-endian 16-bit words) at address 0, for
    /// tests with hand-assembled programs. No statics: the stack may grow
    /// down to the start of SRAM unless `set_ram_limit` says otherwise.
    pub fn from_program(words: &[u16]) -> Result<Sim> {
        let mut bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
        let avr = new_mcu()?;
        // SAFETY: `avr` is initialised, so `flashend` is set.
        let flash = unsafe { (*avr.as_ptr()).flashend } as usize + 1;
        if bytes.len() > flash {
            // SAFETY: `avr` came from simavr and is not used afterwards.
            unsafe { release_mcu(avr) };
            return Err(Error::Simavr(format!("{} bytes exceed flash", bytes.len())));
        }
        // SAFETY: simavr copies `bytes.len()` bytes, which fit in flash.
        unsafe { ffi::avr_loadcode(avr.as_ptr(), bytes.as_mut_ptr(), bytes.len() as u32, 0) };
        let mut sim = Sim::attach(avr, None, RAM_START);
        sim.set_traps(vec![(0, bytes.len() as u32)]);
        Ok(sim)
    }

    /// Wires the harness into an initialised MCU with its code loaded.
    fn attach(avr: NonNull<ffi::avr_t>, elf: Option<ElfInfo>, ram_limit: u16) -> Sim {
        let a = avr.as_ptr();
        let shared = Box::into_raw(Box::new(Shared::new(a)));
        let param = shared as *mut c_void;
        // SAFETY: `a` is a live, initialised avr_t; `param` outlives it (see
        // module invariants); the callbacks match simavr's signatures.
        let (uart_input, uart1_input) = unsafe {
            (*a).sleep = Some(hooks::no_sleep);
            (*a).frequency = FREQ_HZ as u32;
            type Notify = unsafe extern "C" fn(*mut ffi::avr_irq_t, u32, *mut c_void);
            let mut inputs = [std::ptr::null_mut(); 2];
            let wiring: [(u8, [Notify; 3]); 2] = [
                (
                    b'0',
                    [hooks::on_uart_tx, hooks::on_uart_xon, hooks::on_uart_xoff],
                ),
                (
                    b'1',
                    [
                        hooks::on_uart1_tx,
                        hooks::on_uart1_xon,
                        hooks::on_uart1_xoff,
                    ],
                ),
            ];
            for (input, (n, [tx, xon, xoff])) in inputs.iter_mut().zip(wiring) {
                // No echo of UART output to our stdout, and no host usleep
                // while the firmware polls an empty receiver.
                let mut flags: u32 = 0;
                ffi::avr_ioctl(
                    a,
                    ioctl(b'u', b'a', b'g', n),
                    &mut flags as *mut u32 as *mut c_void,
                );
                flags &= !(ffi::AVR_UART_FLAG_STDIO | ffi::AVR_UART_FLAG_POLL_SLEEP);
                ffi::avr_ioctl(
                    a,
                    ioctl(b'u', b'a', b's', n),
                    &mut flags as *mut u32 as *mut c_void,
                );
                let uart = |i: u32| ffi::avr_io_getirq(a, ioctl(b'u', b'a', b'r', n), i as i32);
                ffi::avr_irq_register_notify(uart(ffi::UART_IRQ_OUTPUT), Some(tx), param);
                ffi::avr_irq_register_notify(uart(ffi::UART_IRQ_OUT_XON), Some(xon), param);
                ffi::avr_irq_register_notify(uart(ffi::UART_IRQ_OUT_XOFF), Some(xoff), param);
                *input = uart(ffi::UART_IRQ_INPUT);
            }
            let bad = ffi::avr_get_core_irq(a, ffi::AVR_CORE_BAD_OPCODE as i32);
            ffi::avr_irq_register_notify(bad, Some(hooks::on_bad_opcode), param);
            // Batched runs: simavr's run loop, and the register writes
            // that end a batch where the run loop must look.
            ffi::avr_register_io_write(a, SPL as u16, Some(hooks::on_sp_write), param);
            ffi::avr_register_io_write(a, SPH as u16, Some(hooks::on_sp_write), param);
            ffi::avr_register_io_write(a, SREG, Some(hooks::on_sreg_write), param);
            for ucsra in hooks::UCSR_A {
                ffi::avr_register_io_write(a, ucsra, Some(hooks::on_ucsra_write), param);
            }
            (*a).custom.data = param;
            (*a).run = Some(hooks::run);
            (inputs[0], inputs[1])
        };
        Sim {
            avr,
            // SAFETY: from Box::into_raw, never null.
            shared: unsafe { NonNull::new_unchecked(shared) },
            pin_hooks: Vec::new(),
            uart_input,
            uart1_input,
            elf,
            ram_limit,
            min_sp: RAM_END,
            min_sp_pc: 0,
            // `TAUT_STACK_CHAINS`: every simulation keeps its deepest
            // chain (`stack_chain`), e.g. for a whole HIL run's.
            peak_stack: std::env::var_os("TAUT_STACK_CHAINS").map(|_| Vec::new()),
            pc_watches: Vec::new(),
            resets: 0,
            last_avr_cycle: 0,
            ended: None,
            schedule: PinSchedule::default(),
            endstops: Vec::new(),
            external: [(0, 0); 11],
            step_dir: Vec::new(),
            last_speed: None,
            masked: MaskedSpans::default(),
            call_watches: Vec::new(),
            profile: None,
            eeprom_watch: None,
            code: Vec::new(),
            code_ranges: Vec::new(),
            warned_unseen_mask: false,
            end_checks: Vec::new(),
            spm_guard: None,
            external_resets: 0,
        }
    }

    /// Runs `check` on the simulation when it is dropped, unless the
    /// thread is already panicking: a rule every test of a kind keeps
    /// (a driver on whenever it is stepped), checked over the whole run
    /// without each test having to ask.
    pub fn check_at_end(&mut self, check: fn(&Sim)) {
        self.end_checks.push(check);
    }

    /// Puts the traps of `traps` into the loaded code: on every `cli` in
    /// `ranges` (byte ranges of code) and on the reset vector.
    fn set_traps(&mut self, mut ranges: Vec<(u32, u32)>) {
        let avr = self.avr.as_ptr();
        // SAFETY: `avr` is live; `flash` holds `flashend + 1` bytes and
        // every index below is kept under that.
        unsafe {
            let flash_bytes = (*avr).flashend + 1;
            for r in &mut ranges {
                r.1 = r.1.min(flash_bytes) & !1;
                r.0 = r.0.min(r.1);
            }
            let end = ranges.iter().map(|r| r.1).max().unwrap_or(0);
            let flash = (*avr).flash;
            self.code = (0..end as usize / 2)
                .map(|i| u16::from_le_bytes([*flash.add(2 * i), *flash.add(2 * i + 1)]))
                .collect();
            let mut sites: Vec<u32> = ranges
                .iter()
                .flat_map(|&(a, b)| {
                    crate::traps::cli_sites(&self.code[a as usize / 2..b as usize / 2], a)
                })
                .collect();
            sites.sort_unstable();
            sites.dedup();
            for &at in &sites {
                self.write_flash_word(at, crate::traps::TRAP);
            }
            let has_code = !self.code.is_empty();
            if has_code {
                self.write_flash_word(0, crate::traps::TRAP);
            }
            let mut bits = vec![0u64; self.code.len().div_ceil(64)];
            for &at in &sites {
                let word = at as usize / 2;
                bits[word / 64] |= 1 << (word % 64);
            }
            let shared = self.shared_mut();
            shared.cli_sites = bits;
            shared.zero_trap = has_code;
        }
        self.code_ranges = ranges;
    }

    fn write_flash_word(&mut self, at: u32, word: u16) {
        let avr = self.avr.as_ptr();
        // SAFETY: callers pass addresses inside the loaded code, which is
        // inside the flash.
        unsafe {
            let [lo, hi] = word.to_le_bytes();
            *(*avr).flash.add(at as usize) = lo;
            *(*avr).flash.add(at as usize + 1) = hi;
        }
    }

    /// The avr_t, for a module's own callbacks (`power`).
    pub(crate) fn avr_raw(&self) -> *mut ffi::avr_t {
        self.avr.as_ptr()
    }

    /// simavr's own cycle counter (it drops on a reset).
    pub(crate) fn avr_cycle(&self) -> u64 {
        // SAFETY: `avr` is valid for the life of `self`.
        unsafe { (*self.avr.as_ptr()).cycle }
    }

    pub(crate) fn shared(&self) -> &Shared {
        // SAFETY: module invariants: valid, and no callback runs during `&self`.
        unsafe { self.shared.as_ref() }
    }

    pub(crate) fn shared_mut(&mut self) -> &mut Shared {
        // SAFETY: as `shared`; `&mut self` makes this the only reference.
        unsafe { self.shared.as_mut() }
    }

    /// Counts from now on the cycles spent at each program address.
    pub fn enable_profile(&mut self) {
        self.profile.get_or_insert_with(Default::default);
    }

    /// As [`Sim::enable_profile`], and each function's cycles with its
    /// callees (`Profile::inclusive`).
    pub fn enable_call_profile(&mut self, elf: &Path) -> Result<()> {
        self.enable_profile();
        self.profile.as_mut().unwrap().with_calls(elf)
    }

    /// The cycle counts, if [`Sim::enable_profile`] was called.
    pub fn profile(&self) -> Option<&crate::profile::Profile> {
        self.profile.as_ref()
    }

    /// Section sizes and end of statics, when loaded from an ELF.
    pub fn elf(&self) -> Option<&ElfInfo> {
        self.elf.as_ref()
    }

    /// Cycles since power-on (resets do not restart the count).
    pub fn cycles(&self) -> u64 {
        self.shared().now()
    }

    pub fn time_s(&self) -> f64 {
        self.cycles() as f64 / FREQ_HZ as f64
    }

    pub fn time_us(&self) -> f64 {
        clock::cycles_to_us(self.cycles())
    }

    /// Simulated MHz per host second during the last run.
    pub fn sim_mhz(&self) -> Option<f64> {
        let (cycles, wall) = self.last_speed?;
        let secs = wall.as_secs_f64();
        (secs > 0.0).then(|| cycles as f64 / secs / 1e6)
    }

    /// Watchdog resets so far.
    pub fn watchdog_resets(&self) -> u32 {
        self.resets
    }

    /// Program counter, a byte address (as in the ELF's symbols).
    pub fn pc(&self) -> u32 {
        // SAFETY: `avr` is valid for the life of `self`.
        unsafe { (*self.avr.as_ptr()).pc }
    }

    /// Current stack pointer.
    pub fn sp(&self) -> u16 {
        // SAFETY: `data` holds `ramend + 1` bytes, far above 0x5E.
        unsafe {
            let data = (*self.avr.as_ptr()).data;
            u16::from_le_bytes([*data.add(SPL), *data.add(SPH)])
        }
    }

    /// `len` bytes of data memory from `addr` (registers, I/O, SRAM), e.g.
    /// the stack for a backtrace.
    pub fn ram(&self, addr: u16, len: usize) -> Vec<u8> {
        assert!(addr as usize + len <= RAM_END as usize + 1, "past RAMEND");
        // SAFETY: `data` holds `ramend + 1` bytes, checked above.
        unsafe {
            let data = (*self.avr.as_ptr()).data;
            std::slice::from_raw_parts(data.add(addr as usize), len).to_vec()
        }
    }

    /// Puts `bytes` into data memory at `addr` as they are, as a debugger
    /// does: no I/O register's write callback runs (the peripheral sees
    /// the value when it next reads the register).
    pub fn poke_ram(&mut self, addr: u16, bytes: &[u8]) {
        assert!(
            addr as usize + bytes.len() <= RAM_END as usize + 1,
            "past RAMEND"
        );
        // SAFETY: `data` holds `ramend + 1` bytes, checked above.
        unsafe {
            let data = (*self.avr.as_ptr()).data;
            std::ptr::copy_nonoverlapping(bytes.as_ptr(), data.add(addr as usize), bytes.len());
        }
    }

    /// Record every cycle at which execution reaches byte address `pc` (an
    /// interrupt vector, a task's entry): latencies measured exactly.
    pub fn watch_pc(&mut self, pc: u32) {
        self.pc_watches.push((pc, Vec::new()));
    }

    /// The cycles at which a watched address was reached.
    pub fn pc_hits(&self, pc: u32) -> &[u64] {
        self.pc_watches
            .iter()
            .find(|w| w.0 == pc)
            .map_or(&[], |w| &w.1)
    }

    /// Cycles the MCU has spent asleep (waiting for an interrupt) since
    /// power-on: the rest of [`Sim::cycles`] it was awake.
    pub fn asleep_cycles(&self) -> u64 {
        self.shared().asleep
    }

    /// Time every run of the function at byte address `pc` from now on (a
    /// task: how long it keeps the others waiting).
    pub fn watch_calls(&mut self, pc: u32) {
        self.call_watches.push(crate::calls::CallWatch::new(pc));
    }

    /// The finished runs of a function given to [`Sim::watch_calls`], in
    /// short: how many, the longest and the 99th percentile (cycles).
    pub fn call_summary(&self, pc: u32) -> Option<(usize, u64, u64)> {
        let mut runs: Vec<u64> = self.call_runs(pc).iter().map(|r| r.1).collect();
        runs.sort_unstable();
        let n = runs.len();
        (n > 0).then(|| (n, runs[n - 1], runs[n * 99 / 100]))
    }

    /// The finished runs of a function given to [`Sim::watch_calls`]:
    /// (first cycle, cycles), in order.
    pub fn call_runs(&self, pc: u32) -> &[(u64, u64)] {
        self.call_watches
            .iter()
            .find(|w| w.entry == pc)
            .map_or(&[], |w| &w.runs)
    }

    /// Lowest stack pointer seen, an address (as it stood after any
    /// instruction); `peak_stack_bytes` says how deep that is.
    pub fn lowest_sp(&self) -> u16 {
        self.min_sp
    }

    /// Most stack ever in use, in bytes.
    pub fn peak_stack_bytes(&self) -> u16 {
        RAM_END - self.min_sp
    }

    /// The program counter (byte address) at the deepest stack: look it
    /// up with `avr-addr2line -fe taut.elf`.
    pub fn peak_stack_pc(&self) -> u32 {
        self.min_sp_pc
    }

    /// From now on, keep a copy of the stack each time it goes deeper
    /// than ever: [`Sim::peak_stack`] then holds the return addresses of
    /// the deepest call chain (`simavr/examples/stack_trace.rs` reads them).
    pub fn keep_peak_stack(&mut self) {
        self.peak_stack.get_or_insert_with(Vec::new);
    }

    /// Forget the deepest stack so far: the next ones are a later phase's.
    pub fn reset_peak_stack(&mut self) {
        self.min_sp = RAM_END;
        if let Some(kept) = &mut self.peak_stack {
            kept.clear();
        }
    }

    /// The stack's bytes (from the stack pointer + 1 up to RAMEND) as they
    /// stood at the deepest point, if [`Sim::keep_peak_stack`] was called
    /// before it.
    pub fn peak_stack(&self) -> Option<&[u8]> {
        self.peak_stack.as_deref()
    }

    /// First address past the statics: the stack must stay above it.
    pub fn ram_limit(&self) -> u16 {
        self.ram_limit
    }

    /// The longest stretch, in cycles, during which interrupts were masked,
    /// not counting spans that began at the interrupt vector `exempt` (a
    /// byte address, e.g. the step timer's own vector, whose handler cannot
    /// delay itself). It bounds how late that interrupt can start. Returns
    /// (cycles, byte address where the span began).
    pub fn max_masked_cycles(&self, exempt: u32) -> (u64, u32) {
        self.masked.longest_except(exempt)
    }

    /// Spans that began at `pc` (an interrupt vector: its handler's runs):
    /// (count, mean cycles, longest cycles).
    pub fn masked_stats(&self, pc: u32) -> Option<(u64, f64, u64)> {
        self.masked.stats(pc)
    }

    /// Every masked span's longest duration by start address, longest first.
    pub fn masked_spans(&self) -> Vec<(u64, u32)> {
        self.masked.by_length()
    }

    /// Overrides the end of statics (raw programs have no symbols).
    pub fn set_ram_limit(&mut self, limit: u16) {
        self.ram_limit = limit;
    }
}

/// What one `avr_run` did.
pub(crate) struct Executed {
    /// Byte address of the (first) instruction that ran.
    pub pc_before: u32,
    /// Byte address of the next one.
    pub pc: u32,
    /// simavr's own cycle counter afterwards: it drops on reset.
    pub avr_cycle: u64,
    /// The I flag afterwards.
    pub interrupts_on: bool,
    pub core: Core,
}

/// The core's state as simavr left it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Core {
    Running,
    /// Asleep until an interrupt.
    Sleeping,
    Crashed,
    /// Asleep with interrupts masked: nothing can wake it.
    Hung,
}

/// The wires between simavr and the outside world: pins, USART0's input,
/// the SD card slot on the SPI bus.
impl Sim {
    /// Executes one instruction (or one sleep stretch) when `budget` is
    /// None; else instructions until `budget` cycles have run (ending on the
    /// first instruction boundary at or past it), something a callback
    /// reports happens, the interrupts are masked or unmasked, an
    /// interrupt is entered or the core sleeps (then the sleep stretch).
    pub(crate) fn execute(&mut self, budget: Option<u64>) -> Executed {
        let avr = self.avr.as_ptr();
        let shared = self.shared.as_ptr() as *mut c_void;
        // From reset the reset vector runs as loaded, one instruction.
        // SAFETY: `avr` is live (invariants); no callback runs here.
        let from_reset = unsafe { (*avr).pc == 0 && (*avr).cycle == 0 } && !self.code.is_empty();
        if from_reset {
            self.write_flash_word(0, self.code[0]);
        }
        // SAFETY: as above; the deadline timer's param is our `Shared`,
        // which outlives the avr_t.
        unsafe {
            match budget {
                Some(cycles) if !from_reset => {
                    (*avr).run_cycle_limit = u64::MAX;
                    let running = (*avr).state == ffi::cpu_Running as std::os::raw::c_int;
                    if running || (*self.shared.as_ptr()).hard_deadline {
                        ffi::avr_cycle_timer_register(avr, cycles.max(1), hooks::DEADLINE, shared);
                    }
                }
                _ => {
                    (*avr).run_cycle_limit = 1;
                    (*avr).run_cycle_count = 1;
                }
            }
        }
        // SAFETY: `avr` is live (invariants); callbacks it triggers only
        // touch `Shared`, and no reference into it is held here. `sreg` is
        // simavr's unpacked status register.
        let (pc_before, state, pc, avr_cycle, interrupts_on) = unsafe {
            let pc_before = (*avr).pc;
            let state = ffi::avr_run(avr) as u32;
            (
                pc_before,
                state,
                (*avr).pc,
                (*avr).cycle,
                (*avr).sreg[7] != 0,
            )
        };
        if from_reset {
            self.write_flash_word(0, crate::traps::TRAP);
        }
        let core = match state {
            ffi::cpu_Crashed => Core::Crashed,
            ffi::cpu_Done => Core::Hung,
            ffi::cpu_Sleeping => Core::Sleeping,
            _ => Core::Running,
        };
        Executed {
            pc_before,
            pc,
            avr_cycle,
            interrupts_on,
            core,
        }
    }

    /// Takes the run loop's deadline out of simavr's timers.
    pub(crate) fn clear_deadline(&mut self) {
        // SAFETY: live avr_t; cancelling a timer that is not there is a
        // no-op.
        unsafe {
            ffi::avr_cycle_timer_cancel(
                self.avr.as_ptr(),
                hooks::DEADLINE,
                self.shared.as_ptr() as *mut c_void,
            )
        };
    }

    /// Z and EIND, as a 24-bit word address.
    pub(crate) fn z(&self) -> u32 {
        // SAFETY: `data` holds `ramend + 1` bytes, far above 0x5C.
        unsafe {
            let data = (*self.avr.as_ptr()).data;
            u32::from_le_bytes([*data.add(30), *data.add(31), *data.add(0x5C), 0])
        }
    }

    /// Puts one byte on USART0's (`uart1`: USART1's) receive line now.
    pub(crate) fn raise_uart_rx(&mut self, uart1: bool, byte: u8) {
        let input = if uart1 {
            self.uart1_input
        } else {
            self.uart_input
        };
        // SAFETY: `input` is a UART's input IRQ of our live avr_t; the
        // caller holds no reference into `Shared` across the call.
        unsafe { ffi::avr_raise_irq(input, u32::from(byte)) };
    }

    /// USART1's byte time on an 8N1 line, in cycles, from its UBRR1 and
    /// U2X1 as the firmware set them (its reset values until then).
    pub(crate) fn uart1_cycles_per_byte(&self) -> u64 {
        // UCSR1A 0xC8 (U2X1: bit 1), UBRR1L 0xCC, UBRR1H 0xCD.
        // SAFETY: `data` holds `ramend + 1` bytes, far above 0xCD.
        let (a, lo, hi) = unsafe {
            let data = (*self.avr.as_ptr()).data;
            (*data.add(0xC8), *data.add(0xCC), *data.add(0xCD))
        };
        let ubrr = u64::from(u16::from_le_bytes([lo, hi]) & 0x0FFF);
        let per_bit = if a & 2 != 0 { 8 } else { 16 };
        10 * per_bit * (ubrr + 1)
    }

    /// simavr's IRQ for a board pin's level.
    ///
    /// # Panics
    /// On a pin number past D69.
    fn pin_irq(&self, pin: u8) -> *mut ffi::avr_irq_t {
        let (port, bit) = board_pin(pin);
        // SAFETY: the avr_t is live; an ioctl query has no side effect.
        unsafe {
            ffi::avr_io_getirq(
                self.avr.as_ptr(),
                ioctl(b'i', b'o', b'g', port.letter() as u8),
                i32::from(bit),
            )
        }
    }

    /// Level of a board pin now: the driven output when it is an output.
    pub fn pin_level(&self, pin: u8) -> bool {
        // SAFETY: `pin_irq` returns a live IRQ of our avr_t.
        unsafe { (*self.pin_irq(pin)).value & 0xff != 0 }
    }

    /// Has every level change of `pin` recorded by probe number `probe`.
    pub(crate) fn notify_pin(&mut self, pin: u8, probe: usize) {
        let irq = self.pin_irq(pin);
        let hook = Box::new(PinHook {
            shared: self.shared.as_ptr(),
            probe,
        });
        let param = &*hook as *const PinHook as *mut c_void;
        self.pin_hooks.push(hook);
        // SAFETY: the hook is boxed (stable address) and kept in `pin_hooks`
        // until the Sim drops, after the avr_t is terminated.
        unsafe { ffi::avr_irq_register_notify(irq, Some(hooks::on_pin), param) };
    }

    /// Sets a pin's external level now: recorded as the port's external
    /// state, so simavr keeps it when the firmware rewrites the port (it would
    /// otherwise re-apply the pull-up), and raised on the pin.
    pub(crate) fn drive(&mut self, pin: u8, high: bool) {
        let (port, bit) = board_pin(pin);
        let slot = &mut self.external[port as usize];
        slot.0 |= 1 << bit;
        slot.1 = (slot.1 & !(1 << bit)) | (u8::from(high) << bit);
        // SAFETY: avr_ioport_external_t is plain C data, valid zeroed.
        let mut ext: ffi::avr_ioport_external_t = unsafe { std::mem::zeroed() };
        ext.set_name(port.letter() as u8 as _);
        ext.set_mask(slot.0 as _);
        ext.set_value(slot.1 as _);
        let irq = self.pin_irq(pin);
        // SAFETY: live avr_t and IRQ; the ioctl copies the struct; callbacks
        // triggered by the raise only touch `Shared`, not borrowed here.
        unsafe {
            ffi::avr_ioctl(
                self.avr.as_ptr(),
                ioctl(b'i', b'o', b'p', port.letter() as u8),
                &mut ext as *mut _ as *mut c_void,
            );
            ffi::avr_raise_irq(irq, u32::from(high));
        }
    }

    /// The EEPROM's contents (4 KiB on the ATmega2560).
    pub fn eeprom(&self) -> Vec<u8> {
        let mut bytes = vec![0xFF; EEPROM_BYTES];
        self.eeprom_ioctl(b'g', &mut bytes);
        bytes
    }

    /// Load `bytes` into the EEPROM from its start (before a run: a power
    /// cycle keeps only the EEPROM).
    pub fn set_eeprom(&mut self, bytes: &[u8]) {
        let mut copy = bytes[..bytes.len().min(EEPROM_BYTES)].to_vec();
        self.eeprom_ioctl(b's', &mut copy);
    }

    fn eeprom_ioctl(&self, op: u8, bytes: &mut [u8]) {
        let mut desc = ffi::avr_eeprom_desc_t {
            ee: bytes.as_mut_ptr(),
            offset: 0,
            size: bytes.len() as u32,
        };
        // SAFETY: live avr_t; `desc` points into `bytes`, which outlives the
        // call; simavr copies at most `size` bytes between it and the EEPROM.
        unsafe {
            ffi::avr_ioctl(
                self.avr.as_ptr(),
                ioctl(b'e', b'e', op, b'p'),
                &mut desc as *mut _ as *mut c_void,
            );
        }
    }

    /// The SD card slot, wired to the SPI bus on first use. Until then the
    /// bus has no card model at all and reads whatever simavr leaves in SPDR.
    pub(crate) fn sd_slot_mut(&mut self) -> &mut Slot {
        if !self.shared().spi_wired() {
            self.wire_sd_slot();
        }
        &mut self.shared_mut().sd
    }

    fn wire_sd_slot(&mut self) {
        let cs = self.pin_irq(pinmap::SD_CS);
        let avr = self.avr.as_ptr();
        // simavr names the ATmega2560's only SPI 0 (not '0').
        let spi = |n: u32| {
            // SAFETY: the avr_t is live; an ioctl query has no side effect.
            unsafe { ffi::avr_io_getirq(avr, ioctl(b's', b'p', b'i', 0), n as i32) }
        };
        let (miso, mosi) = (spi(ffi::SPI_IRQ_INPUT), spi(ffi::SPI_IRQ_OUTPUT));
        assert!(!cs.is_null() && !miso.is_null() && !mosi.is_null());
        self.shared_mut().wire_spi(SpiWires { cs, miso });
        let param = self.shared.as_ptr() as *mut c_void;
        // SAFETY: `param` is our `Shared`, which outlives the avr_t
        // (invariants), its wires now set; the callback matches simavr's
        // signature.
        unsafe { ffi::avr_irq_register_notify(mosi, Some(hooks::on_spi_byte), param) };
    }
}

/// Port and bit of a board pin.
///
/// # Panics
/// On a pin number past D69.
fn board_pin(pin: u8) -> (Port, u8) {
    assert!(pin < PIN_COUNT, "no board pin D{pin}");
    pinmap::port_bit(pin)
}

impl Drop for Sim {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            for check in std::mem::take(&mut self.end_checks) {
                check(self);
            }
        }
        // SAFETY: `avr` is live and used no more; callbacks can no longer run
        // once it is terminated, so `shared` may be freed after it.
        unsafe {
            release_mcu(self.avr);
            drop(Box::from_raw(self.shared.as_ptr()));
        }
    }
}

/// A fresh, initialised ATmega2560 at 16 MHz.
/// A new MCU with an ELF's image loaded by simavr.
fn flashed_mcu(elf_path: &Path) -> Result<NonNull<ffi::avr_t>> {
    let c_path = CString::new(elf_path.to_string_lossy().as_bytes())
        .map_err(|_| Error::Elf(format!("{}: NUL in path", elf_path.display())))?;
    // SAFETY: elf_firmware_t is plain C data that simavr requires zeroed
    // before reading; all-zero is valid for its integers and pointers.
    let mut firmware: ffi::elf_firmware_t = unsafe { std::mem::zeroed() };
    // SAFETY: valid NUL-terminated path and a zeroed firmware struct.
    if unsafe { ffi::elf_read_firmware(c_path.as_ptr(), &mut firmware) } != 0 {
        return Err(Error::Elf(format!(
            "simavr could not read {}",
            elf_path.display()
        )));
    }
    let avr = new_mcu()?;
    // SAFETY: `avr` is initialised; `firmware` was filled by simavr.
    unsafe { ffi::avr_load_firmware(avr.as_ptr(), &mut firmware) };
    Ok(avr)
}

fn new_mcu() -> Result<NonNull<ffi::avr_t>> {
    static QUIET: std::sync::Once = std::sync::Once::new();
    // SAFETY: `hooks::log` has the logger signature simavr expects.
    QUIET.call_once(|| unsafe { ffi::avr_global_logger_set(Some(hooks::log)) });
    // SAFETY: a NUL-terminated name; simavr returns a new avr_t or null.
    let avr = NonNull::new(unsafe { ffi::avr_make_mcu_by_name(c"atmega2560".as_ptr()) })
        .ok_or_else(|| Error::Simavr("no atmega2560 core".into()))?;
    // SAFETY: `avr` was just allocated by simavr.
    unsafe {
        (*avr.as_ptr()).frequency = FREQ_HZ as u32;
        if ffi::avr_init(avr.as_ptr()) != 0 {
            free(avr.as_ptr() as *mut c_void);
            return Err(Error::Simavr("avr_init failed".into()));
        }
    }
    Ok(avr)
}

/// # Safety
/// `avr` is an initialised avr_t from `new_mcu`, not used afterwards.
unsafe fn release_mcu(avr: NonNull<ffi::avr_t>) {
    ffi::avr_terminate(avr.as_ptr());
    free(avr.as_ptr() as *mut c_void);
}
