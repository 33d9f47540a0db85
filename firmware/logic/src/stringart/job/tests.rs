//! The job driven by scripted events, through a bench that carries out its
//! actions the way the firmware does.

use super::*;
use crate::axis::AXES;
use crate::stringart::{Save, Winding};
use std::vec::Vec;

mod feed;
mod flow;
mod props;
mod resume;
mod tools;

const HEX: Params = Params {
    shape: 6,
    nails: 24,
    radius_um: 402_000,
};
const PATTERN: [u16; 5] = [0, 7, 13, 23, 2];
const CONFIG: MachineConfig = MachineConfig::STRING_ART;
const ALL: u8 = MACHINE_DRIVERS;

fn valid(params: Params, count: u32) -> Event<'static> {
    valid_pattern(params, count, 0)
}

/// Files of this board and count with pattern number `pattern`.
fn valid_pattern(params: Params, count: u32, pattern: u8) -> Event<'static> {
    let mut id = CardId::default();
    id.param.add(std::format!("{params:?}").as_bytes());
    id.poradi.add(&count.to_le_bytes());
    id.poradi.add(&[pattern]);
    Event::FilesValid {
        params,
        count,
        config: &CONFIG,
        id,
    }
}

fn short(button: Button) -> [Event<'static>; 2] {
    [
        Event::Button(ButtonEvent::Pressed(button)),
        Event::Button(ButtonEvent::Released {
            button,
            held_ms: 150,
        }),
    ]
}

/// Green held for 2 s: pause after the current hole or wrap.
const LONG_GREEN: Event<'static> = Event::Button(ButtonEvent::LongPress(Button::Confirm));

fn board(params: Params) -> Board {
    Board::new(params.shape, params.nails, Milli(params.radius_um as i32)).unwrap()
}

/// The whole drilling / winding sequence as the planners make it.
fn drilled(params: Params) -> Vec<MachineStep> {
    Drilling::blended(board(params), &CONFIG).collect()
}

fn wound(params: Params, pattern: &[u16]) -> Vec<MachineStep> {
    let winder = BlendWinder::new(board(params), &CONFIG).unwrap();
    Winding::new(winder, pattern.iter().copied())
        .map(Result::unwrap)
        .collect()
}

/// The firmware's side: carries out actions, pulls steps, reads the
/// pattern from a "card".
struct Bench {
    job: Job,
    now: u32,
    params: Params,
    pattern: Vec<u16>,
    /// Next index of the pattern the card reader delivers.
    at: usize,
    /// Steps carried out (checkpoints apart), and every action seen.
    steps: Vec<MachineStep>,
    /// Checkpoints written, in order.
    saves: Vec<Save>,
    actions: Vec<Action>,
    pulling: bool,
    drivers: u8,
    pos: [i32; AXES],
}

impl Bench {
    fn new(params: Params, pattern: &[u16]) -> Self {
        Bench {
            job: Job::new(),
            now: 0,
            params,
            pattern: pattern.to_vec(),
            at: 0,
            steps: Vec::new(),
            saves: Vec::new(),
            actions: Vec::new(),
            pulling: false,
            drivers: 0,
            pos: [0; AXES],
        }
    }

    fn send(&mut self, e: Event) -> Vec<Action> {
        let actions: Vec<Action> = self.job.on(e, self.now).into_iter().collect();
        for a in &actions {
            match *a {
                Action::DriversOn(m) => self.drivers |= m,
                Action::DriversOff(m) => self.drivers &= !m,
                Action::SetZero(axis) => self.pos[axis.index()] = 0,
                Action::OpenPattern => self.at = 0,
                Action::NextMoves => self.pulling = true,
                _ => {}
            }
        }
        self.actions.extend(&actions);
        actions
    }

    fn sends(&mut self, events: &[Event]) -> Vec<Action> {
        events.iter().flat_map(|&e| self.send(e)).collect()
    }

    fn green(&mut self) -> Vec<Action> {
        self.sends(&short(Button::Confirm))
    }

    /// Card in, files good: prep drill.
    fn ready(&mut self) {
        let count = self.pattern.len() as u32;
        self.sends(&[
            Event::PowerOn,
            Event::CardInserted,
            valid(self.params, count),
        ]);
        assert_eq!(self.job.state(), State::PrepDrill);
    }

    /// Feeds the pattern while the job wants it.
    fn feed(&mut self) {
        while self.job.wants_nail() && self.at < self.pattern.len() {
            let j = self.pattern[self.at];
            self.at += 1;
            self.send(Event::Nail(j));
        }
    }

    /// Pulls and carries out one batch; false if nothing was asked for.
    fn batch(&mut self) -> bool {
        self.feed();
        if !self.pulling {
            return false;
        }
        self.pulling = false;
        while let Some(step) = self.job.next_step() {
            match step {
                MachineStep::Move(t) => {
                    for (p, t) in self.pos.iter_mut().zip(t) {
                        *p = t.unwrap_or(*p);
                    }
                    self.now += 500;
                }
                MachineStep::Dwell(ms) => self.now += ms as u32,
                MachineStep::Drivers { mask, on: true } => self.drivers |= mask,
                MachineStep::Drivers { mask, on: false } => self.drivers &= !mask,
                MachineStep::Save(save) => {
                    self.saves.push(save);
                    continue;
                }
                MachineStep::Mark(r) => {
                    self.saves.push(Save::Record(r));
                    continue;
                }
                MachineStep::Durable => continue,
            }
            self.steps.push(step);
            self.feed();
        }
        self.send(Event::MotionDone);
        true
    }

    fn run(&mut self) {
        while self.batch() {}
    }

    fn progress(&self) -> Vec<Progress> {
        self.actions
            .iter()
            .filter_map(|a| match a {
                Action::Progress(p) => Some(*p),
                _ => None,
            })
            .collect()
    }
}

fn moves(actions: &[Action]) -> bool {
    actions.contains(&Action::NextMoves)
}

#[test]
fn a_whole_hexagon_job() {
    let mut b = Bench::new(HEX, &PATTERN);
    assert_eq!(
        b.send(Event::PowerOn),
        [
            Action::DriversOff(ALL),
            Action::Enter(State::WaitingForCard),
            Action::Prompt(Prompt::InsertCard)
        ]
    );
    assert_eq!(
        b.send(Event::CardInserted),
        [Action::Enter(State::Reading), Action::ReadFiles]
    );
    assert_eq!(
        b.send(valid(HEX, 5)),
        [
            Action::Configure,
            Action::DriversOn(ALL),
            Action::Enter(State::PrepDrill),
            Action::Prompt(Prompt::StartDrilling)
        ]
    );
    // Green acts on the release of a short press.
    assert_eq!(
        b.send(Event::Button(ButtonEvent::Pressed(Button::Confirm))),
        []
    );
    let go = b.send(Event::Button(ButtonEvent::Released {
        button: Button::Confirm,
        held_ms: 150,
    }));
    assert_eq!(
        go[..3],
        [
            Action::Enter(State::Drilling),
            Action::DriversOn(ALL),
            Action::Progress(Progress {
                phase: Phase::Drilling,
                done: 0,
                total: 24,
                left_s: None
            })
        ]
    );
    assert_eq!(go[3..], [Action::NextMoves]);
    b.run();
    // Every step of the drilling planner, in order; home over nail 0 with
    // the drivers off, and the job waits for the nails.
    assert_eq!(b.steps, drilled(HEX));
    assert_eq!(b.job.state(), State::WaitingForNails);
    assert_eq!(b.drivers, 0);
    assert_eq!(
        b.actions[b.actions.len() - 2..],
        [
            Action::Enter(State::WaitingForNails),
            Action::Prompt(Prompt::StartWinding)
        ]
    );
    // One batch per hole: a progress line after each (24 < 20 · 2), the
    // start's included, and none twice.
    let done: Vec<u32> = b.progress().iter().map(|p| p.done).collect();
    assert_eq!(done, (0..=24).collect::<Vec<_>>());

    b.steps.clear();
    let go = b.green();
    assert_eq!(
        go,
        [
            Action::Enter(State::Winding),
            Action::SetZero(Axis::Base),
            Action::DriversOn(0b011),
            Action::OpenPattern,
            Action::Progress(Progress {
                phase: Phase::Winding,
                done: 0,
                total: 5,
                left_s: None
            }),
            Action::NextMoves
        ]
    );
    b.run();
    // Entry, all five wraps (the last one too), drivers off.
    assert_eq!(b.steps, wound(HEX, &PATTERN));
    assert_eq!(b.job.state(), State::End);
    assert_eq!(b.drivers, 0);
    assert_eq!(b.at, 5, "the pattern was read once");
    let wind: Vec<(u32, u32)> = b
        .progress()
        .iter()
        .filter(|p| p.phase == Phase::Winding)
        .map(|p| (p.done, p.total))
        .collect();
    assert_eq!(wind, [(0, 5), (1, 5), (2, 5), (3, 5), (4, 5), (5, 5)]);
    // The card left in: green reads it for the next job.
    assert_eq!(
        b.green(),
        [Action::Enter(State::Reading), Action::ReadFiles]
    );
    b.send(valid(HEX, 5));
    assert_eq!(b.job.state(), State::PrepDrill);
}

#[test]
fn a_card_changed_at_the_end_is_read_on_green() {
    let mut b = Bench::new(HEX, &PATTERN);
    b.ready();
    b.green();
    b.run();
    b.green();
    b.run();
    assert_eq!(b.job.state(), State::End);
    assert_eq!(
        b.sends(&[Event::CardRemoved, Event::CardInserted]),
        [Action::Log(Msg::CardRemoved)]
    );
    assert_eq!(
        b.green(),
        [Action::Enter(State::Reading), Action::ReadFiles]
    );
    b.send(valid(HEX, 5));
    assert_eq!(b.job.state(), State::PrepDrill);
}

#[test]
fn time_left_is_estimated_from_the_time_spent() {
    let mut b = Bench::new(HEX, &PATTERN);
    b.ready();
    b.green();
    b.run();
    // A hole takes 3 moves of 500 ms and a 250 ms dwell (the first also
    // the raise): after 12 holes, 12 more take about as long again.
    let half = b.progress()[12];
    assert_eq!((half.done, half.left_s), (12, Some(21)));
    let last = *b.progress().last().unwrap();
    assert_eq!(last.left_s, Some(0));
}

#[test]
fn zeroing_takes_two_presses() {
    let mut b = Bench::new(HEX, &PATTERN);
    b.ready();
    let press = |b: &mut Bench, button| b.send(Event::Button(ButtonEvent::Pressed(button)));
    assert_eq!(
        press(&mut b, Button::ZeroRadial),
        [
            Action::DriversOff(0b010),
            Action::Log(Msg::Loose(Axis::Radial))
        ]
    );
    assert_eq!(b.drivers, 0b101);
    // Its release, long or short, does nothing.
    let release = Event::Button(ButtonEvent::Released {
        button: Button::ZeroRadial,
        held_ms: 3000,
    });
    assert_eq!(b.send(release), []);
    // Green is refused while an axis is loose.
    assert_eq!(b.green(), [Action::Log(Msg::ZeroPending)]);
    assert_eq!(b.job.state(), State::PrepDrill);
    b.pos[1] = -77;
    assert_eq!(
        press(&mut b, Button::ZeroRadial),
        [
            Action::SetZero(Axis::Radial),
            Action::DriversOn(0b010),
            Action::Log(Msg::Zeroed(Axis::Radial))
        ]
    );
    assert_eq!((b.pos[1], b.drivers), (0, ALL));
    // Axes are independent.
    press(&mut b, Button::ZeroDrill);
    press(&mut b, Button::ZeroBase);
    assert_eq!(b.drivers, 0b010);
    press(&mut b, Button::ZeroDrill);
    assert_eq!(b.green(), [Action::Log(Msg::ZeroPending)]);
    press(&mut b, Button::ZeroBase);
    assert_eq!(b.drivers, ALL);
    assert_eq!(b.green()[0], Action::Enter(State::Drilling));
    // Outside the preparation states the white buttons do nothing.
    assert_eq!(press(&mut b, Button::ZeroBase), []);
    b.run();
    assert_eq!(b.job.state(), State::WaitingForNails);
    // Waiting for nails: the drivers are off; zeroing switches one on.
    assert_eq!(
        press(&mut b, Button::ZeroDrill)[0],
        Action::DriversOff(0b100)
    );
    assert_eq!(
        press(&mut b, Button::ZeroDrill)[0],
        Action::SetZero(Axis::Drill)
    );
    assert_eq!(b.drivers, 0b100);
    b.green();
    b.run();
    assert_eq!(b.job.state(), State::End);
    assert_eq!(press(&mut b, Button::ZeroBase), []);
}

#[test]
fn long_press_pauses_after_the_batch_and_a_short_press_resumes() {
    let mut b = Bench::new(HEX, &PATTERN);
    b.ready();
    b.green();
    b.batch(); // the raise and the first hole
    let first = b.steps.len();
    // The firmware has taken two steps of the second hole when the long
    // press comes.
    b.pulling = false;
    b.steps
        .extend([b.job.next_step().unwrap(), b.job.next_step().unwrap()]);
    let long = b.send(LONG_GREEN);
    assert_eq!(
        long,
        [
            Action::Enter(State::Paused(Phase::Drilling)),
            Action::Prompt(Prompt::Resume)
        ]
    );
    // The hole is finished first: its dwell and retract still come (the
    // machine stands with the drill raised), then nothing.
    // The hole's record comes between them.
    let mut rest: std::vec::Vec<MachineStep> = core::iter::from_fn(|| b.job.next_step()).collect();
    assert!(
        matches!(
            rest[..],
            [
                MachineStep::Dwell(_),
                MachineStep::Save(Save::Record(_)),
                MachineStep::Move(_)
            ]
        ),
        "{rest:?}"
    );
    rest.remove(1);
    b.steps.extend(rest);
    assert_eq!(b.job.next_step(), None, "paused after the hole");
    assert_eq!(b.send(Event::MotionDone), []);
    assert_eq!(b.job.next_step(), None, "no new hole while paused");
    // Releasing the long press does not resume; the drivers keep holding.
    let release = Event::Button(ButtonEvent::Released {
        button: Button::Confirm,
        held_ms: 2500,
    });
    assert_eq!(b.send(release), []);
    assert_eq!(b.drivers, ALL);
    assert_eq!(b.job.state(), State::Paused(Phase::Drilling));
    let resumed = b.green();
    assert_eq!(
        resumed[..2],
        [Action::Log(Msg::Resumed), Action::Enter(State::Drilling)]
    );
    // The hole finished before the pause counts now.
    assert!(matches!(resumed[2], Action::Progress(p) if p.done == 2));
    assert_eq!(resumed[3..], [Action::NextMoves]);
    assert_eq!(b.steps.len(), first + 4);
    b.run();
    // Nothing lost, nothing repeated.
    assert_eq!(b.steps, drilled(HEX));
    // A long press outside drilling and winding does nothing.
    assert_eq!(b.send(LONG_GREEN), []);
}

#[test]
fn long_press_pauses_winding_and_serial_resume_resumes() {
    let mut b = Bench::new(HEX, &PATTERN);
    b.ready();
    assert_eq!(b.send(LONG_GREEN), [], "nothing to pause");
    b.green();
    b.run();
    b.green();
    b.batch(); // the entry
    b.batch(); // nail 0
    assert_eq!(
        b.send(LONG_GREEN),
        [
            Action::Enter(State::Paused(Phase::Winding)),
            Action::Prompt(Prompt::Resume)
        ]
    );
    assert_eq!(b.send(LONG_GREEN), [], "already paused");
    // The batch the firmware was already asked for is empty, and then
    // nothing more is asked for.
    let len = b.steps.len();
    assert!(b.batch());
    assert!(!b.batch());
    assert_eq!(b.steps.len(), len);
    let resumed = b.send(Event::Resume);
    assert_eq!(
        resumed[..2],
        [Action::Log(Msg::Resumed), Action::Enter(State::Winding)]
    );
    assert!(moves(&resumed));
    assert_eq!(b.send(Event::Resume), [], "not paused");
    b.run();
    assert_eq!(b.steps, [drilled(HEX), wound(HEX, &PATTERN)].concat());
    assert_eq!(b.job.state(), State::End);
}

#[test]
fn ctrl_x_ends_the_job_where_it_is_with_the_drivers_holding() {
    let mut b = Bench::new(HEX, &PATTERN);
    b.ready();
    assert_eq!(b.send(Event::Abort), [], "nothing to stop");
    b.green();
    b.batch();
    assert_eq!(
        b.send(Event::Abort),
        [
            Action::Log(Msg::Aborted),
            Action::Forget,
            Action::Enter(State::End),
            Action::Prompt(Prompt::Finished)
        ]
    );
    assert_eq!(b.job.next_step(), None, "no step after the stop");
    assert_eq!(b.drivers, ALL, "the drivers keep holding");
    assert_eq!(b.send(Event::MotionDone), []);
    // Green starts over: a new job from the card in the slot.
    assert_eq!(
        b.green(),
        [Action::Enter(State::Reading), Action::ReadFiles]
    );
}

#[test]
fn pause_and_resume_before_the_batch_has_finished() {
    let mut b = Bench::new(HEX, &PATTERN);
    b.ready();
    b.green();
    b.pulling = false;
    let header = b.job.next_step().unwrap();
    assert_eq!(header, MachineStep::Save(Save::Begin(Phase::Drilling)));
    let step = b.job.next_step().unwrap();
    b.steps.push(step);
    b.send(LONG_GREEN);
    // Resumed while the machine is still moving: keep pulling.
    assert_eq!(b.send(Event::Resume).last(), Some(&Action::NextMoves));
    assert!(b.pulling);
    b.run();
    assert_eq!(b.steps, drilled(HEX));
}

#[test]
fn bad_files_wait_without_moving() {
    let mut b = Bench::new(HEX, &PATTERN);
    b.send(Event::PowerOn);
    b.send(Event::CardInserted);
    assert_eq!(
        b.send(Event::FilesInvalid),
        [
            Action::Enter(State::BadFiles),
            Action::Prompt(Prompt::ReplaceCard)
        ]
    );
    for e in short(Button::Confirm)
        .into_iter()
        .chain(short(Button::ZeroBase))
        .chain([Event::MotionDone, Event::Resume, Event::Nail(3)])
    {
        assert_eq!(b.send(e), [], "{e:?}");
    }
    assert_eq!(b.job.next_step(), None);
    assert_eq!(b.drivers, 0, "as they were");
    // Replacing the card reads it again.
    let out = b.sends(&[Event::CardRemoved, Event::CardInserted]);
    assert_eq!(out.last(), Some(&Action::ReadFiles));
    // Files that parse but describe a board too small to wind on.
    let tiny = Params {
        shape: 3,
        nails: 30,
        radius_um: 50_000,
    };
    assert_eq!(
        b.send(valid(tiny, 5)),
        [
            Action::Configure,
            Action::Log(Msg::BadBoard(BadBoard::Gap(0))),
            Action::Enter(State::BadFiles),
            Action::Prompt(Prompt::ReplaceCard)
        ]
    );
    assert_eq!(b.green(), []);
    assert!(!b.actions.iter().any(|a| matches!(
        a,
        Action::NextMoves | Action::DriversOn(_) | Action::SetZero(_)
    )));
}

/// Each board that cannot be made is refused with its reason: what to
/// change in `param.txt`.
#[test]
fn a_bad_board_is_refused_with_its_reason() {
    let cases = [
        (3, 30, 50_000, BadBoard::Gap(0)),
        (0, 3, 16_000, BadBoard::Centre),
        (2, 200, 300_000, BadBoard::Shape),
        (0, 2, 300_000, BadBoard::Nails),
        (0, 200, 1_000, BadBoard::Radius),
        (0, 200, u32::MAX, BadBoard::Radius),
        // 3 000 nails 0.6 mm apart on a 300 mm ring: the needle is wider.
        (0, 3000, 300_000, BadBoard::Gap(0)),
    ];
    for (shape, nails, radius_um, why) in cases {
        let mut b = Bench::new(HEX, &PATTERN);
        b.send(Event::PowerOn);
        b.send(Event::CardInserted);
        let params = Params {
            shape,
            nails,
            radius_um,
        };
        let out = b.send(valid(params, 5));
        assert_eq!(out[1], Action::Log(Msg::BadBoard(why)), "{params:?}");
        assert_eq!(out[2], Action::Enter(State::BadFiles), "{params:?}");
    }
}

#[test]
fn a_card_with_nothing_to_read_is_bad_files_until_replaced() {
    let mut b = Bench::new(HEX, &PATTERN);
    b.send(Event::PowerOn);
    assert_eq!(
        b.send(Event::CardUnusable),
        [
            Action::Enter(State::BadFiles),
            Action::Prompt(Prompt::ReplaceCard)
        ]
    );
    assert_eq!(b.green(), []);
    let out = b.sends(&[Event::CardRemoved, Event::CardInserted]);
    assert_eq!(out.last(), Some(&Action::ReadFiles));
    b.send(valid(HEX, 5));
    assert_eq!(b.job.state(), State::PrepDrill);
    // Mid-job it is not the job's card.
    b.green();
    b.batch();
    b.send(Event::CardRemoved);
    assert_eq!(b.send(Event::CardUnusable), [Action::Log(Msg::OtherCard)]);
}

#[test]
fn card_removed_before_drilling_starts_over() {
    let mut b = Bench::new(HEX, &PATTERN);
    b.send(Event::PowerOn);
    b.send(Event::CardInserted);
    assert_eq!(
        b.send(Event::CardRemoved),
        [
            Action::Log(Msg::CardRemoved),
            Action::Enter(State::WaitingForCard),
            Action::Prompt(Prompt::InsertCard)
        ]
    );
    // A late answer of the reader is ignored.
    assert_eq!(b.send(valid(HEX, 5)), []);
    b.send(Event::CardInserted);
    b.send(valid(HEX, 5));
    b.send(Event::Button(ButtonEvent::Pressed(Button::ZeroBase)));
    assert_eq!(
        b.send(Event::CardRemoved),
        [
            Action::Log(Msg::CardRemoved),
            Action::StopMotion,
            Action::DriversOff(ALL),
            Action::Enter(State::WaitingForCard),
            Action::Prompt(Prompt::InsertCard)
        ]
    );
    assert_eq!(b.drivers, 0);
    assert_eq!(b.green(), []);
}

#[test]
fn card_out_while_drilling_is_needed_back_for_winding() {
    let mut b = Bench::new(HEX, &PATTERN);
    b.ready();
    b.green();
    b.batch();
    assert_eq!(b.send(Event::CardRemoved), [Action::Log(Msg::CardRemoved)]);
    b.run();
    assert_eq!(b.job.state(), State::WaitingForNails);
    assert_eq!(
        b.green(),
        [Action::Log(Msg::NoCard), Action::Prompt(Prompt::InsertCard)]
    );
    // Another job's card does not count, even with the same board and
    // count (another pattern).
    assert_eq!(b.send(Event::CardInserted), [Action::ReadFiles]);
    assert_eq!(b.send(valid(HEX, 6)), [Action::Log(Msg::OtherCard)]);
    b.sends(&[Event::CardRemoved, Event::CardInserted]);
    assert_eq!(
        b.send(valid_pattern(HEX, 5, 1)),
        [Action::Log(Msg::OtherCard)]
    );
    assert_eq!(b.green()[0], Action::Log(Msg::NoCard));
    b.sends(&[Event::CardRemoved, Event::CardInserted]);
    assert_eq!(b.send(Event::FilesInvalid), [Action::Log(Msg::OtherCard)]);
    b.sends(&[Event::CardRemoved, Event::CardInserted]);
    assert_eq!(
        b.send(valid(HEX, 5)),
        [
            Action::Log(Msg::CardOk),
            Action::Prompt(Prompt::StartWinding)
        ]
    );
    assert_eq!(b.green()[0], Action::Enter(State::Winding));
    b.run();
    assert_eq!(b.job.state(), State::End);
}

#[test]
fn card_out_while_winding_pauses_and_resumes_where_it_was() {
    let pattern: Vec<u16> = (0..40).map(|k| (k * 7 % 24) as u16).collect();
    let mut b = Bench::new(HEX, &pattern);
    b.ready();
    b.green();
    b.run();
    b.green();
    for _ in 0..6 {
        b.batch();
    }
    assert_eq!(
        b.send(Event::CardRemoved),
        [
            Action::Log(Msg::PatternLost),
            Action::Enter(State::Paused(Phase::Winding)),
            Action::Prompt(Prompt::InsertCard)
        ]
    );
    // The card reader lost its place.
    b.at = 1000;
    assert!(!b.job.wants_nail());
    assert_eq!(
        b.green(),
        [Action::Log(Msg::NoCard), Action::Prompt(Prompt::InsertCard)]
    );
    b.send(Event::CardInserted);
    assert_eq!(
        b.send(valid(HEX, 40)),
        [
            Action::Log(Msg::CardOk),
            Action::OpenPattern,
            Action::Prompt(Prompt::Resume)
        ]
    );
    // Read again from its start: the job passes over what it had.
    assert_eq!(b.at, 0);
    assert!(moves(&b.green()));
    b.run();
    assert_eq!(b.job.state(), State::End);
    let winding = &b.steps[drilled(HEX).len()..];
    assert_eq!(winding, wound(HEX, &pattern));
}

#[test]
fn an_unreadable_pattern_or_a_changed_card_pauses_winding() {
    let pattern = [3; 20];
    let mut b = Bench::new(HEX, &pattern);
    b.ready();
    b.green();
    b.run();
    b.green();
    b.batch();
    b.send(Event::PatternLost);
    assert_eq!(b.job.state(), State::Paused(Phase::Winding));
    assert_eq!(b.send(Event::Resume)[0], Action::Log(Msg::NoCard));
    b.send(Event::CardInserted);
    b.send(valid(HEX, 20));
    b.send(Event::Resume);
    // An index past the last nail: the card is not the one checked.
    b.pattern[b.at] = 24;
    b.batch();
    assert_eq!(b.job.state(), State::Paused(Phase::Winding));
    assert!(b.actions.ends_with(&[
        Action::Log(Msg::PatternLost),
        Action::Enter(State::Paused(Phase::Winding)),
        Action::Prompt(Prompt::InsertCard)
    ]));
}

#[test]
fn progress_at_least_every_1_percent() {
    let circle = Params {
        shape: 0,
        nails: 250,
        radius_um: 402_000,
    };
    let pattern: Vec<u16> = (0..333u32).map(|k| (k * 97 % 250) as u16).collect();
    let mut b = Bench::new(circle, &pattern);
    b.ready();
    b.green();
    b.run();
    b.green();
    b.run();
    assert_eq!(b.job.state(), State::End);
    for (phase, total) in [(Phase::Drilling, 250), (Phase::Winding, 333)] {
        let done: Vec<u32> = b
            .progress()
            .iter()
            .filter(|p| p.phase == phase)
            .map(|p| p.done)
            .collect();
        assert_eq!(done.first(), Some(&0));
        assert_eq!(done.last(), Some(&total));
        assert!(
            done.windows(2)
                .all(|w| w[0] < w[1] && (w[1] - w[0]) * 100 <= total),
            "{phase:?}: {done:?}"
        );
    }
}

#[test]
fn winding_waits_for_the_card_reader() {
    let mut b = Bench::new(HEX, &PATTERN);
    b.ready();
    b.green();
    b.run();
    b.green();
    // The reader is slow: nothing fed yet. The entry needs no index.
    b.pulling = false;
    let mut entry: Vec<MachineStep> = core::iter::from_fn(|| b.job.next_step()).collect();
    assert_eq!(
        entry.remove(0),
        MachineStep::Save(Save::Begin(Phase::Winding))
    );
    assert_eq!(entry.len(), 3);
    assert_eq!(b.send(Event::MotionDone), [], "no index yet: it waits");
    assert!(b.job.wants_nail());
    assert_eq!(b.send(Event::Nail(0)), [Action::NextMoves]);
    assert_eq!(b.send(Event::Nail(7)), [], "already moving");
    b.steps = [drilled(HEX), entry].concat();
    b.at = 2;
    b.run();
    assert_eq!(b.steps[drilled(HEX).len()..], wound(HEX, &PATTERN));
}

#[test]
fn texts() {
    assert!(Prompt::StartDrilling.as_str().contains("press green"));
    for p in [
        Prompt::InsertCard,
        Prompt::ReplaceCard,
        Prompt::StartDrilling,
        Prompt::StartWinding,
        Prompt::Resume,
        Prompt::Finished,
    ] {
        assert!(p.as_str().starts_with(PROMPT_MARK));
        assert_eq!(p.as_str().contains("press green"), p.wants_green(), "{p:?}");
    }
    assert_eq!(Msg::Zeroed(Axis::Drill).as_str(), "drill zeroed");
    assert_eq!(State::Paused(Phase::Winding).name(), "paused");
}
