//! What the job hears ([`Event`]) and what it asks the firmware to do
//! ([`Action`]), with the texts the firmware logs.

use super::progress::Progress;
use crate::axis::Axis;
use crate::buttons::ButtonEvent;
use crate::checkpoint::Saved;
use crate::config::MachineConfig;
use crate::files::check::CardId;
use crate::files::param::Params;
use crate::stringart::Phase;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum State {
    WaitingForCard,
    /// The firmware is reading and checking the card's files.
    Reading,
    /// The files are bad: nothing moves until the card is replaced.
    BadFiles,
    /// Preparation before drilling: zeroing, starting the drill.
    PrepDrill,
    Drilling,
    /// Nails in, thread tied to nail 0, zeroing again.
    WaitingForNails,
    Winding,
    /// Drilling or winding, stopped after the current move; drivers hold.
    Paused(Phase),
    End,
    /// The card of a job a power cut stopped: go on with it (green) or
    /// discard it (green held 2 s)?
    Offer,
    /// Going on with it: the axes were unpowered, every one must be zeroed
    /// again at the zero pose before green.
    PrepResume(Phase),
}

impl State {
    /// Logged as `state: <name>` on every transition.
    pub const fn name(self) -> &'static str {
        match self {
            State::WaitingForCard => "waiting for card",
            State::Reading => "reading",
            State::BadFiles => "bad files",
            State::PrepDrill => "prep drill",
            State::Drilling => "drilling",
            State::WaitingForNails => "waiting for nails",
            State::Winding => "winding",
            State::Paused(_) => "paused",
            State::End => "end",
            State::Offer => "resume offer",
            State::PrepResume(_) => "prep resume",
        }
    }

    /// Drilling or winding, not paused: the only states that move.
    pub const fn is_running(self) -> bool {
        matches!(self, State::Drilling | State::Winding)
    }
}

/// Everything the job reacts to. `'c`: the machine configuration lent
/// with the checked files.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event<'c> {
    /// Once at start-up.
    PowerOn,
    CardInserted,
    /// A card went in that cannot be read at all (no FAT volume, a
    /// partition past its end); the firmware logged why.
    CardUnusable,
    CardRemoved,
    /// The answer to [`Action::ReadFiles`]: `param.txt` and `machine.txt`
    /// read, `poradi.txt` checked completely ([`crate::files::poradi::PoradiCheck`]).
    FilesValid {
        params: Params,
        count: u32,
        /// The machine the card describes (`machine.txt` over the
        /// string-art defaults).
        config: &'c MachineConfig,
        /// The files' lengths and checksums: a card back mid-job must
        /// hold the very same.
        id: CardId,
    },
    /// The answer to [`Action::ReadFiles`] when a file is missing or bad
    /// (the firmware logs the [`crate::files::FileError`] itself).
    FilesInvalid,
    Button(ButtonEvent),
    /// Every step taken from [`super::Job::next_step`] has been carried
    /// out, and `next_step` returned `None`.
    MotionDone,
    /// Serial `~` with no feed hold to end: resume a paused job.
    Resume,
    /// Serial Ctrl-X: the machine was stopped at once and the queued steps
    /// dropped; the job ends where it is (the axes need zeroing again).
    Abort,
    /// The next nail index of `poradi.txt`, while [`super::Job::wants_nail`].
    Nail(u16),
    /// The card could not deliver the next index while winding.
    PatternLost,
    /// The card switched the machine to a plotter (its `machine.txt`): the
    /// job is dropped, quietly; back on this machine it waits for a card.
    OtherMachine,
    /// After `PowerOn`: the checkpoint of a job under way at the last
    /// power-off, found in EEPROM.
    Saved(Saved),
    /// An operator's tool from the console ([`super::tools`]).
    Tool(super::tools::Tool),
}

/// Why the board of `param.txt` cannot be drilled or wound.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BadBoard {
    /// Shape 1 or 2: neither a circle nor a polygon.
    Shape,
    /// Fewer than 3 nails.
    Nails,
    /// The radius is no larger than the nails' margin (or past any
    /// machine's reach).
    Radius,
    /// The winding's inner radius, the needle's clearance inside the
    /// nails, would reach the centre.
    Centre,
    /// The needle cannot pass between this nail and the next.
    Gap(u16),
}

impl From<crate::geometry::BoardError> for BadBoard {
    fn from(e: crate::geometry::BoardError) -> Self {
        use crate::geometry::BoardError;
        match e {
            BoardError::Shape => BadBoard::Shape,
            BoardError::Nails => BadBoard::Nails,
            BoardError::Radius => BadBoard::Radius,
        }
    }
}

impl From<crate::stringart::WindError> for BadBoard {
    fn from(e: crate::stringart::WindError) -> Self {
        use crate::stringart::WindError;
        match e {
            WindError::GapTooNarrow(g) => BadBoard::Gap(g),
            // BadNail is not a board's: a check names no nail past the end.
            WindError::BoardTooSmall | WindError::BadNail(_) => BadBoard::Centre,
        }
    }
}

/// Something the firmware logs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Msg {
    /// The board in `param.txt` cannot be drilled or wound, and why.
    BadBoard(BadBoard),
    /// A zeroing button's first press: that driver is off.
    Loose(Axis),
    /// Its second press: the current position is that axis's zero.
    Zeroed(Axis),
    /// Green refused: an axis is loose, press its button again first.
    ZeroPending,
    CardRemoved,
    /// The card is back, with the job's files.
    CardOk,
    /// A card came back with other or bad files: it does not count.
    OtherCard,
    /// Green refused: the job needs its card.
    NoCard,
    /// Winding lost its pattern stream; it waits for the card.
    PatternLost,
    Resumed,
    /// Ended by Ctrl-X.
    Aborted,
    /// The card is not the checkpoint's job's.
    SavedOtherCard,
    /// Green held at the offer.
    SavedDiscarded,
    /// Green refused before a resume: an axis is not zeroed yet.
    ZeroAll,
    /// A tool refused: the machine moves.
    ToolMoving,
    /// A tool refused: not in this state.
    ToolNotNow,
    /// A tool refused: no such nail or wrap.
    ToolRange,
    WrapTested,
    DriftChecked,
    Jumped,
}

impl Msg {
    pub const fn as_str(self) -> &'static str {
        match self {
            // A log line holds ~74 characters of text.
            Msg::BadBoard(BadBoard::Shape) => {
                "bad board (param.txt): shape must be 0 (circle) or 3+ (polygon)"
            }
            Msg::BadBoard(BadBoard::Nails) => "bad board (param.txt): 3 nails or more",
            Msg::BadBoard(BadBoard::Radius) => {
                "bad board (param.txt): radius too small for the nails"
            }
            Msg::BadBoard(BadBoard::Centre) => {
                "bad board (param.txt): radius too small for the needle"
            }
            // The nail's number and the rest follow (the firmware's log).
            Msg::BadBoard(BadBoard::Gap(_)) => "bad board (param.txt): nail ",
            Msg::Loose(Axis::Base) => "base free",
            Msg::Loose(Axis::Radial) => "radial free",
            Msg::Loose(_) => "drill free",
            Msg::Zeroed(Axis::Base) => "base zeroed",
            Msg::Zeroed(Axis::Radial) => "radial zeroed",
            Msg::Zeroed(_) => "drill zeroed",
            Msg::ZeroPending => "zeroing unfinished",
            Msg::CardRemoved => "card out",
            Msg::CardOk => "card ok",
            Msg::OtherCard => "wrong card",
            Msg::NoCard => "no card",
            Msg::PatternLost => "pattern lost",
            Msg::Resumed => "resumed",
            Msg::Aborted => "job stopped by Ctrl-X",
            Msg::SavedOtherCard => "checkpoint: another card, discarded",
            Msg::SavedDiscarded => "checkpoint discarded",
            Msg::ZeroAll => "zero base, radial and drill first (white buttons)",
            Msg::ToolMoving => "tool refused: the machine moves (pause first)",
            Msg::ToolNotNow => "tool refused: not in this state",
            Msg::ToolRange => "tool refused: no such nail or wrap",
            Msg::WrapTested => "wrap test done",
            Msg::DriftChecked => "drift check done",
            Msg::Jumped => "jumped: green resumes there",
        }
    }
}

/// What a waiting state waits for. Prompts that green answers contain
/// `press green`, so a test bench can answer them; the card prompts do
/// not (green cannot help there). The firmware logs a copy of each text
/// made in flash at compile time, as it does for [`Msg`] and [`State`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Prompt {
    InsertCard,
    ReplaceCard,
    StartDrilling,
    StartWinding,
    Resume,
    Finished,
    ZeroToResume,
}

/// Every prompt starts with this.
pub const PROMPT_MARK: &str = ">>> ";

impl Prompt {
    pub const fn as_str(self) -> &'static str {
        match self {
            Prompt::InsertCard => ">>> insert card",
            Prompt::ReplaceCard => ">>> bad files: replace card",
            Prompt::StartDrilling => ">>> zero, drill on, press green to drill",
            Prompt::StartWinding => ">>> nails, thread on 0, zero, press green to wind",
            Prompt::Resume => ">>> paused: press green to resume",
            Prompt::Finished => ">>> done: press green",
            Prompt::ZeroToResume => {
                ">>> axes were unpowered: zero each at the zero pose, press green to resume"
            }
        }
    }

    pub const fn wants_green(self) -> bool {
        !matches!(self, Prompt::InsertCard | Prompt::ReplaceCard)
    }
}

/// What the firmware must do, in order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    /// Log `state: <name>`.
    Enter(State),
    Log(Msg),
    /// Log the prompt's text.
    Prompt(Prompt),
    /// Read and check the card's files; answer with `FilesValid` or
    /// `FilesInvalid`.
    ReadFiles,
    /// Make the card's machine (the `config` of `FilesValid`) the
    /// machine's own, once it stands: a new job runs on its card's
    /// figures (a card back mid-job is only compared with the job's).
    Configure,
    /// Open `poradi.txt` for streaming from its start
    /// ([`crate::files::poradi::PoradiReader`]), each index an
    /// [`Event::Nail`]; the job passes over those it already had.
    OpenPattern,
    /// Stop any motion under way (a console jog) and drop what is queued,
    /// before what follows (the card went while the machine may move).
    StopMotion,
    /// Switch the drivers in the mask (bit = axis index) on / off, once
    /// the machine stands.
    DriversOn(u8),
    DriversOff(u8),
    /// Take the axis's current position as its zero.
    SetZero(Axis),
    /// Take steps from [`super::Job::next_step`] until it returns `None`,
    /// carry them out, then send [`Event::MotionDone`].
    NextMoves,
    /// Log the progress line.
    Progress(Progress),
    /// Log the resume offer: `>>> resume winding at wrap 1234/3000?
    /// green: resume, hold green 2 s: discard` (the next unit, of `total`).
    Offer {
        phase: Phase,
        next: u32,
        total: u32,
    },
    /// The job's checkpoint is done with (the job ended, or it was
    /// discarded): write an idle header.
    Forget,
    /// Log the drift check: the base's step count (the firmware's) against
    /// where `nail` is expected (`expected`, steps).
    Drift {
        nail: u16,
        expected: i32,
    },
}

/// The actions of one event; never more than this many.
pub type Actions = heapless::Vec<Action, 6>;
