//! Machine time of a whole job as this firmware runs it, worked out on the
//! host: the job's own state machine hands out its batches (a hole, a
//! wrap), the firmware's planner plans them and the firmware's trapezoids
//! time them, exactly as the AVR does; only the tasks' own run times
//! between batches (a few ms each) are left out. The operator is assumed
//! to answer every prompt at once.
//!
//! The steps are carried out by the firmware's own [`Feeder`]: the moves
//! of a batch go into the planner while it has room, so it blends them;
//! a dwell, a driver switch, the end of a hole and a drilling checkpoint
//! wait until the machine stands; a winding record is written while the
//! machine runs on (`firmware/src/store.rs`: one differing EEPROM byte
//! per 4 ms run, the job looking again every 4 ms), and the crossing
//! after it waits until it is durable.

use super::job::{Action, Actions, Event, Feeder, Feeding, Hardware, Job, State, SAVE_POLL_MS};
#[cfg(test)]
use super::BlendWinder;
use super::{machine_time, Drilling, Overlap, Save, Winder, Winding};
use crate::axis::PerAxis;
use crate::buttons::ButtonEvent;
use crate::checkpoint::{self, Header, Record};
use crate::config::MachineConfig;
use crate::files::check::{CardId, Checked, Files, Next};
use crate::files::param::Params;
use crate::files::poradi::PoradiReader;
use crate::files::{FileError, FileName};
use crate::geometry::Board;
use crate::pinmap::Button;
use crate::planner::{Feed, Full, Planner};
use crate::segment::SUBTICKS_PER_S;
use crate::units::Milli;

/// Machine time of each phase, seconds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct JobTime {
    pub drilling_s: f64,
    pub winding_s: f64,
}

impl JobTime {
    pub fn total_s(&self) -> f64 {
        self.drilling_s + self.winding_s
    }
}

/// Why a job could not be estimated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EstimateError {
    /// The job refused the files (the board cannot be drilled or wound).
    Refused,
    /// The pattern ended before the job had all its wraps.
    PatternShort,
}

/// The machine: the firmware's planner, and the time its blocks take.
/// A block is taken (its exit speed fixed) when the one before it ends,
/// or at once by a machine standing — after the feeder's run, as the
/// firmware's refill runs after the job task's.
struct Timed {
    planner: Planner,
    /// Sub-ticks of motion and waiting so far: now.
    subticks: u64,
    /// When the block the machine runs ends (not after now: it stands).
    busy_until: u64,
    /// The EEPROM as the checkpoint writes leave it (blank at first), and
    /// the header in force: only differing bytes take time.
    eeprom: [u8; checkpoint::END as usize],
    seq: u16,
    /// When the checkpoint being written is durable.
    durable_at: u64,
}

/// A run of the Store task, and the job's wait between its looks.
const SAVE_RUN_MS: u64 = SAVE_POLL_MS as u64;

impl Timed {
    /// Time runs on to `t`, each planned block taken as the one before
    /// it ends.
    fn advance_to(&mut self, t: u64) {
        loop {
            let start = self.busy_until.max(self.subticks);
            if start > t {
                break;
            }
            let Some(p) = self.planner.take() else { break };
            self.busy_until = start + p.profile.time(p.profile.events());
        }
        self.subticks = t;
    }

    /// Until the planner takes a block or the machine stands.
    fn run_block(&mut self) {
        self.advance_to(self.subticks);
        self.advance_to(self.busy_until.max(self.subticks));
    }

    /// `ms` pass, the machine running on.
    fn wait(&mut self, ms: u16) {
        self.advance_to(self.subticks + ms as u64 * SUBTICKS_PER_S / 1000);
    }

    fn ms(&self) -> u32 {
        (self.subticks * 1000 / SUBTICKS_PER_S) as u32
    }

    /// The checkpoint bytes `bytes` written at `at`: a run of the store
    /// per differing byte, and its first look.
    fn write(&mut self, at: u16, bytes: &[u8]) {
        let mut ms = SAVE_RUN_MS;
        for (cell, &b) in self.eeprom[at as usize..].iter_mut().zip(bytes) {
            if *cell != b {
                *cell = b;
                ms += SAVE_RUN_MS;
            }
        }
        self.durable_at = self.subticks + ms * SUBTICKS_PER_S / 1000;
    }
}

impl Hardware for Timed {
    fn target(&self) -> PerAxis<i32> {
        self.planner.position()
    }

    fn push(&mut self, to: PerAxis<i32>) -> Result<(), Full> {
        self.planner.push(to, Feed::Rapid)
    }

    fn is_idle(&self) -> bool {
        self.planner.is_idle() && self.busy_until <= self.subticks
    }

    fn unbegun(&self) -> u8 {
        self.planner.queued() as u8
    }

    fn drivers(&mut self, _: u8, _: bool) {}

    fn save(&mut self, save: Save, (nails, count, id): (u16, u32, CardId)) {
        match save {
            Save::Begin(phase) => {
                self.seq = self.seq.wrapping_add(1);
                let header = Header {
                    seq: self.seq,
                    phase: Some(phase),
                    nails,
                    count,
                    id,
                };
                self.write(Header::address(self.seq), &header.encode());
            }
            Save::Record(r) => self.record(r),
        }
    }

    fn record(&mut self, r: Record) {
        self.write(Record::address(r.n), &r.encode(self.seq))
    }

    fn saving(&self) -> bool {
        self.durable_at > self.subticks
    }
}

/// Actions waiting to be carried out (several events' worth).
type Pending = heapless::Deque<Action, 24>;

fn queue(pending: &mut Pending, actions: Actions) {
    for a in actions {
        // Each event gives at most 6, and each is taken before the next.
        pending.push_back(a).expect("pending actions");
    }
}

/// The machine time of the job on the card: `params` and `count` as the
/// firmware checked them, `pattern` the nail indices of `poradi.txt`.
pub fn job_time(
    params: Params,
    count: u32,
    config: &MachineConfig,
    mut pattern: impl Iterator<Item = u16>,
) -> Result<JobTime, EstimateError> {
    let mut m = Timed {
        planner: Planner::new(config),
        subticks: 0,
        busy_until: 0,
        eeprom: [0xFF; checkpoint::END as usize],
        seq: 0,
        durable_at: 0,
    };
    let mut job = Job::new();
    let mut time = JobTime::default();
    let mut started = 0;
    let mut feeder = Feeder::new();
    let mut pending = Pending::new();
    queue(&mut pending, job.on(Event::PowerOn, 0));
    queue(&mut pending, job.on(Event::CardInserted, 0));
    loop {
        while let Some(action) = pending.pop_front() {
            let answer = match action {
                Action::ReadFiles => {
                    let files = Event::FilesValid {
                        params,
                        count,
                        config,
                        id: CardId::default(),
                    };
                    job.on(files, m.ms())
                }
                Action::Enter(State::BadFiles) => return Err(EstimateError::Refused),
                Action::Enter(State::PrepDrill) => press_green(&mut job, m.ms()),
                Action::Enter(State::WaitingForNails) => {
                    time.drilling_s = seconds(m.subticks - started);
                    press_green(&mut job, m.ms())
                }
                Action::Enter(State::Drilling | State::Winding) => {
                    started = m.subticks;
                    Actions::new()
                }
                Action::Enter(State::End) => {
                    time.winding_s = seconds(m.subticks - started);
                    return Ok(time);
                }
                Action::SetZero(axis) => {
                    let mut at: PerAxis<i32> = m.planner.position();
                    at[axis.index()] = 0;
                    m.planner.set_position(at);
                    Actions::new()
                }
                Action::NextMoves => {
                    feeder.pull();
                    Actions::new()
                }
                _ => Actions::new(),
            };
            queue(&mut pending, answer);
        }
        while job.wants_nail() {
            let j = pattern.next().ok_or(EstimateError::PatternShort)?;
            queue(&mut pending, job.on(Event::Nail(j), m.ms()));
        }
        if !pending.is_empty() {
            continue;
        }
        let now = m.ms();
        match feeder.run(&mut job, &mut m, now, u8::MAX) {
            Feeding::Again => {}
            Feeding::PlannerRoom => m.run_block(),
            Feeding::After(ms) => m.wait(ms),
            Feeding::Done => queue(&mut pending, job.on(Event::MotionDone, m.ms())),
            // Nothing moves and nothing is asked: the job waits for
            // what the pattern no longer has.
            Feeding::Idle => return Err(EstimateError::PatternShort),
        }
    }
}

fn press_green(job: &mut Job, now_ms: u32) -> Actions {
    let mut out = job.on(Event::Button(ButtonEvent::Pressed(Button::Confirm)), now_ms);
    out.extend(job.on(
        Event::Button(ButtonEvent::Released {
            button: Button::Confirm,
            held_ms: 100,
        }),
        now_ms,
    ));
    out
}

fn seconds(subticks: u64) -> f64 {
    subticks as f64 / SUBTICKS_PER_S as f64
}

/// A card's job timed both ways: this firmware's, and the original
/// firmware's moves one axis after another.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CardEstimate {
    pub checked: Checked,
    pub firmware: JobTime,
    pub sequential_s: f64,
}

impl CardEstimate {
    /// This firmware's time over the original's.
    pub fn ratio(&self) -> f64 {
        self.firmware.total_s() / self.sequential_s
    }
}

/// Why a card's job could not be timed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CardError {
    /// A file the firmware refuses, as it would log it.
    File(FileError),
    /// A plotter's card (its `machine.txt` names another machine).
    Plotter,
    Job(EstimateError),
}

/// Times the job on a card whose files `file(name)` gives (`None`: not on
/// the card), checked first as the firmware checks them.
pub fn card<'a>(file: impl Fn(FileName) -> Option<&'a [u8]>) -> Result<CardEstimate, CardError> {
    let base = MachineConfig::STRING_ART;
    let mut files = Files::new();
    let checked = loop {
        let next = match file(files.file()) {
            None => files.missing(&base),
            Some(bytes) => files.push(bytes).and_then(|_| files.end(&base)),
        };
        match next.map_err(CardError::File)? {
            Next::Open(_) => {}
            Next::Done => break *files.checked().expect("checked"),
            Next::Machine => return Err(CardError::Plotter),
        }
    };
    let poradi = file(FileName::Poradi).unwrap_or_default();
    let (params, config) = (checked.params, &checked.config);
    let firmware = job_time(
        params,
        checked.count,
        config,
        Nails::new(poradi, params.nails),
    )
    .map_err(CardError::Job)?;
    let refused = CardError::Job(EstimateError::Refused);
    let board = Board::new(params.shape, params.nails, Milli(params.radius_um as i32))
        .map_err(|_| refused)?;
    let winder = Winder::new(board, config).map_err(|_| refused)?;
    let pattern = Nails::new(poradi, params.nails);
    let steps =
        Drilling::new(board, config).chain(Winding::new(winder, pattern).map_while(Result::ok));
    Ok(CardEstimate {
        checked,
        firmware,
        sequential_s: machine_time(steps, config, Overlap::Sequential),
    })
}

/// The nail indices of a checked `poradi.txt`, one by one.
struct Nails<'a> {
    reader: PoradiReader,
    text: &'a [u8],
    /// Bytes read; past the end once the reader has finished.
    at: usize,
}

impl<'a> Nails<'a> {
    fn new(text: &'a [u8], nails: u16) -> Self {
        Nails {
            reader: PoradiReader::new(nails),
            text,
            at: 0,
        }
    }
}

impl Iterator for Nails<'_> {
    type Item = u16;

    fn next(&mut self) -> Option<u16> {
        // The file passed the check: its errors cannot come.
        while self.at < self.text.len() {
            let (used, nail) = self.reader.next(&self.text[self.at..]).ok()?;
            self.at += used;
            if nail.is_some() {
                return nail;
            }
        }
        if self.at > self.text.len() {
            return None;
        }
        self.at += 1;
        self.reader.finish().ok().flatten()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::axis::AXES;
    use crate::stringart::job::FEED;
    use crate::stringart::MachineStep;
    use std::vec::Vec;

    const PARAM: &[u8] = b"tvar = 0\npocet_hrebiku = 12\npolomer_matrice = 15\n";

    fn card_of<'a>(poradi: &'a [u8], machine: Option<&'a [u8]>) -> Result<CardEstimate, CardError> {
        card(|f| match f {
            FileName::Param => Some(PARAM),
            FileName::Machine => machine,
            FileName::Poradi => Some(poradi),
        })
    }

    #[test]
    fn a_job_takes_longer_with_more_wraps_and_less_than_the_original() {
        let short = card_of(b"3, 0, 4, 8", None).unwrap();
        let long = card_of(b"6, 0, 4, 8, 1, 5, 9", None).unwrap();
        assert_eq!(short.firmware.drilling_s, long.firmware.drilling_s);
        assert!(long.firmware.winding_s > short.firmware.winding_s + 1.0);
        for e in [short, long] {
            assert!(e.firmware.drilling_s > 12.0 * DWELL_S, "{e:?}");
            assert!(e.ratio() < 1.0 && e.ratio() > 0.5, "{e:?}");
        }
    }

    const DWELL_S: f64 = super::super::DWELL_MS as f64 / 1000.0;

    /// Each blended move run rest to rest would take its ideal
    /// trapezoid's time (`machine_time`, with floats, the axes together).
    /// The planner joins them at the speeds the axes' jumps allow — the
    /// base turning on into a crossing, its checkpoint record written
    /// meanwhile — so the wraps take less (this pattern: 0.83 of it;
    /// 0.92 when every record stopped the machine), never more.
    #[test]
    fn winding_takes_about_its_ideal_trapezoids() {
        let pattern: Vec<u16> = (0..40).map(|i| (i * 5 % 12) as u16).collect();
        let mut text = std::format!("{}", pattern.len());
        for j in &pattern {
            text += &std::format!(",{j}");
        }
        let e = card_of(text.as_bytes(), None).unwrap();
        let c = MachineConfig::STRING_ART;
        let board = Board::new(0, 12, Milli(150_000)).unwrap();
        let winder = BlendWinder::new(board, &c).unwrap();
        let winding = Winding::new(winder, pattern.iter().copied());
        let ideal = machine_time(
            whole_moves(winding.map(Result::unwrap)),
            &c,
            Overlap::Together,
        );
        let ratio = e.firmware.winding_s / ideal;
        std::eprintln!("XX {} {ideal}", e.firmware.winding_s);
        assert!(
            (0.75..=0.9).contains(&ratio),
            "{} s against {ideal} s",
            e.firmware.winding_s
        );
    }

    /// The moves with a wrap's halves joined: a turn of the base alone
    /// on from one the same way is one move.
    fn whole_moves(steps: impl Iterator<Item = MachineStep>) -> Vec<MachineStep> {
        let (mut out, mut at, mut turning) = (Vec::new(), [0i32; AXES], 0);
        for step in steps {
            let MachineStep::Move(t) = step else {
                out.push(step);
                continue;
            };
            let from = at;
            for (a, t) in at.iter_mut().zip(t) {
                *a = t.unwrap_or(*a);
            }
            let way = if from[1..] == at[1..] {
                (at[0] - from[0]).signum()
            } else {
                0
            };
            if way != 0 && way == turning {
                out.pop();
            }
            turning = way;
            out.push(MachineStep::Move(at.map(Some)));
        }
        out
    }

    /// The bar: the demo card in at most 70 % of the original's
    /// sequential time, at the same limits.
    #[test]
    fn the_demo_card_takes_at_most_70_percent_of_the_original() {
        let e = card(|f| match f {
            FileName::Param => Some(&include_bytes!("../../../../examples/card/param.txt")[..]),
            FileName::Machine => None,
            FileName::Poradi => Some(&include_bytes!("../../../../examples/card/poradi.txt")[..]),
        })
        .unwrap();
        assert!(e.ratio() <= 0.70, "{e:?}");
    }

    #[test]
    fn machine_txt_s_limits_count() {
        let fast = card_of(b"3, 0, 4, 8", Some(b"base_accel = 2000\n")).unwrap();
        let slow = card_of(b"3, 0, 4, 8", None).unwrap();
        assert!(fast.firmware.total_s() < slow.firmware.total_s() - 1.0);
    }

    #[test]
    fn bad_files_and_short_patterns_are_said() {
        match card_of(b"3, 0, 4, 12", None) {
            Err(CardError::File(e)) => assert_eq!(e.file, FileName::Poradi),
            other => panic!("{other:?}"),
        }
        // The count says more nails than `job_time` is given.
        let p = Params {
            shape: 0,
            nails: 12,
            radius_um: 150_000,
        };
        let c = MachineConfig::STRING_ART;
        let few = [0u16, 4, 8];
        assert_eq!(
            job_time(p, few.len() as u32 + FEED as u32, &c, few.into_iter()),
            Err(EstimateError::PatternShort)
        );
        assert!(job_time(p, 3, &c, few.into_iter()).is_ok());
    }
}
