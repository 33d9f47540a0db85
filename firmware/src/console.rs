//! The serial console: G-code lines in, `ok` / `error:<code>` out, Grbl
//! style. Grbl's `protocol` + `gcode` interpreter stage: the parser (host-
//! tested in `taut_logic::gcode`) turns bytes into lines; this file carries
//! them out against the motion task's state. Real-time commands never get
//! here (`realtime`).
//!
//! The console owns the machine's motion only while no string-art job
//! does: during a job it refuses motion, drivers and settings, and still
//! answers reads. Targets outside an axis's soft limits are refused before
//! anything moves; a feed below [`MIN_FEED`] is refused, one above an
//! axis's maximum rate is clamped to it (by the planner).
#![deny(unsafe_code)]

use crate::board::clock;
use crate::motion::Motion;
use crate::queues::{Signal, JOB_CLAIMS_TX, RX};
use crate::reply::{self, Fixed, REPORTED_AXES};
use crate::rt::{stack, Poll};
use core::sync::atomic::Ordering::Relaxed;
use taut_logic::axis::AXES;
use taut_logic::config::MachineConfig;
use taut_logic::gcode::{
    Command, Distance, Error, ErrorKind, Input, Line, Parser, SystemLine, MIN_FEED,
};
use taut_logic::kinematics::{Kinematics, Position};
use taut_logic::planner::Feed;
use taut_logic::settings;
use taut_logic::units::Milli;
use ufmt::{uWrite, uwrite};

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
    /// The motion epoch `target` agrees with: a stop that dropped queued
    /// moves starts a new one, and the target is then read back.
    epoch: u8,
}

#[derive(Clone, Copy)]
enum Listing {
    Settings(usize),
    Queues(u8),
}

/// Who may move the machine now.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Owner {
    Console,
    /// A string-art job is drilling or winding (or paused in it).
    Job,
}

fn refuse(kind: ErrorKind) -> Option<Poll<Signal>> {
    reply::error(&Error::new(kind, 0));
    None
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
            epoch: 0,
        }
    }

    /// Ctrl-X: the line in progress, a waiting line and a listing are
    /// dropped with the bytes not yet read; modal state is Grbl's default.
    pub fn reset(&mut self) {
        let epoch = self.epoch;
        *self = Console::new();
        self.epoch = epoch;
        RX.clear();
    }

    /// Read and carry out input until it runs out or must wait.
    pub fn poll(
        &mut self,
        m: &mut Motion,
        kin: &impl Kinematics,
        cfg: &mut MachineConfig,
        owner: Owner,
    ) -> Poll<Signal> {
        if self.epoch != m.epoch() {
            self.epoch = m.epoch();
            self.target = kin.forward(&m.target());
        }
        loop {
            if !reply::room() || JOB_CLAIMS_TX.load(Relaxed) {
                return Poll::After(2);
            }
            if let Some(listing) = self.listing {
                self.list(listing, cfg);
                return Poll::Again;
            }
            if let Some(line) = self.held.take() {
                if let Some(wait) = self.execute(&line, m, kin, cfg, owner) {
                    self.held = Some(line);
                    return wait;
                }
                // One line per run: the other tasks get their turn.
                return Poll::Again;
            }
            let Some(byte) = RX.pop() else {
                return Poll::Idle;
            };
            match self.parser.push(byte) {
                None | Some(Ok(Input::Realtime(_))) => {}
                Some(Err(e)) => reply::error(&e),
                Some(Ok(Input::Line(line))) => self.held = Some(line),
                Some(Ok(Input::System(s))) => self.system(s, m, cfg, owner),
            }
        }
    }

    /// Carry out one line; `Some(wait)` when it cannot run yet.
    fn execute(
        &mut self,
        line: &Line,
        m: &mut Motion,
        kin: &impl Kinematics,
        cfg: &MachineConfig,
        owner: Owner,
    ) -> Option<Poll<Signal>> {
        let has_axes = line.axes.iter().any(Option::is_some);
        let moves = has_axes
            || matches!(
                line.command,
                Command::EnableDrivers | Command::DisableDrivers | Command::SetPosition
            );
        if moves && owner == Owner::Job {
            return refuse(ErrorKind::JobOwnsMotion);
        }
        if line.f.is_some_and(|f| f.0 < MIN_FEED) {
            return refuse(ErrorKind::FeedTooLow);
        }
        if let Some(d) = line.distance {
            self.distance = d;
        }
        if let Some(f) = line.f {
            self.feed = Some(f);
        }
        match line.command {
            Command::Rapid | Command::Linear => {
                self.rapid = line.command == Command::Rapid;
                if has_axes {
                    return self.move_to(line, m, kin, cfg);
                }
            }
            Command::Empty if has_axes => return self.move_to(line, m, kin, cfg),
            Command::Empty => {}
            Command::Dwell => {
                if !m.is_idle() {
                    return Some(Poll::Wait(Signal::Motion));
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
                return Some(Poll::Wait(Signal::Motion));
            }
            Command::SetPosition => {
                let mut at = self.target;
                for (i, w) in kin.words().iter().enumerate() {
                    if let Some(v) = letter_value(line, *w) {
                        at[i] = v;
                    }
                }
                match kin.inverse(&at) {
                    Ok(steps) => {
                        m.set_position(steps);
                        self.target = at;
                    }
                    Err(_) => return refuse(ErrorKind::InvalidTarget),
                }
            }
            Command::EnableDrivers => m.drivers.set(0xFF, true),
            Command::DisableDrivers => m.drivers.set(0xFF, false),
            Command::WaitIdle => {}
            Command::ReportPosition => report_position(m, kin),
        }
        reply::ok();
        None
    }

    fn move_to(
        &mut self,
        line: &Line,
        m: &mut Motion,
        kin: &impl Kinematics,
        cfg: &MachineConfig,
    ) -> Option<Poll<Signal>> {
        if !m.position_known() {
            return refuse(ErrorKind::Locked);
        }
        let feed = if self.rapid {
            Feed::Rapid
        } else {
            match self.feed {
                Some(f) => Feed::PerMinute(f),
                None => return refuse(ErrorKind::UndefinedFeedRate),
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
        let outside = cfg.axes.iter().zip(&target).any(|(a, t)| {
            let (min, max) = a.travel;
            a.soft_limits && (*t < min || *t > max)
        });
        if outside {
            return refuse(ErrorKind::TravelExceeded);
        }
        // Converted once from the absolute target: relative moves never drift.
        let steps = match kin.inverse(&target) {
            Ok(s) => s,
            Err(_) => return refuse(ErrorKind::InvalidTarget),
        };
        if m.push(steps, feed).is_err() {
            return Some(Poll::Wait(Signal::Motion));
        }
        self.target = target;
        reply::ok();
        None
    }

    fn system(&mut self, s: SystemLine, m: &mut Motion, cfg: &mut MachineConfig, owner: Owner) {
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
                let mut r = reply::line();
                let _ = uwrite!(
                    r,
                    "[stack peak {} B, headroom {} B]",
                    stack::peak(),
                    stack::headroom()
                );
                r.send();
            }
            SystemLine::Unlock => m.unlock(),
            SystemLine::Set { .. } if owner == Owner::Job => {
                return reply::error(&Error::new(ErrorKind::JobOwnsMotion, 0));
            }
            SystemLine::Set { .. } if !m.is_idle() => {
                return reply::error(&Error::new(ErrorKind::NotIdle, 0));
            }
            SystemLine::Set { key, value } => {
                if let Err(e) = settings::set(cfg, &key, &value) {
                    // `$key=value`: the value starts after `$`, the key, `=`.
                    let col = (key.len() + 3 + e.at).min(u8::MAX as usize) as u8;
                    let invalid = Error::new(ErrorKind::InvalidStatement, col);
                    return reply::error_because(&invalid, Some(e.kind));
                }
                m.configure(cfg);
            }
        }
        reply::ok();
    }

    /// One line of a listing per call: the TX ring never overflows.
    fn list(&mut self, listing: Listing, cfg: &MachineConfig) {
        self.listing = match listing {
            Listing::Settings(next) => settings::all().nth(next).map(|s| {
                let mut r = reply::line();
                let _ = uwrite!(r, "${}={}", s, s.get(cfg));
                r.send();
                Listing::Settings(next + 1)
            }),
            Listing::Queues(line) => {
                crate::report::queue_line(line).then_some(Listing::Queues(line + 1))
            }
        };
        if self.listing.is_none() {
            reply::ok();
        }
    }
}

impl Default for Console {
    fn default() -> Self {
        Self::new()
    }
}

fn letter_value(line: &Line, letter: u8) -> Option<Milli> {
    taut_logic::gcode::AxisWord::ALL
        .iter()
        .find(|w| w.letter() == letter)
        .and_then(|w| line.axis(*w))
}

/// `M114`: `C:1.000 X:0.000 Z:0.000 Count C:27 X:0 Z:0` (the executed
/// position).
fn report_position(m: &Motion, kin: &impl Kinematics) {
    let steps = m.stepper.position();
    let pos = kin.forward(&steps);
    let words = kin.words();
    let mut r = reply::line();
    for i in 0..REPORTED_AXES {
        let _ = uwrite!(r, "{}:{} ", words[i] as char, Fixed(pos[i]));
    }
    let _ = r.write_str("Count");
    for i in 0..REPORTED_AXES {
        let _ = uwrite!(r, " {}:{}", words[i] as char, steps[i]);
    }
    r.send();
}
