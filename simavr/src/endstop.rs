//! Limit switches of the simulated machine: a switch to ground that closes
//! (pulls its pin low) while an axis, counted from its own STEP and DIR
//! pins, stands at or below a position, as a MIN end-stop does when the
//! carriage reaches it.

use crate::sim::Sim;

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
}

impl Sim {
    /// Fits a MIN end-stop on board pin `switch`: closed while the axis
    /// driven by the STEP/DIR pair `step`/`dir` (both probed) stands at or
    /// below `at` steps, counted from where it stood when they were probed.
    pub fn endstop(&mut self, switch: u8, step: u8, dir: u8, dir_high_is_positive: bool, at: i64) {
        let closed = at >= 0;
        self.drive(switch, !closed);
        self.endstops.push(Endstop {
            switch,
            step,
            dir,
            dir_high_is_positive,
            at,
            seen: 0,
            position: 0,
            closed,
        });
        self.update_endstops();
    }

    /// Moves every end-stop's axis by the STEP edges since the last look,
    /// and opens or closes its switch.
    pub(crate) fn update_endstops(&mut self) {
        for i in 0..self.endstops.len() {
            let e = &self.endstops[i];
            let (step, dir) = (self.probe_of(e.step), self.probe_of(e.dir));
            let edges = &step.edges()[e.seen..];
            if edges.is_empty() {
                continue;
            }
            let moved: i64 = edges
                .iter()
                .filter(|edge| edge.high)
                .map(
                    |edge| match dir.level_at(edge.cycle) == e.dir_high_is_positive {
                        true => 1,
                        false => -1,
                    },
                )
                .sum();
            let n = edges.len();
            let e = &mut self.endstops[i];
            e.seen += n;
            e.position += moved;
            let closed = e.position <= e.at;
            if closed != e.closed {
                e.closed = closed;
                let pin = e.switch;
                self.drive(pin, !closed);
            }
        }
    }
}
