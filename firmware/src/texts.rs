//! The job's log texts, copied into flash at compile time from the logic
//! crate's own (`as_str`/`name` are `const fn`): used at run time, those
//! would sit in SRAM for the firmware's whole life.

use crate::board::flash::FlashStr;
use crate::flash_str;
use taut_logic::axis::Axis;
use taut_logic::gcode::ErrorKind;
use taut_logic::stringart::job::{BadBoard as Why, Msg, Phase, Prompt, State};

/// `match value { pattern => the flash copy of representative.method() }`.
macro_rules! in_flash {
    ($value:expr, $method:ident, [$($pat:pat => $rep:expr),* $(,)?]) => {
        match $value {
            $($pat => flash_str!($rep.$method()),)*
        }
    };
}

/// `in_flash!` for a fieldless enum, every variant listed: its codes and
/// texts as tables in flash, the code searched for.
macro_rules! searched_in_flash {
    ($value:expr; $ty:ident::$method:ident; [$($v:ident),* $(,)?]) => {{
        const N: usize = [$($ty::$v),*].len();
        // Not called: fails to compile if a variant is missing.
        #[allow(dead_code)]
        const fn every_variant(v: $ty) {
            match v {
                $($ty::$v => {})*
            }
        }
        let codes = taut_progmem::table!(u8; N; [$($ty::$v as u8),*]);
        let texts = taut_progmem::table!(FlashStr; N; [$(flash_str!($ty::$v.$method())),*]);
        let code = $value as u8;
        // Every variant is listed, so the code is found (`0` is not
        // reached: no panic path).
        texts.get((0..N).position(|i| codes.get(i) == code).unwrap_or(0))
    }};
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
        BadBoard(Why::Shape) => BadBoard(Why::Shape),
        BadBoard(Why::Nails) => BadBoard(Why::Nails),
        BadBoard(Why::Radius) => BadBoard(Why::Radius),
        BadBoard(Why::Centre) => BadBoard(Why::Centre),
        BadBoard(Why::Gap(_)) => BadBoard(Why::Gap(0)),
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

/// Grbl's error texts of the console's replies, found by code in two
/// tables in flash: a `match` returning each text cost ~15 bytes of code
/// per arm, an entry costs 5 (the codes are sparse, up to 76, so they
/// are searched, not indexed: an error reply is rare).
pub fn error(e: ErrorKind) -> FlashStr {
    searched_in_flash!(e; ErrorKind::message; [
        ExpectedCommandLetter,
        BadNumberFormat,
        InvalidStatement,
        NegativeValue,
        NoHoming,
        NotIdle,
        Locked,
        LineLengthExceeded,
        LineOverflow,
        TravelExceeded,
        InvalidJogCommand,
        UnsupportedCommand,
        ModalGroupViolation,
        UndefinedFeedRate,
        CommandValueNotInteger,
        AxisCommandConflict,
        RepeatedWord,
        NoAxisWords,
        InvalidLineNumber,
        ValueWordMissing,
        UnsupportedCoordSys,
        G53InvalidMotionMode,
        AxisWordsExist,
        NoAxisWordsInPlane,
        InvalidTarget,
        ArcRadiusError,
        NoOffsetsInPlane,
        UnusedWords,
        G43DynamicAxisError,
        MaxValueExceeded,
        NoCard,
        CardFailed,
        FileNotFound,
        Printing,
        BadChecksum,
        JobOwnsMotion,
        FeedTooLow,
        NoFileSelected,
    ])
}
