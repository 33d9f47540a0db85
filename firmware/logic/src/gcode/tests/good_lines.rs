use super::*;
use std::format;
use AxisWord::{C, X, Y, Z};

#[test]
fn good_lines() {
    use Command::*;
    let table: &[(&str, Line)] = &[
        ("", Line::EMPTY),
        ("   \t ", Line::EMPTY),
        ("(only a comment)", Line::EMPTY),
        ("; only a comment", Line::EMPTY),
        ("G0 X10", line(Rapid).at(X, 10_000)),
        (
            "G1X10 Y-2.5F600",
            line(Linear).at(X, 10_000).at(Y, -2_500).f(600_000),
        ),
        (
            "g1 x1.5 c-90 f60",
            line(Linear).at(X, 1_500).at(C, -90_000).f(60_000),
        ),
        ("G01 Z.5", line(Linear).at(Z, 500)),
        ("G1.0 Y-.25", line(Linear).at(Y, -250)),
        ("G1 X5.", line(Linear).at(X, 5_000)),
        ("G1 X00010.500", line(Linear).at(X, 10_500)),
        ("G1 X+3", line(Linear).at(X, 3_000)),
        ("G1 X1.23456", line(Linear).at(X, 1_235)),
        ("G1 X1.2344999", line(Linear).at(X, 1_234)),
        ("G1 X-1.0005", line(Linear).at(X, -1_001)),
        ("G1 X-0.0004", line(Linear).at(X, 0)),
        ("G1 X2147483.647", line(Linear).at(X, i32::MAX)),
        ("G1 X-2147483.647", line(Linear).at(X, -i32::MAX)),
        ("  G1 X 10 F 600", line(Linear).at(X, 10_000).f(600_000)),
        ("G1 (go) X1 ;done", line(Linear).at(X, 1_000)),
        ("G1 X(gap)1", line(Linear).at(X, 1_000)),
        ("G4 P0.5", line(Dwell).p(500)),
        ("G4 P2 F100", line(Dwell).p(2_000).f(100_000)),
        ("G90", line(Empty).distance(Distance::Absolute)),
        (
            "G91 G1 C1",
            line(Linear).distance(Distance::Relative).at(C, 1_000),
        ),
        (
            "G1 C1 G91",
            line(Linear).distance(Distance::Relative).at(C, 1_000),
        ),
        ("G92 X0 Z-0", line(SetPosition).at(X, 0).at(Z, 0)),
        ("M17", line(EnableDrivers)),
        ("M18", line(DisableDrivers)),
        ("m84", line(DisableDrivers)),
        ("M114", line(ReportPosition)),
        ("M400", line(WaitIdle)),
        ("N7 M114", line(ReportPosition).n(7)),
        ("M114 N9999999", line(ReportPosition).n(9_999_999)),
        ("F1200", line(Empty).f(1_200_000)),
        ("X10 Y5", line(Empty).at(X, 10_000).at(Y, 5_000)),
        ("G1 X1\r", line(Linear).at(X, 1_000)),
    ];
    for (text, expected) in table {
        assert_eq!(parse(text), Ok(Input::Line(*expected)), "{text:?}");
    }
}

#[test]
fn checksummed_lines_report_number_and_checksum() {
    let body = "N12 G1 X1";
    let ck = xor(body);
    let expected = line(Command::Linear).at(X, 1_000).n(12);
    let with = |tail: &str| parse(&format!("{body}*{ck}{tail}"));
    let checked = Line {
        checksum: Some(ck),
        ..expected
    };
    assert_eq!(with(""), Ok(Input::Line(checked)));
    assert_eq!(with("  ; trailing comment"), Ok(Input::Line(checked)));
    assert_eq!(with(";no space"), Ok(Input::Line(checked)));
    // The checksum covers comments and spaces before the `*` too.
    let body = "N3 (c) M400 ";
    let checked = Line {
        checksum: Some(xor(body)),
        ..line(Command::WaitIdle).n(3)
    };
    assert_eq!(
        parse(&format!("{body}*{}", xor(body))),
        Ok(Input::Line(checked))
    );
}

/// Jogs as senders write them (jogging.md's `$J=G91 X10 F100`; CNCjs
/// `$J=G91 G21 X-10 F1000`; UGS `$J=G21G91X1F100`; bCNC's feed far above
/// any rate; machine coordinates `G53`, which are taut's own), each read
/// as the `G1` it moves.
#[test]
fn jogs() {
    use Command::Linear;
    let jog = |text| match parse(text) {
        Ok(Input::Jog(line)) => line,
        other => panic!("{text}: {other:?}"),
    };
    let relative = |l: Line| l.distance(Distance::Relative);
    assert_eq!(
        jog("$J=G91 X10 F100"),
        relative(line(Linear).at(X, 10_000).f(100_000))
    );
    assert_eq!(
        jog("$j=x-1 z2 f60"),
        line(Linear).at(X, -1_000).at(Z, 2_000).f(60_000)
    );
    let cncjs = jog("$J=G91 G21 X-10 F1000");
    assert_eq!(cncjs.units, Some(Units::Mm));
    assert_eq!(
        cncjs,
        Line {
            units: Some(Units::Mm),
            ..relative(line(Linear).at(X, -10_000).f(1_000_000))
        }
    );
    let ugs = jog("$J=G21G91X1F100");
    assert_eq!(
        ugs,
        Line {
            units: Some(Units::Mm),
            ..relative(line(Linear).at(X, 1_000).f(100_000))
        }
    );
    assert_eq!(
        jog("$J=G91 Y1 F100000"),
        relative(line(Linear).at(Y, 1_000).f(100_000_000))
    );
    assert_eq!(jog("$J=G53 X0 F100"), line(Linear).at(X, 0).f(100_000));
    assert_eq!(
        parse("G53 G0 X0"),
        Ok(Input::Line(line(Command::Rapid).at(X, 0)))
    );
}

#[test]
fn system_lines() {
    let set = |key: &str, value: &str| {
        Ok(Input::System(SystemLine::Set {
            key: key.try_into().unwrap(),
            value: value.try_into().unwrap(),
        }))
    };
    assert_eq!(parse("$$"), Ok(Input::System(SystemLine::PrintSettings)));
    assert_eq!(parse(" $Q"), Ok(Input::System(SystemLine::QueueStats)));
    assert_eq!(parse("$s ; stack"), Ok(Input::System(SystemLine::Stack)));
    assert_eq!(parse("$X"), Ok(Input::System(SystemLine::Unlock)));
    assert_eq!(parse("$I"), Ok(Input::System(SystemLine::BuildInfo)));
    assert_eq!(parse("$g"), Ok(Input::System(SystemLine::ParserState)));
    assert_eq!(parse("$#"), Ok(Input::System(SystemLine::Offsets)));
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

#[test]
fn realtime_bytes_act_at_once_and_leave_the_line_alone() {
    let mut parser = Parser::new();
    let out = push_all(&mut parser, b"N1 G1 X1?0!~*");
    let status = |r| Ok(Input::Realtime(r));
    assert_eq!(
        out,
        [
            status(Realtime::Status),
            status(Realtime::FeedHold),
            status(Realtime::CycleStart)
        ]
    );
    // Not part of the line: neither of `X10` nor of the checksum.
    let ck = xor("N1 G1 X10");
    let out = push_all(&mut parser, format!("{ck}\n").as_bytes());
    let expected = Line {
        checksum: Some(ck),
        ..line(Command::Linear).at(X, 10_000).n(1)
    };
    assert_eq!(out, [Ok(Input::Line(expected))]);
}

#[test]
fn reset_drops_the_partial_line() {
    let mut parser = Parser::new();
    let out = push_all(&mut parser, b"G1 X1 Y\x18G0 C2\n");
    assert_eq!(
        out,
        [
            Ok(Input::Realtime(Realtime::Reset)),
            Ok(Input::Line(line(Command::Rapid).at(C, 2_000)))
        ]
    );
}

#[test]
fn parse_milli_reads_setting_values() {
    assert_eq!(parse_milli("26.6667"), Some(Milli(26_667)));
    assert_eq!(parse_milli("-2.5"), Some(Milli(-2_500)));
    assert_eq!(parse_milli("7"), Some(Milli(7_000)));
    assert_eq!(parse_milli(""), None);
    assert_eq!(parse_milli("-"), None);
    assert_eq!(parse_milli("1e3"), None);
    assert_eq!(parse_milli("2147483.648"), None);
}

#[test]
fn card_lines() {
    let select = |name: &str| {
        Ok(Input::Card(CardLine::Select(
            Name::new(name.as_bytes()).unwrap(),
        )))
    };
    assert_eq!(parse("M20"), Ok(Input::Card(CardLine::List)));
    assert_eq!(parse("m21"), Ok(Input::Card(CardLine::Mount)));
    assert_eq!(parse("N5 M24*16"), Ok(Input::Card(CardLine::Start)));
    assert_eq!(parse("M25 ; pause"), Ok(Input::Card(CardLine::Pause)));
    assert_eq!(parse("M27"), Ok(Input::Card(CardLine::Progress)));
    assert_eq!(parse("M524"), Ok(Input::Card(CardLine::Abort)));
    // The rest of the line is the name, in its case, the comment apart.
    assert_eq!(parse("M23 star.gcode"), select("star.gcode"));
    assert_eq!(parse("M23STAR.GCO ; the star"), select("STAR.GCO"));
    assert_eq!(parse("M23   My Drawing.nc  "), select("My Drawing.nc"));
    assert_eq!(parse("N7 M23 A1.NC*102"), select("A1.NC"));
}
