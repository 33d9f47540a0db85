//! A 28BYJ-48 read back from its ULN2003 board's four inputs (probed as
//! `x_in1`..`x_in4`, `y_in*`, `z_in*`): the half-steps it made, when its
//! coils were off, and every change of the inputs a motor could not follow
//! (a state outside the half-step sequence, a jump of more than one
//! half-step, coils coming back on at another phase than they went off).
//! Edges at the same instant are one port write, taken together.

use crate::vcd::Signal;
use taut_logic::coil::{phase_of, step_between};

/// The VCD names of channel `axis`'s (0 X, 1 Y, 2 Z) inputs IN1..IN4.
pub fn names(axis: usize) -> [String; 4] {
    let channel = ["x", "y", "z"][axis];
    [1, 2, 3, 4].map(|k| format!("{channel}_in{k}"))
}

/// What the inputs did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct CoilTrack {
    /// `(time, position after)` of every half-step (time in the edges'
    /// unit: cycles from the simulator's probes, ns from a VCD); positive
    /// as the phase counts up the sequence.
    pub steps: Vec<(u64, i64)>,
    /// `(time, energised)` whenever the coils went on or off.
    pub power: Vec<(u64, bool)>,
    /// `(time, inputs before, inputs after)` of every change a motor
    /// could not follow (IN1 in bit 0).
    pub illegal: Vec<(u64, u8, u8)>,
    /// The inputs at the end.
    pub last: u8,
}

impl CoilTrack {
    /// From four levels (IN1 first): each the level at the start and its
    /// changes `(time, high)`, in time order.
    pub fn decode(inputs: [(bool, &[(u64, bool)]); 4]) -> CoilTrack {
        let mut state = 0u8;
        for (k, (initial, _)) in inputs.iter().enumerate() {
            state |= u8::from(*initial) << k;
        }
        let mut changes: Vec<(u64, usize, bool)> = inputs
            .iter()
            .enumerate()
            .flat_map(|(k, (_, c))| c.iter().map(move |&(t, high)| (t, k, high)))
            .collect();
        changes.sort_by_key(|c| c.0);
        let mut track = CoilTrack::default();
        // The phase the coils stand at, on or off.
        let mut phase = phase_of(state);
        let mut pos = 0i64;
        let mut i = 0;
        while i < changes.len() {
            let t = changes[i].0;
            let mut next = state;
            while i < changes.len() && changes[i].0 == t {
                let (_, k, high) = changes[i];
                next = (next & !(1 << k)) | (u8::from(high) << k);
                i += 1;
            }
            if next == state {
                continue;
            }
            match (state, next) {
                (_, 0) => track.power.push((t, false)),
                (0, _) => {
                    track.power.push((t, true));
                    match (phase, phase_of(next)) {
                        (_, None) => track.illegal.push((t, state, next)),
                        (Some(p), Some(q)) if p != q => track.illegal.push((t, state, next)),
                        (_, q) => phase = q,
                    }
                }
                _ => match (phase, phase_of(next)) {
                    (Some(p), Some(q)) => match step_between(p, q) {
                        Some(d) => {
                            pos += i64::from(d);
                            track.steps.push((t, pos));
                            phase = Some(q);
                        }
                        None => {
                            track.illegal.push((t, state, next));
                            phase = Some(q);
                        }
                    },
                    (_, q) => {
                        track.illegal.push((t, state, next));
                        phase = q;
                    }
                },
            }
            state = next;
        }
        track.last = state;
        track
    }

    /// From a VCD's signals named [`names`]`(axis)`: times in ns.
    pub fn from_signals(signals: &[Signal], axis: usize) -> Result<CoilTrack, String> {
        let names = names(axis);
        let mut found = Vec::new();
        for name in &names {
            let s = signals
                .iter()
                .find(|s| &s.name == name)
                .ok_or(format!("no signal {name} in the trace"))?;
            found.push(s);
        }
        Ok(CoilTrack::decode(std::array::from_fn(|k| {
            (found[k].initial, found[k].changes.as_slice())
        })))
    }

    /// The position after the last half-step.
    pub fn position(&self) -> i64 {
        self.steps.last().map_or(0, |s| s.1)
    }

    /// Whether the coils are energised at the end.
    pub fn energised(&self) -> bool {
        self.last != 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use taut_logic::coil::pattern;

    /// The four inputs' edges of a sequence of port writes, one per µs.
    fn writes(states: &[u8]) -> [(bool, Vec<(u64, bool)>); 4] {
        std::array::from_fn(|k| {
            let mut level = false;
            let mut changes = Vec::new();
            for (t, s) in states.iter().enumerate() {
                let high = s >> k & 1 != 0;
                if high != level {
                    changes.push((t as u64, high));
                    level = high;
                }
            }
            (false, changes)
        })
    }

    fn decode(states: &[u8]) -> CoilTrack {
        let w = writes(states);
        CoilTrack::decode(std::array::from_fn(|k| (w[k].0, w[k].1.as_slice())))
    }

    #[test]
    fn half_steps_both_ways_and_a_release_at_the_same_phase() {
        let mut seq: Vec<u8> = (0..10).map(pattern).collect();
        seq.extend([0, pattern(9)]);
        seq.extend((0..5).map(|k| pattern(9 - k)));
        let t = decode(&seq);
        assert!(t.illegal.is_empty(), "{:?}", t.illegal);
        assert_eq!(t.position(), 9 - 4);
        assert_eq!(t.power, [(0, true), (10, false), (11, true)]);
        assert!(t.energised());
    }

    #[test]
    fn jumps_and_foreign_states_are_illegal() {
        let t = decode(&[pattern(0), pattern(2)]);
        assert_eq!(t.illegal, [(1, pattern(0), pattern(2))]);
        let t = decode(&[pattern(0), 0b0101]);
        assert_eq!(t.illegal.len(), 1);
        // Back on one half-step further than it went off: a lost step.
        let t = decode(&[pattern(3), 0, pattern(4)]);
        assert_eq!(t.illegal, [(2, 0, pattern(4))]);
    }
}
