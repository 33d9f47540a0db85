//! The string-art job as a state machine (`docs/string-art.md`):
//! waiting for card → reading → prep drill → drilling → waiting for nails →
//! winding → end → waiting for card, with `paused` inside drilling and
//! winding and `bad files` when the card's files are unusable.
//!
//! Event-driven: the firmware turns buttons, the card and the console into
//! [`Event`]s, calls [`Job::on`] and carries out the returned [`Action`]s in
//! order. While the job is drilling or winding, the firmware pulls the
//! machine's [`MachineStep`]s from [`Job::next_step`] after each
//! [`Action::NextMoves`] until it returns `None`, runs them, and then sends
//! [`Event::MotionDone`]. While winding it feeds the pattern read from the
//! card through [`Event::Nail`] whenever [`Job::wants_nail`].
//!
//! Steps come in batches of one hole or one wrap: a pause (a long press of
//! green) stops the machine when the current batch is done — drill raised,
//! needle inside the ring — with the drivers holding. (The console's `!` is
//! a feed hold of the motion, not a pause of the job.)
//!
//! Power cuts: each phase keeps a checkpoint ([`crate::checkpoint`]) through
//! [`MachineStep::Save`] steps. After [`Event::PowerOn`] the firmware
//! hands the one it found over as [`Event::Saved`]; once the card is read,
//! the job's own card gets an offer (`resume offer`: green goes on, green
//! held 2 s discards), the axes are zeroed again (`prep resume`: all three,
//! they were unpowered), and the phase goes on from its last record.
//! Another card discards the checkpoint.
//!
//! Buttons: green confirms on a short press (released before 2 s) and
//! pauses drilling or winding on a long press; the white zeroing buttons
//! act on their press, in prep drill and waiting for nails only.
//!
//! The firmware's loop, in outline:
//! ```text
//! on each event e:    for a in job.on(e, now_ms) { carry out a }
//!                     (NextMoves: feeder.pull())
//! while job.wants_nail() and the pattern reader has an index j:
//!                     for a in job.on(Event::Nail(j), now_ms) { … }
//! then:               match feeder.run(job, machine, now_ms, budget) {
//!                         Done => job.on(Event::MotionDone, now_ms), … }
//! ```
//! The [`Feeder`] hands the batch's steps to the machine and waits for it
//! to stand: the same code in the firmware and in the host's estimate.

mod feed;
mod io;
mod phase_steps;
mod progress;
pub mod tools;

pub use super::Phase;
pub use feed::{Feeder, Feeding, Hardware, SAVE_POLL_MS};
pub use io::{Action, Actions, BadBoard, Event, Msg, Prompt, State, PROMPT_MARK};
pub use phase_steps::FEED;
pub use progress::{left_s, Progress};

use super::{bit, BlendWinder, Depths, Drilling, MachineStep, MACHINE_DRIVERS};
use crate::axis::Axis;
use crate::buttons::ButtonEvent;
use crate::checkpoint::Saved;
use crate::config::MachineConfig;
use crate::files::check::CardId;
use crate::files::param::Params;
use crate::geometry::{Board, StepScale};
use crate::pinmap::Button;
use crate::units::Milli;
use phase_steps::PhaseSteps;

/// Where the card stands, as far as the job knows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Card {
    Absent,
    /// Being read to see whether it is this job's card.
    Checking,
    /// In, and (once a job is on) holding the job's files.
    Present,
    /// Inserted at the end of a job: read when the next job starts (as
    /// a card left in is).
    Fresh,
}

/// The job's files, and the planners made from them at reading time (so
/// a board that cannot be made is refused before anything moves).
struct Plan {
    count: u32,
    id: CardId,
    /// The drilling's own figures: its planner is made when it starts.
    depths: Depths,
    /// The winding phase's steps use it in place ([`PhaseSteps::next`]);
    /// it keeps the board and the step scale for the whole plan.
    winder: BlendWinder,
}

impl Plan {
    fn board(&self) -> Board {
        *self.winder.board()
    }

    fn scale(&self) -> StepScale {
        *self.winder.scale()
    }
}

pub struct Job {
    state: State,
    card: Card,
    plan: Option<Plan>,
    /// The running (or paused) phase's steps.
    steps: Option<PhaseSteps>,
    /// Axes whose zeroing button was pressed once: driver off, zero pending.
    loose: u8,
    /// `NextMoves` sent, `MotionDone` not yet received.
    moving: bool,
    /// Winding lost its pattern stream (card removed or unreadable).
    lost: bool,
    /// Indices of a pattern opened again to pass over: fed before it was
    /// lost, or wound before a power cut or a jump.
    skip: u32,
    /// A power cut's checkpoint, until resumed or discarded.
    saved: Option<Saved>,
    /// Axes zeroed since the resume offer was taken.
    zeroed: u8,
    /// An operator's tool under way.
    run: Option<tools::Run>,
    /// `$wrap_step`: 1 asked, 2 its wrap handed out (pause after it).
    step_once: u8,
}

impl Default for Job {
    fn default() -> Self {
        Self::new()
    }
}

/// Collects one event's actions.
struct Out<'a>(&'a mut Actions);

impl Out<'_> {
    /// Out of line: inlined, its ~60 calls cost 1.5 KB of flash.
    #[inline(never)]
    fn push(&mut self, a: Action) {
        // The capacity covers the longest sequence (starting to wind).
        let pushed = self.0.push(a);
        debug_assert!(pushed.is_ok(), "too many actions");
    }

    /// `push(Action::Log(m))` in 8 B a call, not 20: the action is built
    /// here, not at each call.
    #[inline(never)]
    fn log(&mut self, m: Msg) {
        self.push(Action::Log(m));
    }

    /// `push(Action::DriversOn(mask))` or `DriversOff`, as [`Out::log`].
    #[inline(never)]
    fn drivers(&mut self, mask: u8, on: bool) {
        self.push(match on {
            true => Action::DriversOn(mask),
            false => Action::DriversOff(mask),
        });
    }

    /// `push(Action::Prompt(p))`, as [`Out::log`].
    #[inline(never)]
    fn prompt(&mut self, p: Prompt) {
        self.push(Action::Prompt(p));
    }
}

impl Job {
    pub const fn new() -> Self {
        Job {
            state: State::WaitingForCard,
            card: Card::Absent,
            plan: None,
            steps: None,
            loose: 0,
            moving: false,
            lost: false,
            skip: 0,
            saved: None,
            zeroed: 0,
            run: None,
            step_once: 0,
        }
    }

    /// The job's board and files, for its checkpoint's header: nails,
    /// connections, the card's identity.
    pub fn card(&self) -> Option<(u16, u32, CardId)> {
        let p = self.plan.as_ref()?;
        Some((p.board().nails(), p.count, p.id))
    }

    pub fn state(&self) -> State {
        self.state
    }

    /// The next step of the running phase; `None` at the end of a batch
    /// or outside drilling and winding. A pause takes effect at the end of
    /// the batch: its remaining steps still come (drill raised, needle
    /// inside the ring before the machine stands).
    /// Out of line: inlined into the job task, its frame would add to the
    /// task's own (the stack peak).
    #[inline(never)]
    pub fn next_step(&mut self) -> Option<MachineStep> {
        if self.run.is_some() {
            return self.tool_step();
        }
        let finishing = matches!(self.state, State::Paused(_))
            && self.steps.as_ref().is_some_and(PhaseSteps::mid_batch);
        if !self.state.is_running() && !finishing {
            return None;
        }
        let winder = &mut self.plan.as_mut()?.winder;
        self.steps.as_mut()?.next(winder)
    }

    /// The record of the last [`MachineStep::Mark`] handed out.
    pub fn marked(&self) -> Option<crate::checkpoint::Record> {
        self.steps.as_ref()?.marked()
    }

    /// The batch's steps are all out and winding runs on into another
    /// wrap: `MotionDone` need not wait for the machine to stand (its
    /// `advance` pulls the next batch at once), so wraps blend. Not while
    /// a pause, a `$wrap_step` or the pattern's next index is awaited, nor
    /// at the phase's end: those stop the machine.
    pub fn chains(&self) -> bool {
        self.state == State::Winding
            && self.run.is_none()
            && self.step_once == 0
            && !self.lost
            && self
                .steps
                .as_ref()
                .is_some_and(|s| !s.exhausted && !s.starved())
    }

    /// Drilling or winding, or paused inside them: the job owns the
    /// machine's motion, and nothing else may move it.
    pub fn owns_motion(&self) -> bool {
        self.phase().is_some() || self.run.is_some()
    }

    /// Winding wants the next index of the pattern ([`Event::Nail`]).
    pub fn wants_nail(&self) -> bool {
        !self.lost
            && self
                .steps
                .as_ref()
                .is_some_and(|s| self.skip > 0 || s.wants_nail())
    }

    /// Handles one event; `now_ms` is the firmware's millisecond clock
    /// (for the time-left estimate; it may wrap).
    pub fn on(&mut self, event: Event<'_>, now_ms: u32) -> Actions {
        let mut actions = Actions::new();
        self.on_into(event, now_ms, &mut actions);
        actions
    }

    /// [`Job::on`] adding the actions to `actions` (on the AVR, the job
    /// task's queue of them: no copy on the stack).
    pub fn on_into(&mut self, event: Event<'_>, now_ms: u32, actions: &mut Actions) {
        let mut out = Out(actions);
        let o = &mut out;
        match event {
            // One copy of the fresh job for both.
            Event::PowerOn | Event::OtherMachine => {
                *self = Job::new();
                if matches!(event, Event::PowerOn) {
                    o.drivers(MACHINE_DRIVERS, false);
                    self.enter(State::WaitingForCard, o);
                }
            }
            Event::CardInserted => self.card_inserted(o),
            Event::CardUnusable => self.card_unusable(o),
            Event::CardRemoved => self.card_removed(o, now_ms),
            Event::FilesValid {
                params,
                count,
                config,
                id,
            } => self.files_valid(params, count, id, config, o),
            Event::FilesInvalid => self.files_invalid(o),
            Event::Button(b) => self.button(b, o, now_ms),
            Event::MotionDone if self.run.is_some() => {
                self.moving = false;
                self.tool_done(o);
            }
            Event::MotionDone => {
                self.moving = false;
                if let Some(m) = &mut self.steps {
                    m.release();
                }
                if self.state.is_running() {
                    self.advance(o, now_ms);
                }
            }
            Event::Resume => self.resume(o, now_ms),
            Event::Abort => self.abort(o),
            Event::Nail(j) => self.nail(j, o, now_ms),
            Event::Saved(s) => self.saved = Some(s),
            Event::Tool(t) => self.tool(t, o, now_ms),
            Event::PatternLost => {
                if self.phase() == Some(Phase::Winding) {
                    self.card = Card::Absent;
                    self.lose_pattern(o, now_ms);
                }
            }
        }
    }

    /// The phase of drilling, winding or their pause.
    fn phase(&self) -> Option<Phase> {
        match self.state {
            State::Drilling => Some(Phase::Drilling),
            State::Winding => Some(Phase::Winding),
            State::Paused(p) => Some(p),
            _ => None,
        }
    }

    fn enter(&mut self, state: State, o: &mut Out) {
        self.state = state;
        o.push(Action::Enter(state));
        let prompt = match state {
            State::WaitingForCard => Prompt::InsertCard,
            State::BadFiles => Prompt::ReplaceCard,
            State::PrepDrill => Prompt::StartDrilling,
            State::WaitingForNails => Prompt::StartWinding,
            State::Paused(_) if self.lost => Prompt::InsertCard,
            State::Paused(_) => Prompt::Resume,
            State::End => Prompt::Finished,
            State::PrepResume(_) => Prompt::ZeroToResume,
            State::Offer => {
                if let (Some(s), Some(p)) = (self.saved, &self.plan) {
                    let total = match s.phase() {
                        Phase::Drilling => p.board().nails() as u32,
                        Phase::Winding => p.count,
                    };
                    o.push(Action::Offer {
                        phase: s.phase(),
                        next: (s.done() + 1).min(total),
                        total,
                    });
                }
                return;
            }
            State::Reading | State::Drilling | State::Winding => return,
        };
        o.prompt(prompt);
    }

    /// Back to the start: the job and its files are dropped; a card in
    /// the slot (the last job's, left in, or another put in at the end)
    /// is read for the next job at once, else the job waits for one.
    fn restart(&mut self, o: &mut Out) {
        self.plan = None;
        self.steps = None;
        self.loose = 0;
        match self.card {
            Card::Fresh | Card::Present => self.read(o),
            _ => self.enter(State::WaitingForCard, o),
        }
    }

    fn read(&mut self, o: &mut Out) {
        self.card = Card::Checking;
        self.enter(State::Reading, o);
        o.push(Action::ReadFiles);
    }

    fn card_inserted(&mut self, o: &mut Out) {
        match self.state {
            State::WaitingForCard | State::BadFiles => self.read(o),
            // The job is done with its card: the next one is read on green.
            State::End => self.card = Card::Fresh,
            _ if self.card == Card::Absent && self.plan.is_some() => {
                // Is it the job's card again? Checked before it counts.
                self.card = Card::Checking;
                o.push(Action::ReadFiles);
            }
            _ => {}
        }
    }

    /// A card in the slot that has nothing to read: as bad files, never
    /// `insert card` while it is in; mid-job, not the job's card.
    fn card_unusable(&mut self, o: &mut Out) {
        match self.state {
            State::WaitingForCard | State::BadFiles => {
                self.card = Card::Present;
                self.enter(State::BadFiles, o);
            }
            // Read (and refused) when the next job starts.
            State::End => self.card = Card::Fresh,
            _ if self.card == Card::Absent && self.plan.is_some() => o.log(Msg::OtherCard),
            _ => {}
        }
    }

    fn card_removed(&mut self, o: &mut Out, now_ms: u32) {
        self.card = Card::Absent;
        let stops = match self.state {
            State::WaitingForCard => return,
            // Said once: the pattern's stream may have failed first.
            _ if self.phase() == Some(Phase::Winding) && self.lost => return,
            _ if self.phase() == Some(Phase::Winding) => return self.lose_pattern(o, now_ms),
            State::Reading | State::BadFiles => false,
            // Nothing done yet (a checkpoint is kept): start over, with the drivers off as
            // whenever the job waits for a card.
            State::PrepDrill | State::Offer | State::PrepResume(_) => true,
            // Drilling needs no card; winding will ask for it.
            _ => return o.log(Msg::CardRemoved),
        };
        // One copy of what every start over does.
        o.log(Msg::CardRemoved);
        if stops {
            o.push(Action::StopMotion);
            o.drivers(MACHINE_DRIVERS, false);
        }
        self.restart(o);
    }

    /// Winding without its pattern: paused until the card is back.
    fn lose_pattern(&mut self, o: &mut Out, now_ms: u32) {
        self.lost = true;
        o.log(Msg::PatternLost);
        if self.state == State::Winding {
            self.pause(o, now_ms);
        } else {
            o.prompt(Prompt::InsertCard);
        }
    }

    // Out of line: the board's plan is big, and inlined into `on` it
    // would sit in the frame under every event (the stack's peak).
    #[inline(never)]
    fn files_valid(
        &mut self,
        params: Params,
        count: u32,
        id: CardId,
        config: &MachineConfig,
        o: &mut Out,
    ) {
        if self.state == State::Reading {
            o.push(Action::Configure);
            // The gaps are checked on the plan in place, from this frame:
            // no winder or plan on the stack under their trigonometry.
            let planned = self.plan(params, count, id, config).and_then(|()| {
                self.plan
                    .as_ref()
                    .map_or(Ok(()), |p| p.winder.check_gaps().map_err(BadBoard::from))
            });
            if planned.is_err() {
                self.plan = None;
            }
            match planned {
                Ok(()) => {
                    self.card = Card::Present;
                    if let Some(s) = self.saved {
                        let h = s.header;
                        if (h.id, h.count, h.nails) == (id, count, params.nails) {
                            self.enter(State::Offer, o);
                            return;
                        }
                        self.saved = None;
                        o.log(Msg::SavedOtherCard);
                        o.push(Action::Forget);
                    }
                    o.drivers(MACHINE_DRIVERS, true);
                    self.enter(State::PrepDrill, o);
                }
                Err(why) => {
                    o.log(Msg::BadBoard(why));
                    self.card = Card::Present;
                    self.enter(State::BadFiles, o);
                }
            }
            return;
        }
        if self.card != Card::Checking {
            return;
        }
        let same = self.plan.as_ref().is_some_and(|p| p.id == id);
        if !same {
            self.card = Card::Absent;
            o.log(Msg::OtherCard);
            return;
        }
        self.card = Card::Present;
        o.log(Msg::CardOk);
        if self.lost {
            self.lost = false;
            self.open_pattern(self.steps.as_ref().map_or(0, PhaseSteps::fed), o);
        }
        match self.state {
            State::WaitingForNails => o.prompt(Prompt::StartWinding),
            State::Paused(_) => o.prompt(Prompt::Resume),
            _ => {}
        }
    }

    /// The job's plan, its winder's gaps not yet checked; false when the
    /// board cannot be made. Out of line: the plan it builds is not on the
    /// stack under the checks.
    #[inline(never)]
    fn plan(
        &mut self,
        params: Params,
        count: u32,
        id: CardId,
        config: &MachineConfig,
    ) -> Result<(), BadBoard> {
        self.plan = None;
        let radius = i32::try_from(params.radius_um).map_err(|_| BadBoard::Radius)?;
        let board = Board::new(params.shape, params.nails, Milli(radius))?;
        let winder = BlendWinder::unchecked(board, config)?;
        self.plan = Some(Plan {
            count,
            id,
            depths: Depths::blended(config),
            winder,
        });
        Ok(())
    }

    fn files_invalid(&mut self, o: &mut Out) {
        if self.state == State::Reading {
            self.card = Card::Present;
            self.enter(State::BadFiles, o);
        } else if self.card == Card::Checking {
            self.card = Card::Absent;
            o.log(Msg::OtherCard);
        }
    }

    fn button(&mut self, event: ButtonEvent, o: &mut Out, now_ms: u32) {
        if self.run.is_some() {
            // A tool is moving the machine: buttons wait.
            return;
        }
        let axis = |b| match b {
            Button::ZeroBase => Some(Axis::Base),
            Button::ZeroRadial => Some(Axis::Radial),
            Button::ZeroDrill => Some(Axis::Drill),
            Button::Confirm => None,
        };
        match event {
            ButtonEvent::Pressed(b) => {
                if let Some(axis) = axis(b) {
                    if matches!(
                        self.state,
                        State::PrepDrill | State::WaitingForNails | State::PrepResume(_)
                    ) {
                        self.zero(axis, o);
                    }
                }
            }
            ButtonEvent::LongPress(Button::Confirm) if self.state == State::Offer => {
                self.saved = None;
                o.push(Action::Forget);
                o.log(Msg::SavedDiscarded);
                o.drivers(MACHINE_DRIVERS, true);
                self.enter(State::PrepDrill, o);
            }
            ButtonEvent::LongPress(Button::Confirm) => self.pause(o, now_ms),
            e if e.is_short_press(Button::Confirm) => self.confirm(o, now_ms),
            _ => {}
        }
    }

    /// First press: the driver off, to move the axis by hand. Second: the
    /// position is the zero, the driver holds again.
    fn zero(&mut self, axis: Axis, o: &mut Out) {
        let b = bit(axis);
        if self.loose & b == 0 {
            self.loose |= b;
            o.drivers(b, false);
            o.log(Msg::Loose(axis));
        } else {
            self.loose &= !b;
            self.zeroed |= b;
            o.push(Action::SetZero(axis));
            o.drivers(b, true);
            o.log(Msg::Zeroed(axis));
        }
    }

    /// Green, a short press.
    fn confirm(&mut self, o: &mut Out, now_ms: u32) {
        match self.state {
            State::PrepDrill | State::WaitingForNails if self.loose != 0 => {
                o.log(Msg::ZeroPending);
            }
            State::PrepDrill => self.start_drilling(None, o, now_ms),
            State::WaitingForNails if self.card != Card::Present => {
                o.log(Msg::NoCard);
                o.prompt(Prompt::InsertCard);
            }
            State::WaitingForNails => self.start_winding(o, now_ms),
            State::Paused(_) => self.resume(o, now_ms),
            State::End => self.restart(o),
            State::Offer => {
                self.loose = 0;
                self.zeroed = 0;
                o.drivers(MACHINE_DRIVERS, true);
                let phase = self.saved.map_or(Phase::Drilling, |s| s.phase());
                self.enter(State::PrepResume(phase), o);
            }
            State::PrepResume(_) if self.loose != 0 => o.log(Msg::ZeroPending),
            State::PrepResume(_) if self.zeroed != MACHINE_DRIVERS => {
                o.log(Msg::ZeroAll);
            }
            State::PrepResume(_) => self.start_resumed(o, now_ms),
            _ => {}
        }
    }

    /// Zeroed again after a power cut: the checkpoint's phase goes on.
    fn start_resumed(&mut self, o: &mut Out, now_ms: u32) {
        let (Some(s), Some(plan)) = (self.saved.take(), &mut self.plan) else {
            return;
        };
        match s.phase() {
            Phase::Drilling => self.start_drilling(Some(s.n()), o, now_ms),
            _ => {
                self.steps = Some(PhaseSteps::wind(plan.count, Some(s.last), now_ms));
                self.open_pattern(s.done(), o);
                // The resume entry switches the drill's driver off itself.
                self.go(State::Winding, MACHINE_DRIVERS, o, now_ms);
            }
        }
    }

    /// A phase starts (its steps in place): its state, its drivers, its
    /// first line.
    fn go(&mut self, state: State, drivers: u8, o: &mut Out, now_ms: u32) {
        let Some(steps) = &mut self.steps else { return };
        let first = steps.reporter.first(now_ms);
        self.enter(state, o);
        o.drivers(drivers, true);
        o.push(Action::Progress(first));
        self.next_moves(o);
    }

    /// Drilling from the first hole, or from the checkpoint's `resume`:
    /// one copy of the steps' setup for both.
    fn start_drilling(&mut self, resume: Option<u32>, o: &mut Out, now_ms: u32) {
        let Some(plan) = &self.plan else { return };
        let nails = plan.board().nails();
        let resume = resume.map(|n| n.min(u32::from(nails)));
        let hole = resume.unwrap_or(0) as u16;
        self.steps = Some(PhaseSteps::drill(
            Drilling::on(plan.board(), plan.scale(), plan.depths).from_hole(hole),
            nails,
            resume,
            now_ms,
        ));
        self.go(State::Drilling, MACHINE_DRIVERS, o, now_ms);
    }

    fn start_winding(&mut self, o: &mut Out, now_ms: u32) {
        let Some(plan) = &mut self.plan else { return };
        let mut steps = PhaseSteps::wind(plan.count, None, now_ms);
        let first = steps.reporter.first(now_ms);
        self.steps = Some(steps);
        self.enter(State::Winding, o);
        // Drilling came home a whole number of turns from the base's zero,
        // and the winder counts from zero: without this, an unzeroed base
        // would unwind those turns.
        o.push(Action::SetZero(Axis::Base));
        // The winder's entry switches the drill's driver off itself.
        o.drivers(bit(Axis::Base) | bit(Axis::Radial), true);
        self.open_pattern(0, o);
        o.push(Action::Progress(first));
        self.next_moves(o);
    }

    /// The pattern read from its start, its first `skip` indices passed
    /// over.
    fn open_pattern(&mut self, skip: u32, o: &mut Out) {
        self.skip = skip;
        o.push(Action::OpenPattern);
    }

    fn next_moves(&mut self, o: &mut Out) {
        self.moving = true;
        o.push(Action::NextMoves);
    }

    /// The machine has carried out every step handed out: report, then
    /// the next batch, or the end of the phase.
    fn advance(&mut self, o: &mut Out, now_ms: u32) {
        let Some(m) = &mut self.steps else { return };
        if let Some(p) = m.reporter.update(m.done, now_ms) {
            o.push(Action::Progress(p));
        }
        if m.exhausted {
            if let Some(p) = m.reporter.finish(now_ms) {
                o.push(Action::Progress(p));
            }
            self.steps = None;
            // The phase's last step switched the drivers off.
            let next = match self.state {
                State::Drilling => State::WaitingForNails,
                _ => {
                    o.push(Action::Forget);
                    State::End
                }
            };
            self.enter(next, o);
        } else if self.step_once == 2 {
            // `$wrap_step`: that wrap was the one.
            self.step_once = 0;
            self.pause(o, now_ms);
        } else if !m.starved() {
            if self.step_once == 1 {
                self.step_once = 2;
            }
            self.next_moves(o);
        }
    }

    fn pause(&mut self, o: &mut Out, now_ms: u32) {
        let Some(phase) = self.phase().filter(|_| self.state.is_running()) else {
            return;
        };
        if let Some(m) = &mut self.steps {
            m.reporter.pause(now_ms);
        }
        self.enter(State::Paused(phase), o);
    }

    fn resume(&mut self, o: &mut Out, now_ms: u32) {
        let State::Paused(phase) = self.state else {
            return;
        };
        if self.lost {
            o.log(Msg::NoCard);
            o.prompt(Prompt::InsertCard);
            return;
        }
        if let Some(m) = &mut self.steps {
            m.reporter.resume(now_ms);
        }
        o.log(Msg::Resumed);
        self.enter(
            match phase {
                Phase::Drilling => State::Drilling,
                Phase::Winding => State::Winding,
            },
            o,
        );
        if self.moving {
            // Still finishing the last batch: keep pulling.
            o.push(Action::NextMoves);
        } else {
            self.advance(o, now_ms);
        }
    }

    /// Ctrl-X: the steps handed out are gone, the job ends. The drivers
    /// keep holding; the next job starts over from its card.
    fn abort(&mut self, o: &mut Out) {
        if self.phase().is_none() {
            return;
        }
        self.steps = None;
        self.moving = false;
        self.lost = false;
        o.log(Msg::Aborted);
        o.push(Action::Forget);
        self.enter(State::End, o);
    }

    fn nail(&mut self, j: u16, o: &mut Out, now_ms: u32) {
        if !self.wants_nail() {
            return;
        }
        let in_range = self.plan.as_ref().is_some_and(|p| j < p.board().nails());
        if !in_range {
            // The check pass accepted this file: the card has changed.
            self.card = Card::Absent;
            self.lose_pattern(o, now_ms);
            return;
        }
        if self.skip > 0 {
            self.skip -= 1;
            return;
        }
        let Some(m) = &mut self.steps else { return };
        m.feed(j);
        if self.state == State::Winding && !self.moving {
            // It was waiting for this index.
            self.advance(o, now_ms);
        }
    }
}

#[cfg(test)]
mod tests;
