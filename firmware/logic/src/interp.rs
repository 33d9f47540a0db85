//! The G-code interpreter, Grbl's `gc_execute_line`: the modal state
//! (distance mode, motion mode, feed rate, the commanded position) and what
//! a parsed [`Line`] asks of the machine.
//!
//! Pure and two-step: [`Interpreter::plan`] checks a line against the modal
//! state, the machine's figures and what the machine allows now, and
//! returns the [`Order`] with the modal state it leaves; the caller carries
//! the order out and only then [`Interpreter::commit`]s. So a line that
//! fails — or waits for planner room and is planned again — changes no
//! modal state: `G91 G1 X1` without a feed rate is refused and leaves the
//! interpreter in `G90`/`G0` as it was.
//!
//! Arcs (`G2`/`G3`) are checked whole before anything moves — the end on
//! the circle, a radius that reaches, the whole path inside the soft limits
//! and the kinematics' reach — and handed over as an [`Arc`] whose chords
//! the caller queues one by one.

use crate::arc::{self, Arc, ArcError, Circle, Sweep};
use crate::config::MachineConfig;
use crate::gcode::{AxisWord, Command, Distance, ErrorKind, Line, Plane, Units, MIN_FEED};
use crate::kinematics::{KinError, Kinematics, Piece, Position, Segmenter, Steps};
use crate::planner::Feed;
use crate::units::Milli;

/// What a line asks of the machine.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Order {
    /// Nothing but modal state (`G91`, `F100`, a blank line).
    None,
    /// Move to these absolute motor steps.
    Move {
        steps: Steps,
        feed: Feed,
    },
    /// Move along these pieces (positions in G-code coordinates, each
    /// converted with [`Kinematics::inverse`], which cannot fail for them).
    Path {
        path: Path,
        feed: Feed,
    },
    /// Wait this long once motion is done.
    Dwell {
        ms: u32,
    },
    /// The pen servo to this angle, degrees, once motion is done; motion
    /// then waits `ms` for it to get there.
    Pen {
        deg: u8,
        ms: u16,
    },
    /// Hold once motion is done, until `~` or the green button (`M0`).
    Pause,
    /// Home these axes (bits) once motion is done.
    Home {
        axes: u8,
    },
    /// Take these steps as the position (once motion is done).
    SetPosition {
        steps: Steps,
    },
    /// Switch every driver on or off (off once motion is done).
    Drivers {
        on: bool,
    },
    /// Answer once motion is done.
    WaitIdle,
    ReportPosition,
}

/// A move cut into pieces: an arc's chords, or a straight move's pieces
/// on a machine whose kinematics are not linear.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Path {
    Arc(Arc),
    Line(Segmenter),
}

impl Iterator for Path {
    type Item = Position;

    /// The next piece's end.
    fn next(&mut self) -> Option<Position> {
        match self {
            Path::Arc(arc) => arc.next(),
            Path::Line(line) => line.next(),
        }
    }
}

impl Path {
    /// The next piece, its end converted with the kinematics. Out of
    /// line: one copy for the console and the estimate.
    #[inline(never)]
    pub fn next_piece(&mut self, kin: &impl Kinematics) -> Option<Result<Piece, KinError>> {
        let start = match self {
            Path::Arc(arc) => arc.start(),
            Path::Line(line) => line.start(),
        };
        let to = self.next()?;
        Some(kin.inverse_fine(&to).map(|(steps, frac)| Piece {
            start,
            to,
            steps,
            frac,
        }))
    }
}

/// What the machine allows the console now.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Allowed {
    /// No job owns the motion: moves, drivers and `G92` may run.
    pub motion: bool,
    /// The position is known (not lost by a stop at once during motion).
    pub position_known: bool,
}

/// The motion mode: what a line of bare axis words does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Motion {
    Rapid,
    Linear,
    ArcCw,
    ArcCcw,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Modal {
    distance: Distance,
    units: Units,
    motion: Motion,
    plane: Plane,
    feed: Option<Milli>,
    /// Commanded position in milli-units (G-code coordinates).
    target: Position,
}

/// The modal state as `$G` reports it: `[GC:` this `]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ParserState {
    motion: u8,
    plane: u8,
    units: u8,
    distance: u8,
    spindle: u8,
    /// Whole units per minute.
    feed: i32,
}

impl ufmt::uDisplay for ParserState {
    fn fmt<W: ufmt::uWrite + ?Sized>(
        &self,
        f: &mut ufmt::Formatter<'_, W>,
    ) -> Result<(), W::Error> {
        // The fixed words as flash text: literals would sit in the AVR's SRAM.
        ufmt::uwrite!(
            f,
            "G{}{}{}{}{}{}{}{}{}{}{}",
            self.motion,
            taut_progmem::text!(" G54 G"),
            self.plane,
            taut_progmem::text!(" G"),
            self.units,
            taut_progmem::text!(" G"),
            self.distance,
            taut_progmem::text!(" G94 M"),
            self.spindle,
            taut_progmem::text!(" M9 T0 F"),
            self.feed
        )?;
        ufmt::uwrite!(f, "{}", taut_progmem::text!(" S0"))
    }
}

/// A line checked and ready to carry out, with the modal state it leaves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Planned {
    pub order: Order,
    next: Modal,
}

pub struct Interpreter {
    modal: Modal,
}

impl Default for Interpreter {
    fn default() -> Self {
        Self::new()
    }
}

impl Interpreter {
    /// Grbl's power-on state: `G90 G0 G17`, no feed rate, at zero.
    pub const fn new() -> Self {
        Interpreter {
            modal: Modal {
                distance: Distance::Absolute,
                units: Units::Mm,
                motion: Motion::Rapid,
                plane: Plane::Xy,
                feed: None,
                target: [Milli::ZERO; crate::axis::AXES],
            },
        }
    }

    /// Grbl's `$G` report of the modal state, `pen_down` standing for the
    /// spindle: `G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0` (no work offsets,
    /// feed per minute, in the line's units).
    pub fn parser_state(&self, pen_down: bool) -> ParserState {
        let m = &self.modal;
        ParserState {
            motion: match m.motion {
                Motion::Rapid => 0,
                Motion::Linear => 1,
                Motion::ArcCw => 2,
                Motion::ArcCcw => 3,
            },
            plane: match m.plane {
                Plane::Xy => 17,
                Plane::Zx => 18,
                Plane::Yz => 19,
            },
            units: match m.units {
                Units::Inch => 20,
                Units::Mm => 21,
            },
            distance: match m.distance {
                Distance::Absolute => 90,
                Distance::Relative => 91,
            },
            spindle: if pen_down { 3 } else { 5 },
            // Kept in mm: whole units per minute of the line's unit.
            feed: m.feed.map_or(0, |f| match m.units {
                Units::Mm => f.0 / 1000,
                Units::Inch => f.0 / 25_400,
            }),
        }
    }

    /// The commanded position.
    pub fn target(&self) -> Position {
        self.modal.target
    }

    /// The machine was moved or stopped by someone else (a job, a stop
    /// that dropped queued moves): it is commanded where it is.
    pub fn resync(&mut self, target: Position) {
        self.modal.target = target;
    }

    /// Ctrl-X: the modal state back to its power-on values; the position
    /// stays.
    pub fn reset(&mut self) {
        let target = self.modal.target;
        *self = Interpreter::new();
        self.modal.target = target;
    }

    /// Check `line` and work out its order; the modal state is unchanged
    /// until [`Interpreter::commit`]. Never inlined: its temporaries (an
    /// arc's) stay out of the caller's frame on the AVR's small stack.
    #[inline(never)]
    pub fn plan(
        &self,
        line: &Line,
        kin: &impl Kinematics,
        cfg: &MachineConfig,
        allowed: Allowed,
    ) -> Result<Planned, ErrorKind> {
        let mut next = self.modal;
        let has_axes = line.has_axes();
        let moves = has_axes
            || matches!(
                line.command,
                Command::EnableDrivers
                    | Command::DisableDrivers
                    | Command::SetPosition
                    | Command::Home
            );
        if moves && !allowed.motion {
            return Err(ErrorKind::JobOwnsMotion);
        }
        // A word of no channel of this machine (`Y` on the string-art
        // machine) is refused as Grbl refuses a letter it does not know.
        let words = kin.words();
        if AxisWord::ALL
            .iter()
            .any(|w| line.axis(*w).is_some() && !words.contains(&w.letter()))
        {
            return Err(ErrorKind::UnsupportedCommand);
        }
        if let Some(u) = line.units {
            next.units = u;
        }
        let feed = line.f.get().map(|f| mm(f, next.units));
        if feed.is_some_and(|f| f.0 < MIN_FEED) {
            return Err(ErrorKind::FeedTooLow);
        }
        if let Some(d) = line.distance {
            next.distance = d;
        }
        if feed.is_some() {
            next.feed = feed;
        }
        let pen = !cfg.machine.is_string_art();
        if let Some(p) = line.plane {
            next.plane = p;
        }
        let order = match line.command {
            Command::Rapid
            | Command::Linear
            | Command::ArcCw
            | Command::ArcCcw
            | Command::Empty => {
                next.motion = match line.command {
                    Command::Rapid => Motion::Rapid,
                    Command::Linear => Motion::Linear,
                    Command::ArcCw => Motion::ArcCw,
                    Command::ArcCcw => Motion::ArcCcw,
                    _ => next.motion,
                };
                let arc = matches!(next.motion, Motion::ArcCw | Motion::ArcCcw);
                // `I J K R` only with an arc that moves (Grbl's error 36).
                if line.has_arc_words() && !(arc && has_axes) {
                    return Err(ErrorKind::UnusedValueWords);
                }
                if !has_axes {
                    return Ok(Planned {
                        order: Order::None,
                        next,
                    });
                }
                // A plotter's Z lifts (above 0) or lowers its pen and
                // drives no motor.
                if let Some(z) = line.axis(AxisWord::Z).filter(|_| pen) {
                    let alone = AxisWord::ALL
                        .iter()
                        .all(|w| *w == AxisWord::Z || line.axis(*w).is_none());
                    if !alone {
                        return Err(ErrorKind::PenWithMove);
                    }
                    let up = z.0 > 0;
                    return Ok(Planned {
                        order: pen_order(cfg, if up { cfg.pen.up_deg } else { cfg.pen.down_deg }),
                        next,
                    });
                }
                let feed = match (next.motion, next.feed) {
                    (Motion::Rapid, _) => Feed::Rapid,
                    (_, Some(f)) => Feed::PerMinute(f),
                    (_, None) => return Err(ErrorKind::UndefinedFeedRate),
                };
                if !allowed.position_known {
                    return Err(ErrorKind::Locked);
                }
                next.target = self.destination(line, kin, &next);
                check_travel(cfg, &next.target, &next.target)?;
                if arc {
                    return self.arc(line, kin, cfg, next, feed);
                }
                if !kin.is_linear() {
                    return self.pieces(feed, kin, next);
                }
                // Converted once from the absolute target: relative moves
                // never drift.
                let steps = kin
                    .inverse(&next.target)
                    .map_err(|_| ErrorKind::InvalidTarget)?;
                Order::Move { steps, feed }
            }
            // `P` is held in thousandths: of seconds, or of milliseconds.
            Command::Dwell => Order::Dwell {
                ms: line.p.get().map_or(0, |p| match cfg.dwell_p_ms {
                    true => (p.0.max(0) as u32 + 500) / 1000,
                    false => p.0.max(0) as u32,
                }),
            },
            Command::PenDown | Command::PenUp | Command::Servo if !pen => {
                return Err(ErrorKind::UnsupportedCommand)
            }
            Command::PenUp => pen_order(cfg, cfg.pen.up_deg),
            Command::PenDown | Command::Servo => {
                let deg = match line.s.get() {
                    Some(s) => (s.0.clamp(0, 180_000) / 1000) as u8,
                    None => cfg.pen.down_deg,
                };
                pen_order(cfg, deg)
            }
            Command::Pause => Order::Pause,
            Command::Home if cfg.homing.axes == 0 => return Err(ErrorKind::NoHoming),
            Command::Home => Order::Home {
                axes: cfg.homing.axes,
            },
            Command::SetPosition => {
                for (i, w) in kin.words().iter().enumerate() {
                    if let Some(v) = value(line, *w, next.units) {
                        next.target[i] = v;
                    }
                }
                let steps = kin
                    .inverse(&next.target)
                    .map_err(|_| ErrorKind::InvalidTarget)?;
                Order::SetPosition { steps }
            }
            Command::EnableDrivers => Order::Drivers { on: true },
            Command::DisableDrivers => Order::Drivers { on: false },
            Command::WaitIdle => Order::WaitIdle,
            Command::ReportPosition => Order::ReportPosition,
        };
        Ok(Planned { order, next })
    }

    /// A straight move cut into pieces, if the machine reaches every one.
    /// Out of line: its pieces stay off the stack of the other moves.
    #[inline(never)]
    fn pieces(&self, feed: Feed, kin: &impl Kinematics, next: Modal) -> Result<Planned, ErrorKind> {
        let line = Segmenter::new(kin, self.modal.target, &next.target, kin.piece_um());
        // Called for the machines that are not linear only.
        match kin.reaches_line(&line.start(), &line.end()) {
            true => Ok(Planned {
                order: Order::Path {
                    path: Path::Line(line),
                    feed,
                },
                next,
            }),
            false => Err(ErrorKind::InvalidTarget),
        }
    }

    /// The order of `planned` was carried out: take the modal state it
    /// leaves.
    pub fn commit(&mut self, planned: &Planned) {
        self.modal = planned.next;
    }

    /// A jog's (`$J=`, planned as the `G1` the parser made of it) was
    /// carried out: its `G20`/`G21`, `G90`/`G91` and feed were its own, so
    /// only the position is taken (Grbl's jogging.md).
    pub fn commit_jog(&mut self, planned: &Planned) {
        self.modal.target = planned.next.target;
    }

    /// The arc `line` asks for, from the commanded position to
    /// `next.target` in `next.plane`, checked whole. Out of line, and
    /// returning the whole order: the arc is built once, where the caller
    /// takes it (the AVR's stack is small).
    #[inline(never)]
    fn arc(
        &self,
        line: &Line,
        kin: &impl Kinematics,
        cfg: &MachineConfig,
        next: Modal,
        feed: Feed,
    ) -> Result<Planned, ErrorKind> {
        let [w0, w1, w2] = next.plane.axes();
        let index = |w: AxisWord| kin.words().iter().position(|l| *l == w.letter());
        let (Some(axis_0), Some(axis_1)) = (index(w0), index(w1)) else {
            return Err(ErrorKind::ArcNoAxisInPlane);
        };
        if line.axis(w0).is_none() && line.axis(w1).is_none() {
            return Err(ErrorKind::ArcNoAxisInPlane);
        }
        let plane = arc::Plane {
            axis_0,
            axis_1,
            linear: index(w2),
        };
        // Built in place: copies of the ends beside it would be 32 B more
        // under the arc's checks.
        let sweep = Sweep {
            start: self.modal.target,
            end: next.target,
            plane,
            clockwise: next.motion == Motion::ArcCw,
            tolerance: Milli(cfg.arc_tolerance_um.min(i32::MAX as u32) as i32),
        };
        let circle = match line.r.get().map(|r| mm(r, next.units)) {
            Some(_)
                if [axis_0, axis_1]
                    .iter()
                    .all(|&a| sweep.start[a] == sweep.end[a]) =>
            {
                return Err(ErrorKind::InvalidTarget);
            }
            Some(r) => Circle::from_radius(&sweep, r),
            None => {
                // `I J K` are the offsets along X Y Z.
                let offset = |w: AxisWord| {
                    let o = line.offsets[w.index() - AxisWord::X.index()].get();
                    o.map(|o| mm(o, next.units))
                };
                if offset(w0).is_none() && offset(w1).is_none() {
                    return Err(ErrorKind::ArcNoOffsetInPlane);
                }
                let o = [
                    offset(w0).unwrap_or(Milli::ZERO),
                    offset(w1).unwrap_or(Milli::ZERO),
                ];
                Circle::from_centre(&sweep, o)
            }
        }
        .map_err(|e| match e {
            ArcError::EndOffCircle => ErrorKind::InvalidTarget,
            ArcError::RadiusTooSmall => ErrorKind::ArcRadiusInvalid,
        })?;
        // One arc on this frame, checked in place, then moved out.
        let arc = Arc::new(&sweep, &circle);
        check_arc(&arc, kin, cfg)?;
        if !kin.is_linear() && !every_chord_reached(&arc, kin) {
            return Err(ErrorKind::InvalidTarget);
        }
        Ok(Planned {
            order: Order::Path {
                path: Path::Arc(arc),
                feed,
            },
            next,
        })
    }

    /// Where the axis words of `line` take the commanded position.
    fn destination(&self, line: &Line, kin: &impl Kinematics, next: &Modal) -> Position {
        let mut target = self.modal.target;
        for (i, w) in kin.words().iter().enumerate() {
            if let Some(v) = value(line, *w, next.units) {
                target[i] = match next.distance {
                    Distance::Absolute => v,
                    Distance::Relative => Milli(target[i].0.saturating_add(v.0)),
                };
            }
        }
        target
    }
}

/// Refuses an arc that leaves the soft limits or the machine's reach.
/// Out of line: the AVR's stack is small, the arc's caller deep.
#[inline(never)]
fn check_arc(arc: &Arc, kin: &impl Kinematics, cfg: &MachineConfig) -> Result<(), ErrorKind> {
    let (lo, hi) = arc.bounds();
    check_travel(cfg, &lo, &hi)?;
    // A linear kinematics reaches the whole box if it reaches its
    // corners; any other is asked for every chord end by the caller.
    let reached = !kin.is_linear() || (kin.inverse(&lo).is_ok() && kin.inverse(&hi).is_ok());
    match reached {
        true => Ok(()),
        false => Err(ErrorKind::InvalidTarget),
    }
}

/// Whether the machine reaches every chord of `arc`. Out of line: the
/// linear machines never need it.
#[inline(never)]
fn every_chord_reached(arc: &Arc, kin: &impl Kinematics) -> bool {
    let mut from = arc.start();
    arc.ends().all(|to| {
        let ok = kin.reaches_line(&from, &to);
        from = to;
        ok
    })
}

/// Refuses a path whose box `lo..=hi` leaves an axis's soft limits.
fn check_travel(cfg: &MachineConfig, lo: &Position, hi: &Position) -> Result<(), ErrorKind> {
    let outside = cfg.axes.iter().zip(lo.iter().zip(hi)).any(|(a, (l, h))| {
        let (min, max) = a.travel;
        a.soft_limits && (*l < min || *h > max)
    });
    match outside {
        true => Err(ErrorKind::TravelExceeded),
        false => Ok(()),
    }
}

/// The value of the axis word named `letter`, if the line has one, in mm
/// (or degrees: `C` is an angle in either unit).
fn value(line: &Line, letter: u8, units: Units) -> Option<Milli> {
    let v = AxisWord::ALL
        .iter()
        .find(|w| w.letter() == letter)
        .and_then(|w| line.axis(*w))?;
    Some(match letter {
        b'C' => v,
        _ => mm(v, units),
    })
}

/// A length in `units` as mm, rounded once.
fn mm(v: Milli, units: Units) -> Milli {
    match units {
        Units::Mm => v,
        Units::Inch => Milli(crate::units::div_round(v.0 as i64 * 254, 10) as i32),
    }
}

/// The pen to `deg`, then its settle time.
fn pen_order(cfg: &MachineConfig, deg: u8) -> Order {
    Order::Pen {
        deg,
        ms: cfg.pen.settle_ms,
    }
}

pub mod estimate;

#[cfg(test)]
mod tests;
