//! Blended winding replayed step by step as the step interrupt makes the
//! steps (the DDA of `segment::expand`): the needle keeps its clearance
//! from every nail at every step, and the nails it passes beyond are the
//! pattern's.

use super::*;
use crate::config::WindingConfig;
use crate::stringart::clearance::Clearance;
use crate::stringart::Winding;
use crate::units::Milli;
use proptest::prelude::*;
use std::vec::Vec;

const CONFIG: MachineConfig = MachineConfig::STRING_ART;

/// The board's nails in mm, and the needle's replayed position.
pub(crate) struct Needle {
    board: Board,
    turn: f64,
    per_mm: f64,
    /// Angle, radius and (x, y) of each nail.
    nails: Vec<(f64, f64, f64, f64)>,
    pub pos: [i32; 2],
    /// Nails passed beyond their radius, in order.
    pub wrapped: Vec<u16>,
    /// The closest the needle came to a nail, mm.
    pub closest: f64,
}

impl Needle {
    pub fn new(board: Board) -> Self {
        let s = StepScale::from_config(&CONFIG);
        let nails = (0..board.nails())
            .map(|i| {
                let n = board.nail(i);
                let (a, r) = (f64::from(n.angle), f64::from(n.radius));
                (a, r, r * a.cos(), r * a.sin())
            })
            .collect();
        Needle {
            board,
            turn: f64::from(s.steps_per_turn),
            per_mm: f64::from(s.radial.as_f32()),
            nails,
            pos: [0, 0],
            wrapped: Vec::new(),
            closest: f64::INFINITY,
        }
    }

    fn polar(&self, pos: [i32; 2]) -> (f64, f64) {
        let a = f64::from(pos[0]) / self.turn * core::f64::consts::TAU;
        (
            a,
            f64::from(self.board.radius()) + f64::from(pos[1]) / self.per_mm,
        )
    }

    /// One event of the DDA: the needle at `pos`.
    fn visit(&mut self, pos: [i32; 2]) {
        let (a, r) = self.polar(pos);
        let (x, y) = (r * a.cos(), r * a.sin());
        for &(_, _, nx, ny) in &self.nails {
            self.closest = self.closest.min((x - nx).hypot(y - ny));
        }
        // A nail's angle passed, beyond its radius: wrapped.
        let (from, to) = (f64::from(self.pos[0]), f64::from(pos[0]));
        for (i, &(na, nr, _, _)) in self.nails.iter().enumerate() {
            let at = na / core::f64::consts::TAU * self.turn;
            let at = at + ((from.min(to) - at) / self.turn).ceil() * self.turn;
            // A nail on a whole step counts once, on reaching it.
            let passed = (from < at && at <= to) || (to <= at && at < from);
            if passed && r > nr {
                self.wrapped.push(i as u16);
            }
        }
        self.pos = pos;
    }

    /// A move replayed event by event, as `segment::expand` steps it.
    pub fn step_to(&mut self, target: [i32; 2]) {
        let d = [target[0] - self.pos[0], target[1] - self.pos[1]];
        let steps = d.map(|x| x.unsigned_abs());
        let events = steps[0].max(steps[1]);
        let mut counter = [events / 2; 2];
        let mut pos = self.pos;
        for _ in 0..events {
            for i in 0..2 {
                counter[i] += steps[i];
                if counter[i] >= events {
                    counter[i] -= events;
                    pos[i] += d[i].signum();
                }
            }
            self.visit(pos);
        }
        assert_eq!(pos, target);
    }

    pub fn apply(&mut self, step: &MachineStep) {
        if let MachineStep::Move(t) = step {
            assert!(t[2].is_none(), "the needle's height never changes");
            self.step_to([t[0].unwrap_or(self.pos[0]), t[1].unwrap_or(self.pos[1])]);
        }
    }
}

fn blend(
    board: Board,
    config: &MachineConfig,
    pattern: &[u16],
) -> Result<Vec<MachineStep>, WindError> {
    let winder = BlendWinder::new(board, config)?;
    Winding::new(winder, pattern.iter().copied()).collect()
}

/// Whether the angles nails `g` and `g + 1` block (α = asin(c / r)
/// each side, `c` centre to centre) leave less than two base steps
/// between them.
fn too_close(board: &Board, g: u16, c: f32) -> bool {
    let (a, b) = (board.nail(g), board.nail((g + 1) % board.nails()));
    let apart = (f64::from(b.angle) - f64::from(a.angle)).rem_euclid(core::f64::consts::TAU);
    let alpha = |r: f32| (f64::from(c) / f64::from(r)).min(1.0).asin();
    let step = core::f64::consts::TAU / 9600.0;
    apart < alpha(a.radius) + alpha(b.radius) + 2.0 * step
}

proptest! {
    // Each case replays every step against every nail: fewer cases.
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Whatever the board and pattern: at every step the needle keeps its
    /// clearance from every nail (on a dense board, at least clear of the
    /// nails' bodies), and the nails it passes beyond are the pattern's,
    /// the last one included; or the nails stand too close for the
    /// needle, and the winder says so.
    #[test]
    fn every_step_clears_every_nail_and_wraps_the_pattern(
        shape in prop_oneof![Just(0u16), 3u16..9],
        nails in 3u16..300,
        radius in 150_000i32..500_000,
        pattern in prop::collection::vec(any::<u16>(), 1..30),
        // The default nail and needle half the time, else any (µm).
        diameters in prop_oneof![
            Just((1800u16, 1500u16)),
            (500u16..4000, 300u16..3000),
        ],
    ) {
        let board = Board::new(shape, nails, Milli(radius)).unwrap();
        let pattern: Vec<u16> = pattern.iter().map(|j| j % nails).collect();
        let config = MachineConfig {
            winding: WindingConfig { nail_um: diameters.0, needle_um: diameters.1 },
            ..CONFIG
        };
        let clearance = Clearance::of(&config);
        let steps = match blend(board, &config, &pattern) {
            Err(e) => {
                let WindError::GapTooNarrow(g) = e else {
                    return Err(TestCaseError::fail(std::format!("{e:?}")));
                };
                prop_assert!(too_close(&board, g, clearance.contact_mm), "gap {}", g);
                return Ok(());
            }
            Ok(steps) => steps,
        };
        let mut needle = Needle::new(board);
        for step in &steps {
            needle.apply(step);
        }
        let dense = (0..nails).any(|g| too_close(&board, g, clearance.mm));
        let c = if dense { clearance.contact_mm } else { clearance.mm };
        prop_assert!(needle.closest >= f64::from(c) - 1e-3, "{} mm", needle.closest);
        prop_assert_eq!(&needle.wrapped, &pattern);
        prop_assert_eq!(steps.last(), Some(&BlendWinder::new(board, &config).unwrap().finish()));
    }

    /// Absolute targets: a wrap a whole number of turns away is the same
    /// wrap, shifted by those turns, step for step.
    #[test]
    fn wraps_repeat_exactly_turns_apart(j in 0u16..250, turns in -50i32..50, at in 0i32..9600) {
        let board = Board::new(0, 250, Milli(402_000)).unwrap();
        let mut w = BlendWinder::new(board, &CONFIG).unwrap();
        w.base = at;
        let first: Vec<_> = w.wrap(j).unwrap().collect();
        w.base = at + turns * 9600;
        let shifted: Vec<_> = w.wrap(j).unwrap().collect();
        for (a, b) in first.iter().zip(&shifted) {
            let (MachineStep::Move(a), MachineStep::Move(b)) = (a, b) else { panic!() };
            prop_assert_eq!(a[0].unwrap() + turns * 9600, b[0].unwrap());
            prop_assert_eq!(a[1], b[1]);
        }
    }
}

#[test]
fn the_spec_circle_by_hand() {
    // 250 nails at 387 mm: 38.4 steps apart; c = 3.15 mm blocks
    // tan(asin(3.15/387)) = 0.008140 rad = 12.44 steps either side.
    let board = Board::new(0, 250, Milli(402_000)).unwrap();
    let mut w = BlendWinder::new(board, &CONFIG).unwrap();
    // 387 − 3.15 mm = 15 mm + 3.15 mm inside the edge: −580.8 → −581.
    assert_eq!(w.inner(), -581);
    let entry: Vec<_> = (0..4).map_while(|i| w.entry_step(None, i)).collect();
    // Gap after nail 0: steps 12.44 + 0.01 → 13 up to 38.4 − 12.44 → 25.
    assert_eq!(entry[1..], [MachineStep::to(Axis::Base, 13), to(25, -581)]);
    // Nail 10 at 384 steps, ahead: out through the window 359..=371 of the
    // gap before it, over it at 387 + 3.15 mm (−379.2 → −379), in
    // through 397..=409.
    // The rotation there (from 25) and the move over it go out in halves.
    let wrap = w.wrap(10).unwrap();
    assert_eq!(wrap.half_turn(25), Some(to(192, -581)));
    let wrap: Vec<_> = wrap.collect();
    assert_eq!(
        wrap,
        [
            to(359, -581),
            to(371, -379),
            to(384, -379),
            to(397, -379),
            to(409, -581)
        ]
    );
    // Nail 5 behind: mirrored, through the gap after it first.
    let back = w.wrap(5).unwrap();
    assert_eq!(back.half_turn(409), Some(to(313, -581)));
    let back: Vec<_> = back.collect();
    assert_eq!(
        back,
        [
            to(217, -581),
            to(205, -379),
            to(192, -379),
            to(179, -379),
            to(167, -581)
        ]
    );
}
