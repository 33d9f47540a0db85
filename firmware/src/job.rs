//! The job task's state: the string-art job (`taut_logic::stringart::job`)
//! fed by the buttons, the card reader and the console's `~` and Ctrl-X, its
//! actions carried out here — log lines, card requests, drivers, zeroing,
//! and the machine's steps handed to the planner.
//!
//! Log lines wait for room in the TX ring rather than being dropped: the
//! prompts and the bad-file messages must reach the user.

use crate::board::port::Port;
use crate::checkpoint::BootNote;
use crate::motion::Motion;
use crate::queues::{
    CardAsk, CardMsg, CardNews, ClaimTx, Control, JobControls, Presses, Request, Signal, What,
    CHUNK,
};
use crate::rt::Poll;
use crate::store::Store;
use crate::{error, info, report, texts};
use taut_logic::axis::{PerAxis, AXES};
use taut_logic::checkpoint::{Record, Saved};
use taut_logic::config::MachineConfig;
use taut_logic::fat::Name;
use taut_logic::files::check::{CardId, Files, Next};
use taut_logic::files::poradi::PoradiReader;
use taut_logic::files::{FileError, FileName};
use taut_logic::planner::{Feed, Full};
use taut_logic::stringart::job::{
    Action, Actions, BadBoard, Event, Feeder, Feeding, Hardware, Job, Msg, Phase, State,
};
use taut_logic::stringart::Save;

/// Room for a whole log line, claimed from the console while there is none.
fn room_for_a_line(claim: &ClaimTx) -> bool {
    let room = Port::Usb.tx_free() >= LINE_ROOM;
    claim.set(!room);
    room
}

/// Steps handed to the planner per run, to keep runs short.
const STEPS_PER_RUN: u8 = 8;
/// Room a log line needs in the TX ring (the longest line is 96 bytes).
const LINE_ROOM: usize = 96;

/// `poradi.txt` streamed for winding.
struct Pattern {
    reader: PoradiReader,
    chunk: [u8; CHUNK],
    at: u8,
    len: u8,
    ended: bool,
}

/// What the card is streaming to the job.
enum Stream {
    None,
    /// The files being checked.
    Files(Files),
    /// `poradi.txt` while winding.
    Pattern(Pattern),
}

impl Stream {
    /// Files being checked, not yet all read.
    fn checking(&self) -> bool {
        matches!(self, Stream::Files(f) if f.checked().is_none())
    }

    /// The machine the checked files describe, until the job takes it
    /// ([`Action::Configure`]) if it does: at once if the machine stands,
    /// else before the job's first move (a console jog may still run).
    fn checked_machine(&self) -> Option<&MachineConfig> {
        match self {
            Stream::Files(f) => f.checked().map(|c| &c.config),
            _ => None,
        }
    }
}

pub struct JobTask {
    /// Its end of `CARD_IN`.
    card: CardAsk,
    /// Its end of `CARD_OUT`.
    news: CardNews,
    /// Its end of `JOB_CONTROL`.
    controls: JobControls,
    /// Its end of `BUTTONS`.
    presses: Presses,
    /// Its end of `JOB_CLAIMS_TX`.
    claim: ClaimTx,
    job: Job,
    /// Actions not yet carried out, in order: one event's at most, as
    /// inputs are taken only when the last event's are done.
    todo: Actions,
    stream: Stream,
    /// Numbers the card requests; messages of older ones are dropped.
    ticket: u8,
    nails: u16,
    /// Between `NextMoves` and `MotionDone`: the batch's steps handed to
    /// the planner, then the wait for the machine to stand.
    feeder: Feeder,
    /// Queue figures are logged line by line after a job ends.
    report_line: Option<u8>,
    /// What the boot found of a checkpoint, to say once there is room.
    boot_note: Option<BootNote>,
}

impl JobTask {
    pub const fn new(
        card: CardAsk,
        news: CardNews,
        controls: JobControls,
        presses: Presses,
        claim: ClaimTx,
    ) -> Self {
        JobTask {
            card,
            news,
            controls,
            presses,
            claim,
            job: Job::new(),
            todo: Actions::new(),
            stream: Stream::None,
            ticket: 0,
            nails: 0,
            feeder: Feeder::new(),
            report_line: None,
            boot_note: None,
        }
    }

    /// The job drills or winds (or is paused in it): the console may not
    /// move the machine.
    pub fn owns_motion(&self) -> bool {
        self.job.owns_motion()
    }

    /// Once at boot: drivers off, waiting for a card; the checkpoint of a
    /// job a power cut stopped, if any.
    pub fn power_on(&mut self, saved: Option<Saved>, note: Option<BootNote>, now: u32) {
        self.boot_note = note;
        self.event(Event::PowerOn, now);
        if let Some(s) = saved {
            self.event(Event::Saved(s), now);
        }
    }

    /// One run: carry out the pending actions and then each input in turn
    /// (while their log lines fit), feed winding its nails, then move.
    pub fn poll(
        &mut self,
        m: &mut Motion,
        config: &mut MachineConfig,
        store: &mut Store,
        now: u32,
    ) -> Poll<Signal> {
        // Claimed again below if still needed.
        self.claim.set(false);
        if let Some(note) = self.boot_note {
            if !room_for_a_line(&self.claim) {
                return Poll::After(5);
            }
            self.boot_note = None;
            note.log();
        }
        loop {
            if let Some(p) = self.carry_out(m, config, store) {
                return p;
            }
            if let Some(line) = self.report_line {
                if !room_for_a_line(&self.claim) {
                    return Poll::After(5);
                }
                self.report_line = report::queue_line(line).then_some(line + 1);
                continue;
            }
            if !self.input(m, config, now) {
                break;
            }
        }
        if self.claim.claimed() {
            // Card messages wait for room for the line they may end in.
            return Poll::After(5);
        }
        self.feed_nails(now);
        if !self.todo.is_empty() {
            return Poll::Again;
        }
        self.run_steps(m, store, now)
    }

    fn event(&mut self, e: Event<'_>, now: u32) {
        self.job.on_into(e, now, &mut self.todo);
    }

    /// The next input: a button, a card message, the console. False: none.
    fn input(&mut self, m: &mut Motion, config: &mut MachineConfig, now: u32) -> bool {
        if let Some(b) = self.presses.pop() {
            self.event(Event::Button(b), now);
            return true;
        }
        if let Some(c) = self.controls.pop() {
            let e = match c {
                Control::Resume => Event::Resume,
                Control::Abort => {
                    self.feeder.abort();
                    if matches!(self.stream, Stream::Pattern(_)) {
                        self.stream = Stream::None;
                    }
                    Event::Abort
                }
                Control::Tool(t) => Event::Tool(t),
            };
            self.event(e, now);
            return true;
        }
        // Read in place, taken once handled: a copy would sit on the stack
        // under the file checks. The reader, a task that never runs in
        // the middle of this one, writes only free slots. Its end lent:
        // the message is handled with all of `self`.
        let news = self.news.clone();
        let taken = news.peek_with(|msg| {
            // Checking the files ends in a log line (`files ok` or the error).
            if self.stream.checking() && !room_for_a_line(&self.claim) {
                return false;
            }
            // Pattern bytes wait in the queue until winding wants them,
            // unless the card went out behind them: they are dropped (the
            // pattern is read again from its start once it is back).
            let winding = matches!(self.stream, Stream::Pattern(_));
            if matches!(msg.what, What::Data { .. }) && winding && msg.ticket == self.ticket {
                return crate::card::removal_waits(&news);
            }
            self.card(msg, m, config, now);
            true
        });
        if taken != Some(true) {
            return false;
        }
        let _ = news.pop();
        true
    }

    fn card(&mut self, msg: &CardMsg, m: &mut Motion, config: &mut MachineConfig, now: u32) {
        match msg.what {
            What::Inserted => return self.event(Event::CardInserted, now),
            What::Unusable => return self.event(Event::CardUnusable, now),
            What::Removed => {
                if self.stream.checking() {
                    self.stream = Stream::None;
                }
                return self.event(Event::CardRemoved, now);
            }
            _ if msg.ticket != self.ticket => return,
            // Its bytes follow.
            What::Opened { .. } | What::Listed => return,
            _ => {}
        }
        let files = match &mut self.stream {
            Stream::Files(files) if files.checked().is_none() => files,
            Stream::Pattern(_) => return self.pattern_ended(msg, now),
            _ => return,
        };
        let next = match msg.what {
            What::Data { at, len } => match crate::card::bytes(at, len, |b| files.push(b)) {
                Ok(()) => return,
                Err(e) => Err(e),
            },
            What::End => files.end(config),
            What::Missing => files.missing(config),
            _ => {
                error!("card: ", files.file().name(), ": read failed");
                self.stream = Stream::None;
                return self.event(Event::FilesInvalid, now);
            }
        };
        match next {
            Ok(Next::Open(name)) => self.open(name),
            Ok(Next::Machine) => self.other_machine(m, config, now),
            Ok(Next::Done) => self.files_valid(now),
            Err(e) => self.files_invalid(&e, now),
        }
    }

    // The answers to a file's end, out of line: their log lines are on
    // the stack only while they are written, not beside the checks of
    // every file (`Files::end`, the deepest of the job's calls).

    /// A plotter's card: that machine from here on, standing where it is
    /// as its zero (as `$machine=` does).
    #[inline(never)]
    fn other_machine(&mut self, m: &mut Motion, config: &mut MachineConfig, now: u32) {
        if let Stream::Files(f) = &self.stream {
            *config = *f.machine().expect("machine.txt read");
        }
        self.stream = Stream::None;
        m.configure(config);
        m.set_position([0; AXES]);
        m.renew();
        info!("machine.txt: the card is for the ", config.machine.name());
        self.event(Event::OtherMachine, now);
    }

    #[inline(never)]
    fn files_valid(&mut self, now: u32) {
        let Some(c) = (match &self.stream {
            Stream::Files(f) => f.checked(),
            _ => None,
        }) else {
            return;
        };
        info!(
            "files ok: shape ",
            c.params.shape,
            " nails ",
            c.params.nails,
            " radius ",
            c.params.radius_um,
            "um connections ",
            c.count
        );
        self.nails = c.params.nails;
        let event = Event::FilesValid {
            params: c.params,
            count: c.count,
            config: &c.config,
            id: c.id,
        };
        // The checked files stay where they are (the stream) while the job
        // takes them: a copy would sit on the stack under its deepest calls.
        self.job.on_into(event, now, &mut self.todo);
        // The job asks first, if it takes the card's machine at all.
        if !matches!(self.todo.first(), Some(Action::Configure)) {
            self.stream = Stream::None;
        }
    }

    #[inline(never)]
    fn files_invalid(&mut self, e: &FileError, now: u32) {
        self.stream = Stream::None;
        error!(*e);
        self.event(Event::FilesInvalid, now);
    }

    /// The card's machine taken, if the job asked for it and the machine
    /// stands: its figures never change under a move.
    fn configure(&mut self, m: &mut Motion, config: &mut MachineConfig) {
        if let (Some(c), true) = (self.stream.checked_machine(), m.is_idle()) {
            *config = *c;
            self.stream = Stream::None;
            m.configure(config);
        }
    }

    // The streams are built out of line: their values would sit in the
    // job task's frame, under its deepest calls (the files' checks).

    #[inline(never)]
    fn read_files(&mut self) {
        self.stream = Stream::Files(Files::new());
        self.open(FileName::Param);
    }

    #[inline(never)]
    fn open_pattern(&mut self) {
        self.stream = Stream::Pattern(Pattern::new(self.nails));
        self.open(FileName::Poradi);
    }

    /// Ask the card reader for a file; its messages carry the new ticket.
    fn open(&mut self, name: FileName) {
        self.ticket = self.ticket.wrapping_add(1).max(1);
        // The reader takes requests before anything else: a mailbox, this
        // request replacing one still waiting.
        // Byte by byte from flash (the names fit a `Name`).
        let text = name.name();
        let mut name = Name::EMPTY;
        for i in 0..text.len() {
            let _ = name.push(text.byte(i));
        }
        let request = Request::Open(name, self.ticket);
        self.card.put(request);
    }

    /// End, loss or failure of `poradi.txt` while winding.
    fn pattern_ended(&mut self, msg: &CardMsg, now: u32) {
        match (&mut self.stream, &msg.what) {
            (Stream::Pattern(p), What::End) => p.ended = true,
            _ => {
                self.stream = Stream::None;
                self.event(Event::PatternLost, now);
            }
        }
    }

    /// While winding wants nails and the card has delivered them.
    #[inline(never)]
    fn feed_nails(&mut self, now: u32) {
        // One nail's actions at a time: `todo` holds one event's.
        while self.todo.is_empty() && self.job.wants_nail() {
            let Stream::Pattern(p) = &mut self.stream else {
                return;
            };
            let nail = match p.next(&self.news) {
                Ok(Some(nail)) => nail,
                Ok(None) => return,
                Err(e) => {
                    // The file changed since it was checked.
                    error!(e);
                    self.stream = Stream::None;
                    self.event(Event::PatternLost, now);
                    return;
                }
            };
            self.event(Event::Nail(nail), now);
        }
    }

    /// Carry out actions while their log lines fit; `Some` to stop the run.
    #[inline(never)]
    fn carry_out(
        &mut self,
        m: &mut Motion,
        config: &mut MachineConfig,
        store: &mut Store,
    ) -> Option<Poll<Signal>> {
        while let Some(&a) = self.todo.first() {
            let logs = matches!(
                a,
                Action::Enter(_)
                    | Action::Log(_)
                    | Action::Prompt(_)
                    | Action::Progress(_)
                    | Action::Offer { .. }
                    | Action::Drift { .. }
            );
            if logs && !room_for_a_line(&self.claim) {
                return Some(Poll::After(5));
            }
            self.todo.remove(0);
            match a {
                Action::Enter(s) => {
                    info!("state: ", texts::state(s));
                    if s == State::End {
                        self.stream = Stream::None;
                        self.report_line = Some(0);
                    }
                }
                Action::Log(Msg::BadBoard(BadBoard::Gap(nail))) => {
                    let msg = texts::msg(Msg::BadBoard(BadBoard::Gap(nail)));
                    info!(msg, nail, " too close: fewer nails or larger radius")
                }
                Action::Log(msg) => info!(texts::msg(msg)),
                Action::Prompt(p) => info!(texts::prompt(p)),
                Action::ReadFiles => self.read_files(),
                Action::OpenPattern if self.stream.checked_machine().is_some() && !m.is_idle() => {
                    // The card's machine, not yet taken, before the pattern
                    // takes its place.
                    let _ = self.todo.insert(0, a);
                    return Some(Poll::Wait(Signal::PlannerRoom));
                }
                Action::OpenPattern => {
                    self.configure(m, config);
                    self.open_pattern();
                }
                Action::NextMoves if self.feeder.chained() => {
                    // The last wrap still runs: the next blends into it.
                    self.feeder.pull();
                }
                Action::StopMotion | Action::NextMoves if !m.is_idle() => {
                    // A console jog is running (the job's own steps are all
                    // done when it acts, unless chained): the job takes
                    // over once it ends, or once it has been stopped.
                    if a == Action::StopMotion {
                        m.cancel();
                    }
                    let _ = self.todo.insert(0, a);
                    return Some(Poll::Wait(Signal::PlannerRoom));
                }
                Action::DriversOff(mask) if m.busy_axes() & mask != 0 => {
                    // Never from under an axis that a jog is moving.
                    let _ = self.todo.insert(0, a);
                    return Some(Poll::Wait(Signal::PlannerRoom));
                }
                Action::StopMotion => {}
                Action::DriversOn(mask) => m.drivers.set(mask, true),
                Action::DriversOff(mask) => m.drivers.set(mask, false),
                Action::SetZero(_) if !m.is_idle() => {
                    // A console jog still running: zero where it ends.
                    let _ = self.todo.insert(0, a);
                    return Some(Poll::Wait(Signal::PlannerRoom));
                }
                Action::Configure => self.configure(m, config),
                Action::SetZero(axis) => {
                    let mut at = m.target();
                    at[axis.index()] = 0;
                    m.set_position(at);
                }
                Action::NextMoves => {
                    self.configure(m, config);
                    self.feeder.pull();
                }
                Action::Progress(p) => info!(p),
                Action::Offer { phase, next, total } => offer(phase, next, total),
                Action::Drift { nail, expected } => {
                    let base = m.target()[0];
                    info!(
                        "drift check: nail ",
                        nail,
                        ": base at ",
                        base,
                        " steps, expected ",
                        expected,
                        ": is the nail under the needle?"
                    );
                }
                // After a write under way (the last record): the header
                // goes in the other slot, but one write at a time.
                Action::Forget if store.saving() => {
                    let _ = self.todo.insert(0, a);
                    return Some(Poll::After(4));
                }
                Action::Forget => store.forget(),
            }
        }
        None
    }

    /// Hand the job's steps to the planner; report `MotionDone` when the
    /// machine stands after the last one.
    fn run_steps(&mut self, m: &mut Motion, store: &mut Store, now: u32) -> Poll<Signal> {
        let mut rig = Rig { m, store };
        match self.feeder.run(&mut self.job, &mut rig, now, STEPS_PER_RUN) {
            Feeding::Again => Poll::Again,
            Feeding::PlannerRoom => Poll::Wait(Signal::PlannerRoom),
            Feeding::After(ms) => Poll::After(ms),
            Feeding::Done => {
                self.event(Event::MotionDone, now);
                Poll::Again
            }
            Feeding::Idle => Poll::Idle,
        }
    }
}

/// The machine the job's steps run on: the motion, and the store that
/// writes their checkpoints.
struct Rig<'a> {
    m: &'a mut Motion,
    store: &'a mut Store,
}

impl Hardware for Rig<'_> {
    fn target(&self) -> PerAxis<i32> {
        self.m.target()
    }

    fn push(&mut self, to: PerAxis<i32>) -> Result<(), Full> {
        self.m.push(to, Feed::Rapid)
    }

    fn is_idle(&self) -> bool {
        self.m.is_idle()
    }

    fn unbegun(&self) -> u8 {
        self.m.unbegun()
    }

    fn drivers(&mut self, mask: u8, on: bool) {
        self.m.drivers.set(mask, on)
    }

    fn save(&mut self, save: Save, card: (u16, u32, CardId)) {
        match save {
            Save::Begin(phase) => self.store.begin(phase, card),
            Save::Record(r) => self.store.record(r),
        }
    }

    fn record(&mut self, r: Record) {
        self.store.record(r)
    }

    fn saving(&self) -> bool {
        self.store.saving()
    }
}

/// `>>> resume winding at wrap 1234/3000? green: resume, hold green 2 s:
/// discard`: what a power cut left, offered on the job's card.
fn offer(phase: Phase, next: u32, total: u32) {
    let what = match phase {
        Phase::Drilling => crate::flash_str!("drilling at hole "),
        Phase::Winding => crate::flash_str!("winding at wrap "),
    };
    info!(
        ">>> resume ",
        what, next, "/", total, "? green: resume, hold green 2 s: discard"
    );
}

impl Pattern {
    fn new(nails: u16) -> Self {
        Pattern {
            reader: PoradiReader::new(nails),
            chunk: [0; CHUNK],
            at: 0,
            len: 0,
            ended: false,
        }
    }

    /// The next nail index, from the chunk in hand or the card's queue;
    /// `None` until more bytes arrive.
    fn next(&mut self, news: &CardNews) -> Result<Option<u16>, FileError> {
        loop {
            if self.at < self.len {
                let (used, nail) = self
                    .reader
                    .next(&self.chunk[self.at as usize..self.len as usize])?;
                self.at += used as u8;
                if nail.is_some() {
                    return Ok(nail);
                }
                continue;
            }
            if self.ended {
                self.ended = false;
                return self.reader.finish();
            }
            // Copied in place: a copy of the message would sit in the job
            // task's frame.
            let took = news.peek_with(|msg| match msg.what {
                What::Data { at, len } => {
                    crate::card::bytes(at, len, |b| self.chunk[..b.len()].copy_from_slice(b));
                    self.at = 0;
                    self.len = len;
                    true
                }
                _ => false,
            });
            if took != Some(true) {
                return Ok(None);
            }
            let _ = news.pop();
        }
    }
}
