//! Pin levels the outside world will apply later: a bouncing contact is a
//! burst of level changes a few hundred microseconds apart.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Future level changes of input pins, earliest first; changes due at the
/// same cycle keep the order they were planned in.
#[derive(Default)]
pub(crate) struct PinSchedule {
    heap: BinaryHeap<Reverse<(u64, u64, u8, bool)>>,
    planned: u64,
}

impl PinSchedule {
    pub fn push(&mut self, cycle: u64, pin: u8, high: bool) {
        self.heap.push(Reverse((cycle, self.planned, pin, high)));
        self.planned += 1;
    }

    /// Cycle of the earliest pending change.
    pub fn next_due(&self) -> Option<u64> {
        self.heap.peek().map(|Reverse(e)| e.0)
    }

    /// The earliest change due at or before `now`, removed.
    pub fn pop_due(&mut self, now: u64) -> Option<(u8, bool)> {
        match self.heap.peek() {
            Some(Reverse((cycle, _, pin, high))) if *cycle <= now => {
                let change = (*pin, *high);
                self.heap.pop();
                Some(change)
            }
            _ => None,
        }
    }
}

/// Levels of a contact that settles at `settled` after `bounces` short
/// returns to the other level, one change every `period` cycles from `start`.
pub(crate) fn bounce(start: u64, settled: bool, bounces: u32, period: u64) -> Vec<(u64, bool)> {
    (0..=2 * bounces as u64)
        .map(|i| {
            (
                start + i * period,
                if i % 2 == 0 { settled } else { !settled },
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounce_ends_settled() {
        let plan = bounce(100, false, 2, 10);
        assert_eq!(
            plan,
            vec![
                (100, false),
                (110, true),
                (120, false),
                (130, true),
                (140, false)
            ]
        );
        assert_eq!(bounce(0, true, 0, 10), vec![(0, true)]);
    }

    #[test]
    fn schedule_pops_in_time_then_plan_order() {
        let mut s = PinSchedule::default();
        s.push(20, 1, true);
        s.push(10, 2, false);
        s.push(10, 3, true);
        assert_eq!(s.next_due(), Some(10));
        assert_eq!(s.pop_due(9), None);
        assert_eq!(s.pop_due(15), Some((2, false)));
        assert_eq!(s.pop_due(15), Some((3, true)));
        assert_eq!(s.pop_due(15), None);
        assert_eq!(s.pop_due(20), Some((1, true)));
        assert_eq!(s.next_due(), None);
    }
}
