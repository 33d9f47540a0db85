use super::*;
use std::{format, string::String};

/// (line, Grbl error code, column)
const BAD: &[(&str, u8, u8)] = &[
    ("10", 1, 1),
    ("G1 #", 1, 4),
    ("X1 0", 1, 4),
    ("G1 X", 2, 5),
    ("GX1", 2, 2),
    ("G1 X1.2.3", 2, 8),
    ("G1 X--1", 2, 6),
    ("G1 X1-", 2, 6),
    ("G1 X2147483.648", 2, 15),
    ("G1 X99999999", 2, 11),
    ("$Y", 3, 1),
    ("$$$", 3, 3),
    ("$=5", 3, 2),
    ("$key=", 3, 6),
    ("$a-b=1", 3, 3),
    ("$abcdefghijklmnopqrstuvwxy=1", 3, 26),
    // A startup line longer than Grbl keeps (`$N0=` and 75 characters).
    (
        "$N0=G1X1234567890123456789012345678901234567890123456789012345678901234567890123",
        14,
        80,
    ),
    ("$N2=", 3, 5),
    ("G1 X1 F-5", 4, 7),
    ("G4 P-1", 4, 4),
    ("G5 X1", 20, 1),
    ("G2 X1 I1 R1", 36, 7),
    ("G1 X1 I1", 36, 7),
    ("G17 G18", 21, 5),
    ("G38.2 Z-1", 20, 1),
    ("G1.5 X1", 20, 1),
    ("M7", 20, 1),
    ("M23", 28, 1),
    ("M23   ", 28, 1),
    ("M23 abcdefghijklmnopqrstuvwxyz.gcode", 65, 31),
    ("M24 X1", 31, 5),
    ("M20 S1", 36, 5),
    ("M24 F100", 36, 1),
    ("M24 M25", 21, 5),
    ("G1 M24", 21, 4),
    ("M25 G1", 21, 5),
    ("G1 Q5", 20, 4),
    ("G1 X1 A5", 20, 7),
    // Grbl's jogging.md: "Only the following G-codes are valid ... G20,
    // G21 ... G90, G91 ... G53"; "F - Feed rate value" and at least one
    // axis word are required.
    ("$J=G1 X1 F100", 16, 4),
    ("$J=G91 X1 P1 F100", 16, 11),
    ("$J=G17 X1 F100", 16, 1),
    ("$J=M20", 16, 4),
    ("$J=G91 X1", 22, 10),
    ("$J=G91 F100", 26, 12),
    ("$J=", 26, 4),
    ("$RST=x", 3, 6),
    ("G0 G1 X1", 21, 4),
    ("G1 G1 X1", 21, 4),
    ("G90 G91", 21, 5),
    ("M17 M18", 21, 5),
    ("G4 P1 G1 X1", 21, 7),
    ("G1 G92 X0", 24, 4),
    ("G92 G0 X0", 24, 5),
    ("G1 X10 X20", 25, 8),
    ("G1 F1 f2", 25, 7),
    ("N1 N2", 25, 4),
    ("G92", 26, 1),
    ("G92 F1", 26, 1),
    ("N1.5 G1", 27, 3),
    ("N-1", 27, 2),
    ("N10000000", 27, 9),
    ("G4", 28, 1),
    ("G4 X1 P1", 31, 4),
    ("M17 X1", 31, 5),
    ("M114 C0", 31, 6),
    ("G1 X1 P1", 36, 7),
    ("P1", 36, 1),
    ("G1 X1*", 70, 6),
    ("G1 X1*256", 70, 9),
    ("G1 X1*1a", 70, 8),
    ("G1 X1*0", 70, 6),
];

#[test]
fn bad_lines() {
    for &(text, code, column) in BAD {
        let e = parse(text).expect_err(text);
        assert_eq!((e.code(), e.column()), (code, Some(column)), "{text:?}");
    }
}

#[test]
fn a_bad_line_does_not_spoil_the_next() {
    let mut parser = Parser::new();
    for &(text, code, _) in BAD {
        let out = push_all(&mut parser, format!("{text}\nG1 X1\n").as_bytes());
        assert_eq!(out.len(), 2, "{text:?}");
        assert_eq!(out[0].as_ref().map_err(Error::code), Err(code), "{text:?}");
        let ok = line(Command::Linear).at(AxisWord::X, 1_000);
        assert_eq!(out[1], Ok(Input::Line(ok)), "after {text:?}");
    }
}

#[test]
fn only_spaces_and_a_comment_may_follow_the_checksum() {
    let body = "G1 X1";
    let e = parse(&format!("{body}*{} X2", xor(body))).unwrap_err();
    assert_eq!((e.code(), e.column()), (70, Some(10)));
}

#[test]
fn a_corrupted_byte_is_reported_as_a_checksum_error() {
    // The sender computed the checksum of `N5 G1 X1`; `X` arrived as `#`.
    let ck = xor("N5 G1 X1");
    let e = parse(&format!("N5 G1 #1*{ck}")).unwrap_err();
    assert_eq!(
        (e.code(), e.column(), e.line_number()),
        (70, Some(9), Some(5))
    );
}

#[test]
fn errors_carry_the_line_number_for_a_resend() {
    let e = parse("N42 G5 X1").unwrap_err();
    assert_eq!((e.code(), e.line_number()), (20, Some(42)));
    assert_eq!(parse("G5 N42").unwrap_err().line_number(), None);
}

#[test]
fn overlong_lines_fail_at_column_81_and_the_next_line_parses() {
    let exactly: String = format!("G1 X1 ({})", "c".repeat(MAX_LINE as usize - 8));
    assert_eq!(exactly.len(), MAX_LINE as usize);
    assert!(parse(&exactly).is_ok());
    let long = format!("{exactly} G2 @#");
    let e = parse(&long).unwrap_err();
    assert_eq!((e.code(), e.column()), (11, Some(81)));
    let mut parser = Parser::new();
    let out = push_all(&mut parser, format!("{long}{long}\nM17\n").as_bytes());
    assert_eq!(out[0].as_ref().map_err(Error::code), Err(11));
    assert_eq!(out[1], Ok(Input::Line(line(Command::EnableDrivers))));
}

#[test]
fn cr_lf_and_crlf_each_end_one_line() {
    let mut parser = Parser::new();
    let out = push_all(&mut parser, b"M17\rM18\nM114\r\nM400\r\r\n\n");
    let lines: Vec<_> = out
        .iter()
        .map(|r| {
            r.as_ref().map(|i| match i {
                Input::Line(l) => l.command,
                _ => Command::Empty,
            })
        })
        .collect();
    use Command::*;
    assert_eq!(
        lines,
        [
            Ok(EnableDrivers),
            Ok(DisableDrivers),
            Ok(ReportPosition),
            Ok(WaitIdle),
            Ok(Empty),
            Ok(Empty)
        ]
    );
}

/// A `ufmt` writer into a host string.
struct Text(String);

impl ufmt::uWrite for Text {
    type Error = core::convert::Infallible;
    fn write_str(&mut self, s: &str) -> Result<(), Self::Error> {
        self.0.push_str(s);
        Ok(())
    }
}

#[test]
fn errors_print_grbl_style() {
    let mut out = Text(String::new());
    let e = parse("G1 X10 X20").unwrap_err();
    ufmt::uwrite!(out, "{}\n", e).unwrap();
    let e = Error::new(ErrorKind::UndefinedFeedRate, 0);
    ufmt::uwrite!(out, "{}", e).unwrap();
    assert_eq!(
        out.0,
        "error:25 Repeated word (col 8)\nerror:22 Undefined feed rate"
    );
}
