//! A plotter's print from the SD card, as Marlin's: `M20` lists the card,
//! `M23 <name>` selects a file, `M24` starts it (or the green button the
//! first G-code file), `M25` pauses, `M27` tells how far, `M524` aborts.
//! Its lines go through the console's parser and interpreter like the
//! serial line's, without `ok`s; an error names the file, line and column.
//!
//! The file's bytes are taken from `CARD_OUT` in place, as the console
//! wants them. A card pulled (or failing) mid-print stops the reading at
//! the end of the last whole line: the moves already queued finish, and
//! once the card is back, `M24` or the green button opens the file again
//! and goes on from the next line.
//!
//! A print keeps a checkpoint in EEPROM (`taut_logic::checkpoint::plot`):
//! the file, then the offset of the line whose moves the steppers are
//! making and its blocks drawn, at most every half second; cleared when
//! the print ends or is stopped. After a power cut the next power-on
//! offers it (`>>> resume`): `M1000` or green goes on from that line,
//! over its drawn blocks with the pen up, `M524` or green held discards
//! it.

use crate::board::flash::FlashStr;
use crate::board::port::Port;
use crate::log::Level;
use crate::motion::Motion;
use crate::queues::{CardAsk, CardMsg, CardNews, Request, What};
use crate::reply;
use crate::store::Store;
use crate::{flash_str, info, warn};
use taut_logic::buttons::ButtonEvent;
use taut_logic::checkpoint::plot::{Resume, ResumeAction, ResumeEvent, Tracker};
use taut_logic::fat::{short_display, Name};
use taut_logic::gcode::{CardLine, Error, ErrorKind};
use taut_logic::pinmap::Button;
use ufmt::uwrite;

#[derive(Clone, Copy, PartialEq, Eq)]
enum State {
    Idle,
    /// `M20` asked: the reader writes the list, then `Listed`.
    Listing,
    /// `M23` asked (`start`: the green button, which starts at once; or a
    /// lost print opening again).
    Opening {
        start: bool,
    },
    /// Open, not started.
    Selected,
    Running,
    /// The card went away mid-print: `M24` or the green button goes on.
    Lost,
}

/// Where in the file: bytes taken and line ends seen.
#[derive(Clone, Copy)]
struct Mark {
    pos: u32,
    lines: u32,
}

pub struct Print {
    /// Its end of `CARD_IN`.
    card: CardAsk,
    /// Its end of `CARD_OUT`.
    news: CardNews,
    state: State,
    /// Numbers the card requests; messages of older ones are dropped.
    ticket: u8,
    // The file's name is the reader's (`card::opened_name`): it reads
    // one file at a time, and a plotter's card has no other reader.
    size: u32,
    at: Mark,
    /// The start of the line being read: where a lost print goes on.
    line_start: Mark,
    /// After opening again: bytes up to here are passed over.
    skip: u32,
    /// Bytes of the oldest `Data` message already taken.
    taken: u8,
    /// The card sent the file's end.
    ended: bool,
    /// The last byte taken (a `\r` ends a line before its `\n`).
    last: u8,
    /// A console line waits for the reader's answer (`M20`, `M23`, `M24`
    /// opening a lost print again).
    line_waits: bool,
    /// Where the line read last starts.
    read_start: u32,
    /// The print's checkpoint: which line moves (`None`: no print).
    tracker: Option<Tracker>,
    /// A checkpoint header to write once the store is free, or the offer
    /// to say once there is room.
    keep: Keep,
    /// A power cut's print offered or being resumed (from the line at the
    /// tracker's [`Tracker::resume_at`]).
    resume: Option<Resume>,
    /// Blocks of that line drawn before the cut, plus two (0: none):
    /// gone over with the pen up once the print goes on, then the move on
    /// to where the motors stood, then the pen (`machine_io::Trace`).
    trace: u16,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Keep {
    Nothing,
    /// A power cut's print is offered: `>>> resume …`.
    Offer,
    /// A print starts: its file.
    Begin,
    /// The print ended or was stopped: an idle header.
    Forget,
}

/// The answer to the console line that waited: `ok`, or the error.
pub type Answer = Option<Result<(), ErrorKind>>;

impl Print {
    pub const fn new(card: CardAsk, news: CardNews) -> Print {
        Print {
            card,
            news,
            state: State::Idle,
            ticket: 0,
            size: 0,
            at: Mark { pos: 0, lines: 0 },
            line_start: Mark { pos: 0, lines: 0 },
            skip: 0,
            taken: 0,
            ended: false,
            last: 0,
            line_waits: false,
            read_start: 0,
            tracker: None,
            keep: Keep::Nothing,
            resume: None,
            trace: 0,
        }
    }

    /// Lines come from the card now.
    pub fn running(&self) -> bool {
        matches!(self.state, State::Running)
    }

    /// A print is under way (running, lost with its card, or being
    /// resumed after a cut).
    pub fn busy(&self) -> bool {
        matches!(self.state, State::Running | State::Lost)
            || self.resume.is_some_and(|r| r != Resume::Offered)
    }

    /// The file's lines before a cut's checkpoint are being taken again:
    /// checked, not carried out.
    pub fn replaying(&self) -> bool {
        self.resume == Some(Resume::Replaying)
    }

    /// The checkpoint has work ([`Print::keep`]): a print under way, a
    /// header to write, an offer.
    pub fn keeps(&self) -> bool {
        self.tracker.is_some() || self.keep != Keep::Nothing || self.resume.is_some()
    }

    /// A print under way: records follow it ([`Print::keep`]).
    pub fn tracking(&self) -> bool {
        self.tracker.is_some()
    }

    /// A header, an idle header or the offer waits ([`Print::keep`]).
    pub fn waits_to_keep(&self) -> bool {
        self.keep != Keep::Nothing
    }

    /// A power cut's print is offered.
    pub fn offered(&self) -> bool {
        self.resume == Some(Resume::Offered)
    }

    /// At power-on: a print a cut stopped.
    pub fn offer(&mut self) {
        self.resume = Some(Resume::Offered);
        self.keep = Keep::Offer;
    }

    /// The checkpoint's work, each console run: the offer said once there
    /// is room, a header, or the moving line's record once it is due.
    #[inline(never)]
    #[optimize(size)]
    pub fn keep(&mut self, store: &mut Store, m: &Motion, now: u32) {
        if self.keep == Keep::Offer {
            if Port::Usb.tx_free() < crate::log::LINE {
                return;
            }
            self.keep = Keep::Nothing;
            match store.plot_saved() {
                Some(p) => info!(
                    ">>> resume ",
                    short_display(&p.header.short),
                    " from byte ",
                    p.pos(),
                    "/",
                    p.header.size,
                    "? M1000 or green: resume, M524 or hold green 2 s: discard"
                ),
                None => self.resume = None,
            }
        }
        if store.saving() {
            return;
        }
        match core::mem::replace(&mut self.keep, Keep::Nothing) {
            Keep::Begin => {
                // No line of the file is taken before (`next_byte`): the
                // motors' target is where it begins.
                let at = m.target();
                store.plot_begin(crate::card::opened_short(), self.size, [at[0], at[1]]);
            }
            Keep::Forget => store.forget(),
            Keep::Nothing | Keep::Offer => {
                let begun = crate::stepper::blocks_begun();
                let running = m.stepper.is_running();
                let Some(mut r) = self
                    .tracker
                    .as_mut()
                    .and_then(|t| t.due(begun, running, false, now))
                else {
                    return;
                };
                let at = m.stepper.position();
                // Not with a block begun since `begun` was read: the
                // motors are past the one named.
                if crate::stepper::blocks_begun() == begun {
                    r.at = [at[0], at[1]];
                    store.plot_record(r);
                }
            }
        }
    }

    /// `M1000` or green with a print offered: what to do first (home, or
    /// open the file); `homes`: the machine has homing switches.
    #[inline(never)]
    pub fn recover(&mut self, store: &Store, homes: bool) -> Result<ResumeAction, ErrorKind> {
        let (Some(r), Some(p)) = (self.resume, store.plot_saved()) else {
            return Err(ErrorKind::NoFileSelected);
        };
        let (next, action) = r.on(ResumeEvent::Take { homes }, p.pos());
        if action == ResumeAction::None {
            return Err(ErrorKind::Printing);
        }
        self.resume = next;
        self.tracker = Some(Tracker::resuming(&p));
        self.trace = p.done() + 2;
        info!(
            "resuming: ",
            short_display(&p.header.short),
            " from byte ",
            p.pos()
        );
        Ok(action)
    }

    /// Homing for a resume ended (`homed`: the position is known): the
    /// file opens, or the offer stands again.
    pub fn homed(&mut self, store: &Store, homed: bool) {
        if self.resume != Some(Resume::Homing) {
            return;
        }
        if !homed {
            self.back_to_offer();
            return;
        }
        self.resume = Some(Resume::Opening);
        self.open_saved(store);
    }

    /// Waiting for homing to end before opening the file.
    pub fn homing_for_resume(&self) -> bool {
        self.resume == Some(Resume::Homing)
    }

    /// Open the checkpoint's file from its start.
    pub fn open_saved(&mut self, store: &Store) {
        match store.plot_saved() {
            Some(p) => {
                self.size = p.header.size;
                self.open(short_display(&p.header.short), true);
            }
            None => self.resume = None,
        }
    }

    /// A resume stopped short (a reset, a failed homing, a missing file):
    /// offered again, the checkpoint as it was.
    fn back_to_offer(&mut self) {
        if self.resume.is_some_and(|r| r != Resume::Offered) {
            warn!("resume stopped: M1000 or green to try again");
            self.resume = Some(Resume::Offered);
            self.tracker = None;
        }
    }

    /// `M524` or green held with a print offered: the checkpoint goes.
    fn discard(&mut self) {
        if self.resume.take().is_some() {
            info!("checkpoint discarded");
            self.keep = Keep::Forget;
        }
    }

    /// A line of the file was read whole and is about to be taken: the
    /// resume's next step for it (check it; hold it for the travel back,
    /// then the pen; go).
    #[inline(never)]
    pub fn line_ready(&mut self) -> ResumeAction {
        match self.resume {
            None | Some(Resume::Offered) => ResumeAction::Go,
            Some(r) => {
                let e = match r {
                    Resume::Travel | Resume::Pen => ResumeEvent::Done,
                    _ => ResumeEvent::Line(self.read_start),
                };
                let at = self.tracker.as_ref().map_or(0, |t| t.resume_at());
                let (next, action) = r.on(e, at);
                self.resume = next;
                action
            }
        }
    }

    /// The line was taken and goes: its checkpoint candidate, its first
    /// block numbered `first` (`None`: it starts no block, its motion
    /// joined the tiny moves before, which are not queued yet). Not while
    /// a resume goes over the blocks drawn before the cut: its rapid on
    /// to where the pen stood is a block the file does not have. Records
    /// follow from the line after (a cut before goes on from the record
    /// resumed from).
    pub fn line_taken(&mut self, first: Option<u8>) {
        if let (0, Some(first), Some(t)) = (self.trace, first, self.tracker.as_mut()) {
            t.line(self.read_start, first);
        }
    }

    /// Once the print goes on: the blocks to go over.
    pub fn trace(&mut self) -> Option<&mut u16> {
        match self.resume {
            None if self.trace > 0 => Some(&mut self.trace),
            _ => None,
        }
    }

    /// A console line waits for the reader's answer.
    pub fn waiting(&self) -> bool {
        self.line_waits
    }

    fn ask(&mut self, request: impl FnOnce(u8) -> Request) {
        self.ticket = self.ticket.wrapping_add(1).max(1);
        // The reader takes requests before anything else: a mailbox, this
        // request replacing one still waiting.
        let r = request(self.ticket);
        self.card.put(r);
    }

    /// A card command from the console (`M20`, `M23`…); answered `ok`
    /// now, or once the reader has when [`Print::waiting`].
    #[inline(never)]
    #[optimize(size)]
    pub fn command(&mut self, c: CardLine, m: &mut Motion) -> Result<(), ErrorKind> {
        match c {
            CardLine::List => self.list(),
            CardLine::Mount => Ok(()),
            CardLine::Select(name) => self.select(name),
            CardLine::Start if m.resume() => Ok(()),
            CardLine::Start => self.start(true),
            CardLine::Pause => {
                if self.running() {
                    m.hold();
                }
                Ok(())
            }
            CardLine::Progress => {
                self.progress();
                Ok(())
            }
            CardLine::Abort => {
                self.discard();
                self.abort();
                Ok(())
            }
            // The console's (it may home first).
            CardLine::Recover => Ok(()),
        }
    }

    /// The green button on a plotter: go on after a hold or `M0`, else
    /// start the selected file, go on with a lost one, or start the
    /// card's first G-code file.
    #[inline(never)]
    pub fn button(&mut self, event: ButtonEvent, m: &mut Motion) {
        if self.offered() {
            if event == ButtonEvent::LongPress(Button::Confirm) {
                self.discard();
            }
            return;
        }
        if event == ButtonEvent::Pressed(Button::Confirm)
            && !m.resume()
            && self.start(false).is_err()
        {
            self.start_first();
        }
    }

    /// `M20`: `Begin file list`, the files, `End file list` once `Listed`.
    #[inline(never)]
    #[optimize(size)]
    pub fn list(&mut self) -> Result<(), ErrorKind> {
        self.not_busy()?;
        self.close();
        send_line(flash_str!("Begin file list"));
        self.ask(Request::List);
        self.state = State::Listing;
        self.line_waits = true;
        Ok(())
    }

    /// `M23`: open `name`; answered when the reader has.
    pub fn select(&mut self, name: Name) -> Result<(), ErrorKind> {
        self.not_busy()?;
        self.discard();
        self.open(name, false);
        self.line_waits = true;
        Ok(())
    }

    /// The green button with no print: the card's first G-code file.
    pub fn start_first(&mut self) {
        if matches!(self.state, State::Idle) {
            self.ask(Request::OpenFirst);
            self.state = State::Opening { start: true };
            self.skip = 0;
        }
    }

    /// `M24` (`line`) or the green button: start the selected file, or
    /// go on with a lost one (the line is answered once it is open again).
    pub fn start(&mut self, line: bool) -> Result<(), ErrorKind> {
        match self.state {
            State::Selected => self.begin(),
            State::Lost => {
                self.open(crate::card::opened_name(), true);
                self.skip = self.line_start.pos;
                self.line_waits = line;
            }
            State::Running => {}
            _ => return Err(ErrorKind::NoFileSelected),
        }
        Ok(())
    }

    /// `M524`, Ctrl-X: no more lines from the file (a resume under way
    /// stops: offered again).
    #[inline(never)]
    #[optimize(size)]
    pub fn abort(&mut self) {
        if self.resume.is_some() {
            self.back_to_offer();
            self.close();
            return;
        }
        if self.busy() || matches!(self.state, State::Selected) {
            info!("print aborted at line ", self.line_start.lines + 1);
        }
        self.close();
    }

    /// The print starts: its checkpoint's header, then its records.
    fn begin(&mut self) {
        self.state = State::Running;
        self.resume = None;
        self.keep = Keep::Begin;
        self.tracker = Some(Tracker::new());
    }

    /// `M27`: `SD printing byte 1234/5678`, Marlin's words.
    #[inline(never)]
    #[optimize(size)]
    pub fn progress(&self) {
        let mut r = reply::line();
        let _ = match self.state {
            State::Running | State::Lost | State::Selected => uwrite!(
                r,
                "{}{}/{}",
                flash_str!("SD printing byte "),
                self.line_start.pos,
                self.size
            ),
            _ => uwrite!(r, "{}", flash_str!("Not SD printing")),
        };
        r.send();
    }

    fn not_busy(&self) -> Result<(), ErrorKind> {
        match self.busy() {
            true => Err(ErrorKind::Printing),
            false => Ok(()),
        }
    }

    /// Open `name` from its start (a lost print then sets what to pass over).
    fn open(&mut self, name: Name, start: bool) {
        self.ask(|t| Request::Open(name, t));
        self.state = State::Opening { start };
        self.skip = 0;
    }

    fn close(&mut self) {
        if !matches!(self.state, State::Idle) {
            self.card.put(Request::Close);
        }
        self.forget();
        self.state = State::Idle;
        self.line_waits = false;
        self.ticket = self.ticket.wrapping_add(1).max(1);
    }

    /// Take the card's messages up to the next of the file's bytes; the
    /// answer to the waiting line, once there is one.
    #[inline(never)]
    #[optimize(size)]
    pub fn take_messages(&mut self) -> Answer {
        let answer = self.messages();
        match answer {
            Some(_) if core::mem::take(&mut self.line_waits) => answer,
            _ => None,
        }
    }

    fn messages(&mut self) -> Answer {
        let is_data = |m: &CardMsg| (m.ticket, matches!(m.what, What::Data { .. }));
        while let Some((ticket, data)) = self.news.peek_with(is_data) {
            let ours = ticket == self.ticket;
            // Bytes wait in the queue until a line wants them, unless the
            // card went out behind them: the print stops at its last whole
            // line now (the line being carried out may wait on a long move).
            if data && ours && !matches!(self.state, State::Idle) {
                if !crate::card::removal_waits(&self.news) {
                    return None;
                }
                self.lost();
                continue;
            }
            let msg = self.news.pop()?;
            match msg.what {
                What::Opened { size } if ours => return self.opened(size),
                What::Listed if ours => {
                    self.state = State::Idle;
                    send_line(flash_str!("End file list"));
                    return Some(Ok(()));
                }
                What::End if ours => {
                    self.ended = true;
                    return None;
                }
                What::Missing if ours => return self.failed(true),
                What::Failed if ours => return self.failed(false),
                What::Removed => self.lost(),
                What::Inserted if matches!(self.state, State::Lost) => {
                    info!("card back: M24 or the green button goes on");
                }
                // Older requests', and the slot's news when they change nothing.
                _ => {}
            }
        }
        None
    }

    #[inline(never)]
    #[optimize(size)]
    fn opened(&mut self, size: u32) -> Answer {
        let State::Opening { start } = self.state else {
            return None;
        };
        self.taken = 0;
        self.ended = false;
        self.at = Mark { pos: 0, lines: 0 };
        self.read_start = 0;
        if self.resume == Some(Resume::Opening) {
            self.resume = Some(Resume::Placing);
            self.line_start = self.at;
            self.state = State::Running;
            return None;
        }
        if self.skip > 0 {
            // Going on after a lost card: the same lines are counted again.
            self.at.lines = self.line_start.lines;
            info!("print goes on at line ", self.line_start.lines + 1);
            self.state = State::Running;
            return Some(Ok(()));
        }
        let name = crate::card::opened_name();
        self.size = size;
        self.line_start = self.at;
        let mut r = reply::line();
        let _ = uwrite!(
            r,
            "{}{}{}{}",
            flash_str!("File opened: "),
            name,
            flash_str!(" Size: "),
            size
        );
        r.send();
        send_line(flash_str!("File selected"));
        match start {
            true => {
                info!("printing ", name);
                self.begin();
            }
            false => self.state = State::Selected,
        }
        Some(Ok(()))
    }

    #[inline(never)]
    #[optimize(size)]
    fn failed(&mut self, missing: bool) -> Answer {
        if self.resume == Some(Resume::Opening) {
            self.state = State::Idle;
            self.back_to_offer();
            return None;
        }
        match self.state {
            State::Opening { .. } | State::Listing => {
                let green = !self.line_waits && self.skip == 0;
                self.state = match self.skip > 0 {
                    true => State::Lost,
                    false => State::Idle,
                };
                if green {
                    warn!("no G-code file on the card");
                }
                Some(Err(match missing {
                    true => ErrorKind::FileNotFound,
                    false => ErrorKind::NoCard,
                }))
            }
            State::Running => {
                self.lost();
                None
            }
            _ => None,
        }
    }

    /// The card went away: a running print stops at its last whole line.
    #[inline(never)]
    #[optimize(size)]
    fn lost(&mut self) {
        if !matches!(self.state, State::Running) {
            if matches!(self.state, State::Selected) {
                self.state = State::Idle;
            }
            return;
        }
        self.state = State::Lost;
        self.ticket = self.ticket.wrapping_add(1).max(1);
        warn!(
            "card out: print stopped before line ",
            self.line_start.lines + 1,
            ": put it back, then M24 or green"
        );
    }

    /// The print is over: its checkpoint goes.
    fn forget(&mut self) {
        self.trace = 0;
        if self.tracker.take().is_some() && self.resume.is_none() {
            self.keep = Keep::Forget;
        }
    }

    /// The file's next byte for the parser; `None` when the card has not
    /// sent it yet (or the print does not run). At the file's end, a last
    /// line without its newline gets one.
    #[inline(never)]
    pub fn next_byte(&mut self) -> Option<u8> {
        // A print's first line waits for its header (where it begins).
        if !matches!(self.state, State::Running) || self.keep == Keep::Begin {
            return None;
        }
        loop {
            let Some((at, of)) = self.head() else {
                // Nothing waits while the print runs.
                let _ = self.messages();
                if !self.ended || !matches!(self.state, State::Running) {
                    return None;
                }
                return match self.last {
                    b'\n' | b'\r' | 0 => None,
                    _ => {
                        self.at.lines += 1;
                        self.last = b'\n';
                        Some(b'\n')
                    }
                };
            };
            let byte = crate::card::byte(at);
            // Bytes before where a lost print goes on are passed over.
            if self.at.pos < self.skip {
                self.took_run(1, of, 0, self.last);
                continue;
            }
            self.took_run(1, of, (byte == b'\n') as u8, byte);
            return Some(byte);
        }
    }

    /// The file's bytes a line may take now in place, as `next_byte` would
    /// give them one by one: where they start in the block and how many.
    /// `None` when `next_byte` must go on (nothing sent, the print not
    /// running, bytes still to pass over).
    #[inline(always)]
    pub fn run(&self) -> Option<(u16, u8)> {
        if !matches!(self.state, State::Running)
            || self.keep == Keep::Begin
            || self.at.pos < self.skip
        {
            return None;
        }
        self.head().filter(|&(_, of)| of > 0)
    }

    /// The bytes of the oldest `Data` message of this print not yet
    /// taken: where they start in the block and how many.
    #[inline(always)]
    fn head(&self) -> Option<(u16, u8)> {
        let taken = self.taken;
        self.news
            .peek_with(|m| match m.what {
                What::Data { at, len } if m.ticket == self.ticket => {
                    Some((at + u16::from(taken), len - taken))
                }
                _ => None,
            })
            .flatten()
    }

    /// `n` of the `of` bytes of [`Print::head`] were taken (a run, or
    /// `next_byte`'s one), `lines` line ends among them, the last `last`.
    #[inline(never)]
    pub fn took_run(&mut self, n: u8, of: u8, lines: u8, last: u8) {
        self.taken += n;
        if n >= of {
            self.taken = 0;
            let _ = self.news.pop();
        }
        self.at.pos += u32::from(n);
        self.at.lines += u32::from(lines);
        self.last = last;
    }

    /// The parser finished a line: the next one starts here.
    pub fn line_done(&mut self) {
        self.read_start = self.line_start.pos;
        self.line_start = self.at;
    }

    /// The file is read to its end and its last line carried out.
    #[inline(never)]
    #[optimize(size)]
    pub fn finished(&mut self) -> bool {
        let done = matches!(self.state, State::Running)
            && self.ended
            && matches!(self.last, b'\n' | b'\r' | 0)
            && !self.news.any(|m| m.ticket == self.ticket);
        if done {
            self.state = State::Idle;
            self.forget();
            send_line(flash_str!("Done printing file"));
        }
        done
    }

    /// A line of the file failed: `NAME:line:col: error:…`. Harmless
    /// unknown codes (`M117`, tool changes) are passed over, as senders
    /// do; any other error stops the print (its next moves would start
    /// from the wrong place).
    #[inline(never)]
    #[optimize(size)]
    pub fn line_failed(&mut self, e: &Error, why: Option<taut_logic::text::ErrorKind>) {
        // A `\r` ended the line before its `\n` was counted.
        let line = self.at.lines + u32::from(self.last != b'\n');
        crate::log::start(Level::Error, crate::__log_module!());
        crate::log::with_line(|r| {
            let _ = uwrite!(r, "{}:{}:", crate::card::opened_name(), line);
            if let Some(c) = e.column() {
                let _ = uwrite!(r, "{}:", c);
            }
            let _ = uwrite!(r, " {}", reply::Because(e, why));
        });
        crate::log::finish();
        if e.kind() != ErrorKind::UnsupportedCommand {
            warn!("print stopped");
            self.close();
        }
    }
}

#[inline(never)]
#[optimize(size)]
fn send_line(s: FlashStr) {
    let mut r = reply::line();
    let _ = uwrite!(r, "{}", s);
    r.send();
}
