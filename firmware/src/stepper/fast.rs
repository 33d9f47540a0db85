//! The step interrupt's fast path, in assembly.
//!
//! The entry raises the STEP pins of every event first (a fixed 20 cycles
//! after the compare match, whichever path follows). A plain event — inside a segment, every moving axis stepping at every
//! event, no wait beyond the 16-bit timer, no DIR change — needs only: raise
//! the STEP pins, advance the 24.8 time by the interval, move the compare
//! register, hold the pulse, drop the pins. At a segment's last event it
//! also takes the next segment when that one may take this path too, so a
//! pulse set shorter than that work (~14 µs) lasts that long there; the
//! hold is timed from the rise, so none is ever shorter than set. (Holding
//! and dropping first there cost a 1-axis rate of 59 kHz: the interrupt
//! outlasted the step period.) Compiled from Rust that costs
//! ~400 cycles, most of it saving the 33 registers the general path needs;
//! here it is ~170 and saves 13. The Rust handler (`super::on_compare`)
//! decides per segment whether its events may take this path (`fast_ok`)
//! and takes every other event: segment ends, DDA, long waits, DIR.

use super::{Exec, FAST, LOW_WATER, MAP, MIN_LEAD};
use crate::queues::SEGMENTS;
use crate::rt::Ring;
use core::mem::offset_of;
use taut_logic::segment::{Segment, NEW_BLOCK};

#[doc(hidden)]
pub const FAST_OK: usize = offset_of!(Exec, fast_ok);
#[doc(hidden)]
pub const WAITING: usize = offset_of!(Exec, waiting);
#[doc(hidden)]
pub const RAISED: usize = offset_of!(Exec, raised);
#[doc(hidden)]
pub const REFILL: usize = offset_of!(Exec, refill);
#[doc(hidden)]
pub const BLOCK_LEFT: usize = offset_of!(Exec, block_left);
#[doc(hidden)]
pub const RING_HEAD: usize = Ring::<Segment, 16>::HEAD;
#[doc(hidden)]
pub const RING_TAIL: usize = Ring::<Segment, 16>::TAIL;
#[doc(hidden)]
pub const RING_MASK: u8 = 15;
#[doc(hidden)]
pub const SEG_ADD: usize = offset_of!(Segment, add);
#[doc(hidden)]
pub const SEG_COUNT: usize = offset_of!(Segment, count);
#[doc(hidden)]
pub const SEG_FLAGS: usize = offset_of!(Segment, flags);
#[doc(hidden)]
pub const FAST_BIT: u8 = FAST.trailing_zeros() as u8;
#[doc(hidden)]
pub const NEW_BLOCK_BIT: u8 = NEW_BLOCK.trailing_zeros() as u8;
#[doc(hidden)]
pub const LOW: u8 = LOW_WATER as u8 + 1;
const _: () = assert!(core::mem::size_of::<Segment>() == 11 && offset_of!(Segment, interval) == 0);
const _: () = assert!(SEGMENTS.capacity() == RING_MASK as usize);
#[doc(hidden)]
pub const LEFT: usize = offset_of!(Exec, left);
#[doc(hidden)]
pub const MASKS: usize = offset_of!(Exec, masks);
#[doc(hidden)]
pub const FRAC: usize = offset_of!(Exec, frac);
#[doc(hidden)]
pub const INTERVAL: usize = offset_of!(Exec, interval);
#[doc(hidden)]
pub const ADD: usize = offset_of!(Exec, add);
#[doc(hidden)]
pub const PULSE: usize = offset_of!(Exec, pulse_ticks);
#[doc(hidden)]
pub const LATE: usize = offset_of!(Exec, late);
#[doc(hidden)]
pub const LEAD: u16 = MIN_LEAD;

/// PINx data address of STEP slot `s`.
#[doc(hidden)]
pub const fn pin(s: usize) -> u16 {
    match MAP.ports[s] {
        Some(p) => p.pin_register(),
        None => panic!("the fast path expects two STEP ports (RAMPS)"),
    }
}

// The fast path writes exactly two STEP ports, `MAP`'s two slots: a pin
// map needing a third stops the compiler in `step_map`, one using a
// single port stops it at `PIN1` (`pin` panics on an unused slot).
#[doc(hidden)]
pub const PIN0: u16 = pin(0);
#[doc(hidden)]
pub const PIN1: u16 = pin(1);

/// Defines `__vector_32` (TIMER3_COMPA): the fast path, falling back to the
/// `extern "avr-interrupt"` handler `$slow` for any other event.
#[macro_export]
macro_rules! step_vector {
    ($slow:path) => {
        // SAFETY: only the vector table jumps here. Every register the
        // body uses, and SREG, is restored before `reti` or before the jump
        // to `$slow` (an `avr-interrupt` handler that returns with `reti`);
        // `EXEC` and `SEGMENTS` are the step interrupt's, as in `on_compare`.
        #[unsafe(naked)]
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn __vector_32() {
            core::arch::naked_asm!(
                "push r24",
                "in r24, 0x3f",
                "push r24",
                // A split wait: no event now, the Rust path moves on.
                "lds r24, {e}+{waiting}",
                "cpi r24, 0",
                "brne 2f",
                // An event: raise its STEP pins now, on both paths, so the
                // pulse comes at the same delay after the compare match.
                "lds r24, {e}+{masks}+0", "sts {pin0}, r24",
                "lds r24, {e}+{masks}+1", "sts {pin1}, r24",
                "lds r24, 0x94", "sts {e}+{raised}, r24",
                "lds r24, 0x95", "sts {e}+{raised}+1, r24",
                "lds r24, {e}+{fast_ok}",
                "cpi r24, 0",
                "brne 3f",
                "2:",
                "pop r24",
                "out 0x3f, r24",
                "pop r24",
                "jmp {slow}",
                "3:",
                "push r18", "push r19", "push r20", "push r21", "push r22",
                "push r23", "push r25", "push r26", "push r27", "push r30", "push r31",
                // left -= 1; the segment's last event takes the next one
                "lds r24, {e}+{left}", "lds r25, {e}+{left}+1",
                "sbiw r24, 1",
                "breq 10f", "rjmp 6f", "10:", // (branches reach ±64 words)
                // Next segment: queued, fast, same block? Else the Rust path.
                "lds r26, {ring}+{tail}",
                "lds r27, {ring}+{head}",
                "cp r26, r27",
                "brne 11f", "rjmp 7f", "11:",
                "mov r30, r26", "clr r31",                 // Z = ring + tail × 11
                "movw r18, r30",
                "lsl r30", "rol r31", "movw r20, r30",
                "lsl r30", "rol r31", "lsl r30", "rol r31",
                "add r30, r20", "adc r31, r21",
                "add r30, r18", "adc r31, r19",
                "ldi r18, lo8({ring})", "ldi r19, hi8({ring})",
                "add r30, r18", "adc r31, r19",
                "ldd r24, Z+{seg_flags}",
                "sbrs r24, {fast_bit}", "rjmp 7f",
                "sbrc r24, {new_block_bit}", "rjmp 7f",
                "ldd r18, Z+0", "sts {e}+{interval}, r18",
                "ldd r18, Z+1", "sts {e}+{interval}+1, r18",
                "ldd r18, Z+2", "sts {e}+{interval}+2, r18",
                "ldd r18, Z+3", "sts {e}+{interval}+3, r18",
                "ldd r18, Z+{seg_add}", "sts {e}+{add}, r18",
                "ldd r18, Z+{seg_add}+1", "sts {e}+{add}+1, r18",
                "ldd r18, Z+{seg_add}+2", "sts {e}+{add}+2, r18",
                "ldd r18, Z+{seg_add}+3", "sts {e}+{add}+3, r18",
                "ldd r24, Z+{seg_count}", "ldd r25, Z+{seg_count}+1",
                // block_left -= count
                "lds r18, {e}+{block_left}", "lds r19, {e}+{block_left}+1",
                "lds r20, {e}+{block_left}+2", "lds r21, {e}+{block_left}+3",
                "clr r22",
                "sub r18, r24", "sbc r19, r25", "sbc r20, r22", "sbc r21, r22",
                "sts {e}+{block_left}, r18", "sts {e}+{block_left}+1, r19",
                "sts {e}+{block_left}+2, r20", "sts {e}+{block_left}+3, r21",
                // Pop: tail += 1; ask for a refill when few are left.
                "inc r26", "andi r26, {ring_mask}",
                "sts {ring}+{tail}, r26",
                "sub r27, r26", "andi r27, {ring_mask}",
                "cpi r27, {low}",
                "brsh 6f",
                "ldi r18, 1", "sts {e}+{refill}, r18",
                "6:",
                "sts {e}+{left}+1, r25", "sts {e}+{left}, r24",
                // t = frac + interval; ticks (r25:r24) = t >> 8 (< 0x6000)
                "lds r18, {e}+{interval}", "lds r19, {e}+{interval}+1",
                "lds r20, {e}+{interval}+2", "lds r21, {e}+{interval}+3",
                "clr r23",
                "lds r22, {e}+{frac}",
                "add r22, r18",
                "mov r24, r19", "adc r24, r23",
                "mov r25, r20", "adc r25, r23",
                "sts {e}+{frac}, r22",
                // interval += add
                "lds r26, {e}+{add}", "lds r27, {e}+{add}+1",
                "add r18, r26", "adc r19, r27",
                "lds r26, {e}+{add}+2", "lds r27, {e}+{add}+3",
                "adc r20, r26", "adc r21, r27",
                "sts {e}+{interval}, r18", "sts {e}+{interval}+1, r19",
                "sts {e}+{interval}+2, r20", "sts {e}+{interval}+3, r21",
                // at = OCR3A + ticks; late if less than LEAD ahead of TCNT3
                "lds r26, 0x98", "lds r27, 0x99",
                "add r26, r24", "adc r27, r25",
                "lds r18, 0x94", "lds r19, 0x95",
                "movw r20, r26",
                "sub r20, r18", "sbc r21, r19",
                "cpi r20, {lead}", "cpc r21, r23",
                "brge 4f",
                "ldi r20, {lead}",
                "add r18, r20", "adc r19, r23",
                "movw r26, r18",
                "lds r24, {e}+{late}", "lds r25, {e}+{late}+1",
                "adiw r24, 1",
                "sts {e}+{late}+1, r25", "sts {e}+{late}, r24",
                "4:",
                "sts 0x99, r27", "sts 0x98, r26", // OCR3A, high byte first
                // Hold the pulse: TCNT3 - raised >= pulse_ticks. `raised` is
                // read here, not kept from the entry: taking the next
                // segment above uses Z (r31:r30) to address it.
                "lds r30, {e}+{raised}", "lds r31, {e}+{raised}+1",
                "lds r20, {e}+{pulse}", "lds r21, {e}+{pulse}+1",
                "5:",
                "lds r18, 0x94", "lds r19, 0x95",
                "sub r18, r30", "sbc r19, r31",
                "cp r18, r20", "cpc r19, r21",
                "brlo 5b",
                // Drop the STEP pins.
                "lds r24, {e}+{masks}+0", "sts {pin0}, r24",
                "lds r24, {e}+{masks}+1", "sts {pin1}, r24",
                "pop r31", "pop r30", "pop r27", "pop r26", "pop r25",
                "pop r23", "pop r22", "pop r21", "pop r20", "pop r19", "pop r18",
                "pop r24",
                "out 0x3f, r24",
                "pop r24",
                "reti",
                // Not a segment the fast path can take: restore, Rust path.
                "7:",
                "pop r31", "pop r30", "pop r27", "pop r26", "pop r25",
                "pop r23", "pop r22", "pop r21", "pop r20", "pop r19", "pop r18",
                "rjmp 2b",
                e = sym $crate::stepper::EXEC,
                ring = sym $crate::queues::SEGMENTS,
                head = const $crate::stepper::fast::RING_HEAD,
                tail = const $crate::stepper::fast::RING_TAIL,
                ring_mask = const $crate::stepper::fast::RING_MASK,
                seg_add = const $crate::stepper::fast::SEG_ADD,
                seg_count = const $crate::stepper::fast::SEG_COUNT,
                seg_flags = const $crate::stepper::fast::SEG_FLAGS,
                fast_bit = const $crate::stepper::fast::FAST_BIT,
                new_block_bit = const $crate::stepper::fast::NEW_BLOCK_BIT,
                low = const $crate::stepper::fast::LOW,
                refill = const $crate::stepper::fast::REFILL,
                block_left = const $crate::stepper::fast::BLOCK_LEFT,
                slow = sym $slow,
                fast_ok = const $crate::stepper::fast::FAST_OK,
                waiting = const $crate::stepper::fast::WAITING,
                raised = const $crate::stepper::fast::RAISED,
                left = const $crate::stepper::fast::LEFT,
                masks = const $crate::stepper::fast::MASKS,
                frac = const $crate::stepper::fast::FRAC,
                interval = const $crate::stepper::fast::INTERVAL,
                add = const $crate::stepper::fast::ADD,
                pulse = const $crate::stepper::fast::PULSE,
                late = const $crate::stepper::fast::LATE,
                lead = const $crate::stepper::fast::LEAD,
                pin0 = const $crate::stepper::fast::PIN0,
                pin1 = const $crate::stepper::fast::PIN1,
            );
        }
    };
}
