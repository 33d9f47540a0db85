//! The ready set: which spawned tasks wait to run, in dispatch order.

use super::TaskId;

/// The set of tasks waiting to run, for `N` tasks over `P` priority levels.
///
/// One intrusive FIFO list per level, linked through a per-task `link`
/// slot: a task is pending at most once, so one link per task is all the
/// storage needed (`N + 2P` task slots plus `N` flags, a few dozen bytes).
/// `spawn` is O(1); `pop` scans at most `P` level heads.
pub struct Ready<T: TaskId, const N: usize, const P: usize> {
    pending: [bool; N],
    /// The task queued after this one at its level.
    link: [Option<T>; N],
    head: [Option<T>; P],
    tail: [Option<T>; P],
}

impl<T: TaskId, const N: usize, const P: usize> Ready<T, N, P> {
    pub const fn new() -> Self {
        const {
            assert!(N >= T::COUNT, "Ready: fewer task slots than tasks");
            assert!(P > 0, "Ready: no priority level");
        }
        Ready {
            pending: [false; N],
            link: [None; N],
            head: [None; P],
            tail: [None; P],
        }
    }

    /// Marks `task` ready behind the tasks already waiting at its priority.
    /// Returns `false`, changing nothing, if it is already pending.
    pub fn spawn(&mut self, task: T) -> bool {
        let i = task.index();
        if self.pending[i] {
            return false;
        }
        self.pending[i] = true;
        self.link[i] = None;
        let level = task.priority() as usize;
        match self.tail[level] {
            None => self.head[level] = Some(task),
            Some(last) => self.link[last.index()] = Some(task),
        }
        self.tail[level] = Some(task);
        true
    }

    /// Takes the task to run now: the oldest spawn at the highest level.
    pub fn pop(&mut self) -> Option<T> {
        (0..P as u8).rev().find_map(|level| self.pop_level(level))
    }

    /// The oldest spawn at priority `level`, if any.
    /// Inlined: the dispatcher's every pick (at `z` it was a call).
    #[inline(always)]
    pub fn pop_level(&mut self, level: u8) -> Option<T> {
        let l = level as usize;
        let task = self.head[l]?;
        let i = task.index();
        self.head[l] = self.link[i];
        if self.head[l].is_none() {
            self.tail[l] = None;
        }
        self.pending[i] = false;
        Some(task)
    }

    /// Like [`Ready::pop`], among the tasks whose bit (`1 << index`) is
    /// set in `among` only: the oldest spawn at the highest level of those.
    pub fn pop_among(&mut self, among: u16) -> Option<T> {
        for level in (0..P).rev() {
            let mut prev: Option<T> = None;
            let mut at = self.head[level];
            while let Some(task) = at {
                let i = task.index();
                if among >> i & 1 != 0 {
                    match prev {
                        None => self.head[level] = self.link[i],
                        Some(p) => self.link[p.index()] = self.link[i],
                    }
                    if self.tail[level].is_some_and(|t| t.index() == i) {
                        self.tail[level] = prev;
                    }
                    self.pending[i] = false;
                    return Some(task);
                }
                prev = at;
                at = self.link[i];
            }
        }
        None
    }

    /// No task waits.
    pub fn is_empty(&self) -> bool {
        self.head.iter().all(Option::is_none)
    }

    /// The pending tasks as a bit set (`1 << index`; at most 16 tasks).
    pub fn pending_mask(&self) -> u16 {
        const { assert!(T::COUNT <= 16, "a bit per task in a u16") };
        let mut mask = 0u16;
        let mut bit = 1u16;
        for &pending in &self.pending[..T::COUNT] {
            if pending {
                mask |= bit;
            }
            bit <<= 1;
        }
        mask
    }

    pub fn is_pending(&self, task: T) -> bool {
        self.pending[task.index()]
    }

    /// True when no task waits: the idle loop may sleep.
    pub fn is_idle(&self) -> bool {
        self.head.iter().all(Option::is_none)
    }
}

impl<T: TaskId, const N: usize, const P: usize> Default for Ready<T, N, P> {
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

    fn drain(r: &mut R) -> Vec<u8> {
        core::iter::from_fn(|| r.pop()).map(|t| t.id).collect()
    }

    #[test]
    fn higher_priority_runs_first() {
        let mut r = R::new();
        r.spawn(tk(0, 0));
        r.spawn(tk(1, 2));
        r.spawn(tk(2, 1));
        r.spawn(tk(3, 3));
        assert_eq!(drain(&mut r), [3, 1, 2, 0]);
    }

    #[test]
    fn equal_priorities_run_in_spawn_order() {
        let mut r = R::new();
        for id in [4, 1, 6, 2] {
            assert!(r.spawn(tk(id, 1)));
        }
        r.spawn(tk(0, 2));
        assert_eq!(drain(&mut r), [0, 4, 1, 6, 2]);
    }

    #[test]
    fn pending_task_is_not_queued_twice_nor_moved() {
        let mut r = R::new();
        assert!(r.spawn(tk(1, 1)));
        assert!(r.spawn(tk(2, 1)));
        assert!(!r.spawn(tk(1, 1)));
        assert!(r.is_pending(tk(1, 1)));
        assert_eq!(drain(&mut r), [1, 2]);
        assert!(!r.is_pending(tk(1, 1)));
    }

    #[test]
    fn isr_spawns_between_dispatches_keep_the_rules() {
        let mut r = R::new();
        r.spawn(tk(0, 0)); // main: logger
        r.spawn(tk(1, 1)); // main: planner
        assert_eq!(r.pop().map(|t| t.id), Some(1));
        // "ISR" while the planner runs: the UI (same level as planner) and
        // the planner itself again, then a higher-priority job event.
        r.spawn(tk(2, 1));
        assert!(r.spawn(tk(1, 1)), "a running task can be spawned again");
        r.spawn(tk(3, 3));
        assert_eq!(r.pop().map(|t| t.id), Some(3));
        r.spawn(tk(4, 1));
        assert_eq!(drain(&mut r), [2, 1, 4, 0]);
    }

    #[test]
    fn idle_only_when_empty() {
        let mut r = R::new();
        assert!(r.is_idle());
        assert_eq!(r.pop(), None);
        r.spawn(tk(5, 0));
        assert!(!r.is_idle());
        r.pop();
        assert!(r.is_idle());
    }

    #[test]
    fn usable_from_a_static_initialiser() {
        static R0: R = R::new();
        assert!(R0.is_idle());
    }

    /// The obvious model: a list sorted by (priority desc, spawn order).
    #[derive(Default)]
    struct Model {
        waiting: Vec<(Tk, u64)>,
        seq: u64,
    }

    impl Model {
        fn spawn(&mut self, t: Tk) -> bool {
            if self.waiting.iter().any(|(w, _)| w.id == t.id) {
                return false;
            }
            self.seq += 1;
            self.waiting.push((t, self.seq));
            true
        }

        fn pop(&mut self) -> Option<Tk> {
            self.pop_among(u16::MAX)
        }

        fn pop_among(&mut self, among: u16) -> Option<Tk> {
            let best = (0..self.waiting.len())
                .filter(|&i| among >> self.waiting[i].0.id & 1 != 0)
                .min_by_key(|&i| {
                    let (t, seq) = self.waiting[i];
                    (core::cmp::Reverse(t.prio), seq)
                })?;
            Some(self.waiting.remove(best).0)
        }
    }

    #[derive(Clone, Debug)]
    enum Op {
        Spawn(u8),
        Pop,
        PopAmong(u8),
    }

    fn op() -> impl Strategy<Value = Op> {
        prop_oneof![
            (0u8..8).prop_map(Op::Spawn),
            Just(Op::Pop),
            any::<u8>().prop_map(Op::PopAmong)
        ]
    }

    proptest! {
        #[test]
        fn matches_the_sorted_list_model(
            prios in proptest::array::uniform8(0u8..4),
            ops in proptest::collection::vec(op(), 0..200),
        ) {
            let mut r = R::new();
            let mut m = Model::default();
            for o in ops {
                match o {
                    Op::Spawn(id) => {
                        let t = tk(id, prios[id as usize]);
                        prop_assert_eq!(r.spawn(t), m.spawn(t));
                    }
                    Op::Pop => prop_assert_eq!(r.pop(), m.pop()),
                    Op::PopAmong(mask) => {
                        prop_assert_eq!(r.pop_among(mask as u16), m.pop_among(mask as u16))
                    }
                }
                let model_mask = m.waiting.iter().fold(0u16, |a, (t, _)| a | 1 << t.id);
                prop_assert_eq!(r.pending_mask(), model_mask);
                prop_assert_eq!(r.is_idle(), m.waiting.is_empty());
            }
            while let Some(t) = m.pop() {
                prop_assert_eq!(r.pop(), Some(t));
            }
            prop_assert_eq!(r.pop(), None);
        }
    }
}
