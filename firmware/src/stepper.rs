//! The step interrupt: executes [`Segment`]s exactly as
//! `taut_logic::segment::expand` replays them on the host.
//!
//! Per event, in `TIMER3_COMPA`: raise the STEP pins chosen at the previous
//! event (first, so pulse timing does not depend on the work below: one
//! store per port, through the PINx toggle registers), drop them once the
//! pulse width has passed (so every pulse is as long as set), advance the
//! Klipper-style timing (`time += interval; interval += add`, 24.8 fixed
//! point), run the DDA for the next event, program the compare register,
//! and only then change DIR for a new block. Times are absolute (the compare register advances by
//! the interval), so a late interrupt never shifts the events after it.
//! Waits longer than the 16-bit timer are split.
//!
//! An axis driven through a ULN2003 board (`$x_driver=uln2003`) takes the
//! same events: its DDA marks the events it steps at, and the general path
//! writes the next half-step's coil pattern to its four inputs in one port
//! write (its blocks never take the fast path; coils step at ≤ 1 000/s).
//!
//! Positions are not counted per step: the DDA's closed form gives the steps
//! done by each axis from the events fired, so the interrupt only counts
//! events. Everything here is inlined into the handler: a call would make the
//! compiler save every call-clobbered register on each entry.

pub mod fast;

use crate::board::gpio::{regs, Output, Pin};
use crate::board::step_timer::StepTimer;
use crate::queues::{BLOCKS, SEGMENTS};
use crate::rt::byte;
use core::cell::UnsafeCell;
use core::ptr::{read_volatile, write_volatile};
use core::sync::atomic::AtomicU8;
use taut_logic::axis::{PerAxis, AXES};
use taut_logic::coil;
use taut_logic::config::{Driver, MachineConfig};
use taut_logic::pinmap::{coil_port, port_bit, Port, DRIVERS};
use taut_logic::segment::{Segment, StepBlock, FRAC_BITS, NEW_BLOCK, STOP};

/// Refill the queues when this few segments are left (of 15).
pub(crate) const LOW_WATER: usize = 12;

/// Timer3 registers (data-space addresses). Timer1 drives the pen servo
/// on OC1A (D11, RAMPS SERVO0).
const TCNT3: *mut u16 = 0x94 as *mut u16;
const OCR3A: *mut u16 = 0x98 as *mut u16;
const TIMSK3: *mut u8 = 0x71 as *mut u8;
const TIFR3: *mut u8 = 0x38 as *mut u8;
const OCIE3A: u8 = 1 << 1;
const OCF3A: u8 = 1 << 1;

/// Compare times closer than this to "now" would be missed by the 16-bit
/// timer: the event is late and fired this many ticks from now instead.
pub(crate) const MIN_LEAD: u16 = 48;
/// Waits longer than this are split into `WAIT_PART`-tick parts; every part
/// stays below 0x8000 so "how far ahead" reads correctly as an `i16`.
const LONG_WAIT: u32 = 0x6000;
const WAIT_PART: u32 = 0x4000;

/// The ports that carry STEP pins ("slots"), and each axis's slot and bit,
/// worked out from the pin map at compile time. RAMPS puts the X, Y and Z
/// STEP pins on two ports (PF, PL); a pin map needing more stops the
/// compiler in `step_map`.
const SLOTS: usize = 2;
pub(crate) struct StepMap {
    #[doc(hidden)]
    pub(crate) ports: [Option<Port>; SLOTS],
    slot: [usize; AXES],
    bit: [u8; AXES],
}

const fn step_map() -> StepMap {
    let mut m = StepMap {
        ports: [None; SLOTS],
        slot: [0; AXES],
        bit: [0; AXES],
    };
    let mut i = 0;
    while i < AXES {
        let (port, bit) = port_bit(DRIVERS[i].step);
        let mut s = 0;
        loop {
            match m.ports[s] {
                Some(p) if p as u8 == port as u8 => break,
                Some(_) => s += 1,
                None => {
                    m.ports[s] = Some(port);
                    break;
                }
            }
        }
        m.slot[i] = s;
        m.bit[i] = 1 << bit;
        i += 1;
    }
    m
}

pub(crate) const MAP: StepMap = step_map();

/// PINx register of a slot (null for an unused slot). Always inlined: the
/// step interrupt calls it with constant slots, folded to addresses.
#[inline(always)]
const fn slot_pin(s: usize) -> *mut u8 {
    match MAP.ports[s] {
        Some(p) => p.pin_register() as *mut u8,
        None => core::ptr::null_mut(),
    }
}

/// A DIR pin's PINx (toggle) and PORTx registers and its bit.
struct PinReg {
    pin: *mut u8,
    port: *mut u8,
    mask: u8,
}

#[inline(always)]
const fn reg(n: u8) -> PinReg {
    let (pin, _ddr, port, mask) = regs(n);
    PinReg { pin, port, mask }
}

const DIR: [PinReg; AXES] = [
    reg(DRIVERS[0].dir),
    reg(DRIVERS[1].dir),
    reg(DRIVERS[2].dir),
];

/// PORTx data address of each channel's coil inputs and the bit of IN1,
/// worked out at compile time (read only in `const` blocks: a table read at
/// run time would sit in SRAM, with the pin map behind it).
const COIL_REG: [(u16, u8); AXES] = [coil_reg(0), coil_reg(1), coil_reg(2)];

const fn coil_reg(axis: usize) -> (u16, u8) {
    let (port, shift) = coil_port(axis);
    (port.pin_register() + 2, shift)
}

/// State owned by the interrupt once motion runs. `repr(C)`: the assembly
/// fast path (`fast.rs`) reads fields at their `offset_of!`.
#[repr(C)]
#[doc(hidden)]
pub struct Exec {
    /// The pending event and the rest of its segment may take the fast
    /// path: every moving axis steps at every event, no wait beyond the
    /// 16-bit timer, no DIR change.
    fast_ok: u8,
    /// `wait` is not zero: the next compare match is a split wait, not an
    /// event (a byte, for the assembly entry).
    waiting: u8,
    /// TCNT3 when the assembly entry raised the pending event's pins.
    raised: u16,
    /// Set by the assembly path when it took a segment and the queue is
    /// low; the tick handler passes it on as a refill request.
    refill: u8,
    /// STEP bits to toggle at the pending event, per slot.
    masks: [u8; SLOTS],
    /// Events left in the current segment, including the pending one.
    left: u16,
    interval: u32,
    add: i32,
    /// Sub-tick fraction of the pending event's time (OCR3A holds the ticks).
    frac: u8,
    /// Ticks still to wait before the pending event, beyond OCR3A.
    wait: u32,
    block: StepBlock,
    counter: PerAxis<u32>,
    /// STEP bits of the axes that step at every event of the block (as
    /// many steps as events): no DDA needed for them.
    always: [u8; SLOTS],
    /// Axes that step at some events only: the DDA runs for these.
    partial: u8,
    /// Events of the current block not yet loaded from segments (the
    /// current segment's are counted in `left`).
    block_left: u32,
    /// Position when the current block began.
    block_start: PerAxis<i32>,
    /// Bumped whenever `block`/`block_start` change: readers copy them
    /// without masking interrupts and retry if it moved (a seqlock).
    block_gen: u8,
    running: bool,
    /// Direction bits to apply once the current pulse is over.
    new_dir: Option<u8>,
    /// DIR pin level that means positive, per axis (bit set: high).
    dir_high_positive: u8,
    pulse_ticks: u16,
    /// DIR must be stable this long before the next STEP edge.
    dir_setup_ticks: u16,
    late: u16,
    underruns: u16,
    /// The current segment is a hold's stop ([`STOP`]): running out of
    /// segments after it is no underrun.
    stop: u8,
    /// Axes driven through their coils (`Driver::Uln2003`).
    coils: u8,
    /// Coil axes the current block moves: the DDA runs for them.
    coil_moving: u8,
    /// Coil axes that step at the pending event.
    coil_due: u8,
    /// Coil axes whose coils are energised (the driver on).
    energised: u8,
    /// Each coil axis's half-step phase (0..8): kept while the coils are
    /// off, so they come back on where the rotor stands.
    phase: PerAxis<u8>,
}

#[doc(hidden)]
pub struct ExecCell(UnsafeCell<Exec>);
// SAFETY: `Exec` is touched by TIMER3_COMPA, or by task code while that
// interrupt is off (`kick`) or inside a critical section (the readers).
unsafe impl Sync for ExecCell {}

/// Blocks the step interrupt has begun, wrapping: written by it, read by
/// tasks through [`blocks_begun`] (a card print's checkpoint names the line
/// whose block moves). One byte: atomic on the AVR.
static BEGUN: AtomicU8 = AtomicU8::new(0);

/// Blocks the step interrupt has begun, wrapping.
pub fn blocks_begun() -> u8 {
    byte::load(&BEGUN)
}

#[doc(hidden)]
pub static EXEC: ExecCell = ExecCell(UnsafeCell::new(Exec {
    fast_ok: 0,
    waiting: 0,
    raised: 0,
    refill: 0,
    masks: [0; SLOTS],
    left: 0,
    interval: 0,
    add: 0,
    frac: 0,
    wait: 0,
    block: StepBlock {
        steps: [0; AXES],
        events: 0,
        dir: 0,
    },
    counter: [0; AXES],
    always: [0; SLOTS],
    partial: 0,
    block_left: 0,
    block_start: [0; AXES],
    block_gen: 0,
    running: false,
    new_dir: None,
    dir_high_positive: 0xFF,
    pulse_ticks: 80,
    dir_setup_ticks: 80,
    late: 0,
    underruns: 0,
    stop: 0,
    coils: 0,
    coil_moving: 0,
    coil_due: 0,
    energised: 0,
    phase: [0; AXES],
}));

#[inline(always)]
fn exec() -> &'static mut Exec {
    // SAFETY: see `ExecCell`; callers never hold two of these at once.
    unsafe { &mut *EXEC.0.get() }
}

/// From the tick handler: did the assembly path ask for a refill since?
#[inline(always)]
pub fn take_refill() -> bool {
    avr_device::interrupt::free(|_| core::mem::take(&mut exec().refill) != 0)
}

/// RAMPS X/Y/Z STEP and DIR pins, low outputs. The interrupt writes
/// them through the register addresses worked out from
/// `taut_logic::pinmap::DRIVERS` (one store per port); these tokens prove
/// that those pins are outputs and the stepper's alone.
pub struct StepDirPins {
    pub base_step: Pin<54, Output>,
    pub base_dir: Pin<55, Output>,
    pub radial_step: Pin<60, Output>,
    pub radial_dir: Pin<61, Output>,
    pub drill_step: Pin<46, Output>,
    pub drill_dir: Pin<48, Output>,
}

const _: () = {
    assert!(DRIVERS[0].step == 54 && DRIVERS[0].dir == 55);
    assert!(DRIVERS[1].step == 60 && DRIVERS[1].dir == 61);
    assert!(DRIVERS[2].step == 46 && DRIVERS[2].dir == 48);
};

/// The ULN2003 boards' IN1..IN4 (`taut_logic::pinmap::COILS`), low
/// outputs: X on PA0–PA3, Y on PA4–PA7, Z on PC0–PC3. Written by the
/// step interrupt and [`coils`], four bits of one port at a time.
pub struct CoilPins {
    pub x: (
        Pin<22, Output>,
        Pin<23, Output>,
        Pin<24, Output>,
        Pin<25, Output>,
    ),
    pub y: (
        Pin<26, Output>,
        Pin<27, Output>,
        Pin<28, Output>,
        Pin<29, Output>,
    ),
    pub z: (
        Pin<37, Output>,
        Pin<36, Output>,
        Pin<35, Output>,
        Pin<34, Output>,
    ),
}

const _: () = {
    use taut_logic::pinmap::COILS;
    assert!(COILS[0][0] == 22 && COILS[0][3] == 25);
    assert!(COILS[1][0] == 26 && COILS[1][3] == 29);
    assert!(COILS[2][0] == 37 && COILS[2][3] == 34);
};

/// Owner of the STEP and DIR pins, the coil inputs and Timer3.
pub struct Stepper {
    _pins: StepDirPins,
    _coils: CoilPins,
    _timer: StepTimer,
    /// Axes driven through their coils, as the interrupt has them.
    coils: u8,
}

impl Stepper {
    /// Takes the pins, and the pulse timing, DIR polarity and drivers
    /// from `config`. Timer3 must run at clk/1 (`StepTimer`).
    pub fn new(
        pins: StepDirPins,
        coils: CoilPins,
        timer: StepTimer,
        config: &MachineConfig,
    ) -> Stepper {
        let mut s = Stepper {
            _pins: pins,
            _coils: coils,
            _timer: timer,
            coils: 0,
        };
        s.configure(config);
        s
    }

    /// The pulse timing, DIR polarity and drivers of `config`. Only while
    /// stopped (the interrupt reads them per event): coils of an axis
    /// that leaves coil drive are switched off.
    pub fn configure(&mut self, config: &MachineConfig) {
        let mut high_positive = 0;
        let mut coil_axes = 0;
        for i in 0..AXES {
            high_positive |= (config.axes[i].dir_high_is_positive as u8) << i;
            coil_axes |= ((config.axes[i].driver == Driver::Uln2003) as u8) << i;
        }
        coils(self.coils & !coil_axes, false);
        avr_device::interrupt::free(|_| {
            let e = exec();
            e.pulse_ticks = config.pulse.step_pulse_us as u16 * 16;
            e.dir_setup_ticks = config.pulse.dir_setup_us as u16 * 16;
            e.dir_high_positive = high_positive;
            e.coils = coil_axes;
        });
        self.coils = coil_axes;
    }

    /// Axes driven through their coils: their blocks take the general path.
    pub fn coil_axes(&self) -> u8 {
        self.coils
    }

    /// Start executing queued segments if the interrupt is idle; the first
    /// event comes one interval after now. Needs no critical section: while
    /// motion is stopped the compare interrupt is off, and only this code
    /// turns it on.
    /// Returns whether it started.
    pub fn kick(&mut self) -> bool {
        let e = exec();
        let start = !avr_device::interrupt::free(|_| e.running) && !SEGMENTS.is_empty();
        if start {
            Self::start(e);
        }
        start
    }

    /// The interrupt is idle and segments wait: take the first, start the
    /// timer. Out of line: its locals stay off segment preparation's frame,
    /// under the preparer's calls.
    #[inline(never)]
    #[optimize(speed)]
    fn start(e: &mut Exec) {
        if !load_segment(e) {
            return;
        }
        if let Some(dir) = e.new_dir.take() {
            write_dir(dir, e.dir_high_positive);
        }
        e.frac = 0;
        // SAFETY: Timer3 registers, owned by the stepper; its interrupt is off.
        unsafe {
            write_volatile(OCR3A, read_volatile(TCNT3).wrapping_add(MIN_LEAD));
            schedule_next(e);
            e.running = true;
            write_volatile(TIFR3, OCF3A);
            avr_device::interrupt::free(|_| write_volatile(TIMSK3, read_volatile(TIMSK3) | OCIE3A));
        }
    }

    /// Position in steps, as executed so far. Interrupts are masked only
    /// for the six bytes of event counters; the block is read as a seqlock.
    pub fn position(&self) -> PerAxis<i32> {
        let e = EXEC.0.get();
        let (start, block, left) = loop {
            // SAFETY: volatile reads of fields the interrupt may be changing;
            // the generation check below discards a torn copy.
            let (gen, start, block) = unsafe {
                (
                    read_volatile(&(*e).block_gen),
                    read_volatile(&(*e).block_start),
                    read_volatile(&(*e).block),
                )
            };
            let (now_gen, left) = avr_device::interrupt::free(|_| {
                // SAFETY: interrupts are off: no concurrent writer.
                unsafe { ((*e).block_gen, (*e).block_left + (*e).left as u32) }
            });
            if gen == now_gen {
                break (start, block, left);
            }
        };
        let mut p = start;
        for (i, p) in p.iter_mut().enumerate() {
            *p += signed(done(&block, block.events - left, i), block.dir, i);
        }
        p
    }

    /// Redefine the position (`G92`, zeroing). Only while stopped: the
    /// compare interrupt is then off (only `kick` turns it on), so nothing
    /// else touches the executor and nothing needs masking (a critical
    /// section here took 565 cycles).
    pub fn set_position(&mut self, p: PerAxis<i32>) {
        debug_assert!(!self.is_running(), "set_position while moving");
        let e = exec();
        e.block_start = p;
        e.block_gen = e.block_gen.wrapping_add(1);
        e.block_left = 0;
        e.left = 0;
        e.block = StepBlock {
            steps: [0; AXES],
            events: 0,
            dir: e.block.dir,
        };
    }

    /// Stop at once: no event after this, the executor reset to where the
    /// pulses left it (returned). The queues are the caller's to clear.
    pub fn abort(&mut self) -> PerAxis<i32> {
        halt();
        let at = self.position();
        let e = exec();
        e.running = false;
        e.new_dir = None;
        e.wait = 0;
        e.waiting = 0;
        e.fast_ok = 0;
        e.coil_due = 0;
        self.set_position(at);
        at
    }

    pub fn is_running(&self) -> bool {
        avr_device::interrupt::free(|_| exec().running)
    }

    /// Events fired late (the interrupt could not keep up) and segment-queue
    /// underruns during a move, since boot.
    pub fn faults(&self) -> (u16, u16) {
        avr_device::interrupt::free(|_| (exec().late, exec().underruns))
    }
}

/// No more step events: the compare interrupt off. From any context (the
/// receive interrupt on Ctrl-X); the step interrupt is never mid-event
/// then, as nothing preempts it. Pins stay low: a pulse is raised and
/// dropped within one run of the step interrupt.
#[inline(always)]
pub fn halt() {
    avr_device::interrupt::free(|_| {
        // SAFETY: a masked read-modify-write of the Timer3 mask register.
        unsafe { write_volatile(TIMSK3, read_volatile(TIMSK3) & !OCIE3A) }
    });
}

/// Steps axis `i` made in the first `n` events of `block`: the DDA's closed
/// form (its counter starts at `events / 2`).
fn done(block: &StepBlock, n: u32, i: usize) -> u32 {
    if block.events == 0 {
        return 0;
    }
    ((block.events as u64 / 2 + n as u64 * block.steps[i] as u64) / block.events as u64) as u32
}

fn signed(steps: u32, dir: u8, i: usize) -> i32 {
    if dir >> i & 1 != 0 {
        steps as i32
    } else {
        -(steps as i32)
    }
}

/// Apply `dir` bits (set = positive) through the PIN toggle registers.
#[inline(always)]
fn write_dir(dir: u8, high_positive: u8) {
    let level = !(dir ^ high_positive); // bit set: pin high
    for (i, r) in DIR.iter().enumerate() {
        // SAFETY: DIR pins are written only here (interrupt or interrupt off).
        unsafe {
            let is_high = read_volatile(r.port) & r.mask != 0;
            if is_high != (level >> i & 1 != 0) {
                write_volatile(r.pin, r.mask);
            }
        }
    }
}

/// Take the next segment (and its block); false when the queue is empty.
#[inline(always)]
fn load_segment(e: &mut Exec) -> bool {
    // Segment and block read in place: a copy is a `memcpy` call and
    // stack under the interrupt's frame.
    let loaded = SEGMENTS.peek_with(|seg| {
        if seg.flags & NEW_BLOCK != 0 {
            if BLOCKS.peek_with(|block| begin_block(e, block)).is_none() {
                return false;
            }
            let _ = BLOCKS.pop();
            byte::store(&BEGUN, byte::load(&BEGUN).wrapping_add(1));
        }
        e.interval = seg.interval;
        e.add = seg.add;
        e.left = seg.count;
        e.block_left -= seg.count as u32;
        e.fast_ok = seg.flags & FAST;
        e.stop = seg.flags & STOP;
        true
    });
    if loaded != Some(true) {
        return false;
    }
    let _ = SEGMENTS.pop();
    true
}

/// The DDA takes `block` on, the previous one complete.
#[inline(always)]
fn begin_block(e: &mut Exec, block: &StepBlock) {
    e.block_gen = e.block_gen.wrapping_add(1);
    // The previous block is complete: fold it into the start position.
    for i in 0..AXES {
        e.block_start[i] += signed(e.block.steps[i], e.block.dir, i);
    }
    e.block_left = block.events;
    if block.dir != e.block.dir || !e.running {
        e.new_dir = Some(block.dir);
    }
    // Field by field, volatile: an aggregate copy becomes a `memcpy`
    // call, and any call makes the handler save every register.
    for i in 0..AXES {
        // SAFETY: plain writes to fields of `e`.
        unsafe {
            write_volatile(&mut e.block.steps[i], block.steps[i]);
            write_volatile(&mut e.counter[i], block.events / 2);
        }
    }
    e.block.events = block.events;
    e.block.dir = block.dir;
    let mut always = [0u8; SLOTS];
    let mut partial = 0;
    let mut coil_moving = 0;
    for i in 0..AXES {
        if e.coils & (1 << i) != 0 {
            // Coils: no STEP pin; their own DDA marks the events.
            if block.steps[i] != 0 {
                coil_moving |= 1 << i;
            }
        } else if block.steps[i] == block.events {
            always[MAP.slot[i]] |= MAP.bit[i];
        } else if block.steps[i] != 0 {
            partial |= 1 << i;
        }
    }
    e.always = always;
    e.partial = partial;
    e.coil_moving = coil_moving;
    // Set again by the coils' DDA if this block moves any.
    e.coil_due = 0;
}

/// [`Segment::flags`] bit, set by segment preparation: every event of the
/// segment may take the assembly fast path.
pub const FAST: u8 = 0x80;

/// Whether every moving axis of `block` steps at every event: the DDA
/// then has nothing to do.
pub fn every_event(block: &StepBlock) -> bool {
    block.steps.iter().all(|&s| s == 0 || s == block.events)
}

/// Whether `seg`, of a block that steps [`every_event`], can take the
/// fast path: no interval needs a split wait (the 24.8 fraction adds
/// under one tick). Run by segment preparation, not the interrupt.
pub fn fast_segment(seg: &Segment) -> bool {
    let last = seg.interval as i64 + i64::from(seg.add) * i64::from(u16::max(seg.count, 1) - 1);
    let longest = last.max(seg.interval as i64) + 255;
    longest < (LONG_WAIT << FRAC_BITS) as i64
}

#[inline(never)]
#[cold]
#[optimize(speed)]
fn load_segment_cold(e: &mut Exec) -> bool {
    load_segment(e)
}

/// One axis of the DDA, with its slot and bit as constants.
macro_rules! dda_axis {
    ($e:ident, $m:ident, $i:literal) => {
        if $e.partial & (1 << $i) != 0 {
            dda_count!($e, $m, $i);
        }
    };
}

macro_rules! dda_count {
    ($e:ident, $m:ident, $i:literal) => {
        let c = $e.counter[$i].wrapping_add($e.block.steps[$i]);
        if c >= $e.block.events {
            $e.counter[$i] = c - $e.block.events;
            $m[MAP.slot[$i]] |= MAP.bit[$i];
        } else {
            $e.counter[$i] = c;
        }
    };
}

/// The DDA for axes that do not step at every event, out of line: single-
/// axis and equal-count moves never need it.
#[inline(never)]
fn dda_partial(e: &mut Exec, m: &mut [u8; SLOTS]) {
    dda_axis!(e, m, 0);
    dda_axis!(e, m, 1);
    dda_axis!(e, m, 2);
}

/// The DDA of the coil axes: which of them step at the pending event.
#[inline(never)]
fn dda_coils(e: &mut Exec) {
    let mut due = 0;
    for i in 0..AXES {
        if e.coil_moving & (1 << i) != 0 {
            let c = e.counter[i].wrapping_add(e.block.steps[i]);
            if c >= e.block.events {
                e.counter[i] = c - e.block.events;
                due |= 1 << i;
            } else {
                e.counter[i] = c;
            }
        }
    }
    e.coil_due = due;
}

/// The coil axes due at this event take their next half-step, in the
/// block's direction; true when no STEP pin was raised with them (no
/// pulse to hold).
#[inline(never)]
fn step_coils(e: &mut Exec) -> bool {
    // Bit set: the phase counts up (a positive step, DIR not inverted).
    let up = !(e.block.dir ^ e.dir_high_positive);
    for i in 0..AXES {
        if e.coil_due & (1 << i) != 0 {
            let step = if up & (1 << i) != 0 { 1 } else { 7 };
            let phase = (e.phase[i] + step) & 7;
            e.phase[i] = phase;
            if e.energised & (1 << i) != 0 {
                write_coils(i, coil::pattern(phase));
            }
        }
    }
    e.masks == [0; SLOTS]
}

/// Write the four inputs of axis `i`'s coils: one store to their port.
/// From the step interrupt, or with it masked.
#[inline(always)]
fn write_coils(i: usize, inputs: u8) {
    match i {
        0 => write_coils_of::<0>(inputs),
        1 => write_coils_of::<1>(inputs),
        _ => write_coils_of::<2>(inputs),
    }
}

#[inline(always)]
fn write_coils_of<const I: usize>(inputs: u8) {
    let (port, shift) = const { COIL_REG[I] };
    let port = port as *mut u8;
    // SAFETY: the coil ports are the stepper's alone (`CoilPins`); callers
    // run in the step interrupt or with interrupts masked, so this
    // read-modify-write is not torn.
    unsafe {
        let keep = read_volatile(port) & !(0x0F << shift);
        write_volatile(port, keep | inputs << shift);
    }
}

/// Energise (`on`) or release the coils of the coil axes in `mask`, at
/// the phase they stand at: no step is gained or lost across a release.
/// Each axis's write masks interrupts for a few cycles.
pub fn coils(mask: u8, on: bool) {
    for i in 0..AXES {
        if mask & (1 << i) == 0 {
            continue;
        }
        avr_device::interrupt::free(|_| {
            let e = exec();
            if e.coils & (1 << i) == 0 {
                return;
            }
            let inputs = if on {
                e.energised |= 1 << i;
                coil::pattern(e.phase[i])
            } else {
                e.energised &= !(1 << i);
                0
            };
            write_coils(i, inputs);
        });
    }
}

/// Time, DDA and compare register of the next event.
///
/// # Safety
/// Timer3 registers; called from the interrupt or with it masked.
#[inline(always)]
unsafe fn schedule_next(e: &mut Exec) {
    let t = e.frac as u32 + e.interval;
    e.interval = e.interval.wrapping_add(e.add as u32);
    e.frac = t as u8;
    let mut m = e.always;
    if e.partial != 0 {
        dda_partial(e, &mut m);
    }
    if e.coil_moving != 0 {
        dda_coils(e);
    }
    e.masks = m;
    e.wait = t >> FRAC_BITS;
    advance_compare(e);
}

/// Move the compare register towards the pending event by at most
/// `WAIT_PART` ticks at a time, flagging an event that can no longer be on time.
///
/// # Safety
/// Timer3 registers; called from the interrupt or with it masked.
#[inline(always)]
unsafe fn advance_compare(e: &mut Exec) {
    let part = if e.wait > LONG_WAIT {
        WAIT_PART
    } else {
        e.wait
    };
    e.wait -= part;
    e.waiting = (e.wait != 0) as u8;
    let at = read_volatile(OCR3A).wrapping_add(part as u16);
    let now = read_volatile(TCNT3);
    if (at.wrapping_sub(now) as i16) < MIN_LEAD as i16 {
        e.late = e.late.wrapping_add(1);
        write_volatile(OCR3A, now.wrapping_add(MIN_LEAD));
    } else {
        write_volatile(OCR3A, at);
    }
}

/// Toggle the STEP pins of `m`: one store per port.
///
/// # Safety
/// STEP pin registers; called from the interrupt.
#[inline(always)]
unsafe fn toggle_steps(m: &[u8; SLOTS]) {
    if !slot_pin(0).is_null() {
        write_volatile(slot_pin(0), m[0]);
    }
    if !slot_pin(1).is_null() {
        write_volatile(slot_pin(1), m[1]);
    }
}

/// The `TIMER3_COMPA` interrupt's general path, entered from the assembly
/// entry in `fast.rs`, which has raised the STEP pins unless this compare
/// match is part of a split wait (it handles plain events itself). Returns true when the segment queue
/// wants refilling (the app then spawns the `Refill` or `Prepare` task).
#[inline(always)]
pub fn on_compare() -> bool {
    let e = exec();
    // SAFETY: Timer3 and STEP/DIR pin registers, owned by this interrupt.
    unsafe {
        if e.wait > 0 {
            advance_compare(e);
            return false;
        }
        // The assembly entry (`fast.rs`) raised the pins already. The pulse
        // ends at its set width, before the work below (a new segment, the
        // DDA) that can take longer than the pulse.
        let raised = e.raised;
        // Coils step at the event too; a coil-only event raised no pin.
        if e.coil_due == 0 || !step_coils(e) {
            while read_volatile(TCNT3).wrapping_sub(raised) < e.pulse_ticks {}
            toggle_steps(&e.masks);
        }
        e.left -= 1;
        let loaded = e.left == 0 && load_segment_cold(e);
        if e.left > 0 {
            schedule_next(e);
        } else {
            e.running = false;
            // Dry in the middle of a block: the preparer fell behind.
            e.fast_ok = 0;
            if e.block_left > 0 && e.stop == 0 {
                e.underruns = e.underruns.saturating_add(1);
            }
            write_volatile(TIMSK3, read_volatile(TIMSK3) & !OCIE3A);
        }
        if let Some(dir) = e.new_dir.take() {
            write_dir(dir, e.dir_high_positive);
            // Keep the DIR set-up time before the next STEP edge (only
            // binding above ~200 000 steps/s with the 5 µs default).
            let earliest = read_volatile(TCNT3).wrapping_add(e.dir_setup_ticks);
            if e.running && e.wait == 0 && (read_volatile(OCR3A).wrapping_sub(earliest) as i16) < 0
            {
                write_volatile(OCR3A, earliest);
                e.late = e.late.wrapping_add(1);
            }
        }
        // Ask for a refill when a segment was taken (or motion stopped) and
        // the queue is low: once per segment, not once per event.
        (loaded || !e.running) && SEGMENTS.len() <= LOW_WATER
    }
}
