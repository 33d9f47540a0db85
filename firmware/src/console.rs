//! The serial console: G-code lines in, `ok` / `error:<code>` out, Grbl
//! style — the I/O around the executor. The parser (`taut_logic::gcode`)
//! gathers a line's words as its bytes come; the executor
//! (`taut_logic::interp`, both host-tested) checks the line against the
//! modal state and carries its actions out against the machine
//! (`machine_io`), waiting where Grbl waits; this file reads bytes
//! (from the serial line or a card print: `source`), hands whole lines on
//! in Grbl's order (`protocol.c`: overflow, empty, `$`, the G-code lock,
//! G-code) and answers (`answer`). Real-time commands never
//! get here (`realtime`). A line is answered `ok` once its last move is
//! queued, as Grbl does.
//!
//! The console owns the machine's motion only while no string-art job
//! does: during a job the executor refuses motion, drivers, offsets and
//! the pen, and settings are refused here; reads are answered.

mod activity;
mod answer;
mod homing;
mod offsets;
mod seed;
mod source;
mod system;

pub use activity::{Activity, Owner};
pub use offsets::Frame;

use crate::flash_str;
use crate::machine_io::{Io, Trace};
use crate::motion::Motion;
use crate::print::Print;
use crate::queues::{CardAsk, CardNews, Control, Presses, Signal, TellJob, TxClaim};
use crate::reply;
use crate::rt::Poll;
use crate::store::Store;
use homing::HomingRun;
use source::serial_line_waits;
use taut_logic::config::MachineConfig;
use taut_logic::coords::CoordData;
use taut_logic::gcode::{Error, ErrorKind, Input, Parser, Read};
use taut_logic::interp::{
    axis_letters, coords, motor_channels, Allowed, Env, Interpreter, Progress, Wait,
};
use taut_logic::kinematics::Kinematics;
use taut_progmem::{text, Text};
use ufmt::uwrite;

pub struct Console {
    parser: Parser,
    /// The parser holds a line read whole: it is taken in the next run
    /// (reading a line and checking it each take up to ~3 ms).
    line_ready: bool,
    /// The line being carried out is answered `ok` when it is done (not a
    /// card's or a pattern's).
    owed: bool,
    /// A test pattern (`$T5`) read in place of the line, and how far: its
    /// lines are answered once, at its end.
    pattern: Option<(Text, u16)>,
    /// `$$` or `$Q` in progress: its next line.
    listing: Option<Listing>,
    interp: Interpreter,
    /// The motion epoch the executor's position agrees with: a stop that
    /// dropped queued moves starts a new one, and the position is then
    /// read back.
    epoch: u8,
    /// A `$` setting changed since the app last asked.
    settings_changed: bool,
    /// A plotter's print from the card.
    print: Print,
    /// Its end of `JOB_CONTROL`.
    job: TellJob,
    /// Its end of `BUTTONS` (a plotter's card print takes the presses).
    presses: Presses,
    /// Its end of `JOB_CLAIMS_TX`.
    job_claim: TxClaim,
    /// Where the line being read comes from, `None` between lines: while
    /// a print runs, a serial line is read whenever one has arrived whole.
    source: Option<Source>,
    /// The motion queued is jogs (`$J=`): a jog cancel stops it, and
    /// G-code is locked out until it ends (Grbl's `Jog` state).
    jogging: bool,
    /// `$C`: lines are checked and answered, nothing moves.
    checking: bool,
    sleep: Sleep,
    /// Homing (`$H`, at power-on).
    homing: Option<HomingRun>,
    /// Startup lines still to run (a bit each): at boot, after a reset,
    /// after `$H`.
    startup: u8,
    /// The startup line being answered: where its text is.
    echo: u16,
    /// The line being checked is a `$N0=`'s, to keep if it passes.
    storing: bool,
    /// A `$N0=` or `$I=` is being written: answered `ok` once it is.
    saving: bool,
}

/// `$SLP`: until a reset.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Sleep {
    Awake,
    /// Stopping: the drivers go off once the machine stands.
    Falling,
    Asleep,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Source {
    Serial,
    Card,
    /// A startup line from EEPROM.
    Startup,
}

#[derive(Clone, Copy)]
enum Listing {
    Settings(usize),
    Queues(u8),
    Offsets(u8),
    Startup(u8),
}

impl Console {
    pub const fn new(
        card: CardAsk,
        news: CardNews,
        job: TellJob,
        presses: Presses,
        job_claim: TxClaim,
    ) -> Console {
        Console {
            parser: Parser::new(),
            line_ready: false,
            owed: false,
            pattern: None,
            listing: None,
            interp: Interpreter::new(),
            // Unlike the motion's: the first run reads the position through
            // the kinematics (zero steps are not (0, 0) on an arm).
            epoch: u8::MAX,
            settings_changed: false,
            print: Print::new(card, news),
            job,
            presses,
            job_claim,
            source: None,
            jogging: false,
            checking: false,
            sleep: Sleep::Awake,
            homing: None,
            startup: system::STARTUP,
            echo: 0,
            storing: false,
            saving: false,
        }
    }

    /// At power-on: the stored `G54` offset in force.
    pub fn boot(&mut self, coords: &CoordData) {
        self.interp.reset(&coords::stored(coords, 0));
    }

    /// At power-on: a card print a power cut stopped, to go on with once
    /// asked (`M1000`, green).
    pub fn offer_print(&mut self) {
        self.print.offer();
    }

    /// A print's checkpoint header, idle header or offer is still to be
    /// written or said.
    pub fn checkpoint_waits(&self) -> bool {
        self.print.waits_to_keep()
    }

    /// A print under way keeps records of where it is.
    pub fn print_records(&self) -> bool {
        self.print.tracking()
    }

    /// Whether a `$` setting changed since the last call (the app then has
    /// the settings stored).
    pub fn take_settings_changed(&mut self) -> bool {
        core::mem::take(&mut self.settings_changed)
    }

    /// The console's word for the job, the `Realtime` task's too (`~`,
    /// Ctrl-X): false when the job's queue is full.
    pub fn tell_job(&self, c: Control) -> bool {
        self.job.push(c).is_ok()
    }

    /// Ctrl-X: the line in progress, the line being carried out and a
    /// listing are dropped with the bytes not yet read; the modes are
    /// Grbl's power-on ones, `G92` cleared, `G54` (from `coords`) in force
    /// (Grbl's `gc_init`); the startup lines run again.
    pub fn reset(&mut self, coords: &CoordData) {
        self.parser.clear();
        self.line_ready = false;
        self.owed = false;
        self.pattern = None;
        self.listing = None;
        self.interp.reset(&coords::stored(coords, 0));
        self.print.abort();
        self.source = None;
        self.jogging = false;
        self.checking = false;
        self.sleep = Sleep::Awake;
        self.homing = None;
        self.startup = system::STARTUP;
        self.storing = false;
        self.saving = false;
        crate::board::port::clear_input();
    }

    /// A jog cancel (0x85, or `!` or the safety door while jogging): brake
    /// to a stop and drop the jogs queued; the jog being queued is
    /// answered `ok` and dropped on the next run (Grbl answered it when
    /// it took it). False when no jog moves.
    pub fn cancel_jog(&mut self, m: &mut Motion) -> bool {
        if !self.jogging || m.is_idle() {
            return false;
        }
        m.cancel();
        true
    }

    /// The line being carried out was cut short by a stop: dropped, and
    /// answered if it is owed an answer.
    fn drop_line(&mut self) {
        if self.interp.busy() {
            self.interp.drop_line();
            if core::mem::take(&mut self.owed) {
                self.answer_ok();
            }
        }
    }

    /// Read and carry out input until it runs out or must wait.
    #[optimize(speed)]
    pub fn poll(
        &mut self,
        m: &mut Motion,
        kin: &impl Kinematics,
        cfg: &mut MachineConfig,
        owner: Owner,
        store: &mut Store,
    ) -> Poll<Signal> {
        if self.epoch != m.epoch() {
            // The line being carried out ends first, its answer owed: no
            // line is taken or carried on before (one taken meanwhile
            // would be dropped too, answered and never carried out).
            if !reply::room() {
                return Poll::After(2);
            }
            self.epoch = m.epoch();
            // Queued moves were dropped with the motion (homing goes on:
            // its own stops take the epoch; Ctrl-X resets): the line they
            // were part of ends, and the executor reads the position back.
            self.drop_line();
            self.interp
                .resync(&kin.forward(&m.target()), motor_channels(cfg));
        }
        // Only while a print or an offer needs it: each run of a stream
        // of tiny moves comes here.
        if !cfg.machine.is_string_art() && self.print.keeps() {
            self.print.keep(store, m, crate::board::clock::millis());
            // Homing for a resume ended, the position read back.
            if self.print.homing_for_resume() && self.homing.is_none() && self.epoch == m.epoch() {
                self.print.homed(store, m.position_known());
            }
        }
        loop {
            // The step queue is about to run dry inside a planned move:
            // the refill comes first (an underrun is a fault).
            if m.starving() {
                return Poll::Wait(Signal::Refilled);
            }
            // A move staged by the last run is planned a part a run, each
            // ahead of anything else: nothing may wait for it to be queued.
            if m.plan_part() {
                return Poll::Again;
            }
            if !reply::room() || self.job_claim.claimed() {
                return Poll::After(2);
            }
            // A jog cancel or `$SLP` is braking: nothing new until it stands.
            if m.is_cancelling() {
                return Poll::Wait(Signal::PlannerRoom);
            }
            match self.sleep {
                Sleep::Awake => {}
                Sleep::Falling if !m.is_idle() => return Poll::Wait(Signal::PlannerRoom),
                // Only a reset wakes it: lines wait unread.
                Sleep::Asleep => return Poll::Idle,
                Sleep::Falling => {
                    self.sleep = Sleep::Asleep;
                    m.drivers.set(0xFF, false);
                    // The motors may be turned by hand now.
                    m.lose_position();
                    message(text!("Sleeping"));
                    return Poll::Idle;
                }
            }
            if let Some(listing) = self.listing {
                self.list(listing, cfg, store);
                return Poll::Again;
            }
            // A kept text is answered once written, as Grbl's; lines wait
            // until then, after a Ctrl-X too (the text being written is
            // where the store would stage the next one).
            if store.text_saving() {
                return Poll::After(4);
            }
            if self.saving {
                self.saving = false;
                self.ok();
            }
            // A card command waits for the reader.
            if !cfg.machine.is_string_art() && self.card_news(m, cfg, store) {
                return Poll::Idle;
            }
            // A serial line (`M25`, `M27`, `?`-like reads) goes by while
            // the card's line waits for the planner: a held print must
            // still hear `M24`.
            if self.interp.busy() && self.source == Some(Source::Card) && serial_line_waits() {
                self.source = Some(Source::Serial);
                let read = self.read();
                if read == Ok(true) {
                    self.take(m, kin, cfg, owner, store);
                }
                self.source = Some(Source::Card);
                if let Err(wait) = read {
                    return wait;
                }
                continue;
            }
            if self.homing.is_some() {
                return self.home(m, cfg);
            }
            // A line accepted and not yet answered (one with nothing to do
            // is answered here too).
            if self.interp.busy() || self.owed {
                return self.carry_on(m, kin, cfg, owner, store);
            }
            if self.line_ready {
                // A `$` line (`$C`, `$H`, `$J=`, `$SLP`…) sees the tiny
                // moves joined before it queued, as a sender expects.
                if self.interp.joining() && self.parser.first_char() == b'$' {
                    self.interp.flush_soon();
                    continue;
                }
                // A card's line may wait for a resume's travel back.
                if self.source == Some(Source::Card) && !self.card_line_goes(m, kin, cfg, store) {
                    continue;
                }
                self.line_ready = false;
                self.take(m, kin, cfg, owner, store);
                if self.source == Some(Source::Card) {
                    self.card_line_taken(m);
                }
                // One line per run: the other tasks get their turn.
                return Poll::Again;
            }
            match self.startup_line_ready(m, store) {
                Err(wait) => return wait,
                Ok(true) => {
                    self.line_ready = true;
                    return Poll::Again;
                }
                Ok(false) => {}
            }
            match self.read() {
                Err(Poll::Idle) if self.interp.joining() && !self.print.running() => {
                    // The input paused with tiny moves joined: they are
                    // queued once the planner runs low (a card's print
                    // joins as its lines say, whenever they come).
                    if m.planned() >= 2 {
                        return Poll::Wait(Signal::PlannerRoom);
                    }
                    self.interp.flush_soon();
                }
                Err(wait) => return wait,
                // A line read whole is taken in this run, after the
                // checks above (a starving step queue first).
                Ok(true) => self.line_ready = true,
                Ok(false) => {}
            }
        }
    }

    /// The startup lines, each read whole from EEPROM and taken as a line
    /// (`true`), before any other input.
    fn startup_line_ready(&mut self, m: &Motion, store: &Store) -> Result<bool, Poll<Signal>> {
        if self.startup == 0 || self.parser.mid_line() || self.print.busy() {
            return Ok(false);
        }
        if store.busy() {
            return Err(Poll::After(4));
        }
        Ok(self.next_startup_line(m, store))
    }

    /// The executor's view of the machine now.
    fn env<'a, K: Kinematics>(
        &self,
        kin: &'a K,
        cfg: &'a MachineConfig,
        owner: Owner,
    ) -> Env<'a, K> {
        Env {
            kin,
            cfg,
            allowed: Allowed {
                motion: owner == Owner::Console,
                checking: self.checking || self.print.replaying(),
            },
        }
    }

    /// Carry out what is left of the accepted line; `ok` once it is done.
    /// Out of line: a path's piece is worked out in its frame.
    #[inline(never)]
    #[optimize(speed)]
    fn carry_on(
        &mut self,
        m: &mut Motion,
        kin: &impl Kinematics,
        cfg: &MachineConfig,
        owner: Owner,
        store: &mut Store,
    ) -> Poll<Signal> {
        let env = self.env(kin, cfg, owner);
        let mut io = Io {
            m,
            kin,
            store,
            replies: self.owed,
            trace: self.print.trace().map(|left| Trace {
                left,
                pen_deg: self.interp.pen_now(cfg.pen.up_deg),
                settle_ms: cfg.pen.settle_ms,
            }),
        };
        match self.interp.run(&env, &mut io) {
            Progress::Done => {
                if core::mem::take(&mut self.owed) {
                    self.answer_ok();
                }
                Poll::Again
            }
            Progress::Wait(Wait::PlannerRoom) => Poll::Wait(Signal::PlannerRoom),
            Progress::Wait(Wait::Refill) => Poll::Wait(Signal::Refilled),
            Progress::Wait(Wait::Ms(ms)) => Poll::After(ms),
            Progress::Wait(Wait::Again) => Poll::Again,
        }
    }

    /// Read bytes until a line is complete (`Ok(true)`) or a run's share
    /// is read; `Err` when the bytes ran out. Out of line: the parser's
    /// frame stays off the one that carries lines out.
    #[inline(never)]
    #[optimize(speed)]
    fn read(&mut self) -> Result<bool, Poll<Signal>> {
        let mut budget = READ_PER_RUN;
        while budget > 0 {
            // Mid-line from the card: the bytes in place, a run at a time
            // (one parser step a byte, without a byte's own fetch).
            if self.source == Some(Source::Card) && self.parser.mid_line() && self.pattern.is_none()
            {
                if let Some((at, of)) = self.print.run() {
                    let parser = &mut self.parser;
                    let (n, lines, last, end) = crate::card::bytes(at, of.min(budget), |s| {
                        let mut lines = 0;
                        for (i, &b) in s.iter().enumerate() {
                            lines += (b == b'\n') as u8;
                            let end = parser.read(b) == Read::LineEnd;
                            // A line end, or a Ctrl-X that began the line
                            // again (the next line's source is chosen anew).
                            if end || !parser.mid_line() {
                                return (i as u8 + 1, lines, b, end);
                            }
                        }
                        (s.len() as u8, lines, s[s.len() - 1], false)
                    });
                    self.print.took_run(n, of, lines, last);
                    if end {
                        self.print.line_done();
                        return Ok(true);
                    }
                    budget -= n;
                    continue;
                }
            }
            budget -= 1;
            let byte = match self.pattern.as_mut() {
                Some((text, at)) if usize::from(*at) < text.len() => {
                    *at += 1;
                    text.byte(usize::from(*at) - 1)
                }
                // The pattern is drawn: its one answer.
                Some(_) => {
                    self.pattern = None;
                    reply::ok();
                    return Ok(false);
                }
                None => match self.next_byte() {
                    Some(byte) => byte,
                    None => return Err(Poll::Idle),
                },
            };
            if self.parser.read(byte) == Read::LineEnd {
                if self.source == Some(Source::Card) {
                    self.print.line_done();
                }
                return Ok(true);
            }
        }
        // The rest of a long line in the next run: every task waits
        // behind this one.
        Err(Poll::Again)
    }

    /// A line read whole, taken in Grbl's order (`protocol.c` lines
    /// 88–102): overflow, empty, `$`, the G-code lock (alarm or jog),
    /// G-code. Out of line: the line (~100 B) is on the stack only here.
    #[inline(never)]
    fn take(
        &mut self,
        m: &mut Motion,
        kin: &impl Kinematics,
        cfg: &mut MachineConfig,
        owner: Owner,
        store: &mut Store,
    ) {
        // The next line's words are the machine's (`$machine=` may change them).
        self.parser.set_axis_letters(axis_letters(&kin.words()));
        let first = self.parser.first_char();
        let jog_state = self.jogging && !m.is_idle();
        let line = self.parser.take_line();
        // A `$N0=` line must be G-code.
        if self.storing && !matches!(line, Ok(Input::Block(_))) {
            self.stored_checked(false, store);
            if line.is_ok() {
                return self.error(&Error::new(ErrorKind::ExpectedCommandLetter, 1));
            }
        }
        let reads = matches!(&line, Ok(Input::Block(b)) if b.only_reads());
        match line {
            Ok(Input::Realtime(_)) => {}
            Err(e) if e.kind() == ErrorKind::LineOverflow => self.error(&e),
            // Empty or comment only: for syncing, `ok`.
            _ if first == 0 => {
                self.say_message();
                self.ok()
            }
            Ok(Input::System(ref s)) => self.system(s, m, cfg, owner, store),
            Ok(Input::Jog(_))
                if self.checking || !m.position_known() || !(m.is_idle() || jog_state) =>
            {
                self.error(&Error::new(ErrorKind::NotIdle, 0))
            }
            Ok(Input::Jog(_)) if self.printing_from_serial() => {
                self.error(&Error::new(ErrorKind::Printing, 0))
            }
            Ok(Input::Jog(b)) => {
                if self.accept(&b, true, m, kin, cfg, owner, store) {
                    self.jogging = true;
                }
            }
            // `$` lines and jogs that did not parse.
            Err(e) if first == b'$' => self.error(&e),
            // A program's `%` delimiters in a file: passed over (Grbl
            // answers a sender error 1).
            _ if first == b'%' && self.source == Some(Source::Card) => {}
            Ok(Input::Card(c)) => self.card_line(c, m, cfg, store),
            // Grbl's G-code lock: in alarm (the position lost) or while
            // jogs run; `M114` only reads.
            _ if (!m.position_known() || jog_state) && !reads => {
                self.error(&Error::new(ErrorKind::Locked, 0))
            }
            Err(e) => self.error(&e),
            Ok(Input::Seed(s)) => self.seed(s, m, kin, cfg, owner, store),
            // While a print runs, the serial line may only look: `M114`
            // is answered at once, beside the print's own line.
            Ok(Input::Block(_)) if self.printing_from_serial() && reads => {
                crate::machine_io::report_position(m, kin);
                self.ok()
            }
            Ok(Input::Block(_)) if self.printing_from_serial() => {
                self.error(&Error::new(ErrorKind::Printing, 0))
            }
            Ok(Input::Block(b)) => {
                self.jogging = false;
                let accepted = self.accept(&b, false, m, kin, cfg, owner, store);
                if accepted {
                    self.say_message();
                }
                // A `$N0=` line: carried out, and kept if it passed.
                if self.storing {
                    self.stored_checked(accepted, store);
                }
            }
        }
    }

    /// Hand a block to the executor; its error is the answer, else it is
    /// carried out from the next run. True if accepted.
    #[inline(never)]
    #[allow(clippy::too_many_arguments)] // the executor's context, by reference
    fn accept(
        &mut self,
        b: &taut_logic::gcode::Block,
        jog: bool,
        m: &mut Motion,
        kin: &impl Kinematics,
        cfg: &MachineConfig,
        owner: Owner,
        store: &mut Store,
    ) -> bool {
        // A `$N0=` line is answered once kept.
        let owed = self.pattern.is_none() && self.source != Some(Source::Card) && !self.storing;
        let env = self.env(kin, cfg, owner);
        let mut io = Io {
            m,
            kin,
            store,
            replies: owed,
            trace: None,
        };
        match self.interp.accept(b, jog, &env, &mut io) {
            Ok(()) => {
                self.owed = owed;
                true
            }
            Err(kind) => {
                self.error(&Error::new(kind, 0));
                false
            }
        }
    }

    /// Read the programmed position back through the kinematics on the
    /// next run (the machine moved, or is another one), as after a stop.
    fn resync_next_run(&mut self, m: &Motion) {
        self.epoch = m.epoch().wrapping_add(1);
    }
}

/// Grbl's feedback message: `[MSG:<text>]`.
fn message(text: Text) {
    let mut r = reply::line();
    let _ = uwrite!(r, "{}{}]", flash_str!("[MSG:"), text);
    r.send();
}

/// Bytes parsed in one run at most: ~0.03 ms a byte (the fetch and the
/// parser's ~450 cycles), so a run stays under 1 ms, which a `?` or any
/// task waits behind (carrying a line out takes as long); a line of a
/// stream of tiny moves (~20 bytes) in one run, its own cost (~2 000
/// cycles) paid once.
const READ_PER_RUN: u8 = 24;
