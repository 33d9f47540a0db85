//! Running the MCU: watching for a crash, a hang, a watchdog reset and the
//! stack crossing into the statics, timing the interrupts-masked spans, and
//! applying the outside world's inputs when they fall due.
//!
//! simavr runs the instructions in batches (its own loop, up to the next
//! cycle timer): the run loop's deadlines (the next input, the next poll,
//! the end) are a cycle timer too, and every change the loop must see at
//! the instruction boundary where it happens ends the batch there — a pin
//! edge or UART byte (callbacks), the stack pointer going below its lowest
//! (its register writes), the I flag going off (SREG writes, interrupt
//! entry, and each `cli`, trapped: see `traps`) or on (simavr stops for
//! that itself), an invalid opcode, reaching address 0 (trapped), sleep.
//! So every figure is what instruction-by-instruction watching gives.
//! Watches of program addresses, call timing and the profile need every
//! instruction: with any of them on, it runs one instruction at a time.

use crate::clock::cycles_in;
use crate::elf::RAM_END;
use crate::outcome::Outcome;
use crate::serial::{self, SerialLine, CYCLES_PER_BYTE};
use crate::sim::{Core, Executed, Sim};
use crate::traps::ZeroOrigin;
use std::time::{Duration, Instant};

/// A predicate is checked after anything a callback reported, and at least
/// this often (100 µs of simulated time) in between.
const POLL_CYCLES: u64 = 1_600;

impl Sim {
    /// Runs for a simulated duration. `Running` when it went the distance.
    pub fn run_for(&mut self, duration: Duration) -> Outcome {
        self.run_until(|_| false, duration)
    }

    /// Runs until `done` holds (`Done`), the firmware fails, or `timeout` of
    /// simulated time passes (`Running`). `done` sees the simulator after
    /// every pin edge or UART byte and at least every 100 µs.
    pub fn run_until(&mut self, done: impl FnMut(&Sim) -> bool, timeout: Duration) -> Outcome {
        self.run_until_cycles(done, cycles_in(timeout))
    }

    /// Runs at least `cycles` cycles (ends on an instruction boundary).
    pub fn run_cycles(&mut self, cycles: u64) -> Outcome {
        self.run_until_cycles(|_| false, cycles)
    }

    /// Runs to cycle `at` since power-on exactly: it stops on the first
    /// instruction boundary at or past it, a sleep included (a sleep
    /// stretch otherwise runs on to the next timer event, the deadline
    /// taken out so the stretch is the same with or without the harness
    /// looking). For the end of a run, such as a power cut.
    pub fn run_to(&mut self, at: u64) -> Outcome {
        let now = self.cycles();
        if at <= now {
            return self.ended.unwrap_or(Outcome::Running);
        }
        self.shared_mut().hard_deadline = true;
        let o = self.run_until_cycles(|_| false, at - now);
        self.shared_mut().hard_deadline = false;
        o
    }

    /// `run_until` with the timeout in cycles.
    pub fn run_until_cycles(
        &mut self,
        mut done: impl FnMut(&Sim) -> bool,
        timeout: u64,
    ) -> Outcome {
        if let Some(end) = self.ended {
            return end;
        }
        let start = self.cycles();
        let deadline = start + timeout;
        let wall = Instant::now();
        let batched =
            self.profile.is_none() && self.pc_watches.is_empty() && self.call_watches.is_empty();
        let mut next_poll = start;
        let mut seen_events = None;
        let mut next_input = 0;
        let outcome = loop {
            let now = self.cycles();
            let events = self.shared().events;
            // Inputs first: `done` sees the world as of this cycle.
            if now >= next_input || seen_events != Some(events) {
                next_input = self.apply_inputs(now);
            }
            if now >= next_poll || seen_events != Some(events) {
                if done(self) {
                    break Outcome::Done;
                }
                next_poll = now + POLL_CYCLES;
            }
            seen_events = Some(self.shared().events);
            if now >= deadline {
                break Outcome::Running;
            }
            let budget = batched.then(|| next_input.min(next_poll).min(deadline) - now);
            if let Some(end) = self.step(budget) {
                break end;
            }
        };
        self.clear_deadline();
        // Without traps (a board with a bootloader) nothing is watched.
        let trapped = !self.code.is_empty();
        if std::mem::take(&mut self.shared_mut().unseen_mask) && trapped && !self.warned_unseen_mask
        {
            self.warned_unseen_mask = true;
            eprintln!(
                "taut-simavr: interrupts were masked by code outside the ELF's code symbols \
                 (an untrapped cli): interrupts-masked figures may be short"
            );
        }
        self.last_speed = Some((self.cycles() - start, wall.elapsed()));
        if outcome.is_fatal() {
            self.ended = Some(outcome);
        }
        outcome
    }

    /// Runs until the UART output holds `text`.
    pub fn run_until_uart_contains(&mut self, text: &str, timeout: Duration) -> Outcome {
        self.run_until_line_contains(false, text, timeout)
    }

    /// Runs until USART1's output holds `text`.
    pub fn run_until_uart1_contains(&mut self, text: &str, timeout: Duration) -> Outcome {
        self.run_until_line_contains(true, text, timeout)
    }

    fn run_until_line_contains(&mut self, uart1: bool, text: &str, timeout: Duration) -> Outcome {
        let needle = text.as_bytes().to_vec();
        let mut searched = 0;
        self.run_until(
            |sim| {
                let tx = match uart1 {
                    false => &sim.shared().uart.tx,
                    true => &sim.shared().uart1.tx,
                };
                let from = serial::resume_from(searched.min(tx.len()), needle.len());
                searched = tx.len();
                serial::contains(&tx[from..], &needle)
            },
            timeout,
        )
    }

    /// Applies input changes due by `now`; returns the cycle of the next one.
    fn apply_inputs(&mut self, now: u64) -> u64 {
        while let Some((pin, high)) = self.schedule.pop_due(now) {
            self.drive(pin, high);
        }
        self.update_endstops();
        let slot = &mut self.shared_mut().sd;
        slot.apply_due(now);
        let card_due = slot.next_due().unwrap_or(u64::MAX);
        let mut next = self.schedule.next_due().unwrap_or(u64::MAX);
        next = next.min(card_due);
        let uart1_byte = self.uart1_cycles_per_byte();
        for (uart1, byte_time) in [(false, CYCLES_PER_BYTE), (true, uart1_byte)] {
            fn line(sim: &mut Sim, uart1: bool) -> &mut SerialLine {
                match uart1 {
                    false => &mut sim.shared_mut().uart,
                    true => &mut sim.shared_mut().uart1,
                }
            }
            next = next.min(line(self, uart1).release_due(now).unwrap_or(u64::MAX));
            let l = line(self, uart1);
            if l.rx_ready && !l.rx.is_empty() && l.flowing() {
                if now >= l.next_rx_cycle {
                    let byte = l.rx.pop_front().unwrap_or_default();
                    l.next_rx_cycle = now + byte_time;
                    l.in_fifo += 1;
                    if l.in_fifo >= crate::serial::FIFO_BYTES {
                        // The next waits for the firmware to read these.
                        l.rx_ready = false;
                    }
                    self.raise_uart_rx(uart1, byte);
                }
                next = next.min(line(self, uart1).next_rx_cycle);
            }
        }
        next
    }

    /// Executes one instruction, or a batch of them for at most `budget`
    /// cycles, or one sleep stretch, and says whether it ended the run.
    fn step(&mut self, budget: Option<u64>) -> Option<Outcome> {
        let Executed {
            pc_before,
            pc,
            avr_cycle: cycle,
            interrupts_on,
            core,
        } = self.execute(budget);
        if cycle < self.last_avr_cycle {
            // Only a reset sets simavr's counter back, and in a run only the
            // watchdog resets.
            let last = self.last_avr_cycle;
            let before = self.shared_mut().reset_at.take().unwrap_or(last);
            self.after_reset(before);
            self.last_avr_cycle = cycle;
            self.resets += 1;
            return Some(Outcome::WatchdogReset { count: self.resets });
        }
        if let Some(profile) = &mut self.profile {
            profile.add(pc_before, cycle - self.last_avr_cycle);
        }
        let sp = self.profile.is_some().then(|| self.sp());
        if let (Some(profile), Some(sp)) = (&mut self.profile, sp) {
            profile.after(cycle - self.last_avr_cycle, pc, sp);
        }
        self.last_avr_cycle = cycle;
        let now = self.shared().cycle_base + cycle;
        self.masked.observe(now, pc, interrupts_on);
        for (at, hits) in &mut self.pc_watches {
            if *at == pc {
                hits.push(now);
            }
        }
        match core {
            Core::Crashed => {
                let at = self.shared().crash_pc.unwrap_or(pc_before);
                return Some(Outcome::Crashed { pc: at });
            }
            // The `sleep` (one word) that found the interrupts masked.
            Core::Hung => return Some(Outcome::Hung { pc: pc - 2 }),
            Core::Running | Core::Sleeping => {}
        }
        if let Some(pc) = self.shared().bad_opcode_pc {
            return Some(Outcome::Crashed { pc });
        }
        if pc == 0 && self.shared().zero_trap {
            let from = match budget {
                None => pc_before,
                Some(_) => ZeroOrigin {
                    flash: &self.code,
                    ranges: &self.code_ranges,
                    last_sp_write: self.shared().last_sp_write,
                    arrived: cycle,
                    z: self.z(),
                }
                .find()
                .unwrap_or(pc_before),
            };
            return Some(Outcome::Crashed { pc: from });
        }
        let sp = self.sp();
        for w in &mut self.call_watches {
            w.observe(pc, sp, now);
        }
        if sp < self.min_sp && !self.sp_half_written(pc) {
            self.min_sp = sp;
            self.min_sp_pc = pc;
            if self.peak_stack.is_some() {
                self.peak_stack = Some(self.ram(sp + 1, usize::from(RAM_END - sp)));
            }
            self.shared_mut().sp_floor = sp;
            // The last push wrote at sp + 1.
            if u32::from(sp) + 1 < u32::from(self.ram_limit) {
                return Some(Outcome::StackOverflow {
                    sp,
                    limit: self.ram_limit,
                });
            }
        }
        None
    }

    /// Whether the stack pointer holds half of a 16-bit update: the code
    /// wrote SPH and writes SPL next, with at most the SREG restore between
    /// (the compilers' frame set-up: `out SPH; out SREG; out SPL`). The I
    /// flag that restore may set takes effect only after the next
    /// instruction (in simavr too), so nothing uses the stack at the
    /// half-written value, which may lie up to 255 bytes below both the old
    /// and the new one: the new depth counts once SPL is written.
    fn sp_half_written(&self, pc: u32) -> bool {
        use crate::hooks::{out_to, SPL};
        const SREG: usize = 0x5F;
        if !self.shared().sph_alone {
            return false;
        }
        let avr = self.avr.as_ptr();
        // SAFETY: `avr` is live; `flash` holds `flashend + 1` bytes, and
        // `pc + 4` is checked against it.
        unsafe {
            let flash = (*avr).flash;
            if pc + 4 > (*avr).flashend + 1 {
                return false;
            }
            match out_to(flash, pc) {
                Some(SPL) => true,
                Some(SREG) => out_to(flash, pc + 2) == Some(SPL),
                _ => false,
            }
        }
    }
}
