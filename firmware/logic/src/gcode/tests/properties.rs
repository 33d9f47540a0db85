use super::render::{render, Choices};
use super::*;
use crate::units::MaybeMilli;
use proptest::prelude::*;
use std::{format, string::String, vec::Vec};

fn milli() -> impl Strategy<Value = Milli> {
    prop_oneof![-i32::MAX..=i32::MAX, -100_000i32..100_000].prop_map(Milli)
}

fn command() -> impl Strategy<Value = Command> {
    prop::sample::select(&Command::ALL[..])
}

fn plane() -> impl Strategy<Value = Option<Plane>> {
    prop::option::of(prop_oneof![
        Just(Plane::Xy),
        Just(Plane::Zx),
        Just(Plane::Yz)
    ])
}

/// Any line the parser can produce, its words consistent with its command.
fn any_line() -> impl Strategy<Value = Line> {
    let distance = prop::option::of(prop_oneof![
        Just(Distance::Absolute),
        Just(Distance::Relative)
    ]);
    let axes = prop::array::uniform4(prop::option::weighted(0.4, milli()));
    let positive = (0..=i32::MAX).prop_map(Milli);
    (
        command(),
        distance,
        axes,
        prop::option::of(positive.clone()),
        positive,
        prop::option::of(0u32..=9_999_999),
        (
            plane(),
            prop::array::uniform3(prop::option::of(milli())),
            milli(),
            any::<bool>(),
        ),
        (
            prop::option::of(prop_oneof![Just(Units::Inch), Just(Units::Mm)]),
            prop::option::of(0..=180_000i32),
        ),
    )
        .prop_map(
            |(
                command,
                distance,
                mut axes,
                f,
                p,
                n,
                (plane, mut offsets, r, radius),
                (units, s),
            )| {
                let takes_axes = command.uses_axes() || command == Command::Empty;
                if !takes_axes {
                    axes = [None; AXIS_WORDS];
                } else if command == Command::SetPosition && axes.iter().all(Option::is_none) {
                    axes[AxisWord::Z.index()] = Some(Milli(0));
                }
                let p = (command == Command::Dwell).then_some(p);
                // `R` or offsets, and only on an arc (or a line of axis words).
                let arc = matches!(command, Command::ArcCw | Command::ArcCcw | Command::Empty);
                let r = (arc && radius).then_some(r);
                if !arc || radius {
                    offsets = [None; 3];
                }
                // `S` only with `M3` (optional) and `M300` (required).
                let s = match command {
                    Command::Servo => Some(Milli(s.unwrap_or(90_000))),
                    Command::PenDown => s.map(Milli),
                    _ => None,
                };
                Line {
                    n,
                    checksum: None,
                    distance,
                    plane,
                    units,
                    command,
                    axes: axes.map(MaybeMilli::new),
                    f: f.into(),
                    p: p.into(),
                    offsets: offsets.map(MaybeMilli::new),
                    r: r.into(),
                    s: s.into(),
                }
            },
        )
}

/// The reference: `int.frac` (frac as typed) rounded to thousandths, half
/// away from zero, or `None` beyond i32.
fn reference(negative: bool, int: u64, frac: &str) -> Option<i32> {
    let digits = format!("{frac:0<4}");
    let thousandths: u64 = digits[..3].parse().unwrap();
    let round = (digits.as_bytes()[3] >= b'5') as u64;
    let magnitude = int * 1000 + thousandths + round;
    let m = i32::try_from(magnitude).ok()?;
    Some(if negative { -m } else { m })
}

proptest! {
    #[test]
    fn printed_lines_parse_back(line in any_line(), choices in prop::collection::vec(any::<u8>(), 0..64)) {
        let (text, checksum) = render(&mut Choices::new(&choices), &line);
        let result = parse(&text);
        if text.trim_end_matches('\r').len() > MAX_LINE as usize {
            prop_assert_eq!(result.map_err(|e| (e.code(), e.column())), Err((11, Some(81))));
        } else {
            prop_assert_eq!(result, Ok(Input::Line(Line { checksum, ..line })), "{:?}", text);
        }
    }

    #[test]
    fn numbers_round_half_away_from_zero(
        negative: bool,
        int in prop_oneof![0u64..3_000_000, 0u64..10],
        frac in "[0-9]{0,7}",
    ) {
        let text = format!("G1 X{}{int}.{frac}", if negative { "-" } else { "" });
        let expected = reference(negative, int, &frac);
        match parse(&text) {
            Ok(Input::Line(l)) => prop_assert_eq!(l.axis(AxisWord::X).map(|m| m.0), expected),
            other => {
                prop_assert_eq!(expected, None);
                prop_assert_eq!(other.map_err(|e| e.code()), Err(2));
            }
        }
    }

    #[test]
    fn random_bytes_never_panic_and_each_newline_answers_once(
        bytes in prop::collection::vec(prop_oneof![any::<u8>(), prop::sample::select(&b"GXN*;() 1.-\n\r$="[..])], 0..300),
    ) {
        let mut parser = Parser::new();
        let mut lines = 0;
        for &b in &bytes {
            match parser.push(b) {
                Some(Ok(Input::Realtime(r))) => prop_assert_eq!(Realtime::from_byte(b), Some(r)),
                Some(_) => {
                    prop_assert!(b == b'\n' || b == b'\r');
                    lines += 1;
                }
                None => prop_assert!(Realtime::from_byte(b).is_none()),
            }
        }
        // Line ends: every `\r`, and every `\n` not right after one
        // (realtime bytes in between do not count).
        let line_bytes: Vec<u8> =
            bytes.iter().copied().filter(|&b| Realtime::from_byte(b).is_none()).collect();
        let ends = line_bytes
            .iter()
            .enumerate()
            .filter(|&(i, &b)| b == b'\r' || (b == b'\n' && (i == 0 || line_bytes[i - 1] != b'\r')))
            .count();
        prop_assert_eq!(lines, ends);
        // Whatever came before, the parser is clean after the next line end
        // (a `\n` right after a `\r` ends none).
        let out: Vec<_> = b"\rG91 G1 C1\n".iter().filter_map(|&b| parser.push(b)).collect();
        let expected = line(Command::Linear).distance(Distance::Relative).at(AxisWord::C, 1_000);
        prop_assert_eq!(out.len(), 2);
        prop_assert_eq!(&out[1], &Ok(Input::Line(expected)));
    }

    #[test]
    fn columns_point_into_the_line(text in "[ -~]{0,90}") {
        if let Err(e) = parse(&String::from_iter(text.chars().filter(|c| !"?!~".contains(*c)))) {
            let column = e.column().expect("parser errors have a column");
            prop_assert!((1..=MAX_LINE + 1).contains(&column));
        }
    }
}
