//! The watchdog's feed rule: rounds that always end while tasks return.
//!
//! A round is the set of tasks ready when it begins; it ends, and the
//! dispatcher feeds the watchdog, when each of them has run once. Pure
//! priority order cannot promise that: a pair of tasks that keep spawning
//! each other (the console and the planner under a stream of tiny moves,
//! the job and the card reader through a long file) keep a lower task
//! waiting forever, and the watchdog would reset a healthy, busy machine.
//! So a round ages: while it is younger than [`Round::AGE_MS`], tasks run
//! in priority order; after that the tasks it still owes run first (the
//! highest priority of them first). Every round therefore ends within
//! `AGE_MS` plus one run of each task, under any mix of ready tasks, and
//! only a task that never returns holds a round open long enough for the
//! watchdog. The top priority level keeps going first even then: it is
//! for short real-time work (a status report within 10 ms), and each of
//! its runs only delays the round by that run.

use super::{Ready, TaskId};

pub struct Round {
    /// Tasks (bit = index) still owed a run in this round.
    owed: u16,
    /// When the round began, ms.
    began: u32,
}

impl Round {
    /// How long a round keeps plain priority order.
    pub const AGE_MS: u32 = 50;

    /// A finished round: the first call to [`Round::next`] begins one.
    pub const fn new() -> Self {
        Round { owed: 0, began: 0 }
    }

    /// The task to run now, at millisecond `now`; `feed` is called when a
    /// round ends (and a new one begins with the tasks ready then).
    pub fn next<T: TaskId, const N: usize, const P: usize>(
        &mut self,
        ready: &mut Ready<T, N, P>,
        now: u32,
        feed: impl FnOnce(),
    ) -> Option<T> {
        if self.owed == 0 {
            feed();
            self.owed = ready.pending_mask();
            self.began = now;
        }
        let aged = now.wrapping_sub(self.began) >= Self::AGE_MS;
        let task = match ready.pop_level(P as u8 - 1) {
            Some(t) => t,
            None if aged && self.owed != 0 => ready.pop_among(self.owed)?,
            None => ready.pop()?,
        };
        self.owed &= !(1 << task.index());
        Some(task)
    }
}

impl Default for Round {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_task::{tk, Tk};
    use super::*;
    use proptest::prelude::*;
    use std::vec::Vec;

    type R = Ready<Tk, 8, 4>;

    /// Two tasks that keep spawning each other above a low one: the low
    /// one still runs, and rounds keep ending.
    #[test]
    fn a_ping_pong_pair_cannot_starve_a_low_task() {
        let (ping, pong, low) = (tk(0, 2), tk(1, 2), tk(2, 0));
        let mut ready = R::new();
        ready.spawn(ping);
        ready.spawn(low);
        let mut round = Round::new();
        let (mut feeds, mut low_runs) = (0, 0);
        for ms in 0..1000u32 {
            let t = round.next(&mut ready, ms, || feeds += 1).unwrap();
            let next = match t.id {
                0 => pong,
                1 => ping,
                _ => {
                    low_runs += 1;
                    low
                }
            };
            ready.spawn(next);
        }
        assert!(low_runs >= 1000 / 52, "low ran {low_runs} times");
        assert!(feeds >= 1000 / 52, "{feeds} rounds ended");
    }

    /// While young, a round keeps strict priority order.
    #[test]
    fn young_rounds_keep_priority_order() {
        let mut ready = R::new();
        for (id, prio) in [(0, 0), (1, 3), (2, 1)] {
            ready.spawn(tk(id, prio));
        }
        let mut round = Round::new();
        let order: Vec<u8> =
            core::iter::from_fn(|| round.next(&mut ready, 0, || {}).map(|t| t.id)).collect();
        assert_eq!(order, [1, 2, 0]);
    }

    /// The top level is real-time work: it goes first even in an aged
    /// round.
    #[test]
    fn the_top_level_goes_first_in_an_aged_round() {
        let mut ready = R::new();
        let mut round = Round::new();
        ready.spawn(tk(0, 0));
        ready.spawn(tk(1, 1));
        assert_eq!(round.next(&mut ready, 0, || {}), Some(tk(1, 1)));
        ready.spawn(tk(1, 1));
        ready.spawn(tk(3, 3));
        // Aged: the owed low task goes before the level-1 task, not before
        // the top level's.
        let order: Vec<u8> =
            core::iter::from_fn(|| round.next(&mut ready, 100, || {}).map(|t| t.id)).collect();
        assert_eq!(order, [3, 0, 1]);
    }

    proptest! {
        /// Any tasks, priorities and spawn pattern, each run lasting up to
        /// `max_run` ms: a round ends within `AGE_MS` plus one run of each
        /// task (plus the run in progress when it aged). (Tasks only spawn
        /// below the top level, which the firmware keeps for interrupts.)
        #[test]
        fn every_round_ends_in_bounded_time(
            prios in proptest::array::uniform8(0u8..3),
            spawns in proptest::collection::vec((0u8..8, any::<u8>()), 8),
            runs in proptest::collection::vec(0u32..10, 1..400),
        ) {
            let max_run = 10;
            let mut ready = R::new();
            for id in 0..8 {
                ready.spawn(tk(id, prios[id as usize]));
            }
            let mut round = Round::new();
            let mut now = 0u32;
            let mut last_feed = 0u32;
            let mut longest = 0u32;
            for run in runs {
                let mut fed = false;
                let Some(t) = round.next(&mut ready, now, || fed = true) else {
                    break;
                };
                if fed {
                    longest = longest.max(now - last_feed);
                    last_feed = now;
                }
                now += run;
                // Each task spawns a fixed set of others (and maybe itself).
                let (first, mask) = spawns[t.id as usize];
                ready.spawn(tk(first, prios[first as usize]));
                for id in 0..8 {
                    if mask >> id & 1 != 0 {
                        ready.spawn(tk(id, prios[id as usize]));
                    }
                }
            }
            prop_assert!(longest <= Round::AGE_MS + (8 + 1) * max_run, "{longest} ms");
        }
    }
}
