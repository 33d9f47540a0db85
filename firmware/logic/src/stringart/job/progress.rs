//! Progress of a phase: a line at its start and end, whenever another
//! 1 % is done, and after 10 s without one while units get done, with the time left estimated proportionally from the time
//! spent so far (pauses excluded). Integer maths, a division or two per
//! line, never per step.

use crate::stringart::Phase;
use ufmt::{uDisplay, uWrite, uwrite, Formatter};

/// One progress line: `wind 1234/3000 left 3720s`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress {
    pub phase: Phase,
    pub done: u32,
    pub total: u32,
    /// Estimated seconds left; unknown before the first unit is done.
    pub left_s: Option<u32>,
}

impl uDisplay for Progress {
    fn fmt<W: uWrite + ?Sized>(&self, f: &mut Formatter<'_, W>) -> Result<(), W::Error> {
        uwrite!(f, "{} {}/{}", self.phase.name(), self.done, self.total)?;
        match self.left_s {
            Some(s) => uwrite!(f, " left {}s", s),
            None => Ok(()),
        }
    }
}

/// Seconds left if `done` of `total` took `elapsed_ms`.
pub fn left_s(done: u32, total: u32, elapsed_ms: u32) -> Option<u32> {
    if done == 0 {
        return None;
    }
    let left_ms = elapsed_ms as u64 * total.saturating_sub(done) as u64 / done as u64;
    Some((left_ms / 1000).min(u32::MAX as u64) as u32)
}

/// Keeps a phase's clock and decides when a line is due.
#[derive(Clone, Copy, Debug)]
pub(super) struct Reporter {
    phase: Phase,
    total: u32,
    /// Units already done when the clock started (a resumed phase).
    from: u32,
    started_ms: u32,
    /// Time spent paused so far, and the start of the current pause.
    paused_ms: u32,
    pause_from: Option<u32>,
    /// A line is due when `done` reaches `next`; lines are
    /// [`Reporter::every`] apart.
    next: u32,
    /// The last line said the total.
    said_total: bool,
    /// The last line: when, and the units it said.
    last_ms: u32,
    last_done: u32,
}

/// Longest time between lines while units get done, ms: a job of a
/// million wraps is not silent for hours between its 1 % lines.
pub const EVERY_MS: u32 = 10_000;

impl Reporter {
    /// A phase started with `from` units done (0, or a resumed phase's).
    pub fn start_at(phase: Phase, total: u32, from: u32, now_ms: u32) -> Self {
        let every = Self::every(total);
        Reporter {
            phase,
            total,
            from,
            started_ms: now_ms,
            paused_ms: 0,
            pause_from: None,
            next: (from / every + 1) * every,
            said_total: false,
            last_ms: now_ms,
            last_done: from,
        }
    }

    /// Units between lines: 1 % of the total, at least one.
    fn every(total: u32) -> u32 {
        (total / 100).max(1)
    }

    pub fn pause(&mut self, now_ms: u32) {
        self.pause_from.get_or_insert(now_ms);
    }

    pub fn resume(&mut self, now_ms: u32) {
        if let Some(from) = self.pause_from.take() {
            self.paused_ms = self.paused_ms.wrapping_add(now_ms.wrapping_sub(from));
        }
    }

    fn line(&mut self, done: u32, now_ms: u32) -> Progress {
        self.said_total = done == self.total;
        self.last_ms = now_ms;
        self.last_done = done;
        let elapsed = now_ms
            .wrapping_sub(self.started_ms)
            .wrapping_sub(self.paused_ms);
        Progress {
            phase: self.phase,
            done,
            total: self.total,
            left_s: left_s(
                done.saturating_sub(self.from),
                self.total.saturating_sub(self.from),
                elapsed,
            ),
        }
    }

    /// The line for the phase's start.
    pub fn first(&mut self, now_ms: u32) -> Progress {
        self.line(self.from, now_ms)
    }

    /// A line if another 1 % is done, or units were done in the
    /// [`EVERY_MS`] since the last line.
    pub fn update(&mut self, done: u32, now_ms: u32) -> Option<Progress> {
        let late = done > self.last_done && now_ms.wrapping_sub(self.last_ms) >= EVERY_MS;
        if done < self.next && !late {
            return None;
        }
        let every = Self::every(self.total);
        while self.next <= done {
            self.next += every;
        }
        Some(self.line(done, now_ms))
    }

    /// The phase's last line, unless the last update already said it.
    pub fn finish(&mut self, now_ms: u32) -> Option<Progress> {
        (!self.said_total).then(|| self.line(self.total, now_ms))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text::error::tests::show;

    #[test]
    fn lines_read_as_the_issue_shows() {
        let p = Progress {
            phase: Phase::Winding,
            done: 1234,
            total: 3000,
            left_s: Some(3720),
        };
        assert_eq!(show(&p), "wind 1234/3000 left 3720s");
        let start = Progress {
            done: 0,
            left_s: None,
            ..p
        };
        assert_eq!(show(&start), "wind 0/3000");
    }

    #[test]
    fn proportional_estimate() {
        assert_eq!(left_s(0, 100, 5000), None);
        // A quarter done in 60 s: three quarters left take 180 s.
        assert_eq!(left_s(25, 100, 60_000), Some(180));
        assert_eq!(left_s(100, 100, 60_000), Some(0));
        // Hours of a million-wrap job do not overflow.
        assert_eq!(left_s(1000, 1_000_000, 4_000_000_000), Some(3_996_000_000));
        assert_eq!(left_s(1, 1_000_000, 4_000_000_000), Some(u32::MAX));
    }

    #[test]
    fn pauses_do_not_count_as_work() {
        let mut r = Reporter::start_at(Phase::Drilling, 100, 0, 1000);
        r.pause(11_000);
        r.pause(12_000); // a second `!` changes nothing
        r.resume(51_000);
        // 10 s of work, 40 s paused, 10 s of work: 20 s for 50 units.
        let p = r.update(50, 61_000).unwrap();
        assert_eq!(p.left_s, Some(20));
    }

    #[test]
    fn a_line_every_1_percent_and_one_at_the_end() {
        let mut r = Reporter::start_at(Phase::Winding, 3000, 0, 0);
        let lines: std::vec::Vec<u32> = (1..=3000)
            .filter_map(|d| r.update(d, d))
            .map(|p| p.done)
            .collect();
        assert_eq!(lines.len(), 100);
        assert_eq!(lines[0], 30);
        assert!(lines.windows(2).all(|w| w[1] - w[0] == 30));
        assert_eq!(r.finish(3000), None, "3000/3000 was the last line");
        // Small totals: a line per unit; jumps of several units report once.
        let mut r = Reporter::start_at(Phase::Drilling, 7, 0, 0);
        assert!(r.update(1, 0).is_some());
        assert_eq!(r.update(5, 0).map(|p| p.done), Some(5));
        assert!(r.update(5, 0).is_none());
        assert_eq!(r.finish(0).map(|p| p.done), Some(7));
    }

    #[test]
    fn a_resumed_phase_counts_from_where_it_went_on() {
        let mut r = Reporter::start_at(Phase::Winding, 3000, 1234, 0);
        assert_eq!(r.first(0).done, 1234);
        // The next line at the next multiple of 30, estimated from the
        // units done since the resume only: 26 in 2.6 s, 1740 left.
        assert!(r.update(1259, 2_500).is_none());
        let p = r.update(1260, 2_600).unwrap();
        assert_eq!(p.left_s, Some(174));
    }

    #[test]
    fn a_line_at_least_every_10_s_on_a_big_job() {
        // A million wraps of 3 s: 1 % is over 8 hours.
        let mut r = Reporter::start_at(Phase::Winding, 1_000_000, 0, 0);
        let lines: std::vec::Vec<u32> = (1..=100)
            .filter_map(|d| r.update(d, d * 3000))
            .map(|p| p.done)
            .collect();
        assert_eq!(
            lines,
            [
                4, 8, 12, 16, 20, 24, 28, 32, 36, 40, 44, 48, 52, 56, 60, 64, 68, 72, 76, 80, 84,
                88, 92, 96, 100
            ]
        );
        // Nothing done in 10 s (the machine held): no line.
        assert!(r.update(100, 400_000).is_none());
    }
}
