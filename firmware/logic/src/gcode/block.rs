//! What the parser hands on: one block (a G-code line's words gathered
//! as Grbl's `gc_block` gathers them, with its step-2 checks done), a `$`
//! line, a card command or a real-time byte.

use super::system::SystemLine;
use crate::fat::Name;
use crate::units::Milli;

/// Axis letters the command line reads. Which channel each drives is the
/// kinematics' business (string art: C base °, X radial mm, Z drill mm;
/// plotters X, Y and the pen's Z).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum AxisWord {
    C = 0,
    X = 1,
    Y = 2,
    Z = 3,
}

/// Number of axis letters.
pub const AXIS_WORDS: usize = 4;

impl AxisWord {
    pub const ALL: [AxisWord; AXIS_WORDS] = [AxisWord::C, AxisWord::X, AxisWord::Y, AxisWord::Z];

    pub const fn index(self) -> usize {
        self as usize
    }

    /// Upper-case letter of the word.
    pub const fn letter(self) -> u8 {
        match self {
            AxisWord::C => b'C',
            AxisWord::X => b'X',
            AxisWord::Y => b'Y',
            AxisWord::Z => b'Z',
        }
    }

    pub fn from_letter(upper: u8) -> Option<AxisWord> {
        match upper {
            b'C' => Some(AxisWord::C),
            b'X' => Some(AxisWord::X),
            b'Y' => Some(AxisWord::Y),
            b'Z' => Some(AxisWord::Z),
            _ => None,
        }
    }

    /// The word's bit in [`Block::words`].
    pub const fn bit(self) -> u16 {
        1 << (word::C + self as u8)
    }
}

/// Grbl's modal groups (`gcode.h`), a bit each in [`Block::groups`]: at
/// most one command of each per line (error 21).
pub mod group {
    /// G4 G10 G28 G28.1 G30 G30.1 G53 G92 G92.1.
    pub const NON_MODAL: u16 = 1 << 0;
    /// G0 G1 G2 G3 G38.x G80.
    pub const MOTION: u16 = 1 << 1;
    /// G17 G18 G19.
    pub const PLANE: u16 = 1 << 2;
    /// G90 G91.
    pub const DISTANCE: u16 = 1 << 3;
    /// G91.1.
    pub const ARC_DISTANCE: u16 = 1 << 4;
    /// G93 G94.
    pub const FEED_MODE: u16 = 1 << 5;
    /// G20 G21.
    pub const UNITS: u16 = 1 << 6;
    /// G40.
    pub const CUTTER: u16 = 1 << 7;
    /// G43.1 G49.
    pub const TOOL_LENGTH: u16 = 1 << 8;
    /// G54 … G59.
    pub const COORD: u16 = 1 << 9;
    /// G61.
    pub const CONTROL: u16 = 1 << 10;
    /// M0 M1 M2 M30.
    pub const STOPPING: u16 = 1 << 11;
    /// M3 M4 M5.
    pub const SPINDLE: u16 = 1 << 12;
    /// M7 M8 M9.
    pub const COOLANT: u16 = 1 << 13;
    /// taut's own M17 M18 M84 M114 M300 M400: one a line.
    pub const TAUT: u16 = 1 << 14;
}

/// The value words, a bit each in [`Block::words`] (Grbl's `WORD_*`),
/// the axis words after them ([`AxisWord::bit`]).
pub mod word {
    pub const F: u8 = 0;
    pub const I: u8 = 1;
    pub const J: u8 = 2;
    pub const K: u8 = 3;
    pub const L: u8 = 4;
    pub const N: u8 = 5;
    pub const P: u8 = 6;
    pub const R: u8 = 7;
    pub const S: u8 = 8;
    pub const T: u8 = 9;
    /// The first axis word; C, X, Y, Z follow.
    pub const C: u8 = 10;
    /// Every axis word.
    pub const AXES: u16 = 0b1111 << C;
    /// `I J K`.
    pub const IJK: u16 = 0b1110;
}

/// Grbl's non-modal commands (group 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NonModal {
    None,
    /// `G4 P<s>`.
    Dwell,
    /// `G10 L2`/`L20 P<n>`.
    SetCoordData,
    /// `G28`: to the stored position, through the axis words' point.
    GoHome0,
    /// `G28.1`: store the position.
    SetHome0,
    /// `G30`.
    GoHome1,
    /// `G30.1`.
    SetHome1,
    /// `G53`: this line's move in machine coordinates.
    AbsoluteOverride,
    /// `G92`: the axis words name where the machine stands.
    SetCoordOffset,
    /// `G92.1`: the G92 offset cleared.
    ResetCoordOffset,
}

/// The motion mode (group 1): what axis words do.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MotionMode {
    /// `G0`.
    Seek,
    /// `G1`.
    Linear,
    /// `G2`.
    CwArc,
    /// `G3`.
    CcwArc,
    /// `G80`: axis words are an error (31).
    None,
}

/// `G17`/`G18`/`G19`: the plane arcs turn in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Plane {
    /// `G17`: X then Y (offsets `I J`).
    Xy,
    /// `G18`: Z then X (offsets `K I`).
    Zx,
    /// `G19`: Y then Z (offsets `J K`).
    Yz,
}

impl Plane {
    /// The plane's two axes in order, and the third (linear) one.
    pub const fn axes(self) -> [AxisWord; 3] {
        match self {
            Plane::Xy => [AxisWord::X, AxisWord::Y, AxisWord::Z],
            Plane::Zx => [AxisWord::Z, AxisWord::X, AxisWord::Y],
            Plane::Yz => [AxisWord::Y, AxisWord::Z, AxisWord::X],
        }
    }
}

/// `G90`/`G91`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Distance {
    /// `G90`: axis words are positions.
    Absolute,
    /// `G91`: axis words are offsets from the current position.
    Relative,
}

/// `G20`/`G21`: the unit of lengths and feeds. Angles (the base's `C`)
/// are degrees either way.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Units {
    /// `G20`.
    Inch,
    /// `G21`, the default.
    Mm,
}

/// `G93`/`G94`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FeedMode {
    /// `G94`: `F` in units per minute.
    PerMinute,
    /// `G93`: `F` is 1 / minutes the line's move takes, on every move.
    InverseTime,
}

/// `G43.1`/`G49`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ToolLength {
    /// `G49`.
    Cancel,
    /// `G43.1 Z<offset>`.
    Dynamic,
}

/// Group M4: program flow.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Flow {
    /// `M0`: hold once the motion before is done, until `~`.
    Pause,
    /// `M1`: optional stop, ignored (Grbl has no optional-stop switch).
    OptionalStop,
    /// `M2`.
    End,
    /// `M30`.
    EndRewind,
}

/// Group M7: the spindle, which is a plotter's pen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Spindle {
    /// `M3`.
    Cw,
    /// `M4`.
    Ccw,
    /// `M5`.
    Off,
}

/// Group M8: coolant (taut has none: tracked for `$G`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coolant {
    /// `M7`.
    Mist,
    /// `M8`.
    Flood,
    /// `M9`.
    Off,
}

/// taut's own M codes (Marlin's numbers).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TautCode {
    /// `M17`: every driver on.
    EnableDrivers,
    /// `M18`, or its alias `M84`: every driver off once motion is done.
    DisableDrivers,
    /// `M114`: the executed position.
    ReportPosition,
    /// `M400`: `ok` once motion is done.
    WaitIdle,
    /// `M300 S<degrees>` (the Inkscape "unicorn" extension): the pen
    /// servo to that angle.
    Servo,
}

/// Which command takes the axis words (Grbl's `axis_command`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AxisCommand {
    None,
    /// G10, G28, G30, G92.
    NonModal,
    /// A motion command, or the modal motion for bare axis words.
    Motion,
    /// G43.1, G49.
    ToolLength,
}

/// One G-code line as Grbl gathers it: the commands with their groups,
/// the value words with their values. Only what [`Block::groups`] and
/// [`Block::words`] name is meaningful.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Block {
    /// Modal groups given ([`group`]).
    pub groups: u16,
    /// Value and axis words given ([`word`], [`AxisWord::bit`]).
    pub words: u16,
    pub non_modal: NonModal,
    pub motion: MotionMode,
    pub plane: Plane,
    pub distance: Distance,
    pub feed_mode: FeedMode,
    pub units: Units,
    pub tool_length: ToolLength,
    /// `G54` … `G59` as 0 … 5.
    pub coord: u8,
    pub flow: Flow,
    pub spindle: Spindle,
    pub coolant: Coolant,
    pub taut: TautCode,
    pub axis_command: AxisCommand,
    /// `F`, units (or 1 / minutes) per minute.
    pub f: Milli,
    /// `I J K`: an arc's centre offset from its start along X Y Z.
    pub ijk: [Milli; 3],
    /// `L`, whole.
    pub l: u8,
    /// `N`, whole.
    pub n: u32,
    /// `P`: seconds (or ms) of a dwell, or G10's coordinate system.
    pub p: Milli,
    /// `R`: an arc's radius.
    pub r: Milli,
    /// `S`: spindle speed, or `M300`'s angle.
    pub s: Milli,
    /// `T`, whole, ≤ 255.
    pub t: u8,
    /// Axis words in millionths of their unit (nm, or µ° of `C`),
    /// indexed by [`AxisWord::index`]: kept as written.
    pub axes: [i64; AXIS_WORDS],
    /// The `*` checksum; present only if it matched.
    pub checksum: Option<u8>,
}

impl Block {
    /// A block with no words: built by code where it is used (a
    /// constant's copy would keep its bytes in SRAM on the AVR).
    pub const fn empty() -> Block {
        Block {
            groups: 0,
            words: 0,
            non_modal: NonModal::None,
            motion: MotionMode::Seek,
            plane: Plane::Xy,
            distance: Distance::Absolute,
            feed_mode: FeedMode::PerMinute,
            units: Units::Mm,
            tool_length: ToolLength::Cancel,
            coord: 0,
            flow: Flow::OptionalStop,
            spindle: Spindle::Off,
            coolant: Coolant::Off,
            taut: TautCode::WaitIdle,
            axis_command: AxisCommand::None,
            f: Milli::ZERO,
            ijk: [Milli::ZERO; 3],
            l: 0,
            n: 0,
            p: Milli::ZERO,
            r: Milli::ZERO,
            s: Milli::ZERO,
            t: 0,
            axes: [0; AXIS_WORDS],
            checksum: None,
        }
    }

    pub const fn has(&self, group: u16) -> bool {
        self.groups & group != 0
    }

    pub const fn has_word(&self, bit: u8) -> bool {
        self.words >> bit & 1 != 0
    }

    /// The axis word's value (millionths), if the line has it.
    pub fn axis(&self, w: AxisWord) -> Option<i64> {
        (self.words & w.bit() != 0).then_some(self.axes[w.index()])
    }

    pub const fn has_axes(&self) -> bool {
        self.words & word::AXES != 0
    }

    /// `M114` alone (an `N` aside): it only reads, so Grbl's G-code lock
    /// lets it by.
    pub const fn only_reads(&self) -> bool {
        self.groups == group::TAUT
            && matches!(self.taut, TautCode::ReportPosition)
            && self.words & !(1 << word::N) == 0
    }

    /// The line's `N`, if it has one.
    pub fn line_number(&self) -> Option<u32> {
        self.has_word(word::N).then_some(self.n)
    }
}

/// Grbl's single-byte real-time commands: acted on as soon as they
/// arrive, wherever they fall in a line, and never part of it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Realtime {
    /// `?`: report status.
    Status,
    /// `!`: feed hold.
    FeedHold,
    /// `~`: cycle start / resume.
    CycleStart,
    /// Ctrl-X (0x18): soft reset; the parser also drops the partial line.
    Reset,
}

impl Realtime {
    #[inline]
    pub const fn from_byte(byte: u8) -> Option<Realtime> {
        match byte {
            b'?' => Some(Realtime::Status),
            b'!' => Some(Realtime::FeedHold),
            b'~' => Some(Realtime::CycleStart),
            0x18 => Some(Realtime::Reset),
            _ => None,
        }
    }
}

/// Marlin's card commands, run by the console (not the executor).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CardLine {
    /// `M20`: list the card's files.
    List,
    /// `M21`: mount the card (mounted when inserted: answered at once).
    Mount,
    /// `M23 <name>`: select a file by its 8.3 or long name.
    Select(Name),
    /// `M24`: start the selected file, or go on after `M25`.
    Start,
    /// `M25`: pause the print (a feed hold).
    Pause,
    /// `M27`: how far the print is.
    Progress,
    /// `M524`: abort the print (or discard a power cut's checkpoint).
    Abort,
    /// `M1000`: go on with the print a power cut stopped (Marlin's).
    Recover,
}

impl CardLine {
    pub(super) fn from_number(number: u32) -> Option<CardLine> {
        Some(match number {
            20 => CardLine::List,
            21 => CardLine::Mount,
            23 => CardLine::Select(Name::EMPTY),
            24 => CardLine::Start,
            25 => CardLine::Pause,
            27 => CardLine::Progress,
            524 => CardLine::Abort,
            1000 => CardLine::Recover,
            _ => return None,
        })
    }
}

/// What a line read whole is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Input {
    /// A G-code block (answer `ok` once carried out or queued).
    Block(Block),
    /// A `$` line.
    System(SystemLine),
    /// `$J=`: a jog (Grbl 1.1), gathered as Grbl gathers it: its words
    /// checked by the executor's jog rules.
    Jog(Block),
    /// `M20`, `M23 <name>`, `M24`…
    Card(CardLine),
    /// A real-time byte (no `ok`).
    Realtime(Realtime),
    /// Seed 003's raw-step line; `None`: malformed (the seed's `?`).
    Seed(Option<crate::seed::SeedMove>),
}
