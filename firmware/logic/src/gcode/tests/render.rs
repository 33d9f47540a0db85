//! Prints a [`Line`] back to G-code in one of the many spellings the parser
//! must accept, steered by a list of random choices.

use super::*;
use std::{format, string::String, string::ToString, vec::Vec};

/// Random choices, consumed in turn (cycling; all zero when empty).
pub(super) struct Choices<'a> {
    bytes: &'a [u8],
    next: usize,
}

impl<'a> Choices<'a> {
    pub(super) fn new(bytes: &'a [u8]) -> Self {
        Choices { bytes, next: 0 }
    }

    /// A choice in `0..n`.
    fn pick(&mut self, n: usize) -> usize {
        let b = self.bytes.get(self.next % self.bytes.len().max(1)).copied();
        self.next += 1;
        b.unwrap_or(0) as usize % n
    }

    fn flip(&mut self) -> bool {
        self.pick(2) == 1
    }
}

/// `letter` in either case.
fn letter(c: &mut Choices, l: u8) -> char {
    let l = l as char;
    if c.flip() {
        l.to_ascii_lowercase()
    } else {
        l
    }
}

/// A fixed-point value: sign, optional leading zeros, trailing zeros.
fn number(c: &mut Choices, m: Milli) -> String {
    let mut s = String::new();
    if m.0 < 0 {
        s.push('-');
    } else if c.flip() {
        s.push('+');
    }
    let magnitude = m.0.unsigned_abs();
    let (int, frac) = (magnitude / 1000, magnitude % 1000);
    match c.pick(3) {
        0 if int == 0 && frac != 0 => {} // `.5`
        1 => s.push_str(&format!("00{int}")),
        _ => s.push_str(&int.to_string()),
    }
    let mut decimals = format!("{frac:03}");
    if c.flip() {
        decimals.push_str("000"); // more digits, all zero: no rounding
    }
    if c.flip() {
        decimals = decimals.trim_end_matches('0').into();
    }
    if !decimals.is_empty() || c.flip() {
        s.push('.');
    }
    s + &decimals
}

fn command_words(command: Command) -> Option<(u8, &'static [&'static str])> {
    Some(match command {
        Command::Empty => return None,
        Command::Rapid => (b'G', &["0", "00", "0.0"]),
        Command::Linear => (b'G', &["1", "01", "1."]),
        Command::ArcCw => (b'G', &["2", "02"]),
        Command::ArcCcw => (b'G', &["3", "03.0"]),
        Command::Dwell => (b'G', &["4", "04"]),
        Command::SetPosition => (b'G', &["92", "92.000"]),
        Command::EnableDrivers => (b'M', &["17"]),
        Command::DisableDrivers => (b'M', &["18", "84"]),
        Command::ReportPosition => (b'M', &["114"]),
        Command::WaitIdle => (b'M', &["400", "0400"]),
        Command::Home => (b'G', &["28", "28.0"]),
        Command::Pause => (b'M', &["0", "00", "1"]),
        Command::PenDown => (b'M', &["3", "03"]),
        Command::PenUp => (b'M', &["5", "05.0"]),
        Command::Servo => (b'M', &["300"]),
    })
}

/// The words of `line`, each as text, in random order.
fn words(c: &mut Choices, line: &Line) -> Vec<String> {
    let mut words = Vec::new();
    let mut word = |c: &mut Choices, l: u8, value: String| {
        let space = if c.pick(4) == 0 { " " } else { "" };
        words.push(format!("{}{space}{value}", letter(c, l)));
    };
    if let Some(n) = line.n {
        word(c, b'N', n.to_string());
    }
    if let Some((l, spellings)) = command_words(line.command) {
        let spelling = spellings[c.pick(spellings.len())];
        word(c, l, spelling.into());
    }
    if let Some(d) = line.distance {
        word(
            c,
            b'G',
            if d == Distance::Absolute { "90" } else { "91" }.into(),
        );
    }
    for w in AxisWord::ALL {
        if let Some(m) = line.axis(w) {
            let text = number(c, m);
            word(c, w.letter(), text);
        }
    }
    if let Some(u) = line.units {
        let number = match u {
            Units::Inch => "20",
            Units::Mm => "21",
        };
        word(c, b'G', number.into());
    }
    if let Some(p) = line.plane {
        let number = match p {
            Plane::Xy => "17",
            Plane::Zx => "18",
            Plane::Yz => "19",
        };
        word(c, b'G', number.into());
    }
    let [i, j, k] = line.offsets;
    for (l, value) in [
        (b'F', line.f),
        (b'P', line.p),
        (b'I', i),
        (b'J', j),
        (b'K', k),
        (b'R', line.r),
        (b'S', line.s),
    ] {
        let value = value.get();
        if let Some(m) = value {
            let text = number(c, m);
            word(c, l, text);
        }
    }
    for i in (1..words.len()).rev() {
        words.swap(i, c.pick(i + 1));
    }
    words
}

/// What may stand between words.
fn separator(c: &mut Choices) -> &'static str {
    ["", " ", "  ", "\t", "(c)", " (a*b) "][c.pick(6)]
}

/// `line` as text (without the newline) and, when one was appended, its
/// checksum.
pub(super) fn render(c: &mut Choices, line: &Line) -> (String, Option<u8>) {
    let mut text = String::from(separator(c));
    for w in words(c, line) {
        text.push_str(&w);
        text.push_str(separator(c));
    }
    let checksum = c.flip().then(|| xor(&text));
    if let Some(ck) = checksum {
        text.push_str(&format!("*{ck}"));
    }
    if c.flip() {
        text.push_str(" ;end");
    }
    if c.flip() {
        text.push('\r');
    }
    (text, checksum)
}
