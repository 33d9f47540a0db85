//! Recorded pin levels: every edge of a probed pin with the cycle it happened
//! at, and the figures a motion test asks of them.

use crate::clock::cycles_to_us;

/// One level change of a probed pin.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Edge {
    /// Simulated cycle (since power-on, across resets) of the change.
    pub cycle: u64,
    /// Level after the change.
    pub high: bool,
}

/// The edges seen on one board pin since the probe was attached.
#[derive(Clone, Debug)]
pub struct Probe {
    name: String,
    pin: u8,
    initial: bool,
    edges: Vec<Edge>,
}

impl Probe {
    pub(crate) fn new(name: &str, pin: u8, initial: bool) -> Probe {
        Probe {
            name: name.to_owned(),
            pin,
            initial,
            edges: Vec::new(),
        }
    }

    /// Notes the level simavr reports; repeats of the same level are not edges
    /// (simavr re-announces every pin of a port on each port write).
    pub(crate) fn record(&mut self, cycle: u64, high: bool) {
        if high != self.level() {
            self.edges.push(Edge { cycle, high });
        }
    }

    pub fn name(&self) -> &str {
        &self.name
    }

    /// Board pin number (D0..D69).
    pub fn pin(&self) -> u8 {
        self.pin
    }

    /// Level when the probe was attached.
    pub fn initial(&self) -> bool {
        self.initial
    }

    pub fn edges(&self) -> &[Edge] {
        &self.edges
    }

    /// Current level.
    pub fn level(&self) -> bool {
        self.edges.last().map_or(self.initial, |e| e.high)
    }

    /// Level at `cycle` (an edge at exactly `cycle` counts as done).
    pub fn level_at(&self, cycle: u64) -> bool {
        let after = self.edges.partition_point(|e| e.cycle <= cycle);
        match after {
            0 => self.initial,
            n => self.edges[n - 1].high,
        }
    }

    pub fn edge_count(&self) -> usize {
        self.edges.len()
    }

    pub fn rising_count(&self) -> usize {
        self.rising().count()
    }

    fn rising(&self) -> impl Iterator<Item = &Edge> {
        self.edges.iter().filter(|e| e.high)
    }

    /// Every completed high pulse's length, in cycles.
    fn high_cycles(&self) -> impl Iterator<Item = u64> + '_ {
        self.edges
            .windows(2)
            .filter(|w| w[0].high && !w[1].high)
            .map(|w| w[1].cycle - w[0].cycle)
    }

    /// Shortest completed high pulse, in cycles.
    pub fn min_high_cycles(&self) -> Option<u64> {
        self.high_cycles().min()
    }

    /// Longest completed high pulse, in cycles.
    pub fn max_high_cycles(&self) -> Option<u64> {
        self.high_cycles().max()
    }

    /// Shortest time between two rising edges, in cycles.
    pub fn min_period_cycles(&self) -> Option<u64> {
        let rises: Vec<u64> = self.rising().map(|e| e.cycle).collect();
        rises.windows(2).map(|w| w[1] - w[0]).min()
    }

    pub fn min_high_us(&self) -> Option<f64> {
        self.min_high_cycles().map(cycles_to_us)
    }

    pub fn min_period_us(&self) -> Option<f64> {
        self.min_period_cycles().map(cycles_to_us)
    }
}

/// A STEP/DIR pair whose net steps go into reports.
pub(crate) struct StepDir {
    pub step: u8,
    pub dir: u8,
    pub dir_high_is_positive: bool,
}

/// Steps a STEP/DIR driver would have made: every rising STEP edge counts one,
/// positive when DIR was at the level meaning positive at that instant.
pub fn net_steps(step: &Probe, dir: &Probe, dir_high_is_positive: bool) -> i64 {
    step.rising()
        .map(|e| {
            if dir.level_at(e.cycle) == dir_high_is_positive {
                1
            } else {
                -1
            }
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn probe(initial: bool, edges: &[(u64, bool)]) -> Probe {
        let mut p = Probe::new("p", 13, initial);
        for &(cycle, high) in edges {
            p.record(cycle, high);
        }
        p
    }

    #[test]
    fn repeated_levels_are_not_edges() {
        let p = probe(false, &[(1, false), (5, true), (6, true), (9, false)]);
        assert_eq!(p.edge_count(), 2);
        assert_eq!(p.rising_count(), 1);
        assert_eq!(p.min_high_cycles(), Some(4));
        assert_eq!(p.min_period_cycles(), None);
    }

    #[test]
    fn figures_pick_the_shortest() {
        let p = probe(
            false,
            &[(10, true), (20, false), (30, true), (33, false), (50, true)],
        );
        assert_eq!(p.min_high_cycles(), Some(3));
        assert_eq!(p.min_period_cycles(), Some(20));
        assert_eq!(p.min_period_us(), Some(1.25));
        assert!(!p.level_at(9));
        assert!(p.level_at(10));
        assert!(p.level_at(31));
        assert!(p.level());
    }

    #[test]
    fn net_steps_follow_dir_level() {
        // 3 steps with DIR high, then DIR low and 5 steps.
        let mut step = Probe::new("step", 54, false);
        let dir = probe(true, &[(100, false)]);
        for i in 0..8u64 {
            let t = if i < 3 { 10 + i * 10 } else { 200 + i * 10 };
            step.record(t, true);
            step.record(t + 2, false);
        }
        assert_eq!(net_steps(&step, &dir, true), 3 - 5);
        assert_eq!(net_steps(&step, &dir, false), 5 - 3);
    }
}
