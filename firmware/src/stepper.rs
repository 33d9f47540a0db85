//! The step interrupt: executes [`Segment`]s exactly as
//! `taut_logic::segment::expand` replays them on the host.
//!
//! Per event, in `TIMER1_COMPA`: raise the STEP pins chosen at the previous
//! event (first, so pulse timing does not depend on the work below), count
//! positions, advance the Klipper-style timing (`time += interval; interval
//! += add`, 24.8 fixed point), run the DDA for the next event, program the
//! compare register, then drop the STEP pins once the pulse width has passed
//! and only then change DIR pins for a new block. Times are absolute (the
//! compare register advances by the interval), so a late interrupt never
//! shifts the events after it. Waits longer than the 16-bit timer are split.

use crate::rt::Ring;
use core::cell::UnsafeCell;
use core::ptr::{read_volatile, write_volatile};
use taut_logic::axis::{PerAxis, AXES};
use taut_logic::config::MachineConfig;
use taut_logic::pinmap::{port_bit, DRIVERS};
use taut_logic::segment::{Segment, StepBlock, FRAC_BITS, NEW_BLOCK};

/// Segments waiting for the interrupt (11 bytes each).
pub static SEGMENTS: Ring<Segment, 32> = Ring::new();
/// Blocks waiting for their first segment (21 bytes each).
pub static BLOCKS: Ring<StepBlock, 8> = Ring::new();
/// Refill the queues when this few segments are left.
const LOW_WATER: usize = 16;

/// Timer1 registers (data-space addresses).
const TCNT1: *mut u16 = 0x84 as *mut u16;
const OCR1A: *mut u16 = 0x88 as *mut u16;
const TIMSK1: *mut u8 = 0x6F as *mut u8;
const TIFR1: *mut u8 = 0x36 as *mut u8;
const OCIE1A: u8 = 1 << 1;
const OCF1A: u8 = 1 << 1;

/// Compare times closer than this to "now" would be missed by the 16-bit
/// timer: the event is late and fired this many ticks from now instead.
const MIN_LEAD: u16 = 48;
/// Waits longer than this are split into `WAIT_PART`-tick parts; every part
/// stays below 0x8000 so "how far ahead" reads correctly as an `i16`.
const LONG_WAIT: u32 = 0x6000;
const WAIT_PART: u32 = 0x4000;

struct PinReg {
    pin: *mut u8,
    port: *mut u8,
    mask: u8,
}

const fn reg(n: u8) -> PinReg {
    let (port, bit) = port_bit(n);
    let pin = port.pin_register() as *mut u8;
    PinReg {
        pin,
        port: pin.wrapping_add(2),
        mask: 1 << bit,
    }
}

const STEP: [PinReg; AXES] = [
    reg(DRIVERS[0].step),
    reg(DRIVERS[1].step),
    reg(DRIVERS[2].step),
    reg(DRIVERS[3].step),
];
const DIR: [PinReg; AXES] = [
    reg(DRIVERS[0].dir),
    reg(DRIVERS[1].dir),
    reg(DRIVERS[2].dir),
    reg(DRIVERS[3].dir),
];

/// State owned by the interrupt once motion runs.
struct Exec {
    running: bool,
    /// Events left in the current segment, including the pending one.
    left: u16,
    interval: u32,
    add: i32,
    /// Sub-tick fraction of the pending event's time (OCR1A holds the ticks).
    frac: u8,
    /// Ticks still to wait before the pending event, beyond OCR1A.
    wait: u32,
    block: StepBlock,
    counter: PerAxis<u32>,
    /// Axes that step at the pending event.
    pending: u8,
    /// Events of the current block not yet fired.
    block_left: u32,
    /// Direction bits to apply once the current pulse is over.
    new_dir: Option<u8>,
    position: PerAxis<i32>,
    /// DIR pin level that means positive, per axis (bit set: high).
    dir_high_positive: u8,
    pulse_ticks: u16,
    late: u16,
    underruns: u16,
}

struct ExecCell(UnsafeCell<Exec>);
// SAFETY: `Exec` is touched by TIMER1_COMPA, or by task code with that
// interrupt disabled (`start`, `snapshot` run with interrupts off).
unsafe impl Sync for ExecCell {}

static EXEC: ExecCell = ExecCell(UnsafeCell::new(Exec {
    running: false,
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
    pending: 0,
    block_left: 0,
    new_dir: None,
    position: [0; AXES],
    dir_high_positive: 0xFF,
    pulse_ticks: 80,
    late: 0,
    underruns: 0,
}));

fn exec() -> &'static mut Exec {
    // SAFETY: see `ExecCell`; callers never hold two of these at once.
    unsafe { &mut *EXEC.0.get() }
}

/// Owner of the STEP and DIR pins: constructing it proves they are outputs.
pub struct Stepper(());

impl Stepper {
    /// Takes the pins as outputs (STEP low) and the pulse timing and DIR
    /// polarity from `config`. Timer1 must run at clk/1 (`StepTimer`).
    pub fn new(_timer: crate::board::step_timer::StepTimer, config: &MachineConfig) -> Stepper {
        let e = exec();
        e.pulse_ticks = config.pulse.step_pulse_us as u16 * 16;
        e.dir_high_positive = 0;
        for i in 0..AXES {
            if config.axes[i].dir_high_is_positive {
                e.dir_high_positive |= 1 << i;
            }
            // SAFETY: DDR is PIN+1; these pins belong to the stepper alone,
            // and nothing else runs during start-up.
            unsafe {
                for r in [&STEP[i], &DIR[i]] {
                    write_volatile(r.port, read_volatile(r.port) & !r.mask);
                    let ddr = r.pin.wrapping_add(1);
                    write_volatile(ddr, read_volatile(ddr) | r.mask);
                }
            }
        }
        Stepper(())
    }

    pub fn set_pulse_us(&mut self, us: u8) {
        avr_device::interrupt::free(|_| exec().pulse_ticks = us as u16 * 16);
    }

    /// Start executing queued segments if the interrupt is idle; the first
    /// event comes one interval after now.
    pub fn kick(&mut self) {
        avr_device::interrupt::free(|_| {
            let e = exec();
            if e.running || SEGMENTS.is_empty() {
                return;
            }
            if !load_segment(e) {
                return;
            }
            if let Some(dir) = e.new_dir.take() {
                write_dir(dir, e.dir_high_positive);
            }
            e.running = true;
            e.frac = 0;
            // SAFETY: Timer1 registers; the compare interrupt is off here.
            unsafe {
                write_volatile(OCR1A, read_volatile(TCNT1).wrapping_add(MIN_LEAD));
                schedule_next(e);
                write_volatile(TIFR1, OCF1A);
                write_volatile(TIMSK1, read_volatile(TIMSK1) | OCIE1A);
            }
        });
    }

    /// Position in steps, as executed so far.
    pub fn position(&self) -> PerAxis<i32> {
        avr_device::interrupt::free(|_| exec().position)
    }

    /// Redefine the position (`G92`, zeroing); only while idle.
    pub fn set_position(&mut self, p: PerAxis<i32>) {
        avr_device::interrupt::free(|_| exec().position = p);
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

/// Apply `dir` bits (set = positive) through the PIN toggle registers.
fn write_dir(dir: u8, high_positive: u8) {
    let level = !(dir ^ high_positive); // bit set: pin high
    for (i, r) in DIR.iter().enumerate() {
        // SAFETY: DIR pins are written only here (interrupt or interrupts off).
        unsafe {
            let is_high = read_volatile(r.port) & r.mask != 0;
            if is_high != (level >> i & 1 != 0) {
                write_volatile(r.pin, r.mask);
            }
        }
    }
}

/// Take the next segment (and its block); false when the queue is empty.
fn load_segment(e: &mut Exec) -> bool {
    let Some(seg) = SEGMENTS.peek() else {
        return false;
    };
    if seg.flags & NEW_BLOCK != 0 {
        let Some(block) = BLOCKS.pop() else {
            return false;
        };
        e.counter = [block.events / 2; AXES];
        e.block_left = block.events;
        if block.dir != e.block.dir || !e.running {
            e.new_dir = Some(block.dir);
        }
        e.block = block;
    }
    let _ = SEGMENTS.pop();
    e.interval = seg.interval;
    e.add = seg.add;
    e.left = seg.count;
    true
}

/// Time, DDA and compare register of the next event.
///
/// # Safety
/// Timer1 registers; called from the interrupt or with it masked.
unsafe fn schedule_next(e: &mut Exec) {
    let t = e.frac as u32 + e.interval;
    e.interval = e.interval.wrapping_add(e.add as u32);
    e.frac = t as u8;
    let ticks = t >> FRAC_BITS;
    let mut axes = 0;
    for i in 0..AXES {
        let c = &mut e.counter[i];
        *c += e.block.steps[i];
        if *c >= e.block.events {
            *c -= e.block.events;
            axes |= 1 << i;
        }
    }
    e.pending = axes;
    e.wait = ticks;
    advance_compare(e);
}

/// Move the compare register towards the pending event by at most
/// `WAIT_PART` ticks at a time, flagging an event that can no longer be on time.
unsafe fn advance_compare(e: &mut Exec) {
    let part = if e.wait > LONG_WAIT {
        WAIT_PART
    } else {
        e.wait
    };
    e.wait -= part;
    let at = read_volatile(OCR1A).wrapping_add(part as u16);
    let now = read_volatile(TCNT1);
    if (at.wrapping_sub(now) as i16) < MIN_LEAD as i16 {
        e.late = e.late.saturating_add(1);
        write_volatile(OCR1A, now.wrapping_add(MIN_LEAD));
    } else {
        write_volatile(OCR1A, at);
    }
}

/// The `TIMER1_COMPA` interrupt. Returns true when the segment queue wants
/// refilling (the app then spawns the motion task).
#[inline(always)]
pub fn on_compare() -> bool {
    let e = exec();
    // SAFETY: Timer1 and STEP pin registers, owned by this interrupt.
    unsafe {
        if e.wait > 0 {
            advance_compare(e);
            return false;
        }
        let axes = e.pending;
        let raised = read_volatile(TCNT1);
        for (i, r) in STEP.iter().enumerate() {
            if axes >> i & 1 != 0 {
                write_volatile(r.pin, r.mask);
            }
        }
        for i in 0..AXES {
            if axes >> i & 1 != 0 {
                e.position[i] += if e.block.dir >> i & 1 != 0 { 1 } else { -1 };
            }
        }
        e.left -= 1;
        e.block_left -= 1;
        let loaded = e.left == 0 && load_segment(e);
        if e.left > 0 {
            schedule_next(e);
        } else {
            e.running = false;
            // Dry in the middle of a block: the preparer fell behind.
            if e.block_left > 0 {
                e.underruns = e.underruns.saturating_add(1);
            }
            write_volatile(TIMSK1, read_volatile(TIMSK1) & !OCIE1A);
        }
        while read_volatile(TCNT1).wrapping_sub(raised) < e.pulse_ticks {}
        for (i, r) in STEP.iter().enumerate() {
            if axes >> i & 1 != 0 {
                write_volatile(r.pin, r.mask);
            }
        }
        if let Some(dir) = e.new_dir.take() {
            write_dir(dir, e.dir_high_positive);
        }
        // Ask for a refill when a segment was taken (or motion stopped) and
        // the queue is low: once per segment, not once per event.
        (loaded || !e.running) && SEGMENTS.len() <= LOW_WATER
    }
}
