//! The G-code executor, Grbl's `gc_execute_line` after the words are
//! gathered: step 3 checks a [`Block`] against the modal state in
//! `gcode.c`'s order (`gcode.c` lines 347–845), step 4 takes the new state
//! and leaves the line's actions — pen, dwell, moves, program flow — in
//! its order (lines 846–1113), which [`Interpreter::run`] then carries
//! out against a [`MachineIo`], waiting where the machine must: for room
//! in the planner, for the motion before to end, for a dwell's time.
//! The firmware's console and the host's job-time estimate drive the same
//! executor, so there is one set of rules.
//!
//! A line is checked whole before anything happens: a refused line
//! changes neither the modal state nor the position. Positions are
//! machine coordinates kept exactly ([`Exact`]: the words as written,
//! added up), offsets the work coordinate systems `G54`–`G59` (kept by
//! the machine, [`MachineIo::coord`]), `G92` and `G43.1`; soft limits and
//! reach are checked on the machine position, so no offset moves the
//! travel. Steps are rounded once, from the absolute target.
//!
//! Where taut differs from Grbl, and why, is in `docs/console.md`.

pub mod coords;
pub mod estimate;
mod join;
mod raw;
mod run;
mod state;

#[cfg(test)]
mod tests;

pub use coords::{Exact, G28, G30};
pub use state::ParserState;

use crate::arc::{self, Arc, ArcError, Circle, Sweep};
use crate::axis::AXES;
use crate::config::MachineConfig;
use crate::gcode::{
    group, word, AxisCommand, AxisWord, Block, Distance, ErrorKind, FeedMode, Flow, MotionMode,
    NonModal, Plane, Spindle, TautCode, ToolLength, Units, MIN_FEED,
};
use crate::kinematics::{KinError, Kinematics, Piece, Position, Segmenter, Steps};
use crate::planner::Feed;
use crate::units::{div_round, Milli};

/// What the machine allows the console now.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Allowed {
    /// No job owns the motion: moves, drivers, offsets and the pen may
    /// change.
    pub motion: bool,
    /// `$C`: lines are checked and their state taken; nothing moves.
    pub checking: bool,
}

impl Allowed {
    /// Everything (the host's tools).
    pub const ALL: Allowed = Allowed {
        motion: true,
        checking: false,
    };
}

/// What a line's checks and actions need to know of the machine. Passed
/// by reference (the AVR backend garbles arguments passed on the stack).
pub struct Env<'a, K: Kinematics> {
    pub kin: &'a K,
    pub cfg: &'a MachineConfig,
    pub allowed: Allowed,
}

/// What the executor waits for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wait {
    /// Room in the planner, or the motion before to end (the app's
    /// `Signal::PlannerRoom`).
    PlannerRoom,
    /// The step queue to be refilled from the moves planned ahead:
    /// planning another now would take the time the refill needs.
    Refill,
    /// This many milliseconds (a dwell, the pen settling, pacing).
    Ms(u16),
    /// Nothing: a piece of a path was queued, the next comes at the
    /// next call (other tasks run between).
    Again,
}

/// How far [`Interpreter::run`] got.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Progress {
    /// The line's actions are all done or queued: answer `ok`.
    Done,
    Wait(Wait),
}

/// The machine the executor drives: the firmware's motion, pen and
/// drivers, or the host's planner and clock.
pub trait MachineIo {
    /// Grbl's coordinate data (`settings_read_coord_data`): `G54`…`G59`
    /// as 0…5, then [`G28`] and [`G30`]; machine coordinates.
    fn coord(&self, index: u8) -> Exact;
    /// Keeps coordinate data (`settings_write_coord_data`).
    fn set_coord(&mut self, index: u8, value: &Exact);
    /// Whether a move may be queued now (`piece`: one piece of a path):
    /// `None`, or what to wait for.
    fn room(&mut self, piece: bool) -> Option<Wait>;
    /// Where the moves queued end, in motor steps.
    fn steps(&self) -> Steps;
    /// Queue a move to the absolute motor `steps`; false when the planner
    /// is full.
    fn queue(&mut self, steps: &Steps, feed: Feed) -> bool;
    /// Queue a piece of a path on a machine whose kinematics are not
    /// linear: `feed` is the pen's speed along it (the planner's
    /// `stage_piece`). By default, its steps as [`MachineIo::queue`].
    fn queue_piece(&mut self, piece: &Piece, feed: Feed) -> bool {
        self.queue(&piece.steps, feed)
    }
    /// Every queued move is done.
    fn idle(&mut self) -> bool;
    /// The pen servo to `deg`; true if it moves (motion then waits for it
    /// to settle).
    fn pen(&mut self, deg: u8) -> bool;
    /// Every driver on or off.
    fn drivers(&mut self, on: bool);
    /// `M18 S`: the drivers go off `ms` after motion stands (0: never),
    /// instead of after `$1`, until `$1` changes or a reset.
    fn idle_delay(&mut self, ms: u32);
    /// `M0`: hold until `~` (or the green button).
    fn pause(&mut self);
    /// `M114`: the executed position.
    fn report_position(&mut self);
    /// `M2`/`M30` done: `[MSG:Pgm End]`.
    fn program_end(&mut self);
    /// A millisecond clock (wrapping).
    fn millis(&self) -> u32;
}

/// The modal state (Grbl's `gc_modal_t`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Modal {
    motion: MotionMode,
    plane: Plane,
    distance: Distance,
    feed_mode: FeedMode,
    units: Units,
    /// `G54`…`G59` as 0…5.
    coord: u8,
    spindle: Spindle,
    /// [`MIST`] and [`FLOOD`]: `M7`, `M8`, both, or none (`M9`).
    coolant: u8,
    tool_length: ToolLength,
}

const MIST: u8 = 1;
const FLOOD: u8 = 2;

impl Modal {
    /// Grbl's power-on modes: `G0 G54 G17 G21 G90 G94 M5 M9`.
    const fn new() -> Modal {
        Modal {
            motion: MotionMode::Seek,
            plane: Plane::Xy,
            distance: Distance::Absolute,
            feed_mode: FeedMode::PerMinute,
            units: Units::Mm,
            coord: 0,
            spindle: Spindle::Off,
            coolant: 0,
            tool_length: ToolLength::Cancel,
        }
    }
}

/// The actions of an accepted line still to do, in Grbl's order (bits
/// of [`Run::todo`]).
mod todo {
    /// The joined move before the line (`join`) queued first: the line
    /// does not join it, and waits for it or moves.
    pub const FLUSH: u16 = 1 << 0;
    /// The pen from `M3`/`M4`/`M5` or `M300` (Grbl's spindle, `[7]`).
    pub const PEN: u16 = 1 << 1;
    /// `M17`.
    pub const DRIVERS_ON: u16 = 1 << 2;
    /// `G4` (`[10]`).
    pub const DWELL: u16 = 1 << 3;
    /// A plotter's pen from a `Z` word, before the line's moves.
    pub const PEN_Z: u16 = 1 << 4;
    /// Straight moves to `legs[0]`, `legs[1]` (`[19]` `G28`/`G30`, `[20]`).
    pub const LEG_0: u16 = 1 << 5;
    pub const LEG_1: u16 = 1 << 6;
    /// The pieces of `path` (an arc, or a leg on a machine that is not
    /// linear).
    pub const PATH: u16 = 1 << 7;
    /// `M0` (`[21]`).
    pub const PAUSE: u16 = 1 << 8;
    /// `M2`, `M30` (`[21]`).
    pub const END: u16 = 1 << 9;
    /// `M18`, `M84`.
    pub const DRIVERS_OFF: u16 = 1 << 10;
    /// `M400`.
    pub const WAIT: u16 = 1 << 11;
    /// `M114`.
    pub const REPORT: u16 = 1 << 12;
    /// `M18 S`, `M84 S`.
    pub const IDLE_DELAY: u16 = 1 << 13;
}

/// An accepted line's actions.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Run {
    todo: u16,
    /// Angles of `PEN` and `PEN_Z`.
    pen: u8,
    pen_z: u8,
    dwell_ms: u32,
    /// `IDLE_DELAY`'s ms.
    idle_delay_ms: u32,
    /// Where the moves go (machine coordinates), and from where the next
    /// one starts.
    legs: [Exact; 2],
    from: Exact,
    feed: Feed,
    /// The line's path piece by piece: an arc (its last piece on the
    /// exact target of the last leg), or a straight leg's pieces.
    path: Option<Path>,
    /// Its one leg starts a joined move ([`join`]): it did when the line
    /// was accepted, or it may once the move joined before is queued.
    opens: bool,
}

impl Run {
    const fn new() -> Run {
        Run {
            todo: 0,
            pen: 0,
            pen_z: 0,
            dwell_ms: 0,
            idle_delay_ms: 0,
            legs: [[0; AXES]; 2],
            from: [0; AXES],
            feed: Feed::Rapid,
            path: None,
            opens: false,
        }
    }

    /// No actions, as [`Run::new`], written field by field: `*self =
    /// Run::new()` built a whole `Run` (171 B) on the AVR's stack first,
    /// in the frame under which every move is checked.
    fn clear(&mut self) {
        self.todo = 0;
        self.pen = 0;
        self.pen_z = 0;
        self.dwell_ms = 0;
        self.idle_delay_ms = 0;
        self.legs = [[0; AXES]; 2];
        self.from = [0; AXES];
        self.feed = Feed::Rapid;
        self.path = None;
        self.opens = false;
    }
}

/// A move cut into pieces: an arc's chords, or a straight move's pieces
/// on a machine whose kinematics are not linear; or a raw move to these
/// motor steps, one piece.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Path {
    Arc(Arc),
    Line(Segmenter),
    Steps(Steps),
}

impl Iterator for Path {
    type Item = Position;

    /// The next piece's end.
    fn next(&mut self) -> Option<Position> {
        match self {
            Path::Arc(arc) => arc.next(),
            Path::Line(line) => line.next(),
            Path::Steps(_) => None,
        }
    }
}

impl Path {
    /// The next piece for the planner on a machine whose kinematics are
    /// not linear: from the path's start, its end converted with the
    /// kinematics; the channels without a motor at 0 (`motors`). Out of
    /// line, the piece built whole in its frame: on the AVR a returned
    /// pair came back as garbage elsewhere.
    #[inline(never)]
    fn next_piece(&mut self, kin: &impl Kinematics, motors: u8) -> Option<Result<Piece, KinError>> {
        let start = match self {
            Path::Arc(arc) => arc.start(),
            Path::Line(line) => line.start(),
            Path::Steps(_) => return None,
        };
        let to = motor_only(&self.next()?, motors);
        Some(kin.inverse_fine(&to).map(|(steps, frac)| Piece {
            start: motor_only(&start, motors),
            to,
            steps,
            frac,
        }))
    }
}

/// Grbl's parser state (`gc_state`) and the line being carried out.
pub struct Interpreter {
    modal: Modal,
    /// mm (or degrees) per minute; in `G93` the line's 1 / minutes; 0:
    /// none yet.
    feed: Milli,
    /// `S`.
    speed: Milli,
    /// `T`.
    tool: u8,
    /// The programmed position, machine coordinates.
    position: Exact,
    /// The active work system's offset (`G54`…`G59`).
    coord_system: Exact,
    /// `G92`'s offset.
    coord_offset: Exact,
    /// `G43.1`'s offset of the `Z` channel.
    tlo: i64,
    run: Run,
    /// Tiny moves joined into one, not yet queued: it ends at `run.from`.
    join: Option<join::Join>,
    /// The end of a dwell or of the pen's settling.
    dwell_until: Option<u32>,
    /// The work offset changed since the status report last asked.
    wco_changed: bool,
    /// `M300 S255`: the unicorn extension's "servo off": `Z` words leave
    /// the pen alone until `M3`/`M4`/`M5` or `M300` gives it an angle.
    servo_off: bool,
    /// The pen's angle as the last line that set it left it (also in
    /// `$C`, where the pen does not move); 0: none set.
    pen_deg: u8,
}

impl Default for Interpreter {
    fn default() -> Self {
        Self::new()
    }
}

/// The channel the axis word `w` names on this machine.
fn channel(words: &[u8; AXES], w: AxisWord) -> Option<usize> {
    words.iter().position(|&l| l == w.letter())
}

/// The index of the `I J K` word of a plane axis `X Y Z`.
fn ijk(w: AxisWord) -> usize {
    w.index() - AxisWord::X.index()
}

/// `a + b` (or `a - b` with `sign` below 0), channel by channel. Out of
/// line: the channels' 64-bit sums are one loop, not one inlined per use.
#[inline(never)]
fn sum(a: &Exact, b: &Exact, sign: i8) -> Exact {
    core::array::from_fn(|i| if sign < 0 { a[i] - b[i] } else { a[i] + b[i] })
}

/// `new` on the channels in `mask` (bits), `old` on the others.
#[inline(never)]
fn pick(old: &Exact, new: &Exact, mask: u8) -> Exact {
    core::array::from_fn(|i| if mask >> i & 1 != 0 { new[i] } else { old[i] })
}

/// The channel of a plotter's pen (its `Z`), or of the string-art
/// machine's drill: where `G43.1` applies.
const Z: usize = 2;

/// A length in `units` as mm, rounded once (inches are exact to the
/// nanometre up to five decimals).
#[inline(never)]
fn mm_exact(v: i64, units: Units) -> i64 {
    match units {
        Units::Mm => v,
        Units::Inch => div_round(v.saturating_mul(254), 10),
    }
}

/// A feed or length in thousandths of `units` as thousandths of a mm.
#[inline(never)]
fn mm_milli(v: Milli, units: Units) -> Milli {
    match units {
        Units::Mm => v,
        Units::Inch => {
            Milli(div_round(v.0 as i64 * 254, 10).clamp(i32::MIN as i64, i32::MAX as i64) as i32)
        }
    }
}

impl Interpreter {
    /// Grbl's power-on state: `G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0`,
    /// at zero, no offsets; [`Interpreter::reset`] then loads `G54`.
    #[inline(always)]
    pub const fn new() -> Self {
        Interpreter {
            modal: Modal::new(),
            feed: Milli::ZERO,
            speed: Milli::ZERO,
            tool: 0,
            position: [0; AXES],
            coord_system: [0; AXES],
            coord_offset: [0; AXES],
            tlo: 0,
            run: Run::new(),
            join: None,
            dwell_until: None,
            wco_changed: true,
            servo_off: false,
            pen_deg: 0,
        }
    }

    /// Grbl's `gc_init` (power-on, Ctrl-X, leaving `$C`): the power-on
    /// modes, `G54`'s offset (`g54`, the coordinate data's first) loaded,
    /// `G92` and `G43.1` cleared, the line being carried out dropped; the
    /// position stays.
    pub fn reset(&mut self, g54: &Exact) {
        let position = self.position;
        *self = Interpreter::new();
        self.position = position;
        self.coord_system = *g54;
    }

    /// The programmed position (machine coordinates, thousandths).
    pub fn target(&self) -> Position {
        coords::milli(&self.position)
    }

    /// The programmed position, exactly.
    pub fn position(&self) -> Exact {
        self.position
    }

    /// The machine was moved or stopped by someone else (homing, a job, a
    /// stop that dropped queued moves): it is programmed where it stands,
    /// on the channels in `channels` (bits; a plotter's pen channel keeps
    /// its programmed `Z`). The line being carried out is dropped.
    pub fn resync(&mut self, at: &Position, channels: u8) {
        let at = coords::exact(at);
        for (i, p) in self.position.iter_mut().enumerate() {
            if channels >> i & 1 != 0 {
                *p = at[i];
            }
        }
        self.run.clear();
        self.join = None;
        self.dwell_until = None;
    }

    /// Going on with a print a cut stopped, its lines before read again
    /// without moving: the pen up (`up_deg`), then a rapid from where the
    /// machine stands (`at`) to the programmed position, the start of the
    /// line that was moving. Carried out by [`Interpreter::run`].
    pub fn travel_back(&mut self, at: &Position, up_deg: u8) {
        self.run.clear();
        self.join = None;
        self.run.pen = up_deg;
        self.run.from = coords::exact(at);
        self.run.legs[0] = self.position;
        self.run.todo = todo::PEN | todo::LEG_0;
    }

    /// Then the pen as the lines before left it (up if none set it).
    pub fn pen_back(&mut self, up_deg: u8) {
        self.run.clear();
        self.run.pen = self.pen_now(up_deg);
        self.run.todo = todo::PEN;
    }

    /// The pen as the lines taken so far left it (up if none set it).
    pub fn pen_now(&self, up_deg: u8) -> u8 {
        match self.pen_deg {
            0 => up_deg,
            deg => deg,
        }
    }

    /// The work coordinate offset of each channel (Grbl's `WCO`: the work
    /// system's, `G92`'s and the tool length's), thousandths.
    pub fn wco(&self) -> Position {
        let mut wco = [0; AXES];
        for (i, w) in wco.iter_mut().enumerate() {
            *w = self.coord_system[i] + self.coord_offset[i] + if i == Z { self.tlo } else { 0 };
        }
        coords::milli(&wco)
    }

    /// Whether the work offset changed since the last call (Grbl's
    /// `system_flag_wco_change`: the next status report carries `WCO:`).
    pub fn take_wco_changed(&mut self) -> bool {
        core::mem::take(&mut self.wco_changed)
    }

    /// `G92`'s offset and the tool length offset, for `$#`.
    pub fn offsets(&self) -> (Position, Milli) {
        let tlo = coords::milli(&[self.tlo, 0, 0])[0];
        (coords::milli(&self.coord_offset), tlo)
    }

    /// Whether the accepted line still has actions to carry out.
    pub fn busy(&self) -> bool {
        self.run.todo != 0
    }

    /// The accepted line's motion was dropped (a jog cancel, a pulled
    /// card): its other actions too.
    pub fn drop_line(&mut self) {
        self.run.clear();
        self.join = None;
        self.dwell_until = None;
    }

    /// Tiny moves are joined, not yet queued ([`join`]).
    pub fn joining(&self) -> bool {
        self.join.is_some()
    }

    /// The joined moves are queued at the next [`Interpreter::run`] (no
    /// line is carried out now): the input paused.
    pub fn flush_soon(&mut self) {
        if self.join.is_some() && self.run.todo == 0 {
            self.run.todo = todo::FLUSH;
        }
    }

    /// For a print's checkpoint, once a line is accepted: the blocks
    /// queued before its own (1: the joined moves before it), or `None`
    /// when it starts none (it joined the moves before, or it has no
    /// motion and they are not queued yet).
    pub fn blocks_before(&self) -> Option<u8> {
        let flush = self.run.todo & todo::FLUSH != 0;
        match (self.join.is_some(), flush, self.run.opens) {
            (false, _, _) => Some(0),
            (true, true, _) => Some(1),
            (true, false, true) => Some(0),
            (true, false, false) => None,
        }
    }

    /// Checks `block` (a jog's if `jog`) against the modal state in
    /// Grbl's order and, if it passes, takes the state it leaves and its
    /// actions (carried out by [`Interpreter::run`]). A refused line
    /// changes nothing. Never inlined: its temporaries (an arc's) stay
    /// out of the caller's frame on the AVR's small stack.
    #[inline(never)]
    pub fn accept<K: Kinematics>(
        &mut self,
        b: &Block,
        jog: bool,
        env: &Env<K>,
        io: &mut impl MachineIo,
    ) -> Result<(), ErrorKind> {
        let (kin, cfg) = (env.kin, env.cfg);
        let plotter = !cfg.machine.is_string_art();
        let names = kin.words();
        if !env.allowed.motion && moves(b) {
            return Err(ErrorKind::JobOwnsMotion);
        }
        // Marlin's `M17 X`/`M18 X` name the drivers to switch, not a move
        // (taut switches them all): refused, so the axis words move nothing.
        if b.has(group::TAUT)
            && matches!(b.taut, TautCode::EnableDrivers | TautCode::DisableDrivers)
            && b.has_axes()
        {
            return Err(ErrorKind::AxisWordsExist);
        }
        if b.has(group::TAUT) && b.taut == TautCode::Servo {
            if !plotter {
                return Err(ErrorKind::UnsupportedCommand);
            }
            if !b.has_word(word::S) {
                return Err(ErrorKind::ValueWordMissing);
            }
        }
        // The block's modes: the state's, with the line's changes
        // (`gc_block.modal`).
        let mut m = self.modal;
        if jog {
            m.motion = MotionMode::Linear;
            m.feed_mode = FeedMode::PerMinute;
        }
        if b.has(group::MOTION) {
            m.motion = b.motion;
        }
        if b.has(group::PLANE) {
            m.plane = b.plane;
        }
        if b.has(group::DISTANCE) {
            m.distance = b.distance;
        }
        if b.has(group::FEED_MODE) && !jog {
            m.feed_mode = b.feed_mode;
        }
        if b.has(group::UNITS) {
            m.units = b.units;
        }
        if b.has(group::TOOL_LENGTH) {
            m.tool_length = b.tool_length;
        }
        if b.has(group::COORD) {
            m.coord = b.coord;
        }
        // The axis words by channel, in mm ([12]); a letter of no channel
        // is one Grbl does not know.
        let mut axes: Exact = [0; AXES];
        let mut given = 0u8;
        for w in AxisWord::ALL {
            if let Some(v) = b.axis(w) {
                let Some(i) = channel(&names, w) else {
                    return Err(ErrorKind::UnsupportedCommand);
                };
                axes[i] = match w {
                    AxisWord::C => v,
                    _ => mm_exact(v, m.units),
                };
                given |= 1 << i;
            }
        }
        // [0] Bare axis words move in the motion mode.
        let mut axis_command = b.axis_command;
        if given != 0 && axis_command == AxisCommand::None {
            axis_command = AxisCommand::Motion;
        }
        let mut words = b.words;
        // [2], [3] The feed rate.
        let has_f = b.has_word(word::F);
        let feed = if jog {
            if !has_f {
                return Err(ErrorKind::UndefinedFeedRate);
            }
            mm_milli(b.f, m.units)
        } else if m.feed_mode == FeedMode::InverseTime {
            let feed_move = !matches!(m.motion, MotionMode::None | MotionMode::Seek);
            if axis_command == AxisCommand::Motion && feed_move && !has_f {
                return Err(ErrorKind::UndefinedFeedRate);
            }
            if has_f {
                b.f
            } else {
                Milli::ZERO
            }
        } else if has_f {
            mm_milli(b.f, m.units)
        } else if self.modal.feed_mode == FeedMode::PerMinute {
            self.feed
        } else {
            // From G93 to G94: no feed until one is given.
            Milli::ZERO
        };
        // [4], [5] Spindle speed and tool (Grbl takes `T` from every line,
        // 0 when it has none). `M300`'s `S` is its angle, `M18 S`'s the
        // drivers' idle delay.
        let servo = b.has(group::TAUT) && b.taut == TautCode::Servo;
        let idle_delay = b.has(group::TAUT) && b.taut == TautCode::DisableDrivers;
        let speed = match b.has_word(word::S) && !servo && !idle_delay {
            true => b.s,
            false => self.speed,
        };
        // [10] A dwell needs its time.
        if b.non_modal == NonModal::Dwell {
            if !b.has_word(word::P) {
                return Err(ErrorKind::ValueWordMissing);
            }
            words &= !(1 << word::P);
        }
        // [11] The plane's channels.
        let [w0, w1, _] = m.plane.axes();
        let (axis_0, axis_1) = (channel(&names, w0), channel(&names, w1));
        // [14] G43.1 takes Z alone.
        if axis_command == AxisCommand::ToolLength
            && m.tool_length == ToolLength::Dynamic
            && b.words & word::AXES != AxisWord::Z.bit()
        {
            return Err(ErrorKind::G43DynamicAxisError);
        }
        // [15] Another work system's offset.
        let mut block_coord = self.coord_system;
        if m.coord != self.modal.coord {
            block_coord = io.coord(m.coord);
        }
        // [19] Coordinate data, offsets, and where the axis words go.
        let mut target = self.position;
        // At most one of G10's data, G92's offset and G28/G30's position:
        // one value, as each is ~25 B of a frame under every move's check.
        let mut sets = Sets::Nothing;
        match b.non_modal {
            NonModal::SetCoordData => {
                if given == 0 {
                    return Err(ErrorKind::NoAxisWords);
                }
                if !b.has_word(word::P) && !b.has_word(word::L) {
                    return Err(ErrorKind::ValueWordMissing);
                }
                let p = b.p.0 / 1000;
                if p > 6 {
                    return Err(ErrorKind::UnsupportedCoordSys);
                }
                if b.l != 20 && (b.l != 2 || b.has_word(word::R)) {
                    return Err(ErrorKind::UnsupportedCommand);
                }
                words &= !(1 << word::L | 1 << word::P);
                let index = match p {
                    0 => m.coord,
                    _ => p as u8 - 1,
                };
                // L20: WCS = MPos - G92 - TLO - WPos; L2: the words.
                let base = match b.l {
                    20 => sum(&self.position, &self.plus_tlo(&self.coord_offset), -1),
                    _ => [0; AXES],
                };
                let sign = if b.l == 20 { -1 } else { 1 };
                sets = Sets::CoordData(
                    index,
                    pick(&io.coord(index), &sum(&base, &axes, sign), given),
                );
            }
            NonModal::SetCoordOffset => {
                if given == 0 {
                    return Err(ErrorKind::NoAxisWords);
                }
                // G92 = MPos - WCS - TLO - WPos.
                let base = sum(&self.position, &self.plus_tlo(&block_coord), -1);
                sets = Sets::Offset(pick(&self.coord_offset, &sum(&base, &axes, -1), given));
            }
            _ => {
                if axis_command != AxisCommand::ToolLength {
                    // The named channels from where their words count
                    // from, the others where they are: one pass, no
                    // intermediate arrays (every line of a stream of
                    // moves comes here).
                    for i in 0..AXES {
                        if given >> i & 1 != 0 {
                            let from = match (b.non_modal, m.distance) {
                                (NonModal::AbsoluteOverride, _) => 0,
                                (_, Distance::Absolute) => {
                                    let tlo = if i == Z { self.tlo } else { 0 };
                                    block_coord[i] + self.coord_offset[i] + tlo
                                }
                                (_, Distance::Relative) => self.position[i],
                            };
                            target[i] = from + axes[i];
                        }
                    }
                }
                match b.non_modal {
                    NonModal::GoHome0 | NonModal::GoHome1 => {
                        let index = match b.non_modal {
                            NonModal::GoHome0 => G28,
                            _ => G30,
                        };
                        // Only the named axes go home, the others stay;
                        // with none, all go.
                        if given == 0 {
                            axis_command = AxisCommand::None;
                        }
                        let mask = if given == 0 { 0b111 } else { given };
                        sets = Sets::Home(pick(&self.position, &io.coord(index), mask));
                    }
                    NonModal::AbsoluteOverride
                        if !matches!(m.motion, MotionMode::Seek | MotionMode::Linear) =>
                    {
                        return Err(ErrorKind::G53InvalidMotionMode);
                    }
                    _ => {}
                }
            }
        }
        // [20] Motion modes.
        let mut arc = None;
        if m.motion == MotionMode::None {
            if given != 0 {
                return Err(ErrorKind::AxisWordsExist);
            }
        } else if axis_command == AxisCommand::Motion {
            if m.motion != MotionMode::Seek && feed.0 == 0 {
                return Err(ErrorKind::UndefinedFeedRate);
            }
            match m.motion {
                MotionMode::CwArc | MotionMode::CcwArc => {
                    if given == 0 {
                        return Err(ErrorKind::NoAxisWords);
                    }
                    let in_plane = |c: Option<usize>| c.is_some_and(|i| given >> i & 1 != 0);
                    let (Some(a0), Some(a1)) = (axis_0, axis_1) else {
                        return Err(ErrorKind::NoAxisWordsInPlane);
                    };
                    if !in_plane(axis_0) && !in_plane(axis_1) {
                        return Err(ErrorKind::NoAxisWordsInPlane);
                    }
                    let clockwise = m.motion == MotionMode::CwArc;
                    let sweep_plane = arc::Plane {
                        axis_0: a0,
                        axis_1: a1,
                        linear: channel(&names, m.plane.axes()[2]),
                    };
                    let circle = if b.has_word(word::R) {
                        words &= !(1 << word::R);
                        if target == self.position {
                            return Err(ErrorKind::InvalidTarget);
                        }
                        Some(mm_milli(b.r, m.units))
                    } else {
                        if !b.has_word(word::I + ijk(w0) as u8)
                            && !b.has_word(word::I + ijk(w1) as u8)
                        {
                            return Err(ErrorKind::NoOffsetsInPlane);
                        }
                        words &= !word::IJK;
                        None
                    };
                    let offsets = [
                        mm_milli(b.ijk[ijk(w0)], m.units),
                        mm_milli(b.ijk[ijk(w1)], m.units),
                    ];
                    let ask = ArcAsk {
                        plane: sweep_plane,
                        clockwise,
                        radius: circle,
                        offsets,
                    };
                    arc = Some(self.arc(&target, &ask, cfg)?);
                }
                MotionMode::Seek | MotionMode::Linear if given == 0 => {
                    axis_command = AxisCommand::None;
                }
                _ => {}
            }
        }
        // [0] Words no command used.
        words &= match jog {
            true => !(1 << word::N | 1 << word::F),
            false => !(1 << word::N | 1 << word::F | 1 << word::S | 1 << word::T),
        };
        if axis_command != AxisCommand::None {
            words &= !word::AXES;
        }
        if words != 0 {
            return Err(ErrorKind::UnusedWords);
        }
        if jog {
            let allowed = group::DISTANCE | group::UNITS | group::NON_MODAL;
            let override_only = matches!(b.non_modal, NonModal::None | NonModal::AbsoluteOverride);
            if b.groups & !allowed != 0 || !override_only {
                return Err(ErrorKind::InvalidJogCommand);
            }
            // Grbl's jogging document requires an axis word.
            if given == 0 {
                return Err(ErrorKind::NoAxisWords);
            }
        }
        // taut's own checks, after Grbl's: a feed too slow to plan, and
        // every move inside the travel and the reach, in machine
        // coordinates.
        if has_f && m.feed_mode == FeedMode::PerMinute && feed.0 < MIN_FEED && feed.0 != 0 {
            return Err(ErrorKind::FeedTooLow);
        }
        let motors = motor_channels(cfg);
        let moving = axis_command == AxisCommand::Motion && m.motion != MotionMode::None;
        let mut legs = [self.position; 2];
        let mut count = 0;
        if let Sets::Home(h) = &sets {
            if axis_command != AxisCommand::None {
                legs[0] = target;
                count = 1;
            }
            legs[count] = *h;
            count += 1;
        } else if moving || jog {
            legs[0] = target;
            count = 1;
        }
        let mut from = &self.position;
        for leg in &legs[..count] {
            if let Some(a) = &arc {
                check_arc(a, motors, kin, cfg)?;
            } else {
                check_leg(from, leg, motors, kin, cfg)?;
            }
            from = leg;
        }

        // Step 4: the line is good. Its state, then its actions.
        self.run.clear();
        self.run.from = self.position;
        let pen_deg = |down: bool| {
            if down {
                cfg.pen.down_deg
            } else {
                cfg.pen.up_deg
            }
        };
        if jog {
            self.run.feed = Feed::PerMinute(feed);
        } else {
            self.feed = feed;
            self.speed = speed;
            self.tool = if b.has_word(word::T) { b.t } else { 0 };
            // [7] The spindle: a plotter's pen.
            if b.has(group::SPINDLE) {
                self.modal.spindle = b.spindle;
                if plotter {
                    self.run.pen = pen_deg(b.spindle != Spindle::Off);
                    self.pen_deg = self.run.pen;
                    self.run.todo |= todo::PEN;
                    self.servo_off = false;
                }
            }
            // `M300 S` over 180: the servo off (the pen stays).
            if servo {
                self.servo_off = b.s.0 > 180_000;
                if !self.servo_off {
                    self.run.pen = (b.s.0 / 1000) as u8;
                    self.pen_deg = self.run.pen;
                    self.run.todo |= todo::PEN;
                }
            }
            // [8] Coolant: kept for `$G`.
            if b.has(group::COOLANT) {
                self.modal.coolant = match b.coolant {
                    crate::gcode::Coolant::Mist => self.modal.coolant | MIST,
                    crate::gcode::Coolant::Flood => self.modal.coolant | FLOOD,
                    crate::gcode::Coolant::Off => 0,
                };
            }
            if b.non_modal == NonModal::Dwell {
                self.run.dwell_ms = dwell_ms(b.p, cfg);
                self.run.todo |= todo::DWELL;
            }
            self.modal.plane = m.plane;
            self.modal.units = m.units;
            self.modal.feed_mode = m.feed_mode;
            // [14] The tool length offset.
            if axis_command == AxisCommand::ToolLength {
                self.modal.tool_length = m.tool_length;
                let tlo = match m.tool_length {
                    ToolLength::Dynamic => axes[Z],
                    ToolLength::Cancel => 0,
                };
                self.wco_changed |= tlo != self.tlo;
                self.tlo = tlo;
            }
            // [15] The work system.
            if m.coord != self.modal.coord {
                self.modal.coord = m.coord;
                self.coord_system = block_coord;
                self.wco_changed = true;
            }
            self.modal.distance = m.distance;
            // [19]
            if let Sets::CoordData(index, data) = &sets {
                io.set_coord(*index, data);
                if *index == self.modal.coord {
                    self.coord_system = *data;
                    self.wco_changed = true;
                }
            }
            match b.non_modal {
                NonModal::SetHome0 => io.set_coord(G28, &self.position),
                NonModal::SetHome1 => io.set_coord(G30, &self.position),
                NonModal::ResetCoordOffset => {
                    self.coord_offset = [0; AXES];
                    self.wco_changed = true;
                }
                _ => {}
            }
            if let Sets::Offset(offset) = &sets {
                self.coord_offset = *offset;
                self.wco_changed = true;
            }
            // [20]
            self.modal.motion = m.motion;
        }
        // A plain `G1` may join the tiny moves around it (a line of one
        // leg, nothing else to do, at a feed per minute: `join_or_flush`).
        let joins = plotter && !jog;
        if count > 0 {
            if !jog {
                self.run.feed = match (
                    matches!(sets, Sets::Home(_)) || m.motion == MotionMode::Seek,
                    m.feed_mode,
                ) {
                    (true, _) => Feed::Rapid,
                    (false, FeedMode::PerMinute) => Feed::PerMinute(feed),
                    (false, FeedMode::InverseTime) => {
                        let length = match &arc {
                            Some(a) => a.length(),
                            None => length_um(&self.position, &legs[0]),
                        };
                        inverse_time(feed, length)
                    }
                };
            }
            // A plotter's Z is its pen, set before the moves.
            if plotter && given >> Z & 1 != 0 && !self.servo_off {
                let work_z = legs[count - 1][Z] - self.work_offset(Z);
                self.run.pen_z = pen_deg(work_z <= 0);
                self.pen_deg = self.run.pen_z;
                self.run.todo |= todo::PEN_Z;
            }
            self.run.legs = legs;
            self.run.todo |= match count {
                1 => todo::LEG_0,
                _ => todo::LEG_0 | todo::LEG_1,
            };
            if let Some(a) = arc {
                self.run.path = Some(Path::Arc(a));
                self.run.todo = self.run.todo & !todo::LEG_0 | todo::PATH;
            }
            self.position = legs[count - 1];
        }
        if !jog {
            // [21] Program flow.
            if b.has(group::STOPPING) {
                match b.flow {
                    Flow::Pause => self.run.todo |= todo::PAUSE,
                    Flow::OptionalStop => {}
                    Flow::End | Flow::EndRewind => {
                        self.program_end(io);
                        self.run.todo |= todo::END;
                    }
                }
            }
            if b.has(group::TAUT) {
                self.run.todo |= match b.taut {
                    TautCode::EnableDrivers => todo::DRIVERS_ON,
                    // Marlin's `M18 S`/`M84 S`: the drivers go off this many
                    // seconds (thousandths: ms) after motion stands, 0
                    // never; nothing is switched now.
                    TautCode::DisableDrivers if b.has_word(word::S) => {
                        self.run.idle_delay_ms = b.s.0.max(0) as u32;
                        todo::IDLE_DELAY
                    }
                    TautCode::DisableDrivers => todo::DRIVERS_OFF,
                    TautCode::ReportPosition => todo::REPORT,
                    TautCode::WaitIdle => todo::WAIT,
                    TautCode::Servo => 0,
                };
            }
        }
        // Checked, not carried out: only reads are answered.
        if env.allowed.checking {
            self.run.todo &= todo::REPORT;
        }
        self.join_or_flush(joins, env);
        self.dwell_until = None;
        Ok(())
    }

    /// The work offset of channel `i`, millionths.
    fn work_offset(&self, i: usize) -> i64 {
        self.coord_system[i] + self.coord_offset[i] + if i == Z { self.tlo } else { 0 }
    }

    /// `offset` with the tool length offset on `Z`. A value of its own,
    /// made where it is used: an `[0, 0, tlo]` kept for the sums was 24 B
    /// more of [`Interpreter::accept`]'s frame.
    #[inline(never)]
    fn plus_tlo(&self, offset: &Exact) -> Exact {
        let mut o = *offset;
        o[Z] += self.tlo;
        o
    }

    /// `M2`/`M30`: the modes LinuxCNC resets at a program's end (`gcode.c`
    /// line 1077): `G1 G17 G90 G94 G54 M5 M9`; `F`, `S`, units and
    /// offsets stay.
    #[inline(never)]
    fn program_end(&mut self, io: &impl MachineIo) {
        let m = &mut self.modal;
        m.motion = MotionMode::Linear;
        m.plane = Plane::Xy;
        m.distance = Distance::Absolute;
        m.feed_mode = FeedMode::PerMinute;
        m.coord = 0;
        m.spindle = Spindle::Off;
        m.coolant = 0;
        self.coord_system = io.coord(0);
        self.wco_changed = true;
    }

    /// The arc from the programmed position to `target`, checked: `R`'s
    /// circle (`radius`) or the centre's `offsets`. Out of line: the arc
    /// is built once, where the caller keeps it (the AVR's stack is
    /// small).
    #[inline(never)]
    fn arc(&self, target: &Exact, ask: &ArcAsk, cfg: &MachineConfig) -> Result<Arc, ErrorKind> {
        let sweep = Sweep {
            start: coords::milli(&self.position),
            end: coords::milli(target),
            plane: ask.plane,
            clockwise: ask.clockwise,
            tolerance: Milli(cfg.arc_tolerance_um.min(i32::MAX as u32) as i32),
        };
        let circle = match ask.radius {
            Some(r) => Circle::from_radius(&sweep, r),
            None => Circle::from_centre(&sweep, ask.offsets),
        }
        .map_err(|e| match e {
            ArcError::EndOffCircle => ErrorKind::InvalidTarget,
            ArcError::RadiusTooSmall => ErrorKind::ArcRadiusError,
        })?;
        Ok(Arc::new(&sweep, &circle))
    }
}

/// What a line's `[19]` sets or goes to besides its target.
enum Sets {
    Nothing,
    /// `G10`: a work system's data (its index, the new data).
    CoordData(u8, Exact),
    /// `G92`: the coordinate offset.
    Offset(Exact),
    /// `G28`/`G30`: the stored position the line goes to.
    Home(Exact),
}

/// An arc's figures besides its ends: by reference, as the AVR backend
/// garbles arguments passed on the stack (an arc's offsets came as
/// garbage, `error:33`).
struct ArcAsk {
    plane: arc::Plane,
    clockwise: bool,
    /// `R` (mm), or the centre's offsets from the start in the plane.
    radius: Option<Milli>,
    offsets: [Milli; 2],
}

/// Whether the line would move the machine or change what a job owns
/// (refused while a string-art job runs).
fn moves(b: &Block) -> bool {
    b.has_axes()
        || b.has(group::TAUT)
            && matches!(
                b.taut,
                TautCode::EnableDrivers | TautCode::DisableDrivers | TautCode::Servo
            )
        || b.has(group::SPINDLE)
        || b.has(group::STOPPING) && b.flow != Flow::OptionalStop
        || !matches!(b.non_modal, NonModal::None | NonModal::Dwell)
}

/// The axis letters a machine with these channel `words` has, a bit per
/// [`AxisWord`] (the parser's [`set_axis_letters`](crate::gcode::Parser::set_axis_letters)).
pub fn axis_letters(words: &[u8; AXES]) -> u8 {
    AxisWord::ALL
        .iter()
        .filter(|w| words.contains(&w.letter()))
        .fold(0, |bits, w| bits | 1 << w.index())
}

/// The channels motors drive (bits): a plotter's `Z` is its pen.
pub fn motor_channels(cfg: &MachineConfig) -> u8 {
    match cfg.machine.is_string_art() {
        true => 0b111,
        false => 0b011,
    }
}

/// `G4 P`: seconds (Grbl), or milliseconds where `dwell_p_ms` says so
/// (the plotters: Marlin's and the unicorn extension's `G4 P150`).
fn dwell_ms(p: Milli, cfg: &MachineConfig) -> u32 {
    let p = p.0.max(0) as u32;
    match cfg.dwell_p_ms {
        true => (p + 500) / 1000,
        false => p,
    }
}

/// The straight length from `a` to `b`, thousandths.
fn length_um(a: &Exact, b: &Exact) -> f32 {
    let d = coords::milli(&core::array::from_fn(|i| b[i] - a[i]));
    let sq: f32 = d.iter().map(|v| v.0 as f32 * v.0 as f32).sum();
    crate::fmath::sqrt(sq)
}

/// `G93`'s feed: `F` moves a line in 1 / F minutes, so its speed is its
/// length times `F` (never below what the planner takes).
fn inverse_time(f: Milli, length_um: f32) -> Feed {
    let per_min = f.0 as f32 / 1000.0 * length_um;
    Feed::PerMinute(Milli((per_min as i32).max(MIN_FEED)))
}

/// Refuses a straight move from `from` to `to` that leaves the soft
/// limits or the machine's reach.
#[inline(never)]
fn check_leg(
    from: &Exact,
    to: &Exact,
    motors: u8,
    kin: &impl Kinematics,
    cfg: &MachineConfig,
) -> Result<(), ErrorKind> {
    check_travel(cfg, to, to, motors)?;
    if kin.is_linear() {
        // The steps queued later fit (`motor_steps`), mostly seen at once.
        let fits = (0..AXES)
            .all(|i| motors >> i & 1 == 0 || cfg.axes[i].steps_per_unit.surely_fits(to[i]));
        if fits {
            return Ok(());
        }
        return motor_steps(to, motors, kin, cfg).map(drop);
    }
    let (a, b) = (motor_milli(from, motors), motor_milli(to, motors));
    match kin.reaches_line(&a, &b) {
        true => Ok(()),
        false => Err(ErrorKind::InvalidTarget),
    }
}

/// Refuses an arc that leaves the soft limits or the machine's reach.
/// Out of line: the AVR's stack is small, the arc's caller deep.
#[inline(never)]
fn check_arc(
    arc: &Arc,
    motors: u8,
    kin: &impl Kinematics,
    cfg: &MachineConfig,
) -> Result<(), ErrorKind> {
    check_arc_travel(arc, motors, cfg)?;
    let reached = match kin.is_linear() {
        // A linear kinematics reaches the whole box if it reaches its
        // corners.
        true => corners_reached(arc, kin),
        false => every_chord_reached(arc, kin),
    };
    match reached {
        true => Ok(()),
        false => Err(ErrorKind::InvalidTarget),
    }
}

/// Refuses an arc whose box leaves a motor channel's soft limits. Out of
/// line: its boxes would sit in the frame under the chords' check.
#[inline(never)]
fn check_arc_travel(arc: &Arc, motors: u8, cfg: &MachineConfig) -> Result<(), ErrorKind> {
    let (lo, hi) = arc.bounds();
    check_travel(cfg, &coords::exact(&lo), &coords::exact(&hi), motors)
}

/// Whether the machine reaches both corners of `arc`'s box. Out of line,
/// as [`check_arc_travel`].
#[inline(never)]
fn corners_reached(arc: &Arc, kin: &impl Kinematics) -> bool {
    let (lo, hi) = arc.bounds();
    kin.inverse(&lo).is_ok() && kin.inverse(&hi).is_ok()
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

/// Refuses a path whose box `lo..=hi` (machine coordinates) leaves a
/// motor channel's soft limits.
fn check_travel(cfg: &MachineConfig, lo: &Exact, hi: &Exact, motors: u8) -> Result<(), ErrorKind> {
    let outside = (0..AXES).any(|i| {
        let a = &cfg.axes[i];
        let (min, max) = a.travel;
        let milli = 1000;
        motors >> i & 1 != 0
            && a.soft_limits
            && (lo[i] < min.0 as i64 * milli || hi[i] > max.0 as i64 * milli)
    });
    match outside {
        true => Err(ErrorKind::TravelExceeded),
        false => Ok(()),
    }
}

/// `pos` in thousandths, the channels without a motor at 0 (and not
/// converted: a plotter's spare channel costs nothing). Out of line:
/// one copy of its three conversions for its half-dozen callers.
#[inline(never)]
fn motor_milli(pos: &Exact, motors: u8) -> Position {
    core::array::from_fn(|i| match motors >> i & 1 {
        0 => Milli::ZERO,
        _ => Milli(coords::to_milli(pos[i])),
    })
}

/// `pos` with the channels without a motor at 0 (a path's piece: no
/// 64-bit division on the way, as [`motor_milli`] of it would take).
fn motor_only(pos: &Position, motors: u8) -> Position {
    let mut p = *pos;
    for (i, v) in p.iter_mut().enumerate() {
        if motors >> i & 1 == 0 {
            *v = Milli::ZERO;
        }
    }
    p
}

/// The motors' steps for `pos`, rounded once: on a linear machine from
/// the exact position, channel by channel; on the others through the
/// kinematics (whose floats are far coarser than a µm).
fn motor_steps(
    pos: &Exact,
    motors: u8,
    kin: &impl Kinematics,
    cfg: &MachineConfig,
) -> Result<Steps, ErrorKind> {
    if !kin.is_linear() {
        return kin
            .inverse(&motor_milli(pos, motors))
            .map_err(|_| ErrorKind::InvalidTarget);
    }
    let mut steps = [0; AXES];
    for (i, s) in steps.iter_mut().enumerate() {
        if motors >> i & 1 != 0 {
            *s = cfg.axes[i]
                .steps_per_unit
                .steps_exact(pos[i])
                .ok_or(ErrorKind::InvalidTarget)?;
        }
    }
    Ok(steps)
}
