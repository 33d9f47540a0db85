//! The feeder hands a batch's steps to a machine with little room: every
//! move's targets merged with where the last one ends, none lost on a full
//! planner, dwells, driver switches and checkpoints only with the machine
//! standing, and `Done` once, when it stands after the last step.

use super::*;
use crate::axis::PerAxis;
use crate::axis::AXES;
use std::collections::VecDeque;
use std::vec;

/// What the machine was asked to do, and whether it stood then.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Did {
    Push([i32; AXES]),
    Drivers {
        idle: bool,
    },
    Save {
        idle: bool,
    },
    /// A wait of the feeder: ms, and whether the machine stood.
    Wait {
        ms: u16,
        idle: bool,
    },
    Done {
        idle: bool,
    },
}

/// A planner of two blocks; a `Motion` wait runs the oldest to its end.
#[derive(Default)]
struct Cramped {
    target: [i32; AXES],
    queue: VecDeque<[i32; AXES]>,
    /// Looks left before the checkpoint being written is done.
    saving: u8,
    did: Vec<Did>,
}

impl Hardware for Cramped {
    fn target(&self) -> PerAxis<i32> {
        self.target
    }

    fn push(&mut self, to: PerAxis<i32>) -> Result<(), crate::planner::Full> {
        if self.queue.len() == 2 {
            return Err(crate::planner::Full);
        }
        self.queue.push_back(to);
        self.target = to;
        self.did.push(Did::Push(to));
        Ok(())
    }

    fn is_idle(&self) -> bool {
        self.queue.is_empty()
    }

    /// The oldest block runs.
    fn unbegun(&self) -> u8 {
        self.queue.len().saturating_sub(1) as u8
    }

    fn drivers(&mut self, _: u8, _: bool) {
        let idle = self.is_idle();
        self.did.push(Did::Drivers { idle });
    }

    fn save(&mut self, _: Save, _: (u16, u32, CardId)) {
        let idle = self.is_idle();
        self.did.push(Did::Save { idle });
        self.saving = 3;
    }

    fn record(&mut self, _: crate::checkpoint::Record) {
        let idle = self.is_idle();
        self.did.push(Did::Save { idle });
        self.saving = 3;
    }

    fn saving(&self) -> bool {
        self.saving > 0
    }
}

/// A job that has just started drilling (its first batch asked for).
fn drilling() -> Job {
    let mut job = Job::new();
    let mut events = vec![Event::PowerOn, Event::CardInserted, valid(HEX, 5)];
    events.extend(short(Button::Confirm));
    for e in events {
        job.on(e, 0);
    }
    assert_eq!(job.state(), State::Drilling);
    job
}

/// The moves of the job's next batch, merged into whole targets.
fn batch_targets(job: &mut Job) -> Vec<[i32; AXES]> {
    let mut at = [0; AXES];
    let mut out = Vec::new();
    while let Some(step) = job.next_step() {
        if let MachineStep::Move(t) = step {
            for (a, t) in at.iter_mut().zip(t) {
                *a = t.unwrap_or(*a);
            }
            out.push(at);
        }
    }
    out
}

/// Runs the feeder over one batch, 3 steps per run, as the firmware's
/// job task would; what the machine was asked, and the runs it took.
fn feed_batch(job: &mut Job, m: &mut Cramped, feeder: &mut Feeder) -> usize {
    let mut now = 0u32;
    for runs in 1..10_000 {
        let fed = feeder.run(job, m, now, 3);
        let idle = m.is_idle();
        match fed {
            Feeding::Again => {}
            Feeding::PlannerRoom => {
                m.queue.pop_front().expect("a wait for motion with some");
            }
            Feeding::After(ms) => {
                m.did.push(Did::Wait { ms, idle });
                now += ms as u32;
                m.saving = m.saving.saturating_sub(1);
            }
            Feeding::Done => {
                m.did.push(Did::Done { idle });
                return runs;
            }
            Feeding::Idle => panic!("idle before the batch was done"),
        }
    }
    panic!("the batch never ended");
}

#[test]
fn a_batch_is_fed_whole_and_waits_stand() {
    let expected = batch_targets(&mut drilling());
    assert!(expected.len() >= 3, "a hole is several moves");
    let (mut job, mut m, mut feeder) = (drilling(), Cramped::default(), Feeder::new());
    feeder.pull();
    feed_batch(&mut job, &mut m, &mut feeder);

    let pushed: Vec<_> = m
        .did
        .iter()
        .filter_map(|d| match d {
            Did::Push(t) => Some(*t),
            _ => None,
        })
        .collect();
    assert_eq!(pushed, expected, "every move, merged, none lost or doubled");
    // The hole's dwell, and the checkpoint's looks, all with the machine
    // standing; the checkpoint written before the next step.
    for (i, d) in m.did.iter().enumerate() {
        match *d {
            Did::Drivers { idle } | Did::Save { idle } | Did::Wait { idle, .. } => {
                assert!(idle, "{d:?} while moving (step {i})")
            }
            _ => {}
        }
    }
    assert!(m.did.contains(&Did::Wait {
        ms: crate::stringart::DWELL_MS,
        idle: true
    }));
    let saves = m
        .did
        .iter()
        .filter(|d| matches!(d, Did::Save { .. }))
        .count();
    let looks = m
        .did
        .iter()
        .filter(|d| {
            **d == Did::Wait {
                ms: SAVE_POLL_MS,
                idle: true,
            }
        })
        .count();
    assert!(saves >= 1 && looks >= 3 * saves, "{:?}", m.did);
    assert!(matches!(m.did.last(), Some(Did::Done { idle: true })));
    assert!(m.is_idle());
    // Nothing more until the next batch is asked for.
    assert_eq!(feeder.run(&mut job, &mut m, 0, 3), Feeding::Idle);
}

#[test]
fn an_abort_drops_the_steps_in_hand() {
    let (mut job, mut m, mut feeder) = (drilling(), Cramped::default(), Feeder::new());
    feeder.pull();
    // The header written, then the planner fills: the third move waits
    // in the feeder.
    let fed = (0..20)
        .map(|_| {
            m.saving = 0;
            feeder.run(&mut job, &mut m, 0, 1)
        })
        .find(|&f| f == Feeding::PlannerRoom);
    assert_eq!(fed, Some(Feeding::PlannerRoom));
    feeder.abort();
    m.queue.clear();
    assert_eq!(feeder.run(&mut job, &mut m, 0, 3), Feeding::Idle);
    assert_eq!(
        m.did.iter().filter(|d| matches!(d, Did::Push(_))).count(),
        2
    );
}
