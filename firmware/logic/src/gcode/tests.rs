//! Host tests of the command line: tables of good and bad lines, and
//! property tests (round trip through text, random bytes).

mod bad_lines;
mod good_lines;
mod properties;
mod render;

use super::*;
use crate::fat::Name;
use crate::units::Milli;
use std::format;
use std::vec::Vec;

/// Every non-`None` result of pushing `bytes`.
fn push_all(parser: &mut Parser, bytes: &[u8]) -> Vec<Result<Input, Error>> {
    bytes.iter().filter_map(|&b| parser.push(b)).collect()
}

/// The result of one line: `text` and a newline into a fresh parser, which
/// must answer exactly once (at its line end: the newline, or a `\r` that
/// ends `text`).
fn parse(text: &str) -> Result<Input, Error> {
    let mut parser = Parser::new();
    let mut out = push_all(&mut parser, format!("{text}\n").as_bytes());
    assert_eq!(out.len(), 1, "{text:?} answered {out:?}");
    out.remove(0)
}

/// XOR of the bytes of `text`: the checksum Marlin hosts append.
fn xor(text: &str) -> u8 {
    text.bytes().fold(0, |x, b| x ^ b)
}

/// Builders for expected lines.
fn line(command: Command) -> Line {
    Line {
        command,
        ..Line::EMPTY
    }
}

trait Build {
    fn at(self, word: AxisWord, milli: i32) -> Line;
    fn f(self, milli: i32) -> Line;
    fn p(self, milli: i32) -> Line;
    fn n(self, n: u32) -> Line;
    fn distance(self, d: Distance) -> Line;
}

impl Build for Line {
    fn at(mut self, word: AxisWord, milli: i32) -> Line {
        self.axes[word.index()] = Some(Milli(milli)).into();
        self
    }
    fn f(self, milli: i32) -> Line {
        Line {
            f: Some(Milli(milli)).into(),
            ..self
        }
    }
    fn p(self, milli: i32) -> Line {
        Line {
            p: Some(Milli(milli)).into(),
            ..self
        }
    }
    fn n(self, n: u32) -> Line {
        Line { n: Some(n), ..self }
    }
    fn distance(self, d: Distance) -> Line {
        Line {
            distance: Some(d),
            ..self
        }
    }
}
