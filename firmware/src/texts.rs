//! The job's log texts, copied into flash at compile time from the logic
//! crate's own (`as_str`/`name` are `const fn`): used at run time, those
//! would sit in SRAM for the firmware's whole life.
#![deny(unsafe_code)]

use crate::board::flash::FlashStr;
use crate::flash_str;
use taut_logic::axis::Axis;
use taut_logic::gcode::ErrorKind;
use taut_logic::stringart::job::{Msg, Phase, Prompt, State};

/// `match value { pattern => the flash copy of representative.method() }`.
macro_rules! in_flash {
    ($value:expr, $method:ident, [$($pat:pat => $rep:expr),* $(,)?]) => {
        match $value {
            $($pat => flash_str!($rep.$method()),)*
        }
    };
}

pub fn state(s: State) -> FlashStr {
    use State::*;
    in_flash!(s, name, [
        WaitingForCard => WaitingForCard,
        Reading => Reading,
        BadFiles => BadFiles,
        PrepDrill => PrepDrill,
        Drilling => Drilling,
        WaitingForNails => WaitingForNails,
        Winding => Winding,
        Paused(_) => Paused(Phase::Drilling),
        End => End,
        Offer => Offer,
        PrepResume(_) => PrepResume(Phase::Drilling),
    ])
}

pub fn prompt(p: Prompt) -> FlashStr {
    use Prompt::*;
    in_flash!(p, as_str, [
        InsertCard => InsertCard,
        ReplaceCard => ReplaceCard,
        StartDrilling => StartDrilling,
        StartWinding => StartWinding,
        Resume => Resume,
        Finished => Finished,
        ZeroToResume => ZeroToResume,
    ])
}

pub fn msg(m: Msg) -> FlashStr {
    use Msg::*;
    in_flash!(m, as_str, [
        BadBoard => BadBoard,
        Loose(Axis::Base) => Loose(Axis::Base),
        Loose(Axis::Radial) => Loose(Axis::Radial),
        Loose(_) => Loose(Axis::Drill),
        Zeroed(Axis::Base) => Zeroed(Axis::Base),
        Zeroed(Axis::Radial) => Zeroed(Axis::Radial),
        Zeroed(_) => Zeroed(Axis::Drill),
        ZeroPending => ZeroPending,
        CardRemoved => CardRemoved,
        CardOk => CardOk,
        OtherCard => OtherCard,
        NoCard => NoCard,
        PatternLost => PatternLost,
        Resumed => Resumed,
        Aborted => Aborted,
        SavedOtherCard => SavedOtherCard,
        SavedDiscarded => SavedDiscarded,
        ZeroAll => ZeroAll,
        ToolMoving => ToolMoving,
        ToolNotNow => ToolNotNow,
        ToolRange => ToolRange,
        WrapTested => WrapTested,
        DriftChecked => DriftChecked,
        Jumped => Jumped,
    ])
}

/// Grbl's error texts of the console's replies.
pub fn error(e: ErrorKind) -> FlashStr {
    use ErrorKind::*;
    in_flash!(e, message, [
        ExpectedCommandLetter => ExpectedCommandLetter,
        BadNumberFormat => BadNumberFormat,
        InvalidStatement => InvalidStatement,
        NegativeValue => NegativeValue,
        NotIdle => NotIdle,
        Locked => Locked,
        LineOverflow => LineOverflow,
        TravelExceeded => TravelExceeded,
        UnsupportedCommand => UnsupportedCommand,
        ModalGroupViolation => ModalGroupViolation,
        UndefinedFeedRate => UndefinedFeedRate,
        AxisWordConflict => AxisWordConflict,
        RepeatedWord => RepeatedWord,
        NoAxisWords => NoAxisWords,
        InvalidLineNumber => InvalidLineNumber,
        ValueWordMissing => ValueWordMissing,
        UnusedAxisWords => UnusedAxisWords,
        InvalidTarget => InvalidTarget,
        ArcNoAxisInPlane => ArcNoAxisInPlane,
        ArcRadiusInvalid => ArcRadiusInvalid,
        ArcNoOffsetInPlane => ArcNoOffsetInPlane,
        UnusedValueWords => UnusedValueWords,
        BadChecksum => BadChecksum,
        JobOwnsMotion => JobOwnsMotion,
        FeedTooLow => FeedTooLow,
        PenWithMove => PenWithMove,
        NoHoming => NoHoming,
        InvalidJogCommand => InvalidJogCommand,
        NoCard => NoCard,
        CardFailed => CardFailed,
        FileNotFound => FileNotFound,
        Printing => Printing,
        NoFileSelected => NoFileSelected,
    ])
}
