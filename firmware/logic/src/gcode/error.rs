//! Command-line errors, numbered like Grbl's so senders that know Grbl's
//! table (UGS, bCNC, CNCjs) show the right text. Code 70 (checksum) is
//! taut's own: Grbl has no checksums, Marlin has no error numbers.

use ufmt::{uDisplay, uWrite, uwrite, Formatter};

/// What went wrong. The discriminant is the number printed after `error:`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum ErrorKind {
    /// A word must start with a letter (`10`, `#`).
    ExpectedCommandLetter = 1,
    /// A letter without a number, a stray sign or point, or an overflow.
    BadNumberFormat = 2,
    /// A `$` line taut does not know.
    InvalidStatement = 3,
    /// `F` or `P` below zero.
    NegativeValue = 4,
    /// More than [`MAX_LINE`](super::MAX_LINE) characters.
    LineOverflow = 11,
    /// A G/M number or a letter taut does not implement.
    UnsupportedCommand = 20,
    /// Two commands of one group (`G0 G1`, `G90 G91`, two M words, …).
    ModalGroupViolation = 21,
    /// `G1` before any `F`: raised by the interpreter, which knows the
    /// modal feed rate; the parser never does.
    UndefinedFeedRate = 22,
    /// Two commands that both take the axis words (`G1 G92 X0`).
    AxisWordConflict = 24,
    /// A letter given twice (`X1 X2`).
    RepeatedWord = 25,
    /// `G92` without an axis word.
    NoAxisWords = 26,
    /// `$J=` with a command or word a jog cannot take.
    InvalidJogCommand = 16,
    /// `N` negative, fractional or above 9 999 999.
    InvalidLineNumber = 27,
    /// `G4` without `P`.
    ValueWordMissing = 28,
    /// Axis words on a command that takes none (`G4`, `M17`, …).
    UnusedAxisWords = 31,
    /// `P` on a command other than `G4`.
    UnusedValueWords = 36,
    /// A setting or a `G92` while motion is under way (interpreter).
    NotIdle = 8,
    /// Motion while the position is unknown (a stop at once during
    /// motion): Grbl's alarm lock, lifted by `G92` or `$X`.
    Locked = 9,
    /// A target outside an axis's soft limits (interpreter).
    TravelExceeded = 15,
    /// An arc without an axis word of its plane (interpreter).
    ArcNoAxisInPlane = 32,
    /// A target the kinematics cannot reach or the step counter cannot
    /// hold, or an arc's end off its circle (interpreter).
    InvalidTarget = 33,
    /// No circle of the arc's `R` joins its ends (interpreter).
    ArcRadiusInvalid = 34,
    /// An arc with neither `R` nor an offset of its plane (interpreter).
    ArcNoOffsetInPlane = 35,
    /// `M20`, `M23`…: no card in the slot, or none with a FAT volume
    /// (numbered as FluidNC's SD errors).
    NoCard = 60,
    /// The card failed while a file was read.
    CardFailed = 61,
    /// `M23`: no such file (or a name longer than any kept).
    FileNotFound = 65,
    /// A card print is running: `M25` pauses it, `M524` aborts it.
    Printing = 67,
    /// `M24` with no file selected by `M23` (taut's).
    NoFileSelected = 76,
    /// `*` checksum wrong, malformed, or followed by more words.
    BadChecksum = 70,
    /// Motion, drivers or settings while a string-art job runs (taut's).
    JobOwnsMotion = 71,
    /// `F` below [`MIN_FEED`] (taut's: Grbl creeps instead).
    FeedTooLow = 72,
    /// A plotter's `Z` (its pen) with other axis words (taut's).
    PenWithMove = 73,
    /// `G28`/`$H` on a machine with no axis set to home (Grbl's "setting
    /// disabled").
    NoHoming = 5,
    /// A startup line or build info line (`$N0=`, `$I=`) longer than is
    /// kept.
    LineLengthExceeded = 14,
}

/// The slowest feed rate accepted, thousandths of a unit per minute.
pub const MIN_FEED: i32 = 10_000;

impl ErrorKind {
    /// Grbl's text (the firmware logs a copy made in flash at compile time).
    pub const fn message(self) -> &'static str {
        match self {
            ErrorKind::ExpectedCommandLetter => "Expected command letter",
            ErrorKind::BadNumberFormat => "Bad number format",
            ErrorKind::InvalidStatement => "Invalid statement",
            ErrorKind::NegativeValue => "Negative value",
            ErrorKind::LineOverflow => "Line overflow",
            ErrorKind::UnsupportedCommand => "Unsupported command",
            ErrorKind::ModalGroupViolation => "Modal group violation",
            ErrorKind::UndefinedFeedRate => "Undefined feed rate",
            ErrorKind::AxisWordConflict => "Two commands use axis words",
            ErrorKind::RepeatedWord => "Repeated word",
            ErrorKind::NoAxisWords => "No axis words",
            ErrorKind::InvalidLineNumber => "Invalid line number",
            ErrorKind::ValueWordMissing => "Value word missing",
            ErrorKind::UnusedAxisWords => "Unused axis words",
            ErrorKind::UnusedValueWords => "Unused value words",
            ErrorKind::NotIdle => "Not idle",
            ErrorKind::Locked => "Position unknown: G92 or $X first",
            ErrorKind::TravelExceeded => "Travel exceeded (soft limit)",
            ErrorKind::InvalidTarget => "Invalid target",
            ErrorKind::ArcNoAxisInPlane => "Arc without an axis of its plane",
            ErrorKind::ArcRadiusInvalid => "Arc radius invalid",
            ErrorKind::ArcNoOffsetInPlane => "Arc without R or an offset of its plane",
            ErrorKind::NoCard => "No card",
            ErrorKind::CardFailed => "Card read failed",
            ErrorKind::FileNotFound => "File not found",
            ErrorKind::Printing => "Printing from the card (M25, M524)",
            ErrorKind::NoFileSelected => "No file selected (M23)",
            ErrorKind::BadChecksum => "Bad checksum",
            ErrorKind::JobOwnsMotion => "A job is running",
            ErrorKind::FeedTooLow => "Feed rate below 10/min",
            ErrorKind::PenWithMove => "Pen Z with X/Y: one line each",
            ErrorKind::NoHoming => "Homing not enabled (homing_axes)",
            ErrorKind::InvalidJogCommand => "Invalid jog command",
            ErrorKind::LineLengthExceeded => "Line length exceeded",
        }
    }
}

/// An error with where it happened, printed as
/// `error:<code> <message> (col <c>)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Error {
    kind: ErrorKind,
    /// 1-based column of the offending character; 0 when unknown.
    column: u8,
    /// The line's `N`, if it was read before the error, so a Marlin-style
    /// host can be asked to resend it.
    line_number: Option<u32>,
}

impl Error {
    /// `column` is 1-based; 0 means "no column" (e.g. interpreter errors).
    pub const fn new(kind: ErrorKind, column: u8) -> Error {
        Error {
            kind,
            column,
            line_number: None,
        }
    }

    pub(super) fn with_line_number(self, line_number: Option<u32>) -> Error {
        Error {
            line_number,
            ..self
        }
    }

    pub const fn kind(&self) -> ErrorKind {
        self.kind
    }

    /// Grbl's error number.
    pub const fn code(&self) -> u8 {
        self.kind as u8
    }

    pub const fn message(&self) -> &'static str {
        self.kind.message()
    }

    /// 1-based column of the offending character, if known.
    pub const fn column(&self) -> Option<u8> {
        if self.column == 0 {
            None
        } else {
            Some(self.column)
        }
    }

    /// The `N` of the failed line, if it had been read.
    pub const fn line_number(&self) -> Option<u32> {
        self.line_number
    }
}

impl uDisplay for Error {
    fn fmt<W: uWrite + ?Sized>(&self, f: &mut Formatter<'_, W>) -> Result<(), W::Error> {
        uwrite!(f, "error:{} {}", self.code(), self.message())?;
        match self.column() {
            Some(c) => uwrite!(f, " (col {})", c),
            None => Ok(()),
        }
    }
}
