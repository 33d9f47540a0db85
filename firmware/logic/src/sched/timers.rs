//! Timed spawns on the wrapping millisecond clock: `spawn_after`, periodic
//! tasks, and handing due ones to the ready set.

use super::{Ready, TaskId};

/// No free timer slot: the caller decides (retry, or size `N` up).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Full;

#[derive(Clone, Copy)]
struct Timer<T> {
    task: T,
    /// Instant (ms) it falls due.
    at: u32,
    /// 0: one-shot; else re-armed this many ms after each firing.
    period: u32,
}

/// Longest delay the signed comparison can order: half the clock's range.
const MAX_DELAY: u32 = i32::MAX as u32;

/// Signed distance from `now` to `at`: negative or zero means due. Correct
/// across the `u32` wrap as long as the two are less than 2^31 ms apart.
fn until(at: u32, now: u32) -> i32 {
    at.wrapping_sub(now) as i32
}

/// Up to `N` armed timers. Arming scans `N` slots, so keep `N` a handful.
pub struct Timers<T: TaskId, const N: usize> {
    slots: [Option<Timer<T>>; N],
}

impl<T: TaskId, const N: usize> Timers<T, N> {
    pub const fn new() -> Self {
        Timers { slots: [None; N] }
    }

    /// Spawns `task` once, `delay_ms` after `now_ms` (clamped to 2^31-1 ms),
    /// replacing its one-shot timer if it had one: a task spawned often
    /// (by every received byte) must not fill the slots with wake-ups it
    /// no longer needs. Its periodic timer, if any, keeps running.
    pub fn spawn_after(&mut self, task: T, now_ms: u32, delay_ms: u32) -> Result<(), Full> {
        for slot in &mut self.slots {
            if slot.is_some_and(|t| t.task.index() == task.index() && t.period == 0) {
                *slot = None;
            }
        }
        self.arm(task, now_ms.wrapping_add(delay_ms.min(MAX_DELAY)), 0)
    }

    /// Spawns `task` every `period_ms` (at least 1), first at `now + period`.
    /// Firings stay on the original grid; if the dispatcher falls more than a
    /// period behind, the missed firings are skipped rather than bunched.
    pub fn every(&mut self, task: T, now_ms: u32, period_ms: u32) -> Result<(), Full> {
        let period = period_ms.clamp(1, MAX_DELAY);
        self.arm(task, now_ms.wrapping_add(period), period)
    }

    fn arm(&mut self, task: T, at: u32, period: u32) -> Result<(), Full> {
        let free = self.slots.iter_mut().find(|s| s.is_none()).ok_or(Full)?;
        *free = Some(Timer { task, at, period });
        Ok(())
    }

    /// The most overdue timer at `now_ms`, if any is due; re-arms it if
    /// periodic, frees its slot otherwise.
    pub fn due(&mut self, now_ms: u32) -> Option<T> {
        let slot = self
            .slots
            .iter_mut()
            .filter(|s| s.is_some_and(|t| until(t.at, now_ms) <= 0))
            .min_by_key(|s| s.map_or(0, |t| until(t.at, now_ms)))?;
        let timer = slot.take()?;
        if timer.period != 0 {
            let mut at = timer.at.wrapping_add(timer.period);
            if until(at, now_ms) <= 0 {
                at = now_ms.wrapping_add(timer.period);
            }
            *slot = Some(Timer { at, ..timer });
        }
        Some(timer.task)
    }

    /// Spawns every task due at `now_ms` into `ready`, oldest deadline first
    /// (so equal-priority tasks queue in deadline order). A firing whose task
    /// is still pending coalesces with it. Returns how many tasks became ready.
    pub fn fire_due<const R: usize, const P: usize>(
        &mut self,
        now_ms: u32,
        ready: &mut Ready<T, R, P>,
    ) -> usize {
        let mut spawned = 0;
        // Each due timer is fired once: a periodic one re-arms in the future.
        for _ in 0..N {
            match self.due(now_ms) {
                Some(task) => spawned += usize::from(ready.spawn(task)),
                None => break,
            }
        }
        spawned
    }

    /// Milliseconds from `now_ms` to the earliest deadline (0 if one is
    /// already due); `None` when nothing is armed. The idle loop's horizon.
    pub fn ms_to_next(&self, now_ms: u32) -> Option<u32> {
        self.slots
            .iter()
            .flatten()
            .map(|t| until(t.at, now_ms).max(0) as u32)
            .min()
    }
}

impl<T: TaskId, const N: usize> Default for Timers<T, N> {
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

    type Tm = Timers<Tk, 4>;
    const A: Tk = tk(0, 1);
    const B: Tk = tk(1, 1);
    const C: Tk = tk(2, 2);
    const D: Tk = tk(3, 0);

    #[test]
    fn one_shot_fires_once_at_its_deadline() {
        let mut t = Tm::new();
        t.spawn_after(A, 1000, 50).unwrap();
        assert_eq!(t.due(1049), None);
        assert_eq!(t.ms_to_next(1049), Some(1));
        assert_eq!(t.due(1050), Some(A));
        assert_eq!(t.due(1050), None);
        assert_eq!(t.ms_to_next(1050), None);
    }

    #[test]
    fn deadlines_across_the_u32_wrap() {
        let mut t = Tm::new();
        let now = u32::MAX - 10;
        t.spawn_after(A, now, 30).unwrap(); // due at 19 after the wrap
        t.spawn_after(B, now, 5).unwrap(); // due before the wrap
        assert_eq!(t.ms_to_next(now), Some(5));
        assert_eq!(t.due(u32::MAX - 6), None);
        assert_eq!(t.due(u32::MAX), Some(B));
        assert_eq!(t.due(u32::MAX), None, "19 after the wrap is not yet");
        assert_eq!(t.due(18), None);
        assert_eq!(t.ms_to_next(18), Some(1));
        assert_eq!(t.due(19), Some(A));
    }

    #[test]
    fn most_overdue_fires_first() {
        let mut t = Tm::new();
        t.spawn_after(A, 0, 30).unwrap();
        t.spawn_after(B, 0, 10).unwrap();
        t.spawn_after(C, 0, 20).unwrap();
        assert_eq!(t.ms_to_next(100), Some(0));
        let order: Vec<_> = core::iter::from_fn(|| t.due(100)).collect();
        assert_eq!(order, [B, C, A]);
    }

    #[test]
    fn periodic_stays_on_its_grid_and_skips_missed_firings() {
        let mut t = Tm::new();
        t.every(A, u32::MAX - 5, 10).unwrap(); // grid: 4, 14, 24 …
        assert_eq!(t.due(3), None);
        assert_eq!(t.due(7), Some(A)); // served late …
        assert_eq!(t.ms_to_next(7), Some(7)); // … next still at 14
        assert_eq!(t.due(14), Some(A));
        // Dispatcher stalls past several periods: one firing, then a period on.
        assert_eq!(t.due(60), Some(A));
        assert_eq!(t.due(60), None);
        assert_eq!(t.ms_to_next(60), Some(10));
    }

    #[test]
    fn a_new_delay_replaces_the_one_shot_and_keeps_the_period() {
        let mut t = Tm::new();
        t.spawn_after(A, 0, 5).unwrap();
        t.every(A, 0, 7).unwrap();
        t.spawn_after(B, 0, 9).unwrap();
        t.spawn_after(C, 0, 9).unwrap();
        assert_eq!(t.spawn_after(D, 0, 1), Err(Full));
        // A's one-shot is replaced in its own slot: no slot is needed.
        t.spawn_after(A, 0, 3).unwrap();
        assert_eq!(t.ms_to_next(0), Some(3));
        assert_eq!(t.due(3), Some(A));
        assert_eq!(t.due(3), None);
        assert_eq!(t.due(7), Some(A), "the period goes on");
    }

    #[test]
    fn fire_due_spawns_in_deadline_order_and_coalesces() {
        let mut t = Tm::new();
        let mut r: Ready<Tk, 8, 4> = Ready::new();
        t.spawn_after(B, 0, 2).unwrap();
        t.every(A, 0, 1).unwrap();
        t.spawn_after(A, 0, 3).unwrap();
        t.spawn_after(C, 0, 50).unwrap();
        assert_eq!(t.fire_due(10, &mut r), 2, "A's two timers coalesce");
        assert_eq!(r.pop(), Some(A));
        assert_eq!(r.pop(), Some(B));
        assert_eq!(r.pop(), None);
        assert_eq!(t.ms_to_next(10), Some(1), "A's period goes on");
    }

    #[test]
    fn fire_due_fires_a_periodic_task_once_per_call() {
        let mut t = Tm::new();
        let mut r: Ready<Tk, 8, 4> = Ready::new();
        t.every(C, 0, 1).unwrap();
        assert_eq!(t.fire_due(500, &mut r), 1);
        assert_eq!(t.ms_to_next(500), Some(1));
    }

    #[test]
    fn delays_are_clamped_to_the_comparable_range() {
        let mut t = Tm::new();
        t.spawn_after(A, 7, u32::MAX).unwrap();
        assert_eq!(t.due(7), None, "a huge delay must not read as overdue");
        assert_eq!(t.ms_to_next(7), Some(i32::MAX as u32));
    }

    proptest! {
        /// Wherever the clock stands, timers fire in delay order and each
        /// exactly when its delay has elapsed.
        #[test]
        fn fires_in_delay_order_anywhere_on_the_clock(
            start in any::<u32>(),
            delays in proptest::collection::vec(0u32..1000, 1..=4),
        ) {
            let mut t = Tm::new();
            for (i, &d) in delays.iter().enumerate() {
                t.spawn_after(tk(i as u8, 0), start, d).unwrap();
            }
            let mut fired = Vec::new();
            for dt in 0..1000u32 {
                while let Some(task) = t.due(start.wrapping_add(dt)) {
                    prop_assert_eq!(delays[task.id as usize], dt);
                    fired.push(task.id);
                }
            }
            prop_assert_eq!(fired.len(), delays.len());
            prop_assert!(fired.windows(2).all(|w| delays[w[0] as usize] <= delays[w[1] as usize]));
        }
    }
}
