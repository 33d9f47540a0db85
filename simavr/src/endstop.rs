//! Limit switches of the simulated machine: a switch to ground that closes
//! (pulls its pin low) while an axis, counted from its own STEP and DIR
//! pins, stands at or below a position, as a MIN end-stop does when the
//! carriage reaches it.

use crate::probe::Probe;

pub(crate) struct Endstop {
    switch: u8,
    step: u8,
    dir: u8,
    dir_high_is_positive: bool,
    /// Closed at or below this many steps, counted from where the axis
    /// stood when its pins were probed.
    at: i64,
    /// STEP edges looked at so far.
    seen: usize,
    position: i64,
    closed: bool,
    /// The switch has closed at least once: the firmware homed against it.
    tripped: bool,
}

impl Endstop {
    /// A MIN end-stop on board pin `switch`: closed while the axis driven
    /// by the STEP/DIR pair `step`/`dir` stands at or below `at` steps.
    pub(crate) fn new(
        switch: u8,
        step: u8,
        dir: u8,
        dir_high_is_positive: bool,
        at: i64,
    ) -> Endstop {
        let closed = at >= 0;
        Endstop {
            switch,
            step,
            dir,
            dir_high_is_positive,
            at,
            seen: 0,
            position: 0,
            closed,
            tripped: closed,
        }
    }

    pub(crate) fn switch(&self) -> u8 {
        self.switch
    }

    /// The STEP and DIR pins its axis is counted from.
    pub(crate) fn pins(&self) -> (u8, u8) {
        (self.step, self.dir)
    }

    pub(crate) fn closed(&self) -> bool {
        self.closed
    }

    /// The switch has ever closed (the axis was homed against it, or
    /// stood on it).
    pub(crate) fn tripped(&self) -> bool {
        self.tripped
    }

    /// The STEP edges since the last look, and the steps they moved the
    /// axis by.
    pub(crate) fn moved(&self, step: &Probe, dir: &Probe) -> (usize, i64) {
        let edges = &step.edges()[self.seen..];
        let moved = edges
            .iter()
            .filter(|edge| edge.high)
            .map(
                |edge| match dir.level_at(edge.cycle) == self.dir_high_is_positive {
                    true => 1,
                    false => -1,
                },
            )
            .sum();
        (edges.len(), moved)
    }

    /// Counts `edges` STEP edges that moved the axis `moved` steps; the
    /// switch's new state when it opened or closed.
    pub(crate) fn advance(&mut self, edges: usize, moved: i64) -> Option<bool> {
        self.seen += edges;
        self.position += moved;
        let closed = self.position <= self.at;
        if closed == self.closed {
            return None;
        }
        self.closed = closed;
        self.tripped |= closed;
        Some(closed)
    }
}
