//! The string-art job read from the pulse trace: holes, the drill's
//! stillness below the surface, the needle's crossings of the ring of nails
//! and the nails wrapped.
//!
//! Frame: base position b steps puts the board's angle θ = 2π·b/turn under
//! the tool (base 0 = nail 0 under it); the tool is at radius
//! R + radial/steps_per_mm on the board (radial 0 = the board's edge,
//! positive outwards); the drill is below the surface when its position is
//! above 0 (0 = tip on the surface, positive = down).

use super::{Ring, StepEvent, Trace};
use crate::vcd::Signal;
use taut_logic::axis::Axis;
use taut_logic::config::MachineConfig;
use taut_logic::geometry::{Board, StepScale};

/// Closer than this to the ring (mm), the needle is on it, on neither side.
const ON_RING_MM: f64 = 1e-3;

/// The drill went below the surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plunge {
    pub at_ns: u64,
    /// Base and radial positions at that moment, steps.
    pub base: i64,
    pub radial: i64,
}

/// A base or radial step while the drill was below the surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StrayStep {
    pub at_ns: u64,
    pub axis: Axis,
    /// The axis's position after the step, and the drill's, steps.
    pub pos: i64,
    pub drill: i64,
}

/// Which way the needle crossed the ring.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    Out,
    In,
}

/// The needle crossed the ring of nails.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crossing {
    /// When the needle was first on the other side.
    pub at_ns: u64,
    pub direction: Direction,
    /// Base and radial positions then, steps.
    pub base: i64,
    pub radial: i64,
    /// The base angle, radians in [0, 2π).
    pub angle: f64,
    /// `Some(i)`: in the gap after nail i, more than a base step from any
    /// nail; `None`: at a nail.
    pub gap: Option<u16>,
}

/// A nail wrapped: out across the ring, round, back in.
#[derive(Clone, Debug, PartialEq)]
pub struct Wrap {
    pub out: Crossing,
    pub back: Crossing,
    /// The nails between the two crossings on the rotation (one, normally).
    pub nails: Vec<u16>,
}

/// Which side of the ring the needle is on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Side {
    Inside,
    On,
    Outside,
}

/// The job on `board`, from a [`Trace`].
pub struct JobReplay {
    pub trace: Trace,
    pub board: Board,
    pub ring: Ring,
    radial_steps_per_mm: f64,
    events: Vec<StepEvent>,
    /// Crossings and wraps are looked for in this window, ns.
    winding: (u64, u64),
}

impl JobReplay {
    /// Winding is taken to start at the second press of green (the first
    /// starts drilling) and to last to the end of the trace; without a
    /// second press, the whole trace is searched. See [`Self::set_winding`].
    pub fn new(trace: Trace, board: Board, config: &MachineConfig) -> JobReplay {
        let scale = StepScale::from_config(config);
        let start = trace.presses("confirm").get(1).copied().unwrap_or(0);
        JobReplay {
            winding: (start, trace.end_ns),
            events: trace.events(),
            ring: Ring::new(&board, scale.steps_per_turn),
            radial_steps_per_mm: f64::from(scale.radial.as_f32()),
            trace,
            board,
        }
    }

    pub fn from_signals(
        signals: &[Signal],
        board: Board,
        config: &MachineConfig,
    ) -> Result<JobReplay, String> {
        Ok(Self::new(
            Trace::from_signals(signals, config)?,
            board,
            config,
        ))
    }

    /// Look for crossings between `from` and `to` (ns) only.
    pub fn set_winding(&mut self, from: u64, to: u64) {
        self.winding = (from, to);
    }

    pub fn winding(&self) -> (u64, u64) {
        self.winding
    }

    /// Every step in time order.
    pub fn events(&self) -> &[StepEvent] {
        &self.events
    }

    /// The tool's distance from the board's centre at radial position
    /// `radial`, mm.
    pub fn tool_radius(&self, radial: i64) -> f64 {
        f64::from(self.board.radius()) + radial as f64 / self.radial_steps_per_mm
    }

    /// The tool's point on the board (mm, x towards nail 0, CCW).
    pub fn tool_xy(&self, base: i64, radial: i64) -> (f64, f64) {
        let (a, r) = (self.ring.angle(base), self.tool_radius(radial));
        (r * a.cos(), r * a.sin())
    }

    /// Runs through the steps with the positions after each, `(time, [base,
    /// radial, drill], index of the axis that stepped)`.
    fn walk(&self, mut visit: impl FnMut(&StepEvent, &[i64; 3])) {
        let mut pos = [0i64; 3];
        for e in &self.events {
            pos[e.axis] = e.pos;
            visit(e, &pos);
        }
    }

    /// Each time the drill went below the surface, in order.
    pub fn plunges(&self) -> Vec<Plunge> {
        let mut out = Vec::new();
        let mut drill = 0;
        self.walk(|e, pos| {
            if e.axis == 2 {
                if drill <= 0 && e.pos > 0 {
                    out.push(Plunge {
                        at_ns: e.at_ns,
                        base: pos[0],
                        radial: pos[1],
                    });
                }
                drill = e.pos;
            }
        });
        out
    }

    /// Base and radial steps made while the drill was below the surface
    /// (there must be none).
    pub fn moves_while_plunged(&self) -> Vec<StrayStep> {
        let mut out = Vec::new();
        self.walk(|e, pos| {
            if e.axis != 2 && pos[2] > 0 {
                out.push(StrayStep {
                    at_ns: e.at_ns,
                    axis: super::MACHINE_AXES[e.axis],
                    pos: e.pos,
                    drill: pos[2],
                });
            }
        });
        out
    }

    fn side(&self, base: i64, radial: i64) -> Side {
        let d = self.tool_radius(radial) - self.ring.radius_at(self.ring.angle(base));
        if d > ON_RING_MM {
            Side::Outside
        } else if d < -ON_RING_MM {
            Side::Inside
        } else {
            Side::On
        }
    }

    /// The needle's crossings of the ring while winding.
    pub fn crossings(&self) -> Vec<Crossing> {
        self.crossings_between(self.winding.0, self.winding.1)
    }

    /// The needle's crossings of the ring between `from` and `to` (ns): a
    /// change from inside to outside or back (moments on the ring itself
    /// belong to neither side). Steps at the same instant count together.
    pub fn crossings_between(&self, from: u64, to: u64) -> Vec<Crossing> {
        let t = &self.trace;
        let mut base = t.position(Axis::Base, from);
        let mut radial = t.position(Axis::Radial, from);
        let mut side = self.side(base, radial);
        let mut out = Vec::new();
        let first = self.events.partition_point(|e| e.at_ns <= from);
        let window = self.events[first..].iter().take_while(|e| e.at_ns <= to);
        let mut iter = window.filter(|e| e.axis < 2).peekable();
        while let Some(e) = iter.next() {
            match e.axis {
                0 => base = e.pos,
                _ => radial = e.pos,
            }
            if iter.peek().is_some_and(|n| n.at_ns == e.at_ns) {
                continue; // the rest of this instant first
            }
            let now = self.side(base, radial);
            if now != Side::On {
                if side != Side::On && now != side {
                    out.push(Crossing {
                        at_ns: e.at_ns,
                        direction: if now == Side::Outside {
                            Direction::Out
                        } else {
                            Direction::In
                        },
                        base,
                        radial,
                        angle: self.ring.angle(base),
                        gap: self.ring.gap_at(base),
                    });
                }
                side = now;
            }
        }
        out
    }

    /// The wraps while winding: each outward crossing with the inward one
    /// that follows it (an inward crossing with none before it, such as
    /// the entry's, wraps nothing).
    pub fn wraps(&self) -> Vec<Wrap> {
        let mut out = Vec::new();
        let mut pending: Option<Crossing> = None;
        for c in self.crossings() {
            match (c.direction, pending.take()) {
                (Direction::Out, _) => pending = Some(c),
                (Direction::In, Some(o)) => out.push(Wrap {
                    nails: self.ring.nails_between(o.base, c.base),
                    out: o,
                    back: c,
                }),
                (Direction::In, None) => {}
            }
        }
        out
    }

    /// The nails wrapped, in order.
    pub fn wrapped_nails(&self) -> Vec<u16> {
        self.wraps().into_iter().flat_map(|w| w.nails).collect()
    }

    /// The needle's closest approach to a nail while winding: the
    /// distance between their axes (mm), when (ns), and the nail. Checked
    /// at every step, the position replayed from the pulses, so a blended
    /// path that crosses the ring mid-move is judged where it crosses.
    pub fn closest_to_nails(&self) -> (f64, u64, u16) {
        let (from, to) = self.winding;
        let t = &self.trace;
        let mut at = [t.position(Axis::Base, from), t.position(Axis::Radial, from)];
        let nails: Vec<(f64, f64)> = (0..self.ring.nails())
            .map(|i| self.ring.nail_xy(i))
            .collect();
        let mut best = (f64::INFINITY, from, 0);
        let first = self.events.partition_point(|e| e.at_ns <= from);
        let window = self.events[first..].iter().take_while(|e| e.at_ns <= to);
        for e in window.filter(|e| e.axis < 2) {
            at[e.axis] = e.pos;
            let (x, y) = self.tool_xy(at[0], at[1]);
            for (i, &(nx, ny)) in nails.iter().enumerate() {
                let d = (x - nx).hypot(y - ny);
                if d < best.0 {
                    best = (d, e.at_ns, i as u16);
                }
            }
        }
        best
    }

    /// The crossings while winding that were not inside a gap.
    pub fn crossings_outside_gaps(&self) -> Vec<Crossing> {
        self.crossings()
            .into_iter()
            .filter(|c| c.gap.is_none())
            .collect()
    }
}
