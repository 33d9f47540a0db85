//! Drilling every nail's hole, in order: the tool is raised 1 cm above the
//! surface, the base and the carriage move together to the nail, the drill
//! plunges 1 cm deep along its tilted axis, dwells and retracts. The base
//! and the carriage only move while the drill is raised. After the last
//! hole the tool goes back to nail 0's angle at the board's edge (the zero
//! pose) and the drivers are switched off.

use super::{
    MachineStep, DRILL_ANGLE_DEG, DRILL_CLEARANCE_MM, DWELL_MS, HOLE_DEPTH_MM, MACHINE_DRIVERS,
    SIDEWAYS_CLEARANCE_MM,
};
use crate::axis::{Axis, AXES};
use crate::config::MachineConfig;
use crate::fmath;
use crate::geometry::{Board, StepScale};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage {
    Raise,
    Approach,
    Plunge,
    Dwell,
    Retract,
    Home,
    Off,
    Done,
}

/// The drilling sequence, from the zero pose (base 0 = nail 0's angle,
/// tool at the board's edge, tip on the surface).
pub struct Drilling {
    board: Board,
    scale: StepScale,
    /// Drill positions 1 cm above the surface and 1 cm deep, steps.
    raised: i32,
    plunged: i32,
    nail: u16,
    base: i32,
    stage: Stage,
}

/// The drill's positions of [`Drilling::blended`], steps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Depths {
    raised: i32,
    plunged: i32,
}

impl Depths {
    pub fn blended(config: &MachineConfig) -> Self {
        Depths {
            raised: -tool_axis_steps(config, SIDEWAYS_CLEARANCE_MM),
            plunged: tool_axis_steps(config, HOLE_DEPTH_MM),
        }
    }
}

/// Drill steps for a vertical distance, along the tilted axis: rounded once.
fn tool_axis_steps(config: &MachineConfig, vertical_mm: f32) -> i32 {
    let along = vertical_mm / fmath::sin_cos(DRILL_ANGLE_DEG.to_radians()).0;
    libm::roundf(along * config.axes[Axis::Drill.index()].steps_per_unit.as_f32()) as i32
}

impl Drilling {
    pub fn new(board: Board, config: &MachineConfig) -> Self {
        Drilling {
            board,
            scale: StepScale::from_config(config),
            raised: -tool_axis_steps(config, DRILL_CLEARANCE_MM),
            plunged: tool_axis_steps(config, HOLE_DEPTH_MM),
            nail: 0,
            base: 0,
            stage: Stage::Raise,
        }
    }

    /// Drilling as the firmware runs it: the tool crosses from hole to
    /// hole [`SIDEWAYS_CLEARANCE_MM`] above the surface, so the retract
    /// and the next plunge each end as soon as the tip is clear of it.
    pub fn blended(board: Board, config: &MachineConfig) -> Self {
        Self::on(
            board,
            StepScale::from_config(config),
            Depths::blended(config),
        )
    }

    /// Drilling `board` with the figures kept apart (the job keeps a
    /// board and its scale once, not in each phase's planner too).
    pub fn on(board: Board, scale: StepScale, depths: Depths) -> Self {
        Drilling {
            board,
            scale,
            raised: depths.raised,
            plunged: depths.plunged,
            nail: 0,
            base: 0,
            stage: Stage::Raise,
        }
    }

    /// After a power cut: the drill raised first, then on from hole
    /// `hole` (the one being drilled, or the next).
    pub fn from_hole(mut self, hole: u16) -> Self {
        self.nail = hole.min(self.board.nails());
        self
    }

    /// Base and carriage together over nail `i`, the shorter way round.
    fn over_nail(&mut self, i: u16) -> MachineStep {
        let nail = self.board.nail(i);
        self.base = self.scale.shorter_rotation(self.base, nail.angle);
        let mut t = [None; AXES];
        t[Axis::Base.index()] = Some(self.base);
        t[Axis::Radial.index()] = Some(self.scale.radial_steps(&self.board, nail.radius));
        MachineStep::Move(t)
    }
}

impl Drilling {
    /// After the last hole: back to nail 0's angle with the tool at the
    /// board's edge (the zero pose), clear of the nails about to go in.
    fn home(&mut self) -> MachineStep {
        self.base = self
            .scale
            .shorter_rotation(self.base, self.board.nail(0).angle);
        let mut t = [None; AXES];
        t[Axis::Base.index()] = Some(self.base);
        t[Axis::Radial.index()] = Some(0);
        MachineStep::Move(t)
    }
}

impl Iterator for Drilling {
    type Item = MachineStep;

    fn next(&mut self) -> Option<MachineStep> {
        let (step, next) = match self.stage {
            Stage::Raise => {
                // A resumed drilling may have no hole left: home at once.
                let next = if self.nail < self.board.nails() {
                    Stage::Approach
                } else {
                    Stage::Home
                };
                (MachineStep::to(Axis::Drill, self.raised), next)
            }
            Stage::Approach => (self.over_nail(self.nail), Stage::Plunge),
            Stage::Plunge => (MachineStep::to(Axis::Drill, self.plunged), Stage::Dwell),
            Stage::Dwell => (MachineStep::Dwell(DWELL_MS), Stage::Retract),
            Stage::Retract => {
                self.nail += 1;
                let next = if self.nail < self.board.nails() {
                    Stage::Approach
                } else {
                    Stage::Home
                };
                (MachineStep::to(Axis::Drill, self.raised), next)
            }
            Stage::Home => (self.home(), Stage::Off),
            Stage::Off => (
                MachineStep::Drivers {
                    mask: MACHINE_DRIVERS,
                    on: false,
                },
                Stage::Done,
            ),
            Stage::Done => return None,
        };
        self.stage = next;
        Some(step)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::units::Milli;
    use std::vec::Vec;

    fn mv(base: i32, radial: i32) -> MachineStep {
        MachineStep::Move([Some(base), Some(radial), None])
    }

    #[test]
    fn hexagon_of_24_nails_exactly() {
        let board = Board::new(6, 24, Milli(402_000)).unwrap();
        let steps: Vec<MachineStep> = Drilling::new(board, &MachineConfig::STRING_ART).collect();
        // 10 mm / sin(74.333°) = 10.386 mm = 1384.8 drill steps.
        let (up, down) = (
            MachineStep::to(Axis::Drill, -1385),
            MachineStep::to(Axis::Drill, 1385),
        );
        assert_eq!(steps.len(), 1 + 24 * 4 + 2);
        assert_eq!(steps[0], up);
        // Nail 0: vertex at 0°, 387 mm = 15 mm inside the edge = −480 steps.
        assert_eq!(
            steps[1..5],
            [mv(0, -480), down, MachineStep::Dwell(250), up]
        );
        // Nail 1: 13.898°, 348.837 mm → 371 base, −1701 radial steps.
        assert_eq!(steps[5], mv(371, -1701));
        // Nail 2: the edge's midpoint, 30°, 335.152 mm.
        assert_eq!(steps[9], mv(800, -2139));
        // Nail 23 (346.1°): the base keeps turning forwards, past 9229.
        assert_eq!(steps[1 + 23 * 4], mv(9229, -1701));
        // Back to nail 0's angle the short way (a full turn on), tool at the
        // board's edge, then off.
        assert_eq!(
            steps[97..],
            [
                mv(9600, 0),
                MachineStep::Drivers {
                    mask: 0b111,
                    on: false
                }
            ]
        );
    }

    #[test]
    fn base_and_carriage_move_only_with_the_drill_raised() {
        let board = Board::new(0, 250, Milli(402_000)).unwrap();
        let c = MachineConfig::STRING_ART;
        // Blended: raised only 2 mm, 277 steps along the tilted axis.
        for (drilling, raised) in [
            (Drilling::new(board, &c), -1385),
            (Drilling::blended(board, &c), -277),
        ] {
            sideways_only_above_the_surface(drilling, raised);
        }
    }

    /// No step of the base or the carriage below the surface (the drill
    /// never moves in the same block as they do, so checking each move's
    /// start is checking each of its steps); a hole at every nail.
    fn sideways_only_above_the_surface(drilling: Drilling, raised: i32) {
        let mut drill = 0;
        let mut holes = Vec::new();
        let mut base = 0;
        for step in drilling {
            if let MachineStep::Move(t) = step {
                if t[0].is_some() || t[1].is_some() {
                    assert!(t[2].is_none(), "{step:?}");
                    assert_eq!(drill, raised, "{step:?} with the drill at {drill}");
                }
                base = t[0].unwrap_or(base);
                if let Some(d) = t[2] {
                    if d > 0 {
                        holes.push(base);
                    }
                    drill = d;
                }
            }
        }
        // One hole per nail, at 38.4 steps per nail rounded once.
        let expect: Vec<i32> = (0..250).map(|i| (i * 9600 * 2 + 250) / 500).collect();
        assert_eq!(holes, expect);
    }
}
