//! The planners checked against the machine's rules by replaying their
//! steps, and the hexagon pattern's exact sequence.

use super::*;
use crate::axis::Axis;
use crate::config::MachineConfig;
use crate::geometry::{Board, StepScale};
use crate::units::Milli;
use proptest::prelude::*;
use std::vec::Vec;

const R: Milli = Milli(402_000);

fn wind(board: Board, pattern: &[u16]) -> Vec<MachineStep> {
    let winder = Winder::new(board, &MachineConfig::STRING_ART).unwrap();
    Winding::new(winder, pattern.iter().copied())
        .map(Result::unwrap)
        .collect()
}

#[test]
fn hexagon_of_24_nails_wound_exactly() {
    let board = Board::new(6, 24, R).unwrap();
    let steps = wind(board, &[0, 7, 13, 23, 2]);
    let (base, radial) = (
        |t| MachineStep::to(Axis::Base, t),
        |t| MachineStep::to(Axis::Radial, t),
    );
    // Inner: 335.152 − 20 mm = 86.848 mm inside the edge = −2779 steps.
    // Outer of a vertex nail: 387 + 29 = 416 mm = +448 steps; of nails 7,
    // 13, 23 (348.837 mm): −773; of nail 2 (335.152 mm): −1211.
    let mut expect = std::vec![
        MachineStep::Drivers {
            mask: 0b100,
            on: false
        },
        base(185), // half a nail: the gap after nail 0, 6.949°
        radial(-2779),
        base(0),
    ];
    for wrap in [
        [-185, 448, 185],   // nail 0 between its gaps at 353.051° and 6.949°
        [2615, -773, 3015], // nail 7: gaps 98.051° and 113.051°
        [4985, -773, 5385], // nail 13, entered from its gap before
        [9015, -773, 9415],
        [10185, -1211, 10615], // nail 2, forwards across the seam
    ] {
        expect.extend([base(wrap[0]), radial(wrap[1]), base(wrap[2]), radial(-2779)]);
    }
    expect.push(MachineStep::Drivers {
        mask: 0b111,
        on: false,
    });
    assert_eq!(steps, expect);
}

#[test]
fn nail_past_the_last_is_an_error() {
    let board = Board::new(0, 250, R).unwrap();
    let winder = Winder::new(board, &MachineConfig::STRING_ART).unwrap();
    let out: Vec<_> = Winding::new(winder, [3u16, 251, 4].into_iter()).collect();
    assert_eq!(out.len(), 4 + 4 + 1);
    assert_eq!(out[8], Err(WindError::BadNail(251)));
    let tiny = Board::new(3, 30, Milli(50_000)).unwrap(); // (35·½ − 20) mm < 0
    assert!(matches!(
        Winder::new(tiny, &MachineConfig::STRING_ART),
        Err(WindError::BoardTooSmall)
    ));
}

/// The machine's state while replaying steps.
struct Replay {
    board: Board,
    scale: StepScale,
    pos: [i32; AXES],
    /// The nails passed over from outside the ring, in order.
    wrapped: Vec<u16>,
}

impl Replay {
    fn new(board: Board) -> Self {
        let scale = StepScale::from_config(&MachineConfig::STRING_ART);
        Replay {
            board,
            scale,
            pos: [0; AXES],
            wrapped: Vec::new(),
        }
    }

    fn radius_mm(&self) -> f32 {
        self.board.radius() + self.pos[1] as f32 / 32.0
    }

    /// Nails whose angle lies strictly between two absolute base positions.
    fn swept(&self, a: i32, b: i32) -> Vec<u16> {
        let (lo, hi) = (a.min(b), a.max(b));
        (0..self.board.nails())
            .filter(|&k| {
                let s = self.scale.base_steps(self.board.nail(k).angle);
                let first = s + (lo - s).div_euclid(9600) * 9600 + 9600; // > lo
                let first = if first - 9600 > lo {
                    first - 9600
                } else {
                    first
                };
                first < hi
            })
            .collect()
    }

    fn is_gap(&self, base: i32) -> bool {
        let b = base.rem_euclid(9600);
        (0..self.board.nails()).any(|k| self.scale.base_steps(self.board.gap_after(k)) == b)
    }

    fn apply(&mut self, step: &MachineStep) -> Result<(), TestCaseError> {
        let MachineStep::Move(t) = step else {
            return Ok(());
        };
        prop_assert!(t[2].is_none(), "the needle's height never changes");
        if let Some(b) = t[0] {
            prop_assert!(t[1].is_none(), "turning and moving radially at once");
            let rho = self.radius_mm();
            let swept = self.swept(self.pos[0], b);
            for &k in &swept {
                let r = self.board.nail(k).radius;
                prop_assert!(
                    rho < r - 10.0 || rho > r + 10.0,
                    "sweeping nail {} at {} mm",
                    k,
                    rho
                );
            }
            if rho > self.board.min_nail_radius() {
                // Beyond the ring: passing over nails wraps them.
                self.wrapped.extend(&swept);
            }
            self.pos[0] = b;
        }
        if let Some(r) = t[1] {
            let (a, b) = (self.pos[1].min(r), self.pos[1].max(r));
            let band = [
                self.scale
                    .radial_steps(&self.board, self.board.min_nail_radius()),
                self.scale
                    .radial_steps(&self.board, self.board.radius() - 15.0),
            ];
            if a < band[1] && b > band[0] {
                prop_assert!(
                    self.is_gap(self.pos[0]),
                    "crossing the ring at base {}",
                    self.pos[0]
                );
            }
            self.pos[1] = r;
        }
        Ok(())
    }
}

proptest! {
    /// Whatever the board and pattern: base moves keep 1 cm clear of every
    /// nail they pass, the ring is crossed only at gap angles, and the nails
    /// passed over from outside are exactly the pattern, last one included.
    #[test]
    fn every_connection_is_wrapped_and_no_nail_is_hit(
        shape in prop_oneof![Just(0u16), 3u16..9],
        nails in 8u16..300,
        radius in 150_000i32..500_000,
        pattern in prop::collection::vec(any::<u16>(), 1..40),
    ) {
        let board = Board::new(shape, nails, Milli(radius)).unwrap();
        let pattern: Vec<u16> = pattern.iter().map(|j| j % nails).collect();
        let mut replay = Replay::new(board);
        // The entry move starts outside nail 0 and passes nothing.
        let steps = wind(board, &pattern);
        for step in &steps[1..4] {
            replay.apply(step)?;
        }
        prop_assert!(replay.wrapped.is_empty());
        for step in &steps[4..] {
            replay.apply(step)?;
        }
        prop_assert_eq!(&replay.wrapped, &pattern);
        prop_assert_eq!(steps.last(), Some(&MachineStep::Drivers { mask: MACHINE_DRIVERS, on: false }));
    }
}

#[test]
fn trapezoid_times_by_hand() {
    let c = MachineConfig::STRING_ART;
    // 2000 steps never reach 2000 steps/s: 2·√(2000/500) = 4 s. 10 000
    // steps: 5 s at full rate + 4 s of ramps = 9 s.
    let steps = [
        MachineStep::Move([Some(10_000), Some(2000), None]),
        MachineStep::Dwell(250),
        MachineStep::to(Axis::Base, 12_000),
    ];
    assert!((machine_time(steps, &c, Overlap::Together) - (9.0 + 0.25 + 4.0)).abs() < 1e-9);
    assert!((machine_time(steps, &c, Overlap::Sequential) - (9.0 + 4.0 + 0.25 + 4.0)).abs() < 1e-9);
}

#[test]
fn moving_together_saves_time_when_drilling() {
    let c = MachineConfig::STRING_ART;
    let board = Board::new(6, 24, R).unwrap();
    let together = machine_time(Drilling::new(board, &c), &c, Overlap::Together);
    let sequential = machine_time(Drilling::new(board, &c), &c, Overlap::Sequential);
    // Approaching nails 1..=23 the base and the carriage both move, as does
    // the final return over nail 0.
    assert!(together < sequential - 5.0, "{together} vs {sequential}");
    // Winding moves one axis at a time: no overlap to gain.
    let w = wind(board, &[0, 7, 13, 23, 2]);
    let (t, s) = (
        machine_time(w.iter().copied(), &c, Overlap::Together),
        machine_time(w.iter().copied(), &c, Overlap::Sequential),
    );
    assert!((t - s).abs() < 1e-9 && t > 0.0);
}
