//! Command-line errors, numbered like Grbl's so senders that know Grbl's
//! table (UGS, bCNC, CNCjs) show the right text. Code 70 (checksum) is
//! taut's own: Grbl has no checksums, Marlin has no error numbers.

use ufmt::{uDisplay, uWrite, uwrite, Formatter};

/// What went wrong. The discriminant is the number printed after `error:`:
/// Grbl's own (`doc/csv/error_codes_en_US.csv`) up to 38, taut's from 60.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum ErrorKind {
    /// A word must start with a letter (`10`, `#`, `%`).
    ExpectedCommandLetter = 1,
    /// A letter without a number, or a stray sign or point.
    BadNumberFormat = 2,
    /// A `$` line taut does not know.
    InvalidStatement = 3,
    /// `F N P S T` below zero.
    NegativeValue = 4,
    /// `$H` on a machine with no axis set to home (Grbl's "setting
    /// disabled").
    NoHoming = 5,
    /// A setting or a jog while the machine is not idle.
    NotIdle = 8,
    /// G-code while the position is unknown (alarm) or a jog runs:
    /// Grbl's "G-code lock", lifted by `$X`, `$H` or the jog's end.
    Locked = 9,
    /// A startup line or build info line (`$N0=`, `$I=`) longer than is
    /// kept.
    LineLengthExceeded = 14,
    /// More than 79 characters kept (comments and spaces do not count).
    LineOverflow = 11,
    /// A target outside an axis's soft limits (the line is refused before
    /// anything moves, as Grbl refuses a jog).
    TravelExceeded = 15,
    /// `$J=` with a command or word a jog cannot take.
    InvalidJogCommand = 16,
    /// A G/M number or a letter taut does not implement.
    UnsupportedCommand = 20,
    /// Two commands of one modal group (`G90 G91`, `M3 M5`, …).
    ModalGroupViolation = 21,
    /// A feed move before any `F` (or without `F` in `G93`).
    UndefinedFeedRate = 22,
    /// A G/M number that is not whole (`G1.5`).
    CommandValueNotInteger = 23,
    /// Two commands that both take the axis words (`G0 G92 X0`).
    AxisCommandConflict = 24,
    /// A word given twice (`X1 X2`).
    RepeatedWord = 25,
    /// A command that needs axis words has none (`G92`, `G10`, `G2`).
    NoAxisWords = 26,
    /// `N` above 10 000 000.
    InvalidLineNumber = 27,
    /// A command without its value word (`G4` without `P`, `G10`
    /// without `L` or `P`).
    ValueWordMissing = 28,
    /// `G10 P` above 6.
    UnsupportedCoordSys = 29,
    /// `G53` in a motion mode other than `G0` or `G1`.
    G53InvalidMotionMode = 30,
    /// Axis words no command uses (`G80 X1`, `G4 P1 X1`).
    AxisWordsExist = 31,
    /// An arc without an axis word of its plane.
    NoAxisWordsInPlane = 32,
    /// A target the machine cannot reach or hold, or an arc's end off its
    /// circle.
    InvalidTarget = 33,
    /// No circle of the arc's `R` joins its ends.
    ArcRadiusError = 34,
    /// An arc with neither `R` nor an offset of its plane.
    NoOffsetsInPlane = 35,
    /// Value words no command uses (`P` without `G4`, `I` without an arc).
    UnusedWords = 36,
    /// `G43.1` with another axis word than `Z`.
    G43DynamicAxisError = 37,
    /// `T` above 255.
    MaxValueExceeded = 38,
    /// `M20`, `M23`…: no card in the slot, or none with a FAT volume
    /// (numbered as FluidNC's SD errors).
    NoCard = 60,
    /// The card failed while a file was read.
    CardFailed = 61,
    /// `M23`: no such file (or a name longer than any kept).
    FileNotFound = 65,
    /// A card print is running: `M25` pauses it, `M524` aborts it.
    Printing = 67,
    /// `*` checksum wrong, malformed, or followed by more words.
    BadChecksum = 70,
    /// Motion, drivers or settings while a string-art job runs (taut's).
    JobOwnsMotion = 71,
    /// `F` below [`MIN_FEED`] (taut's: Grbl creeps instead).
    FeedTooLow = 72,
    /// `M24` with no file selected by `M23` (taut's).
    NoFileSelected = 76,
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
            ErrorKind::NegativeValue => "Value < 0",
            ErrorKind::NoHoming => "Setting disabled (homing_axes)",
            ErrorKind::NotIdle => "Not idle",
            ErrorKind::Locked => "G-code lock",
            ErrorKind::LineLengthExceeded => "Line length exceeded",
            ErrorKind::LineOverflow => "Line overflow",
            ErrorKind::TravelExceeded => "Travel exceeded (soft limit)",
            ErrorKind::InvalidJogCommand => "Invalid jog command",
            ErrorKind::UnsupportedCommand => "Unsupported command",
            ErrorKind::ModalGroupViolation => "Modal group violation",
            ErrorKind::UndefinedFeedRate => "Undefined feed rate",
            ErrorKind::CommandValueNotInteger => "Command value not integer",
            ErrorKind::AxisCommandConflict => "Two commands use axis words",
            ErrorKind::RepeatedWord => "Repeated word",
            ErrorKind::NoAxisWords => "No axis words",
            ErrorKind::InvalidLineNumber => "Invalid line number",
            ErrorKind::ValueWordMissing => "Value word missing",
            ErrorKind::UnsupportedCoordSys => "Unsupported coordinate system",
            ErrorKind::G53InvalidMotionMode => "G53 only with G0 or G1",
            ErrorKind::AxisWordsExist => "Unused axis words",
            ErrorKind::NoAxisWordsInPlane => "Arc without an axis word of its plane",
            ErrorKind::InvalidTarget => "Invalid target",
            ErrorKind::ArcRadiusError => "Arc radius invalid",
            ErrorKind::NoOffsetsInPlane => "Arc without an offset of its plane",
            ErrorKind::UnusedWords => "Unused value words",
            ErrorKind::G43DynamicAxisError => "G43.1 takes Z only",
            ErrorKind::MaxValueExceeded => "Tool number above 255",
            ErrorKind::NoCard => "No card",
            ErrorKind::CardFailed => "Card read failed",
            ErrorKind::FileNotFound => "File not found",
            ErrorKind::Printing => "Printing from the card (M25, M524)",
            ErrorKind::NoFileSelected => "No file selected (M23)",
            ErrorKind::BadChecksum => "Bad checksum",
            ErrorKind::JobOwnsMotion => "A job is running",
            ErrorKind::FeedTooLow => "Feed rate below 10/min",
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
