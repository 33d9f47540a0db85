//! A timer's compare match that simavr would skip for a whole period.
//!
//! simavr arms a period's compare matches when it handles the timer's
//! overflow (`avr_timer_tov`), and only those still ahead of the cycle it
//! handles it at. Cycle timers run between instructions, so an overflow
//! that falls inside a multi-cycle instruction (`call`, `ret`, an
//! interrupt's entry: up to 5 cycles) is handled a few cycles late, and a
//! compare in those cycles (OCR 0–3 at prescaler 1) is never armed: it
//! comes a whole wrap late, where the part matches it as any other. The
//! firmware's step timer sets such compares (a step 65 536 cycles late in
//! the scheduler's test). After each run of the cycle timers,
//! [`Timers::catch_up`] raises such a compare's interrupt, as late as any
//! interrupt behind a long instruction. Only compares with their output
//! pin disconnected: the pin's action is simavr's own (a static function).

use simavr_ffi::{avr_regbit_t, avr_t, avr_timer_t};
use std::ffi::CStr;

/// The part's timers, each with the overflow base last seen.
pub(crate) struct Timers {
    timers: Vec<(*mut avr_timer_t, u64)>,
}

impl Timers {
    /// The timers of `avr`'s I/O modules.
    ///
    /// # Safety
    /// `avr` is a live, initialised avr_t.
    pub unsafe fn of(avr: *mut avr_t) -> Timers {
        let mut timers = Vec::new();
        let mut io = (*avr).io_port;
        while !io.is_null() {
            let kind = (*io).kind;
            // `avr_timer_t` begins with its `avr_io_t`.
            if !kind.is_null() && CStr::from_ptr(kind).to_bytes() == b"timer" {
                let t = io as *mut avr_timer_t;
                timers.push((t, (*t).tov_base));
            }
            io = (*io).next;
        }
        Timers { timers }
    }

    /// Raise the compares an overflow handled since the last call left
    /// unarmed though their time has come.
    ///
    /// # Safety
    /// `avr` is the live avr_t the timers belong to.
    pub unsafe fn catch_up(&mut self, avr: *mut avr_t) {
        for (t, seen) in self.timers.iter_mut() {
            let t = *t;
            let base = (*t).tov_base;
            if base == *seen {
                continue;
            }
            let period = (*t).tov_cycles;
            // An overflow moves the base on by a period; a reconfiguring
            // write (TCNT, the clock) moves it elsewhere and leaves past
            // compares for the next period, as the part does.
            let overflowed = period != 0 && base == seen.wrapping_add(period);
            *seen = base;
            if !overflowed {
                continue;
            }
            let since = (*avr).cycle.saturating_sub(base);
            for comp in (*t).comp.iter_mut() {
                let at = comp.comp_cycles;
                // `avr_timer_tov` armed it when `at >= since`.
                let skipped = at != 0 && at < period && at < since;
                if skipped && regbit(avr, &comp.com) == 0 {
                    simavr_ffi::avr_raise_interrupt(avr, &mut comp.interrupt);
                }
            }
        }
    }
}

/// The value of a register's bit field (simavr's inline `avr_regbit_get`).
///
/// # Safety
/// `avr` is live and `rb` names one of its I/O registers (or none).
unsafe fn regbit(avr: *mut avr_t, rb: &avr_regbit_t) -> u8 {
    let reg = rb.reg() as usize;
    if reg == 0 {
        return 0;
    }
    (*(*avr).data.add(reg) >> rb.bit()) & rb.mask() as u8
}
