//! Winding's records written while the machine moves: the feeder on a
//! machine that runs its blocks in time, one poll of the feeder a tick.
//! Each record starts only once the crossing before it is done, and is
//! durable before the crossing it is about is handed over; a record in
//! time leaves the half before its crossing still planned (the planner
//! blends them), a late one lets the machine reach the vertex first.

use super::*;
use crate::axis::PerAxis;
use crate::axis::AXES;
use crate::checkpoint::Record;
use std::collections::VecDeque;

/// Blocks run `ticks` polls each; a record takes `write` polls.
struct Timeline {
    ticks: u32,
    write: u32,
    target: [i32; AXES],
    /// Where the last block begun ends.
    end: [i32; AXES],
    planned: VecDeque<[i32; AXES]>,
    /// The block running (its start, end) and the ticks it has left.
    running: Option<([i32; AXES], [i32; AXES], u32)>,
    saving: u32,
    /// Crossings of the band handed over and done (after the entry's).
    crossings: Vec<bool>,
    /// Records started; durable once `saving` is 0.
    records: Vec<u32>,
    /// At each crossing handed over: the block before it still planned.
    blended: Vec<bool>,
}

impl Timeline {
    fn new(ticks: u32, write: u32, at: [i32; AXES]) -> Self {
        Timeline {
            ticks,
            write,
            target: at,
            end: at,
            planned: VecDeque::new(),
            running: None,
            saving: 0,
            crossings: Vec::new(),
            records: Vec::new(),
            blended: Vec::new(),
        }
    }

    fn crossing(from: [i32; AXES], to: [i32; AXES]) -> bool {
        from[1] != to[1]
    }

    /// The next block begins if the machine has none running.
    fn begin(&mut self) {
        if self.running.is_none() {
            if let Some(to) = self.planned.pop_front() {
                self.running = Some((self.end, to, self.ticks));
                self.end = to;
            }
        }
    }

    /// One poll's time.
    fn tick(&mut self) {
        self.saving = self.saving.saturating_sub(1);
        if let Some((from, to, left)) = self.running.as_mut() {
            *left -= 1;
            if *left == 0 {
                let (from, to) = (*from, *to);
                self.running = None;
                if Self::crossing(from, to) {
                    if let Some(done) = self.crossings.iter_mut().find(|d| !**d) {
                        *done = true;
                    }
                }
                self.begin();
            }
        }
    }
}

impl Hardware for Timeline {
    fn target(&self) -> PerAxis<i32> {
        self.target
    }

    fn push(&mut self, to: PerAxis<i32>) -> Result<(), crate::planner::Full> {
        if to == self.target {
            return Ok(());
        }
        let from = self.target;
        // The entry's crossing comes before any record.
        if Self::crossing(from, to) && !self.records.is_empty() {
            // Crossing k is about record k, durable by now.
            let k = self.crossings.len() as u32 + 1;
            assert_eq!(self.records.last(), Some(&k), "the record of crossing {k}");
            assert_eq!(self.saving, 0, "crossing {k} before its record is durable");
            self.blended.push(!self.planned.is_empty());
            self.crossings.push(false);
        }
        self.planned.push_back(to);
        self.target = to;
        Ok(())
    }

    fn is_idle(&self) -> bool {
        self.planned.is_empty() && self.running.is_none()
    }

    fn unbegun(&self) -> u8 {
        self.planned.len() as u8
    }

    fn drivers(&mut self, _: u8, _: bool) {}

    fn save(&mut self, save: Save, _: (u16, u32, CardId)) {
        assert_eq!(
            save,
            Save::Begin(Phase::Winding),
            "the phase's header alone"
        );
        assert!(self.is_idle());
        self.saving = self.write;
    }

    fn record(&mut self, r: Record) {
        assert_eq!(self.saving, 0, "record {} over the last", r.n);
        // Record 2k+1 after k wraps' crossings, 2k+2 after the one out.
        let done = self.crossings.iter().filter(|d| **d).count() as u32;
        assert_eq!(self.crossings.len() as u32, done, "a crossing still to run");
        assert_eq!(r.n, done + 1, "record {} after {done} crossings", r.n);
        self.records.push(r.n);
        self.saving = self.write;
    }

    fn saving(&self) -> bool {
        self.saving > 0
    }
}

/// Winds the pattern on `m` through the feeder; the machine's log.
fn wind(m: &mut Timeline) {
    let mut b = Bench::new(HEX, &PATTERN);
    b.ready();
    b.green();
    b.run();
    b.green();
    assert_eq!(b.job.state(), State::Winding);
    *m = Timeline::new(m.ticks, m.write, b.pos);
    let (mut job, mut feeder) = (b.job, Feeder::new());
    feeder.pull();
    let (mut now, mut at) = (0u32, 0);
    for _ in 0..200_000 {
        while job.wants_nail() && at < PATTERN.len() {
            job.on(Event::Nail(PATTERN[at]), now);
            at += 1;
        }
        let fed = feeder.run(&mut job, m, now, 8);
        // The refill runs after the job task.
        m.begin();
        match fed {
            Feeding::Again => {}
            Feeding::PlannerRoom | Feeding::After(_) => {
                m.tick();
                now += 1;
            }
            Feeding::Done => {
                for a in job.on(Event::MotionDone, now) {
                    if a == Action::NextMoves {
                        feeder.pull();
                    }
                }
                if job.state() == State::End {
                    return;
                }
            }
            Feeding::Idle => panic!("idle while winding"),
        }
    }
    panic!("the winding never ended");
}

#[test]
fn records_in_time_let_every_crossing_blend_in() {
    let mut m = Timeline::new(40, 3, [0; AXES]);
    wind(&mut m);
    assert_eq!(m.records, (1..=10).collect::<Vec<_>>());
    // The halves of this pattern's rotations and moves over the nails:
    // each still planned when its crossing came. Not the first wrap's:
    // the entry left the needle in its window, nothing to turn, so its
    // record is written standing.
    assert_eq!(m.blended.len(), 10);
    assert!(!m.blended[0]);
    assert!(m.blended[1..].iter().all(|b| *b), "{:?}", m.blended);
}

#[test]
fn a_late_record_stops_the_machine_at_its_vertex() {
    // Blocks run faster than a record is written.
    let mut m = Timeline::new(1, 6, [0; AXES]);
    wind(&mut m);
    assert_eq!(m.records, (1..=10).collect::<Vec<_>>());
    assert!(m.blended.iter().all(|b| !*b), "{:?}", m.blended);
}
