//! The serial console: G-code lines in, `ok` / `error:<code>` out, Grbl
//! style. Grbl's `protocol` + `gcode` interpreter stage: the parser (host-
//! tested in `taut_logic::gcode`) turns bytes into lines; this file carries
//! them out against the motion task's state.

use crate::board::{clock, usart};
use crate::job::{Hold, CLAIMS_TX, HOLDS};
use crate::motion::Motion;
use crate::rt::stack;
use crate::{flash_str, warn};
use core::sync::atomic::Ordering::Relaxed;
use taut_logic::axis::AXES;
use taut_logic::config::MachineConfig;
use taut_logic::gcode::{Command, Distance, Error, Input, Line, Parser, Realtime, SystemLine};
use taut_logic::kinematics::{Kinematics, Position};
use taut_logic::planner::Feed;
use taut_logic::settings;
use taut_logic::units::Milli;
use ufmt::{uWrite, uwrite};

/// Longest reply line; a line is only executed when its reply fits.
const REPLY_ROOM: usize = 72;

/// What the console waits for when it returns.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Poll {
    /// Nothing more to read.
    Drained,
    /// A line waits for planner room or for motion to finish: run again
    /// when the motion task makes progress.
    Motion,
    /// Try again after this many ms (dwell, serial output full).
    After(u16),
    /// One line was carried out and more input may wait: run again after
    /// the tasks already ready (a task's run stays short, so the motion
    /// task is never held up by a burst of lines).
    Yield,
}

pub struct Console {
    parser: Parser,
    /// A line read but not yet carried out (back-pressure).
    held: Option<Line>,
    dwell_until: Option<u32>,
    /// `$$` or `$Q` in progress: its next line.
    listing: Option<Listing>,
    distance: Distance,
    rapid: bool,
    feed: Option<Milli>,
    /// Commanded position in milli-units (G-code coordinates).
    target: Position,
}

#[derive(Clone, Copy)]
enum Listing {
    Settings(usize),
    Queues(u8),
}

/// A reply line assembled on the stack and queued whole.
struct Reply(heapless::Vec<u8, REPLY_ROOM>);

impl uWrite for Reply {
    type Error = ();
    fn write_str(&mut self, s: &str) -> Result<(), ()> {
        self.0.extend_from_slice(s.as_bytes()).map_err(|_| ())
    }
}

impl Reply {
    fn new() -> Reply {
        Reply(heapless::Vec::new())
    }
    fn send(mut self) {
        let _ = self.0.push(b'\n');
        // Room was checked before the line ran (REPLY_ROOM).
        usart::send(&self.0);
    }
}

fn ok() {
    usart::send(b"ok\n");
}

fn reply_error(e: &Error) {
    let mut r = Reply::new();
    let _ = uwrite!(r, "error:{} ", e.code());
    let _ = uwrite!(r, "{}", e.message());
    if let Some(c) = e.column() {
        let _ = uwrite!(r, " (col {})", c);
    }
    r.send();
}

/// A fixed-point value as `-12.345`.
struct Fixed(Milli);

impl ufmt::uDisplay for Fixed {
    fn fmt<W: uWrite + ?Sized>(&self, f: &mut ufmt::Formatter<'_, W>) -> Result<(), W::Error> {
        let v = self.0 .0;
        if v < 0 {
            f.write_str("-")?;
        }
        let a = v.unsigned_abs();
        let frac = a % 1000;
        uwrite!(f, "{}.", a / 1000)?;
        if frac < 100 {
            f.write_str("0")?;
        }
        if frac < 10 {
            f.write_str("0")?;
        }
        uwrite!(f, "{}", frac)
    }
}

impl Console {
    pub const fn new() -> Console {
        Console {
            parser: Parser::new(),
            held: None,
            dwell_until: None,
            listing: None,
            distance: Distance::Absolute,
            rapid: true,
            feed: None,
            target: [Milli::ZERO; AXES],
        }
    }

    /// Read and carry out input until it runs out or must wait.
    pub fn poll(&mut self, m: &mut Motion, kin: &impl Kinematics, cfg: &mut MachineConfig) -> Poll {
        loop {
            if usart::TX.free() < REPLY_ROOM || CLAIMS_TX.load(Relaxed) {
                return Poll::After(2);
            }
            if let Some(listing) = self.listing {
                self.list(listing, cfg);
                return Poll::Yield;
            }
            if let Some(line) = self.held.take() {
                if let Some(wait) = self.execute(&line, m, kin) {
                    self.held = Some(line);
                    return wait;
                }
                continue;
            }
            let Some(byte) = usart::RX.pop() else {
                return Poll::Drained;
            };
            match self.parser.push(byte) {
                None => {}
                Some(Err(e)) => reply_error(&e),
                Some(Ok(Input::Line(line))) => self.held = Some(line),
                Some(Ok(Input::System(s))) => self.system(s, m, cfg),
                Some(Ok(Input::Realtime(r))) => self.realtime(r, m, kin),
            }
        }
    }

    /// Carry out one line; `Some(wait)` when it cannot run yet.
    fn execute(&mut self, line: &Line, m: &mut Motion, kin: &impl Kinematics) -> Option<Poll> {
        if let Some(d) = line.distance {
            self.distance = d;
        }
        if let Some(f) = line.f {
            self.feed = Some(f);
        }
        let has_axes = line.axes.iter().any(Option::is_some);
        match line.command {
            Command::Rapid | Command::Linear => {
                self.rapid = line.command == Command::Rapid;
                if has_axes {
                    return self.move_to(line, m, kin);
                }
            }
            Command::Empty if has_axes => return self.move_to(line, m, kin),
            Command::Empty => {}
            Command::Dwell => {
                if !m.is_idle() {
                    return Some(Poll::Motion);
                }
                let now = clock::millis();
                let until = *self
                    .dwell_until
                    .get_or_insert(now.wrapping_add(line.p.map_or(0, |p| p.0 as u32)));
                let left = until.wrapping_sub(now) as i32;
                if left > 0 {
                    return Some(Poll::After(left.min(u16::MAX as i32) as u16));
                }
                self.dwell_until = None;
            }
            Command::SetPosition | Command::DisableDrivers | Command::WaitIdle if !m.is_idle() => {
                return Some(Poll::Motion);
            }
            Command::SetPosition => {
                let words = kin.words();
                for (i, w) in words.iter().enumerate() {
                    if let Some(v) = letter_value(line, *w) {
                        self.target[i] = v;
                    }
                }
                match kin.inverse(&self.target) {
                    Ok(steps) => m.set_position(steps),
                    Err(_) => {
                        return reply(Error::new(taut_logic::gcode::ErrorKind::InvalidTarget, 0))
                    }
                }
            }
            Command::EnableDrivers => m.drivers.set(0xFF, true),
            Command::DisableDrivers => m.drivers.set(0xFF, false),
            Command::WaitIdle => {}
            Command::ReportPosition => report_position(m, kin),
        }
        ok();
        None
    }

    fn move_to(&mut self, line: &Line, m: &mut Motion, kin: &impl Kinematics) -> Option<Poll> {
        let feed = if self.rapid {
            Feed::Rapid
        } else {
            match self.feed {
                Some(f) => Feed::PerMinute(f),
                None => {
                    return reply(Error::new(
                        taut_logic::gcode::ErrorKind::UndefinedFeedRate,
                        0,
                    ))
                }
            }
        };
        let mut target = self.target;
        for (i, w) in kin.words().iter().enumerate() {
            if let Some(v) = letter_value(line, *w) {
                target[i] = match self.distance {
                    Distance::Absolute => v,
                    Distance::Relative => Milli(target[i].0.saturating_add(v.0)),
                };
            }
        }
        // Converted once from the absolute target: relative moves never drift.
        let steps = match kin.inverse(&target) {
            Ok(s) => s,
            Err(_) => return reply(Error::new(taut_logic::gcode::ErrorKind::InvalidTarget, 0)),
        };
        if m.push(steps, feed).is_err() {
            return Some(Poll::Motion);
        }
        self.target = target;
        ok();
        None
    }

    fn system(&mut self, s: SystemLine, m: &mut Motion, cfg: &mut MachineConfig) {
        match s {
            SystemLine::PrintSettings => {
                self.listing = Some(Listing::Settings(0));
                return;
            }
            SystemLine::QueueStats => {
                self.listing = Some(Listing::Queues(0));
                return;
            }
            SystemLine::Stack => {
                let mut r = Reply::new();
                let _ = uwrite!(
                    r,
                    "[stack peak {} B, headroom {} B]",
                    stack::peak(),
                    stack::headroom()
                );
                r.send();
            }
            SystemLine::Set { key, value } => {
                if !m.is_idle() {
                    return reply_error(&Error::new(taut_logic::gcode::ErrorKind::NotIdle, 0));
                }
                if settings::set(cfg, &key, &value).is_err() {
                    return reply_error(&Error::new(
                        taut_logic::gcode::ErrorKind::InvalidStatement,
                        0,
                    ));
                }
                m.configure(cfg);
            }
        }
        ok();
    }

    /// One line of a listing per call: the TX ring never overflows.
    fn list(&mut self, listing: Listing, cfg: &MachineConfig) {
        self.listing = match listing {
            Listing::Settings(next) => settings::all().nth(next).map(|s| {
                let mut r = Reply::new();
                let _ = uwrite!(r, "${}={}", s, s.get(cfg));
                r.send();
                Listing::Settings(next + 1)
            }),
            Listing::Queues(line) => {
                crate::report::queue_line(line).then_some(Listing::Queues(line + 1))
            }
        };
        if self.listing.is_none() {
            ok();
        }
    }

    fn realtime(&mut self, r: Realtime, m: &mut Motion, kin: &impl Kinematics) {
        match r {
            Realtime::Status => {
                let mut rep = Reply::new();
                let state = if m.is_idle() {
                    flash_str!("Idle")
                } else {
                    flash_str!("Run")
                };
                let _ = uwrite!(rep, "<{}|MPos:", state);
                let pos = kin.forward(&m.stepper.position());
                for (i, p) in pos.iter().enumerate() {
                    let _ = uwrite!(rep, "{}{}", if i > 0 { "," } else { "" }, Fixed(*p));
                }
                let _ = rep.write_str(">");
                rep.send();
            }
            // The job pauses after its current move and resumes (`job`).
            Realtime::FeedHold => push_hold(Hold::Pause),
            Realtime::CycleStart => push_hold(Hold::Resume),
            Realtime::Reset => {}
        }
    }
}

fn reply(e: Error) -> Option<Poll> {
    reply_error(&e);
    None
}

fn letter_value(line: &Line, letter: u8) -> Option<Milli> {
    taut_logic::gcode::AxisWord::ALL
        .iter()
        .find(|w| w.letter() == letter)
        .and_then(|w| line.axis(*w))
}

/// `M114`: `C:1.000 X:0.000 Z:0.000 A:0.000 Count C:27 X:0 Z:0 A:0`.
fn report_position(m: &Motion, kin: &impl Kinematics) {
    let steps = m.stepper.position();
    let pos = kin.forward(&steps);
    let words = kin.words();
    let mut r = Reply::new();
    for i in 0..AXES {
        let _ = uwrite!(r, "{}:{} ", words[i] as char, Fixed(pos[i]));
    }
    let _ = r.write_str("Count");
    for i in 0..AXES {
        let _ = uwrite!(r, " {}:{}", words[i] as char, steps[i]);
    }
    r.send();
}

fn push_hold(h: Hold) {
    if HOLDS.push(h).is_err() {
        warn!("hold queue full");
    }
}
