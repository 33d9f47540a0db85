//! The serial console: G-code lines in, `ok` / `error:<code>` out, Grbl
//! style — the I/O around the interpreter. The parser (`taut_logic::gcode`)
//! turns bytes into lines, the interpreter (`taut_logic::interp`, both
//! host-tested) turns a line into an order with the modal state it leaves;
//! this file carries the order out against the motion task's state and
//! only then commits the line. Real-time commands never get here
//! (`realtime`). An arc, or a straight move of a machine whose kinematics
//! are not linear, is queued piece by piece, a piece a run, and answered
//! `ok` once its last piece is queued, as Grbl does.
//!
//! The console owns the machine's motion only while no string-art job
//! does: during a job the interpreter refuses motion, drivers and `G92`,
//! and settings are refused here; reads are answered.
#![deny(unsafe_code)]

mod system;

use crate::board::clock;
use crate::endstop;
use crate::motion::Motion;
use crate::print::Print;
use crate::queues::{Signal, BUTTONS, JOB_CLAIMS_TX, RX};
use crate::reply;
use crate::rt::Poll;
use crate::store::Store;
use crate::{flash_str, info};
use core::sync::atomic::Ordering::Relaxed;
use taut_logic::axis::AXES;
use taut_logic::buttons::ButtonEvent;
use taut_logic::config::{MachineConfig, PenConfig};
use taut_logic::gcode::{CardLine, Error, ErrorKind, Input, Line, Parser, Read};
use taut_logic::homing::{self, Homing, HomingError, Leg, Next};
use taut_logic::interp::{Allowed, Interpreter, Order, Path};
use taut_logic::kinematics::Kinematics;
use taut_logic::pinmap::Button;
use taut_logic::planner::Feed;
use taut_logic::units::{Decimal, Milli};
use taut_progmem::{text, Text};
use ufmt::uwrite;

pub struct Console {
    parser: Parser,
    /// The line being carried out while it waits for room.
    pending: Option<Pending>,
    /// A test pattern (`$T5`) read in place of the line, and how far: its
    /// lines are answered once, at its end.
    pattern: Option<(Text, u16)>,
    dwell_until: Option<u32>,
    /// `$$` or `$Q` in progress: its next line.
    listing: Option<Listing>,
    interp: Interpreter,
    /// The motion epoch the interpreter's position agrees with: a stop that
    /// dropped queued moves starts a new one, and the position is then
    /// read back.
    epoch: u8,
    /// A `$` setting changed since the app last asked.
    settings_changed: bool,
    /// A plotter's print from the card.
    print: Print,
    /// Where the line being read comes from, `None` between lines: while
    /// a print runs, a serial line is read whenever one has arrived whole.
    source: Option<Source>,
    /// The motion queued is jogs (`$J=`): a jog cancel stops it, other
    /// lines wait for it to end.
    jogging: bool,
    /// `$C`: lines are checked and answered, nothing moves.
    checking: bool,
    sleep: Sleep,
    /// Startup lines still to run (a bit each): at boot, after a reset,
    /// after `$H`.
    startup: u8,
    /// The startup line being answered: where its text is.
    echo: u16,
    /// The line waiting in `pending` is a `$N0=`'s, to check and keep.
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

enum Pending {
    /// Read but not yet carried out (back-pressure).
    Line(Line),
    /// A jog (`$J=`) the same way.
    Jog(Line),
    /// A path whose line was taken, its pieces not all queued yet.
    Path { path: Path, feed: Feed },
    /// Homing (`G28`, `$H`, at power-on), a leg moving or not; `reply`:
    /// answer `ok` at the end (a line asked for it).
    Home {
        homing: Homing,
        moving: bool,
        reply: bool,
    },
}

#[derive(Clone, Copy)]
enum Listing {
    Settings(usize),
    Queues(u8),
    Offsets(u8),
    Startup(u8),
}

/// What the console is doing, for the status report.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Activity {
    /// Reading and carrying out lines.
    Lines,
    Homing,
    Jogging,
    /// `$C`: checking lines without moving.
    Checking,
    /// `$SLP`: the drivers off until a reset.
    Sleeping,
}

/// Who may move the machine now.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Owner {
    Console,
    /// A string-art job is drilling or winding (or paused in it).
    Job,
}

impl Console {
    pub const fn new() -> Console {
        Console {
            parser: Parser::new(),
            pending: None,
            pattern: None,
            dwell_until: None,
            listing: None,
            interp: Interpreter::new(),
            // Unlike the motion's: the first run reads the position through
            // the kinematics (zero steps are not (0, 0) on an arm).
            epoch: u8::MAX,
            settings_changed: false,
            print: Print::new(),
            source: None,
            jogging: false,
            checking: false,
            sleep: Sleep::Awake,
            startup: system::STARTUP,
            echo: 0,
            storing: false,
            saving: false,
        }
    }

    /// Whether a `$` setting changed since the last call (the app then has
    /// the settings stored).
    pub fn take_settings_changed(&mut self) -> bool {
        core::mem::take(&mut self.settings_changed)
    }

    /// Ctrl-X: the line in progress, a waiting line and a listing are
    /// dropped with the bytes not yet read; modal state is Grbl's default.
    pub fn reset(&mut self) {
        self.parser = Parser::new();
        self.pending = None;
        self.pattern = None;
        self.dwell_until = None;
        self.listing = None;
        self.interp.reset();
        self.print.abort();
        self.source = None;
        self.jogging = false;
        self.checking = false;
        self.sleep = Sleep::Awake;
        self.startup = system::STARTUP;
        self.storing = false;
        self.saving = false;
        RX.clear();
    }

    /// A jog cancel (0x85, or `!` or the safety door while jogging): brake
    /// to a stop and drop the jogs queued; the jogs read and not yet
    /// queued are answered `ok` and dropped on the next run (Grbl answered
    /// them when it took them). False when no jog moves.
    pub fn cancel_jog(&mut self, m: &mut Motion) -> bool {
        if !self.jogging || m.is_idle() {
            return false;
        }
        m.cancel();
        true
    }

    /// The safety door while homing: stop at once, not homed (Grbl's alarm
    /// 7); the line that asked is answered `ok`, as Grbl's.
    pub fn abort_homing(&mut self, m: &mut Motion) {
        let Some(Pending::Home { reply, .. }) = self.pending else {
            return;
        };
        endstop::disarm();
        m.stop_now();
        m.lose_position();
        self.pending = None;
        self.resync_next_run(m);
        reply::alarm(7);
        if reply {
            self.ok();
        }
    }

    /// Drop a jog that waited to be queued or was being queued piece by
    /// piece (a jog cancel), answering it.
    fn drop_jog(&mut self) {
        if self.jogging && matches!(self.pending, Some(Pending::Jog(_) | Pending::Path { .. })) {
            self.pending = None;
            self.ok();
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
            self.epoch = m.epoch();
            // Queued pieces were dropped with the motion (homing goes on:
            // its own stops bump the epoch too; Ctrl-X resets it); a
            // cancelled jog's are answered.
            if reply::room() {
                self.drop_jog();
            }
            if let Some(Pending::Path { .. }) = self.pending {
                self.pending = None;
            }
            self.interp.resync(kin.forward(&m.target()));
        }
        loop {
            // A move staged by the last run is planned a part a run, each
            // ahead of anything else: nothing may wait for it to be queued.
            if m.plan_part() {
                return Poll::Again;
            }
            if !reply::room() || JOB_CLAIMS_TX.load(Relaxed) {
                return Poll::After(2);
            }
            // A jog cancel or `$SLP` is braking: nothing new until it stands.
            if m.is_cancelling() {
                self.drop_jog();
                return Poll::Wait(Signal::Motion);
            }
            match self.sleep {
                Sleep::Awake => {}
                Sleep::Falling if !m.is_idle() => return Poll::Wait(Signal::Motion),
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
            if !cfg.machine.is_string_art() && self.card_news(m) {
                return Poll::Idle;
            }
            // A serial line (`M25`, `M27`, `?`-like reads) goes by while
            // the card's line waits for the planner: a held print must
            // still hear `M24`.
            if self.pending.is_some() && self.source == Some(Source::Card) && serial_line_waits() {
                self.source = Some(Source::Serial);
                let read = self.read(m, cfg, owner, store);
                self.source = Some(Source::Card);
                if let Err(wait) = read {
                    return wait;
                }
                continue;
            }
            let jog = match &self.pending {
                Some(Pending::Path { .. }) => return self.next_piece(m, kin),
                Some(Pending::Home { .. }) => return self.home(m, cfg),
                Some(Pending::Line(_)) => Some(false),
                Some(Pending::Jog(_)) => Some(true),
                None => None,
            };
            if let Some(jog) = jog {
                // Other lines wait for the jogs to end.
                if !jog && self.jogging {
                    if !m.is_idle() {
                        return Poll::Wait(Signal::Motion);
                    }
                    self.jogging = false;
                }
                if let Some(wait) = self.run_line(jog, m, kin, cfg, owner, store) {
                    return wait;
                }
                // One line per run: the other tasks get their turn.
                return Poll::Again;
            }
            // The startup lines first, each read whole from EEPROM.
            if self.startup != 0 && !self.parser.mid_line() && !self.print.busy() {
                if store.busy() {
                    return Poll::After(4);
                }
                self.next_startup_line(m, store);
                continue;
            }
            if let Err(wait) = self.read(m, cfg, owner, store) {
                return wait;
            }
            // A line read whole is carried out in a run of its own: reading
            // and planning one each take up to ~3 ms, and `?` waits for
            // the run in progress.
            if matches!(self.pending, Some(Pending::Line(_) | Pending::Jog(_))) {
                return Poll::Again;
            }
        }
    }

    /// Plan the line (or the jog) waiting in `pending`, then carry it out
    /// and commit it, or in check mode only commit it; `Some(wait)` when it
    /// must wait (it stays in `pending`). The line is read where it waits,
    /// not copied. Out of line: its plan (arc-sized) stays off the frame
    /// that reads lines and runs `$` commands.
    #[inline(never)]
    fn run_line(
        &mut self,
        jog: bool,
        m: &mut Motion,
        kin: &impl Kinematics,
        cfg: &MachineConfig,
        owner: Owner,
        store: &mut Store,
    ) -> Option<Poll<Signal>> {
        let allowed = Allowed {
            motion: owner == Owner::Console,
            position_known: m.position_known(),
        };
        let planned = match &self.pending {
            Some(Pending::Line(line) | Pending::Jog(line)) => {
                self.interp.plan(line, kin, cfg, allowed)
            }
            _ => return None,
        };
        // A `$N0=` line: checked, kept, not carried out.
        if self.storing {
            self.pending = None;
            self.stored_checked(planned.is_ok(), store);
        }
        let planned = match planned {
            Err(kind) => {
                self.pending = None;
                self.error(&Error::new(kind, 0));
                return None;
            }
            Ok(_) if self.saving => return None,
            Ok(planned) => planned,
        };
        if self.checking {
            // Checked, not carried out; reads are still answered.
            self.pending = None;
            if matches!(planned.order, Order::ReportPosition) {
                report_position(m, kin);
            }
            self.interp.commit(&planned);
            self.ok();
            return None;
        }
        // A path or homing takes `pending`'s place.
        if let Some(wait) = self.carry_out(&planned.order, m, kin) {
            return Some(wait);
        }
        match jog {
            true => self.interp.commit_jog(&planned),
            false => self.interp.commit(&planned),
        }
        self.jogging |= jog;
        if matches!(self.pending, Some(Pending::Line(_) | Pending::Jog(_))) {
            self.pending = None;
            self.ok();
        }
        None
    }

    /// Read bytes until an input is complete, and take it: a G-code line
    /// waits in `pending`, the others are carried out. `Err` when the
    /// bytes ran out. Out of line: the parser's copies of a line stay off
    /// the frame that plans and cuts moves.
    #[inline(never)]
    #[optimize(speed)]
    fn read(
        &mut self,
        m: &mut Motion,
        cfg: &mut MachineConfig,
        owner: Owner,
        store: &mut Store,
    ) -> Result<(), Poll<Signal>> {
        let mut budget = READ_PER_RUN;
        loop {
            // The rest of a long line in the next run: every task waits
            // behind this one.
            if budget == 0 {
                return Err(Poll::Again);
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
                    return Ok(());
                }
                None => match self.next_byte() {
                    Some(byte) => byte,
                    None => return Err(Poll::Idle),
                },
            };
            if self.parser.read(byte) == Read::LineEnd {
                self.line_end(m, cfg, owner, store);
                return Ok(());
            }
        }
    }

    /// A line has ended: its result, acted on. Out of line, so the line
    /// (~100 B) is on the stack only here, not while bytes are read.
    #[inline(never)]
    fn line_end(
        &mut self,
        m: &mut Motion,
        cfg: &mut MachineConfig,
        owner: Owner,
        store: &mut Store,
    ) {
        if self.source == Some(Source::Card) {
            self.print.line_done();
        }
        match self.parser.take_line() {
            Ok(Input::Realtime(_)) => {}
            Err(e) => self.error(&e),
            // While a print runs, the serial line may only look.
            Ok(Input::Line(_)) if self.printing_from_serial() => {
                self.error(&Error::new(ErrorKind::Printing, 0))
            }
            Ok(Input::Line(line)) => self.pending = Some(Pending::Line(line)),
            // Grbl jogs from `Idle` or `Jog` only.
            Ok(Input::Jog(_)) if self.checking || !(m.is_idle() || self.jogging) => {
                self.error(&Error::new(ErrorKind::NotIdle, 0))
            }
            Ok(Input::Jog(line)) => self.pending = Some(Pending::Jog(line)),
            Ok(Input::System(ref s)) => self.system(s, m, cfg, owner, store),
            Ok(Input::Card(c)) => self.card_line(c, m, cfg),
        }
    }

    /// The next byte of the line being read: a line from the card, or
    /// from the serial line once it has arrived whole while a print runs
    /// (its lines are not cut into by the card's).
    #[inline(never)]
    fn next_byte(&mut self) -> Option<u8> {
        if self.source == Some(Source::Card) && !self.print.running() {
            // The print stopped mid-line: the part read is dropped (a lost
            // print reads the line again).
            self.parser = Parser::new();
            self.source = None;
        }
        if !self.parser.mid_line() {
            self.source = Some(match self.print.running() && !serial_line_waits() {
                true => Source::Card,
                false => Source::Serial,
            });
        }
        let byte = match self.source {
            Some(Source::Card) => self.print.next_byte(),
            _ => RX.pop(),
        };
        if byte.is_none() {
            self.print.finished();
        }
        byte
    }

    /// A serial line while a print runs.
    fn printing_from_serial(&self) -> bool {
        self.print.busy() && self.source != Some(Source::Card)
    }

    /// A plotter's buttons and card messages; `true` while a card command
    /// still waits for the reader.
    #[inline(never)]
    fn card_news(&mut self, m: &mut Motion) -> bool {
        self.green_button(m);
        let waited = self.print.waiting();
        match self.print.take_messages() {
            Some(Ok(())) => self.ok(),
            Some(Err(kind)) => self.error(&Error::new(kind, 0)),
            None => return waited,
        }
        false
    }

    /// The green button on a plotter: go on after a hold or `M0`, else
    /// start the selected file, go on with a lost one, or start the
    /// card's first G-code file.
    #[inline(never)]
    fn green_button(&mut self, m: &mut Motion) {
        while let Some(event) = BUTTONS.pop() {
            if event == ButtonEvent::Pressed(Button::Confirm)
                && !m.resume()
                && self.print.start(false).is_err()
            {
                self.print.start_first();
            }
        }
    }

    /// `M20`, `M23`…: a plotter's card print (the string-art job owns the
    /// card on its machine; a file cannot run card commands).
    #[inline(never)]
    #[optimize(size)]
    fn card_line(&mut self, c: CardLine, m: &mut Motion, cfg: &MachineConfig) {
        if cfg.machine.is_string_art() || self.source == Some(Source::Card) {
            return self.error(&Error::new(ErrorKind::UnsupportedCommand, 1));
        }
        let done = match c {
            CardLine::List => self.print.list(),
            CardLine::Mount => Ok(()),
            CardLine::Select(name) => self.print.select(name),
            CardLine::Start if m.resume() => Ok(()),
            CardLine::Start => self.print.start(true),
            CardLine::Pause => {
                if self.print.running() {
                    m.hold();
                }
                Ok(())
            }
            CardLine::Progress => {
                self.print.progress();
                Ok(())
            }
            CardLine::Abort => {
                self.print.abort();
                Ok(())
            }
        };
        match done {
            Err(kind) => self.error(&Error::new(kind, 0)),
            // Answered when the reader has.
            Ok(()) if self.print.waiting() => {}
            Ok(()) => self.ok(),
        }
    }

    /// Carry out an order; `Some(wait)` when it cannot run yet.
    #[optimize(speed)]
    fn carry_out(
        &mut self,
        order: &Order,
        m: &mut Motion,
        kin: &impl Kinematics,
    ) -> Option<Poll<Signal>> {
        let after_motion = matches!(
            order,
            Order::Dwell { .. }
                | Order::Pen { .. }
                | Order::Pause
                | Order::SetPosition { .. }
                | Order::Drivers { on: false }
                | Order::WaitIdle
        );
        if after_motion && !m.is_idle() {
            return Some(Poll::Wait(Signal::Motion));
        }
        match order {
            Order::None | Order::WaitIdle => {}
            Order::Move { steps, feed } => {
                if m.stage(*steps, *feed).is_err() {
                    return Some(Poll::Wait(Signal::Motion));
                }
            }
            Order::Dwell { ms } => return self.dwell(*ms),
            Order::Pen { deg, ms } => {
                // Set once, then its settle time like a dwell.
                if self.dwell_until.is_none() {
                    m.pen.set_pulse_us(PenConfig::pulse_us(*deg));
                }
                return self.dwell(u32::from(*ms));
            }
            // Held like `!`: `~` or the green button goes on.
            Order::Pause => m.hold(),
            Order::Home { axes } => self.start_homing(*axes, m, true),
            Order::Path { path, feed } => {
                self.pending = Some(Pending::Path {
                    path: *path,
                    feed: *feed,
                })
            }
            Order::SetPosition { steps } => m.set_position(*steps),
            Order::Drivers { on } => m.drivers.set(0xFF, *on),
            Order::ReportPosition => report_position(m, kin),
        }
        None
    }

    /// What the console is doing.
    pub fn activity(&self) -> Activity {
        match self.pending {
            _ if self.sleep != Sleep::Awake => Activity::Sleeping,
            Some(Pending::Home { .. }) => Activity::Homing,
            _ if self.checking => Activity::Checking,
            _ if self.jogging => Activity::Jogging,
            _ => Activity::Lines,
        }
    }

    /// Home `axes` (bits), their drivers on; `reply`: answer the line
    /// that asked at the end.
    pub fn start_homing(&mut self, axes: u8, m: &mut Motion, reply: bool) {
        m.drivers.set(axes, true);
        self.pending = Some(Pending::Home {
            homing: Homing::new(axes),
            moving: false,
            reply,
        });
    }

    /// One step of homing: wait for the leg to end (done, or stopped at
    /// its switch), then the next leg, the zero, or the end. Out of line:
    /// the console's frame stays small.
    #[inline(never)]
    fn home(&mut self, m: &mut Motion, cfg: &MachineConfig) -> Poll<Signal> {
        let Some(Pending::Home {
            homing,
            moving,
            reply,
        }) = self.pending.as_mut()
        else {
            return Poll::Again;
        };
        // Looked at every 10 ms while a leg moves (the tick wakes it at
        // once when the switch stops the steps).
        if *moving && !endstop::hit() && !m.is_idle() {
            return Poll::After(LEG_POLL_MS);
        }
        let hit = endstop::disarm();
        if hit {
            // The steps stopped at the switch: drop the rest of the leg
            // (a stop of our own: homing goes on).
            m.stop_now();
            self.epoch = m.epoch();
        }
        *moving = false;
        match homing.next(cfg, hit, endstop::closed(homing.axis())) {
            Next::Move(leg) => {
                if leg.until_closed {
                    endstop::watch(leg.axis);
                }
                let to = homing::target(m.target(), &leg);
                // The machine stands: the planner has room.
                let _ = m.push(to, leg_feed(cfg, &leg));
                *moving = true;
                return Poll::After(LEG_POLL_MS);
            }
            Next::Zero { axis, steps } => {
                let mut at = m.target();
                at[axis] = steps;
                m.set_position(at);
            }
            Next::Done => {
                let reply = *reply;
                self.pending = None;
                self.resync_next_run(m);
                // Grbl runs the startup lines after a homing cycle.
                self.startup = system::STARTUP;
                match reply {
                    true => self.ok(),
                    false => info!("homed"),
                }
            }
            // Grbl's alarms 8 (the switch stayed closed after the pull-off)
            // and 9 (no switch within the travel); the line that asked is
            // then answered `ok`, as Grbl's. Motion waits for `$H`, `G92`
            // or `$X`.
            Next::Failed(e) => {
                let reply = *reply;
                self.pending = None;
                self.resync_next_run(m);
                m.lose_position();
                reply::alarm(match e {
                    HomingError::Stuck => 8,
                    HomingError::NotFound => 9,
                });
                if reply {
                    self.ok();
                }
            }
        }
        Poll::Again
    }

    /// `ok` to a line, unless it is a pattern's (answered at its end) or
    /// the card's; a startup line's `>line:ok`.
    fn ok(&self) {
        match self.source {
            Some(Source::Startup) => system::startup_reply(self.echo, None),
            Some(Source::Card) => {}
            _ if self.pattern.is_some() => {}
            _ => reply::ok(),
        }
    }

    /// An error: the answer to the line, or to the pattern, which stops,
    /// or in the log with the card's file and line.
    fn error(&mut self, e: &Error) {
        self.error_because(e, None);
    }

    fn error_because(&mut self, e: &Error, why: Option<taut_logic::text::ErrorKind>) {
        self.pattern = None;
        match self.source {
            Some(Source::Card) => self.print.line_failed(e, why),
            Some(Source::Startup) => system::startup_reply(self.echo, Some(e)),
            _ => reply::error_because(e, why),
        }
    }

    /// Read the commanded position back through the kinematics on the
    /// next run (the machine moved, or is another one), as after a stop.
    fn resync_next_run(&mut self, m: &Motion) {
        self.epoch = m.epoch().wrapping_add(1);
    }

    /// Wait `ms` from the first call (motion done): `Some(wait)` until then.
    fn dwell(&mut self, ms: u32) -> Option<Poll<Signal>> {
        let now = clock::millis();
        let until = *self.dwell_until.get_or_insert(now.wrapping_add(ms));
        let left = until.wrapping_sub(now) as i32;
        if left > 0 {
            return Some(Poll::After(left.min(u16::MAX as i32) as u16));
        }
        self.dwell_until = None;
        None
    }

    /// Queue the path's next piece; `ok` once the last one is queued. Out
    /// of line: its copy of the path stays off the console's frame.
    #[inline(never)]
    #[optimize(speed)]
    fn next_piece(&mut self, m: &mut Motion, kin: &impl Kinematics) -> Poll<Signal> {
        let Some(Pending::Path { path, feed }) = self.pending.as_mut() else {
            return Poll::Again;
        };
        // Cut a piece only when the planner can take it.
        if !m.has_room() {
            return Poll::Wait(Signal::Motion);
        }
        // And not while the step queue runs short with pieces planned
        // ahead: planning one takes a few ms, which the segments' refill
        // needs first (with none ahead the planner would run dry instead).
        if crate::motion::urgent() && m.planned() >= 2 {
            return Poll::After(1);
        }
        let before = *path;
        match path.next_piece(kin) {
            Some(Ok(piece)) => {
                if m.stage_piece(&piece, *feed).is_err() {
                    *path = before;
                    return Poll::Wait(Signal::Motion);
                }
            }
            None => {
                self.pending = None;
                self.ok();
            }
            // The interpreter checked every chord: not reached.
            Some(Err(_)) => {
                self.pending = None;
                self.interp.resync(kin.forward(&m.target()));
                self.error(&Error::new(ErrorKind::InvalidTarget, 0));
            }
        }
        Poll::Again
    }
}

impl Default for Console {
    fn default() -> Self {
        Self::new()
    }
}

/// Line `line` of `$#`; `false` past the last: the work coordinate data
/// the store keeps; taut keeps no `G92` offset, tool length or probe yet:
/// zeros, in Grbl's format.
fn offsets_line(line: u8, coords: &taut_logic::coords::CoordData) -> bool {
    use taut_progmem::text;
    // A table in flash: a `match` costs ~15 B of code an arm.
    const NAMES: usize = 11;
    let names = taut_progmem::table!(taut_progmem::Text; NAMES; [
        text!("G54"),
        text!("G55"),
        text!("G56"),
        text!("G57"),
        text!("G58"),
        text!("G59"),
        text!("G28"),
        text!("G30"),
        text!("G92"),
        text!("TLO"),
        text!("PRB"),
    ]);
    if line as usize >= NAMES {
        return false;
    }
    let name = names.get(line as usize);
    let mut r = reply::line();
    let _ = uwrite!(r, "[{}", name);
    match taut_logic::coords::Slot::at(line as usize) {
        Some(slot) => {
            let v = coords.get(slot);
            let _ = uwrite!(
                r,
                ":{},{},{}]",
                Decimal(v[0].0, 3),
                Decimal(v[1].0, 3),
                Decimal(v[2].0, 3)
            );
        }
        None => {
            let zeros = match line {
                9 => flash_str!(":0.000]"),
                10 => flash_str!(":0.000,0.000,0.000:0]"),
                _ => flash_str!(":0.000,0.000,0.000]"),
            };
            let _ = uwrite!(r, "{}", zeros);
        }
    }
    r.send();
    true
}

/// Grbl's feedback message: `[MSG:<text>]`.
fn message(text: Text) {
    let mut r = reply::line();
    let _ = uwrite!(r, "{}{}]", flash_str!("[MSG:"), text);
    r.send();
}

/// A whole line has arrived on the serial line.
fn serial_line_waits() -> bool {
    RX.any(|&b| b == b'\n' || b == b'\r')
}

/// Bytes parsed in one run at most: ~0.06 ms a byte on average (0.1 ms
/// at most), the line end that completes a line up to ~0.5 ms; a 40-byte
/// line read whole took ~2.4 ms, which a `?` or any task waited behind.
const READ_PER_RUN: u8 = 6;

/// `M114`: `C:1.000 X:0.000 Z:0.000 Count C:27 X:0 Z:0` (the executed
/// position).
#[inline(never)]
fn report_position(m: &Motion, kin: &impl Kinematics) {
    let steps = m.stepper.position();
    let pos = kin.forward(&steps);
    let words = kin.words();
    let mut r = reply::line();
    for i in 0..AXES {
        let _ = uwrite!(r, "{}:{} ", words[i] as char, Decimal(pos[i].0, 3));
    }
    let _ = uwrite!(r, "{}", flash_str!("Count"));
    for i in 0..AXES {
        let _ = uwrite!(r, " {}:{}", words[i] as char, steps[i]);
    }
    r.send();
}

/// How often homing looks whether a leg has ended, ms.
const LEG_POLL_MS: u16 = 10;

/// The feed that moves `leg`'s axis at its rate: units per minute.
fn leg_feed(cfg: &MachineConfig, leg: &Leg) -> Feed {
    let spu = cfg.axes[leg.axis].steps_per_unit;
    let milli_per_min =
        u64::from(leg.rate) * 60_000 * u64::from(spu.den) / u64::from(spu.num.max(1));
    Feed::PerMinute(Milli(milli_per_min.min(i32::MAX as u64) as i32))
}
