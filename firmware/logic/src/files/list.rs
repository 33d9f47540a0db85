//! A comma-separated list of non-negative integers, read as a stream:
//! `3000,0,159,\r\n 251, 56,` — blanks and line breaks anywhere between
//! numbers, an optional trailing comma. O(1) memory.

use crate::files::cursor::{Cursor, Feed};
use crate::files::error::{FileError, FileName};
use crate::text::num::push_digit;
use crate::text::ErrorKind;

/// A number of the list and where its first digit is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Number {
    pub value: u32,
    pub line: u32,
    pub col: u32,
}

#[derive(Clone, Copy, Debug)]
enum State {
    /// At the start or after a comma: a number must come next.
    Before,
    /// Inside a number.
    In(Number),
    /// After a number and blanks: a comma must come next.
    After,
}

#[derive(Clone, Copy, Debug)]
pub struct List {
    file: FileName,
    cursor: Cursor,
    state: State,
    /// Any number seen: tells an empty file from a bad one.
    any: bool,
}

impl List {
    pub const fn new(file: FileName) -> Self {
        List {
            file,
            cursor: Cursor::new(),
            state: State::Before,
            any: false,
        }
    }

    /// Feeds one byte; returns the number it completes, if any.
    pub fn push(&mut self, b: u8) -> Result<Option<Number>, FileError> {
        match self.cursor.feed(b) {
            Feed::Skip => Ok(None),
            Feed::Bad(kind) => {
                let (line, col) = self.cursor.next_pos();
                Err(FileError::at(self.file, line, col, kind))
            }
            // Held bytes are not digits: they fail, never complete a number.
            Feed::Pass { held } => {
                for &h in held {
                    self.byte(h)?;
                }
                self.byte(b)
            }
        }
    }

    /// End of file: the last number if nothing followed it.
    pub fn finish(&mut self) -> Result<Option<Number>, FileError> {
        let last = match self.state {
            State::In(n) => Some(n),
            _ => None,
        };
        self.state = State::After;
        if !self.any {
            return Err(FileError::whole(self.file, ErrorKind::Empty));
        }
        Ok(last)
    }

    fn byte(&mut self, b: u8) -> Result<Option<Number>, FileError> {
        let (line, col) = self.cursor.advance(b);
        // One error built, only when it is one (a digit's was built
        // eagerly for every digit).
        let (line, col, kind) = match (self.state, b) {
            (State::In(n), b' ' | b'\t' | b'\r' | b'\n') => {
                self.state = State::After;
                return Ok(Some(n));
            }
            (_, b' ' | b'\t' | b'\r' | b'\n') => return Ok(None),
            (State::Before, b'0'..=b'9') => {
                self.any = true;
                let value = (b - b'0') as u32;
                self.state = State::In(Number { value, line, col });
                return Ok(None);
            }
            (State::In(mut n), b'0'..=b'9') => match push_digit(n.value, b) {
                Some(value) => {
                    n.value = value;
                    self.state = State::In(n);
                    return Ok(None);
                }
                None => (n.line, n.col, ErrorKind::TooBig),
            },
            (State::In(n), b',') => {
                self.state = State::Before;
                return Ok(Some(n));
            }
            (State::After, b',') => {
                self.state = State::Before;
                return Ok(None);
            }
            (State::Before, _) => (line, col, ErrorKind::NotANumber),
            (_, _) => (line, col, ErrorKind::ExpectedComma),
        };
        Err(FileError::at(self.file, line, col, kind))
    }
}
