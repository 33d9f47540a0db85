//! What the parser hands to the interpreter: one parsed line, a `$` line
//! or a realtime byte.

use super::system::SystemLine;
use crate::fat::Name;
use crate::units::{MaybeMilli, Milli};

/// Axis letters the command line accepts. Which channel each drives is the
/// kinematics' business (string art: C base °, X radial mm, Z drill mm).
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

    pub(super) fn from_letter(upper: u8) -> Option<AxisWord> {
        AxisWord::ALL.into_iter().find(|w| w.letter() == upper)
    }
}

/// `G90`/`G91`: a modal setting that may share a line with a command
/// (`G91 G1 C1`), so it is a field of [`Line`], not a [`Command`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Distance {
    /// `G90`: axis words are positions.
    Absolute,
    /// `G91`: axis words are offsets from the current position.
    Relative,
}

/// `G20`/`G21`: the unit of lengths and feeds, modal like [`Distance`].
/// Angles (the base's `C`) are degrees either way.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Units {
    /// `G20`.
    Inch,
    /// `G21`, the default.
    Mm,
}

/// `G17`/`G18`/`G19`: the plane arcs turn in, modal like [`Distance`].
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

/// The one command of a line (taut runs at most one per line).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Command {
    /// No G/M command. Axis words then move in the modal motion mode and
    /// `F` alone sets the feed rate, as in Grbl.
    Empty,
    /// `G0`.
    Rapid,
    /// `G1`. The parser does not check that a feed rate was ever given
    /// (Grbl's error 22): only the interpreter knows the modal `F`.
    Linear,
    /// `G2`: a clockwise arc in the plane, from `I J K` or `R`.
    ArcCw,
    /// `G3`: the same, counter-clockwise.
    ArcCcw,
    /// `G4 P<seconds>`: `p` holds thousandths of a second, i.e. ms.
    Dwell,
    /// `G92`: the axis words name the current position.
    SetPosition,
    /// `M17`.
    EnableDrivers,
    /// `M18`, or its alias `M84`.
    DisableDrivers,
    /// `M114`.
    ReportPosition,
    /// `M400`: answer `ok` only once motion is done.
    WaitIdle,
    /// `G28`: home the machine's homing axes against their switches.
    Home,
    /// `M0`, `M1`: pause once motion is done, until `~` or the green
    /// button.
    Pause,
    /// `M3` (Grbl's servo forks): the pen down, or to `S` degrees.
    PenDown,
    /// `M5`: the pen up.
    PenUp,
    /// `M300 S<degrees>` (the Inkscape "unicorn" extension, drawbots):
    /// the pen servo to that angle.
    Servo,
}

impl Command {
    /// Every command.
    pub const ALL: [Command; 16] = [
        Command::Empty,
        Command::Rapid,
        Command::Linear,
        Command::ArcCw,
        Command::ArcCcw,
        Command::Dwell,
        Command::SetPosition,
        Command::EnableDrivers,
        Command::DisableDrivers,
        Command::ReportPosition,
        Command::WaitIdle,
        Command::Home,
        Command::Pause,
        Command::PenDown,
        Command::PenUp,
        Command::Servo,
    ];

    /// The command a G or M number names. G/M numbers are read as
    /// fixed-point like every value and matched exactly, so `G1`, `G01`
    /// and `G1.0` are one command while `G38.2` or `G1.5` are unsupported.
    pub(super) fn from_word(letter: u8, number: Milli) -> Option<Command> {
        Some(match (letter, number.0) {
            (b'G', 0) => Command::Rapid,
            (b'G', 1000) => Command::Linear,
            (b'G', 2000) => Command::ArcCw,
            (b'G', 3000) => Command::ArcCcw,
            (b'G', 4000) => Command::Dwell,
            (b'G', 92_000) => Command::SetPosition,
            (b'G', 28_000) => Command::Home,
            (b'M', 17_000) => Command::EnableDrivers,
            (b'M', 18_000) | (b'M', 84_000) => Command::DisableDrivers,
            (b'M', 114_000) => Command::ReportPosition,
            (b'M', 400_000) => Command::WaitIdle,
            (b'M', 0) | (b'M', 1000) => Command::Pause,
            (b'M', 3000) => Command::PenDown,
            (b'M', 5000) => Command::PenUp,
            (b'M', 300_000) => Command::Servo,
            _ => return None,
        })
    }

    /// Whether the command consumes the axis words (Grbl's error 24 when
    /// two such commands share a line).
    pub(super) const fn uses_axes(self) -> bool {
        matches!(
            self,
            Command::Rapid
                | Command::Linear
                | Command::ArcCw
                | Command::ArcCcw
                | Command::SetPosition
        )
    }
}

/// One G-code line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Line {
    /// `N` line number, 0..=9 999 999. Checking that it follows the last
    /// one is the console's job.
    pub n: Option<u32>,
    /// The `*` checksum; present only if it matched.
    pub checksum: Option<u8>,
    pub distance: Option<Distance>,
    pub plane: Option<Plane>,
    pub units: Option<Units>,
    pub command: Command,
    /// Axis words, indexed by [`AxisWord::index`].
    pub axes: [MaybeMilli; AXIS_WORDS],
    /// Feed rate, units per minute, never negative.
    pub f: MaybeMilli,
    /// `P`, only with `G4`: seconds in thousandths, i.e. milliseconds.
    pub p: MaybeMilli,
    /// `I J K`: an arc's centre, offset from its start, per axis X Y Z.
    pub offsets: [MaybeMilli; 3],
    /// `R`: an arc's radius (negative: the longer way round).
    pub r: MaybeMilli,
    /// `S`, only with `M3` and `M300`: the pen servo's angle, degrees.
    pub s: MaybeMilli,
}

impl Line {
    /// A blank line (or one holding only comments): answered with `ok`.
    pub const EMPTY: Line = Line::empty();

    /// [`Line::EMPTY`] built by code where it is used at run time: a
    /// constant's copy would keep its bytes in SRAM on the AVR.
    pub const fn empty() -> Line {
        Line {
            n: None,
            checksum: None,
            distance: None,
            plane: None,
            units: None,
            command: Command::Empty,
            axes: [MaybeMilli::NONE; AXIS_WORDS],
            f: MaybeMilli::NONE,
            p: MaybeMilli::NONE,
            offsets: [MaybeMilli::NONE; 3],
            r: MaybeMilli::NONE,
            s: MaybeMilli::NONE,
        }
    }

    pub fn axis(&self, word: AxisWord) -> Option<Milli> {
        self.axes[word.index()].get()
    }

    pub fn has_axes(&self) -> bool {
        self.axes.iter().any(|a| a.is_some())
    }

    /// Whether the line has an arc's `I J K` or `R`.
    pub fn has_arc_words(&self) -> bool {
        self.r.is_some() || self.offsets.iter().any(|o| o.is_some())
    }
}

/// Grbl's single-byte realtime commands: acted on as soon as they arrive,
/// wherever they fall in a line, and never part of it.
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

/// Marlin's card commands, run by the console (not the interpreter).
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
    /// `M524`: abort the print.
    Abort,
}

impl CardLine {
    pub(super) fn from_number(number: Milli) -> Option<CardLine> {
        Some(match number.0 {
            20_000 => CardLine::List,
            21_000 => CardLine::Mount,
            23_000 => CardLine::Select(Name::EMPTY),
            24_000 => CardLine::Start,
            25_000 => CardLine::Pause,
            27_000 => CardLine::Progress,
            524_000 => CardLine::Abort,
            _ => return None,
        })
    }
}

/// What a byte pushed into the parser completed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Input {
    /// A G-code line (answer `ok` once executed or queued).
    Line(Line),
    /// A `$` line.
    System(SystemLine),
    /// `$J=`: a jog (Grbl 1.1), read as the `G1` it moves: axis words and
    /// `F`, with `G20`/`G21`, `G90`/`G91` and `G53` for this line only.
    Jog(Line),
    /// `M20`, `M23 <name>`, `M24`…
    Card(CardLine),
    /// A realtime byte (no `ok`).
    Realtime(Realtime),
}
