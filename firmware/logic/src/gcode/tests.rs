//! Host tests of the command line: Grbl's reading of a line (comments,
//! the length limit, spaces, numbers) and its step-2 checks, each case
//! with the line of Grbl's `protocol.c` or `gcode.c` it follows, and
//! property tests over random bytes and numbers.

use super::*;
use crate::units::Milli;
use proptest::prelude::*;
use std::{format, string::String, vec::Vec};

/// Every non-`None` result of pushing `bytes`.
fn push_all(parser: &mut Parser, bytes: &[u8]) -> Vec<Result<Input, Error>> {
    bytes.iter().filter_map(|&b| parser.push(b)).collect()
}

/// The result of one line: `text` and a newline into a fresh parser,
/// which must answer exactly once.
fn parse(text: &str) -> Result<Input, Error> {
    parse_bytes(text.as_bytes())
}

fn parse_bytes(text: &[u8]) -> Result<Input, Error> {
    let mut parser = Parser::new();
    let mut bytes = text.to_vec();
    bytes.push(b'\n');
    let mut out = push_all(&mut parser, &bytes);
    assert_eq!(out.len(), 1, "{text:?} answered {out:?}");
    out.remove(0)
}

fn block(text: &str) -> Block {
    match parse(text) {
        Ok(Input::Block(b)) => b,
        other => panic!("{text:?}: {other:?}"),
    }
}

fn code(text: &str) -> Option<u8> {
    parse(text).err().map(|e| e.code())
}

/// XOR of the bytes of `text`: the checksum Marlin hosts append.
fn xor(text: &str) -> u8 {
    text.bytes().fold(0, |x, b| x ^ b)
}

#[test]
fn words_are_gathered_with_their_groups_and_values() {
    let b = block("G1X10 Y-2.5F600");
    assert_eq!(b.groups, group::MOTION);
    assert_eq!(b.motion, MotionMode::Linear);
    assert_eq!(b.axis(AxisWord::X), Some(10_000_000));
    assert_eq!(b.axis(AxisWord::Y), Some(-2_500_000));
    assert_eq!(b.axis(AxisWord::Z), None);
    assert_eq!(b.f, Milli(600_000));
    assert_eq!(b.axis_command, AxisCommand::Motion);
    // Grbl's preamble, every word of its own group.
    let b = block("G21 G90 G17 G94 G40 G49 G80 G54 G61 G91.1 M5 M9 T1");
    assert_eq!(b.groups.count_ones(), 12);
    assert_eq!(
        (b.units, b.distance, b.plane),
        (Units::Mm, Distance::Absolute, Plane::Xy)
    );
    assert_eq!(
        (b.motion, b.tool_length, b.coord),
        (MotionMode::None, ToolLength::Cancel, 0)
    );
    assert_eq!(b.t, 1);
    let b = block("G10 L20 P1 X0 Y0");
    assert_eq!(
        (b.non_modal, b.l, b.p),
        (NonModal::SetCoordData, 20, Milli(1000))
    );
    assert_eq!(b.axis_command, AxisCommand::NonModal);
    for (text, nm) in [
        ("G28", NonModal::GoHome0),
        ("G28.1", NonModal::SetHome0),
        ("G30", NonModal::GoHome1),
        ("G30.1", NonModal::SetHome1),
        ("G92.1", NonModal::ResetCoordOffset),
        ("G53 G0 X1", NonModal::AbsoluteOverride),
    ] {
        assert_eq!(block(text).non_modal, nm, "{text}");
    }
    // gcode.c line 150: only G10/28/30/92 take the axis words.
    assert_eq!(block("G28.1 X1").axis_command, AxisCommand::None);
    assert_eq!(block("G59").coord, 5);
    assert_eq!(block("M30").flow, Flow::EndRewind);
    assert_eq!(block("M4 S1000").spindle, Spindle::Ccw);
    assert_eq!(block("M7").coolant, Coolant::Mist);
    assert_eq!(block("M84").taut, TautCode::DisableDrivers);
    assert_eq!(block("N12 M300 S30").n, 12);
    assert_eq!(block("N12 M300 S30").s, Milli(30_000));
    assert_eq!(block("G43.1 Z2").tool_length, ToolLength::Dynamic);
    // Grbl drops `.1` of G49 without a word (line 219).
    assert_eq!(block("G49.1").tool_length, ToolLength::Cancel);
}

/// protocol.c lines 118–147: whitespace and control bytes, comments and
/// `/` are thrown away before the words are read; letters upper-cased.
#[test]
fn what_grbl_throws_away_before_the_words() {
    let same = |a: &str, b: &str| {
        let of = |t| parse(t).map_err(|e| e.code());
        assert_eq!(of(a), of(b), "{a:?} vs {b:?}")
    };
    same("X1 0", "X10");
    same("g1 x 1 . 5 f 6 0", "G1X1.5F60");
    same("G1 (go) X1 ;done", "G1X1");
    same("G1 X(gap)1", "G1X1");
    same("/G1 X1", "G1X1");
    same("G1\tX1\x01\x7f", "G1X1\x7f");
    same("G0 X1\r", "G0X1");
    assert_eq!(block("(only a comment)"), Block::empty());
    assert_eq!(block("; only a comment"), Block::empty());
    assert_eq!(block(""), Block::empty());
}

/// The text of the line's `(MSG, …)` comment, read before its end.
fn message_of(text: &str) -> String {
    let mut parser = Parser::new();
    for &b in text.as_bytes() {
        assert!(parser.push(b).is_none());
    }
    let said: String = parser.message().as_str().into();
    assert!(parser.push(b'\n').is_some());
    // Kept after the line's end (the console says it once the line is
    // accepted); the next line starts with none.
    assert_eq!(parser.message().as_str(), said);
    assert!(parser.push(b'G').is_none());
    assert!(parser.message().is_empty());
    said
}

/// LinuxCNC's operator message `(MSG, text)`, which grblHAL prints as
/// `[MSG:text]`: the line is G-code as before (a comment), its text kept
/// for the console. Other comments, and `;`, are no message.
#[test]
fn a_msg_comment_is_kept_for_the_console() {
    let pen = "M0 (MSG, change the pen: pass 2 of 3, Red fill)";
    assert_eq!(message_of(pen), "change the pen: pass 2 of 3, Red fill");
    assert_eq!(block(pen), block("M0"));
    assert_eq!(message_of("( msg ,Hello )G0X1"), "Hello");
    assert_eq!(message_of("(MSG,a)(MSG,b)"), "b");
    for none in [
        "(MESSAGE, no)",
        "(MSG no comma)",
        "; MSG, no",
        "(SMG,x)",
        "G0 X1",
    ] {
        assert_eq!(message_of(none), "", "{none}");
    }
    // Cut at its length; bytes outside printable ASCII read `?`.
    let long = "x".repeat(100);
    assert_eq!(message_of(&format!("(MSG,{long})")).len(), MSG_LEN);
    assert_eq!(message_of("(MSG,caf\u{e9})"), "caf??");
}

/// protocol.c line 141: the limit counts the characters kept (79 fit the
/// 80-byte buffer with its terminator), so a comment of any length is
/// fine; past it, error 11 once the line ends.
#[test]
fn the_length_limit_counts_what_is_kept() {
    let comment = format!("(Generated by Inkscape {})", "x".repeat(300));
    assert_eq!(block(&comment), Block::empty());
    assert_eq!(
        block(&format!("G1 X1 F100 {comment} ; {comment}")),
        block("G1X1F100")
    );
    // 79 kept: fine; 80: error 11.
    let kept = |n: usize| format!("G4P{}", "0".repeat(n - 3));
    assert_eq!(parse(&kept(MAX_LINE as usize)).map(|_| ()), Ok(()));
    assert_eq!(code(&kept(MAX_LINE as usize + 1)), Some(11));
    let spaced = |n: usize| format!("G4 P {} ", " 0".repeat(n - 3));
    assert!(parse(&spaced(MAX_LINE as usize)).is_ok());
    assert_eq!(code(&spaced(MAX_LINE as usize + 1)), Some(11));
    // Overflow wins over the errors in the text after it.
    assert_eq!(code(&format!("G1 X1 {}#", "N1".repeat(40))), Some(11));
    // And the next line is read afresh.
    let mut p = Parser::new();
    let out = push_all(&mut p, format!("{}\nG0 X1\n", "Y0".repeat(60)).as_bytes());
    assert_eq!(out[0].as_ref().map_err(|e| e.code()), Err(11));
    assert_eq!(out[1], Ok(Input::Block(block("G0X1"))));
}

/// A line whose bytes the receive ring lost ends at the interrupt's
/// `LINE_CUT` with error 11, however short the part that arrived; an
/// `\n` after it is a line of its own (the interrupt puts the marker in
/// the place of the line's end), and the next line is read afresh.
#[test]
fn a_line_cut_by_a_full_ring_is_an_overflow() {
    let mut p = Parser::new();
    let mut bytes = b"G1 X1".to_vec();
    bytes.push(LINE_CUT);
    bytes.push(LINE_CUT);
    bytes.extend_from_slice(b"G0 X2\r\n");
    let out = push_all(&mut p, &bytes);
    assert_eq!(out.len(), 3, "{out:?}");
    assert_eq!(out[0].as_ref().map_err(|e| e.code()), Err(11));
    assert_eq!(out[1].as_ref().map_err(|e| e.code()), Err(11));
    assert_eq!(out[2], Ok(Input::Block(block("G0X2"))));
    // After a CR the marker is still a line of its own.
    let out = push_all(&mut p, &[b'G', b'0', b'\r', LINE_CUT]);
    assert_eq!(out.len(), 2, "{out:?}");
    assert_eq!(out[1].as_ref().map_err(|e| e.code()), Err(11));
}

/// A UTF-8 byte-order mark before a line's first character (a file's
/// first line, or a stream's) is skipped; `%` is no letter (gcode.c line
/// 118: Grbl 1.1h answers it error 1).
#[test]
fn a_byte_order_mark_is_skipped_and_percent_is_no_letter() {
    assert_eq!(parse_bytes(b"\xEF\xBB\xBFG0 X1"), parse("G0X1"));
    assert_eq!(
        parse_bytes(b"\xEF\xBB\xBF(header)"),
        Ok(Input::Block(Block::empty()))
    );
    assert_eq!(code("%"), Some(1));
    assert_eq!(parse("%").unwrap_err().column(), Some(1));
    // A mark inside a line is no mark.
    assert_eq!(code("G0 \u{FEFF}X1"), Some(1));
}

/// (line, Grbl's error, column), each from the line of `gcode.c` that
/// raises it in step 2 (the words in the line's order).
const STEP_2: &[(&str, u8, u8, &str)] = &[
    ("10", 1, 1, "118: a word starts with a letter"),
    ("G1 #", 1, 4, "118"),
    (
        "G1 X1.2.3",
        1,
        8,
        "120 read_float stops at the second point, 118",
    ),
    ("G1 X1-", 1, 6, "118"),
    ("G1 X", 2, 5, "120: no digits"),
    ("GX1", 2, 2, "120"),
    ("G1 X--1", 2, 6, "120"),
    ("G1 X.", 2, 6, "120"),
    ("G5 X1", 20, 1, "233: unsupported G"),
    ("G38.2 Z-1", 20, 1, "171 (taut: no probe input)"),
    ("G90.1", 20, 1, "187: G90.1"),
    ("G91.2", 20, 1, "187"),
    ("G43 Z1", 20, 1, "218: G43 without .1"),
    ("G61.1", 20, 1, "230"),
    ("G28.2", 20, 1, "158"),
    ("M6", 20, 1, "282: tool change"),
    ("M56", 20, 1, "282: parking override not built"),
    ("G-1", 20, 1, "233"),
    ("G1.5 X1", 23, 1, "235: non-integer command"),
    ("G54.1", 23, 1, "235"),
    ("G4.1 P1", 23, 1, "235"),
    ("M3.5", 23, 1, "241: no Mxx.x"),
    ("M100.5", 23, 1, "241 before 282"),
    (
        "G0 G1 X5",
        24,
        4,
        "165: a second motion command is an axis conflict first",
    ),
    ("G80 G80", 21, 5, "238: two of group 1"),
    ("G90 G91", 21, 5, "238"),
    ("G17 G18", 21, 5, "238"),
    ("G20 G21", 21, 5, "238"),
    ("G54 G55", 21, 5, "238"),
    ("G4 P1 G53 G0", 21, 7, "238: two non-modal"),
    ("M3 M5", 21, 4, "287"),
    ("M7 M8", 21, 4, "287"),
    ("M0 M30", 21, 4, "287"),
    ("M17 M18", 21, 5, "taut's group"),
    ("G1 G92 X0", 24, 4, "149: G92 after a motion"),
    ("G92 G0 X0", 24, 5, "165: a motion after G92"),
    ("G10 G28", 24, 5, "149"),
    ("G43.1 G1 Z1", 24, 7, "165"),
    ("G1 G43.1 Z1", 24, 4, "211"),
    ("G1 X10 X20", 25, 8, "337: repeated word"),
    ("F1 F2", 25, 4, "337"),
    ("N1 N2", 25, 4, "337"),
    ("G1 X1 F-5", 4, 7, "340: negative F"),
    ("G4 P-1", 4, 4, "340"),
    ("N-1", 4, 1, "340"),
    ("S-1", 4, 1, "340"),
    ("T-1", 4, 1, "340"),
    ("T256", 38, 1, "316: tool above 255"),
    ("T255.5", 38, 1, "316"),
    ("N10000001", 27, 0, "362: line number above 10 000 000"),
    ("G1 Q5", 20, 4, "320: letter Grbl does not know"),
    ("G1 X1 A5", 20, 7, "320"),
    ("E5", 20, 1, "320"),
];

#[test]
fn grbl_s_step_2_errors_in_the_line_s_order() {
    for (text, code, column, why) in STEP_2 {
        match parse(text) {
            Err(e) => assert_eq!(
                (e.code(), e.column().unwrap_or(0)),
                (*code, *column),
                "{text:?} (gcode.c {why})"
            ),
            ok => panic!("{text:?} (gcode.c {why}): {ok:?}"),
        }
    }
}

#[test]
fn grbl_s_odd_but_good_lines() {
    // N with a fraction is truncated (line 309); T's fraction too.
    assert_eq!(block("N1.5").n, 1);
    assert_eq!(block("N10000000").n, 10_000_000);
    assert_eq!(block("T3.7").t, 3);
    // A G/M number's hundredths: 1.001 rounds to G1 (line 129).
    assert_eq!(block("G1.001 X1").motion, MotionMode::Linear);
    assert_eq!(code("G01 G00.0 X1"), Some(24));
}

#[test]
fn a_machine_without_y_refuses_it_in_the_line_s_order() {
    let mut p = Parser::new();
    // The string-art machine: C X Z.
    p.set_axis_letters(0b1011);
    let out = push_all(&mut p, b"G0 X1 Y2 X3\nG0 C1 Z2\n");
    assert_eq!(
        out[0].as_ref().map_err(|e| (e.code(), e.column())),
        Err((20, Some(7)))
    );
    assert!(matches!(out[1], Ok(Input::Block(_))));
}

#[test]
fn checksummed_lines_report_number_and_checksum() {
    let body = "N12 G1 X1";
    let ck = xor(body);
    let with = |tail: &str| parse(&format!("{body}*{ck}{tail}"));
    let mut expected = block(body);
    expected.checksum = Some(ck);
    assert_eq!(with(""), Ok(Input::Block(expected)));
    assert_eq!(with("  ; trailing comment"), Ok(Input::Block(expected)));
    assert_eq!(parse(&format!("{body}*{}", ck ^ 1)).unwrap_err().code(), 70);
    assert_eq!(parse(&format!("{body}*{ck} X1")).unwrap_err().code(), 70);
    assert_eq!(parse(&format!("{body}*")).unwrap_err().code(), 70);
}

/// Jogs are gathered as Grbl gathers them (a `G1` in `G94`); whether
/// their words fit a jog is the executor's check.
#[test]
fn jogs_and_system_lines() {
    let jog = |text| match parse(text) {
        Ok(Input::Jog(b)) => b,
        other => panic!("{text}: {other:?}"),
    };
    let b = jog("$J=G91 G21 X-10 F1000");
    assert_eq!(
        (b.motion, b.distance, b.units),
        (MotionMode::Linear, Distance::Relative, Units::Mm)
    );
    assert_eq!(b.axis(AxisWord::X), Some(-10_000_000));
    assert_eq!(jog("$j=x-1 z2 f60").f, Milli(60_000));
    assert_eq!(jog("$J=G53 X0 F100").non_modal, NonModal::AbsoluteOverride);
    assert_eq!(parse("$$"), Ok(Input::System(SystemLine::PrintSettings)));
    assert_eq!(
        parse("$ G ; state"),
        Ok(Input::System(SystemLine::ParserState))
    );
    assert_eq!(parse("$#"), Ok(Input::System(SystemLine::Offsets)));
}

/// `$` lines (Grbl's `system.c`): commands, settings and the texts kept.
#[test]
fn system_lines() {
    let set = |key: &str, value: &str| {
        Ok(Input::System(SystemLine::Set {
            key: key.try_into().unwrap(),
            value: value.try_into().unwrap(),
        }))
    };
    assert_eq!(parse(" $Q"), Ok(Input::System(SystemLine::QueueStats)));
    assert_eq!(parse("$s ; stack"), Ok(Input::System(SystemLine::Stack)));
    assert_eq!(parse("$X"), Ok(Input::System(SystemLine::Unlock)));
    assert_eq!(parse("$I"), Ok(Input::System(SystemLine::BuildInfo)));
    // Grbl's commands.md: `$N` "View startup blocks", `$C` "Check gcode
    // mode", `$SLP` "Enable Sleep Mode", `$RST=$`, `$RST=#`, `$RST=*`
    // "Restore Grbl settings and data to defaults".
    assert_eq!(parse("$N"), Ok(Input::System(SystemLine::StartupLines)));
    assert_eq!(parse("$C"), Ok(Input::System(SystemLine::CheckMode)));
    assert_eq!(parse("$SLP"), Ok(Input::System(SystemLine::Sleep)));
    for (text, what) in [
        ("$", Restore::Settings),
        ("#", Restore::Offsets),
        ("*", Restore::All),
    ] {
        let line = format!("$RST={text}");
        assert_eq!(parse(&line), Ok(Input::System(SystemLine::Restore(what))));
    }
    assert_eq!(parse("$N0=G20"), set("N0", "G20"));
    // 79 kept, comments and spaces not counted: the longest startup line.
    let longest = format!("G4P{}", "0".repeat(72));
    assert_eq!(
        parse(&format!("$N0= {longest} (a comment)")),
        set("N0", &longest)
    );
    // Grbl's help, and the texts `$N0=`, `$N1=`, `$I=` cleared.
    assert_eq!(parse("$"), Ok(Input::System(SystemLine::Help)));
    assert_eq!(parse("$N0="), set("N0", ""));
    assert_eq!(parse("$n1="), set("n1", ""));
    assert_eq!(parse("$I="), set("I", ""));
    assert_eq!(parse("$N1=G20 (inches) G90"), set("N1", "G20G90"));
    assert_eq!(parse("$ steps_c = 26.667"), set("steps_c", "26.667"));
    assert_eq!(parse("$100=80"), set("100", "80"));
    assert_eq!(parse("$Q=-1"), set("Q", "-1"));
    assert_eq!(
        parse("$abcdefghijklmnop=0123456789abcdef"),
        set("abcdefghijklmnop", "0123456789abcdef")
    );
    assert_eq!(
        parse(&format!("$$*{}", xor("$$"))),
        Ok(Input::System(SystemLine::PrintSettings))
    );
}

/// (line, Grbl's error, column) of `$` lines: all Grbl's 3 (`system.c`),
/// but a text to keep longer than is kept (14).
const BAD_SYSTEM: &[(&str, u8, u8)] = &[
    ("$Y", 3, 1),
    ("$$$", 3, 3),
    ("$=5", 3, 2),
    ("$key=", 3, 6),
    ("$a-b=1", 3, 3),
    ("$abcdefghijklmnopqrstuvwxy=1", 3, 26),
    // `$N0=` and 76 characters kept: 80, Grbl's line overflow
    // (`protocol.c` 141) before `$N0=` would see it.
    (
        "$N0=G1X12345678901234567890123456789012345678901234567890123456789012(c)34567890123",
        11,
        0,
    ),
    ("$N2=", 3, 5),
];

#[test]
fn bad_system_lines() {
    for (text, code, column) in BAD_SYSTEM {
        match parse(text) {
            Err(e) => assert_eq!(
                (e.code(), e.column().unwrap_or(0)),
                (*code, *column),
                "{text:?}"
            ),
            ok => panic!("{text:?}: {ok:?}"),
        }
    }
}

/// `M114` alone only reads: Grbl's G-code lock lets it by.
#[test]
fn m114_alone_only_reads() {
    assert!(block("M114").only_reads());
    assert!(block("N7 M114").only_reads());
    for text in ["M114 G0", "M114 X1", "M114 F100", "M400", "G4 P0", ""] {
        assert!(!block(text).only_reads(), "{text}");
    }
}

#[test]
fn card_lines() {
    assert_eq!(parse("M20"), Ok(Input::Card(CardLine::List)));
    assert_eq!(parse("N5 M524"), Ok(Input::Card(CardLine::Abort)));
    assert_eq!(parse("M1000"), Ok(Input::Card(CardLine::Recover)));
    match parse("M23 star drawing.gcode") {
        Ok(Input::Card(CardLine::Select(name))) => {
            assert_eq!(name.as_bytes(), b"star drawing.gcode")
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(code("M23"), Some(28));
    assert_eq!(code("M24 X1"), Some(36));
    assert_eq!(code("M24 M25"), Some(21));
    assert_eq!(code("G1 M24"), Some(21));
}

#[test]
fn realtime_bytes_act_wherever_they_fall() {
    let mut p = Parser::new();
    let out = push_all(&mut p, b"G0 X?1!\n");
    assert_eq!(
        out,
        [
            Ok(Input::Realtime(Realtime::Status)),
            Ok(Input::Realtime(Realtime::FeedHold)),
            Ok(Input::Block(block("G0X1"))),
        ]
    );
    // Ctrl-X drops the line so far.
    let out = push_all(&mut p, b"G0 X\x18G1 X1 F10\n");
    assert_eq!(out[0], Ok(Input::Realtime(Realtime::Reset)));
    assert_eq!(out[1], Ok(Input::Block(block("G1X1F10"))));
}

/// A decimal number of up to 9 digits and 6 decimals, as text, with its
/// value in millionths.
fn decimal() -> impl Strategy<Value = (String, i64)> {
    (any::<bool>(), 0u32..1000, 0u32..1_000_000, 0usize..=6).prop_map(|(neg, int, frac, places)| {
        let frac = frac / 10u32.pow(6 - places as u32);
        let text = match places {
            0 => format!("{}{int}", if neg { "-" } else { "" }),
            p => format!("{}{int}.{frac:0p$}", if neg { "-" } else { "" }),
        };
        let value = int as i64 * 1_000_000 + frac as i64 * 10i64.pow(6 - places as u32);
        (text, if neg { -value } else { value })
    })
}

proptest! {
    /// Numbers are kept as written: exact in millionths, never rounded
    /// to a thousandth.
    #[test]
    fn axis_words_are_exact((text, value) in decimal()) {
        let b = block(&format!("G1 X{text}"));
        prop_assert_eq!(b.axis(AxisWord::X), Some(value));
    }

    /// Whatever came before, every line end is answered once, errors are
    /// explained, and a good line parses after it.
    #[test]
    fn any_bytes_then_a_good_line(bytes in prop::collection::vec(any::<u8>(), 0..300)) {
        let mut p = Parser::new();
        for &b in &bytes {
            match p.push(b) {
                Some(Ok(Input::Realtime(r))) => prop_assert_eq!(Realtime::from_byte(b), Some(r)),
                Some(result) => {
                    prop_assert!(b == b'\n' || b == b'\r' || b == LINE_CUT);
                    if let Err(e) = result {
                        prop_assert!(!e.message().is_empty());
                    }
                }
                None => prop_assert!(Realtime::from_byte(b).is_none()),
            }
        }
        let out = push_all(&mut p, b"\rM400\n");
        prop_assert_eq!(out.last().cloned(), Some(Ok(Input::Block(block("M400")))));
    }
}

/// A line starting with `+` or `-` is seed 003's raw-step line, read
/// beside G-code and `$` lines in the same stream.
#[test]
fn a_seed_line_is_read_beside_gcode() {
    use crate::seed::SeedMove;
    let seed = |steps, pen_up| Ok(Input::Seed(Some(SeedMove { steps, pen_up })));
    assert_eq!(parse("+0615-0950n"), seed([615, -950], false));
    assert_eq!(parse("  -0615+0950U ; back"), seed([-615, 950], true));
    assert_eq!(
        parse("+0615-0950n*58"),
        Err(Error::new(ErrorKind::BadChecksum, 12))
    );
    for bad in ["+0615-0950", "+0615-0950k", "-", "+0615-0950nG1"] {
        assert_eq!(parse(bad), Ok(Input::Seed(None)), "{bad:?}");
    }
    let mut p = Parser::new();
    let out = push_all(&mut p, b"G1 X1\r\n+0001+0001u\n$$\n");
    assert!(matches!(out[0], Ok(Input::Block(_))));
    assert_eq!(out[1], seed([1, 1], true));
    assert!(matches!(out[2], Ok(Input::System(_))));
}
