//! `key = value` lines, read as a stream: bytes arrive in chunks of any
//! size and a line may span chunks, so only the current line is kept
//! (at most [`MAX_LINE`] bytes). Accepts `#` comments, blank lines, LF, CR
//! or CRLF line ends, blanks around `=` and a byte-order mark at the start.

use crate::files::cursor::{Cursor, Feed};
use crate::files::error::{FileError, FileName};
use crate::text::num::trim;
use crate::text::ErrorKind;

/// Longest line accepted, comment included, in characters.
pub const MAX_LINE: usize = 64;

/// One `key = value` line, both sides trimmed; columns are 1-based.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Item<'a> {
    pub key: &'a [u8],
    pub value: &'a [u8],
    pub line: u32,
    pub key_col: u32,
    pub value_col: u32,
}

pub struct KvReader {
    file: FileName,
    cursor: Cursor,
    /// The current line up to its comment.
    buf: [u8; MAX_LINE],
    len: u8,
    in_comment: bool,
    /// The line in `buf` is complete (its number); the next byte starts anew.
    ended: Option<u32>,
}

impl KvReader {
    pub const fn new(file: FileName) -> Self {
        KvReader {
            file,
            cursor: Cursor::new(),
            buf: [0; MAX_LINE],
            len: 0,
            in_comment: false,
            ended: None,
        }
    }

    /// Feeds one byte; returns the item of the line it completes, if any.
    pub fn push(&mut self, b: u8) -> Result<Option<Item<'_>>, FileError> {
        match self.cursor.feed(b) {
            Feed::Skip => return Ok(None),
            Feed::Bad(kind) => {
                let (line, col) = self.cursor.next_pos();
                return Err(FileError::at(self.file, line, col, kind));
            }
            // Held bytes are never a newline, so they cannot end a line.
            Feed::Pass { held } => {
                for &h in held {
                    self.byte(h)?;
                }
            }
        }
        self.byte(b)?;
        match self.ended {
            Some(line) => self.item(line),
            None => Ok(None),
        }
    }

    /// Feeds `chunk`, each line's item to `take` (`param.txt`'s values or
    /// `machine.txt`'s settings). Through `dyn`, not a generic: one copy
    /// of the reading loop for both files (two cost ~300 bytes more on
    /// the AVR).
    pub fn push_chunk(
        &mut self,
        chunk: &[u8],
        take: &mut dyn FnMut(Item<'_>) -> Result<(), FileError>,
    ) -> Result<(), FileError> {
        for &b in chunk {
            if let Some(item) = self.push(b)? {
                take(item)?;
            }
        }
        Ok(())
    }

    /// End of file: the item of a last line without a newline, if any.
    pub fn finish(&mut self) -> Result<Option<Item<'_>>, FileError> {
        if self.ended.is_some() {
            return Ok(None);
        }
        let (line, _) = self.cursor.next_pos();
        self.ended = Some(line);
        self.item(line)
    }

    fn byte(&mut self, b: u8) -> Result<(), FileError> {
        if self.ended.take().is_some() {
            self.len = 0;
            self.in_comment = false;
        }
        let (line, col) = self.cursor.advance(b);
        if Cursor::ends_line(b) {
            self.ended = Some(line);
            return Ok(());
        }
        // Only multi-byte characters can fill the buffer before the column
        // limit.
        let kept = !self.in_comment && b != b'#';
        let slot = match kept {
            true => self.buf.get_mut(self.len as usize),
            false => None,
        };
        if col as usize > MAX_LINE || kept && slot.is_none() {
            return Err(FileError::at(self.file, line, col, ErrorKind::LineTooLong));
        }
        if let Some(slot) = slot {
            *slot = b;
            self.len += 1;
        }
        self.in_comment |= b == b'#';
        Ok(())
    }

    /// The item of the completed line `line`, `None` for a blank line.
    fn item(&self, line: u32) -> Result<Option<Item<'_>>, FileError> {
        let text = &self.buf[..self.len as usize];
        let col = |offset: usize| 1 + super::cursor::chars(&text[..offset]);
        let (start, content) = trim(text);
        if content.is_empty() {
            return Ok(None);
        }
        // No `=` reads as an empty key: one error built, only when it is one.
        let eq = content.iter().position(|&b| b == b'=').unwrap_or(0);
        let (key_start, key) = trim(&content[..eq]);
        if key.is_empty() {
            let kind = ErrorKind::ExpectedKeyValue;
            return Err(FileError::at(self.file, line, col(start + eq), kind));
        }
        let (value_start, value) = trim(&content[eq + 1..]);
        Ok(Some(Item {
            key,
            value,
            line,
            key_col: col(start + key_start),
            value_col: col(start + eq + 1 + value_start),
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::string::String;
    use std::vec::Vec;

    type Owned = (String, String, u32, u32, u32);

    /// Feeds `text` byte by byte, collecting items or the error.
    fn read(text: &[u8]) -> Result<Vec<Owned>, FileError> {
        let own = |i: Item| {
            (
                String::from_utf8_lossy(i.key).into_owned(),
                String::from_utf8_lossy(i.value).into_owned(),
                i.line,
                i.key_col,
                i.value_col,
            )
        };
        let mut kv = KvReader::new(FileName::Param);
        let mut out = Vec::new();
        for &b in text {
            if let Some(item) = kv.push(b)? {
                out.push(own(item));
            }
        }
        if let Some(item) = kv.finish()? {
            out.push(own(item));
        }
        Ok(out)
    }

    fn item(key: &str, value: &str, line: u32, key_col: u32, value_col: u32) -> Owned {
        (key.into(), value.into(), line, key_col, value_col)
    }

    fn err(line: u32, col: u32, kind: ErrorKind) -> Result<Vec<Owned>, FileError> {
        Err(FileError::at(FileName::Param, line, col, kind))
    }

    #[test]
    fn lines_comments_and_blanks() {
        let text =
            b"\xEF\xBB\xBF# header\r\n\r\n  tvar = 0   # circle\r\n\tpocet_hrebiku=250\nx =\t40.2";
        assert_eq!(
            read(text),
            Ok(std::vec![
                item("tvar", "0", 3, 3, 10),
                item("pocet_hrebiku", "250", 4, 2, 16),
                item("x", "40.2", 5, 1, 5),
            ])
        );
    }

    #[test]
    fn bad_lines_are_located() {
        use ErrorKind::*;
        assert_eq!(read(b"tvar 0\n"), err(1, 1, ExpectedKeyValue));
        assert_eq!(read(b"\n  = 5\n"), err(2, 3, ExpectedKeyValue));
        let long = [b'#'; 65];
        assert_eq!(read(&long), err(1, 65, LineTooLong));
        assert!(read(&long[..64]).is_ok(), "64 characters fit");
        assert_eq!(
            read(std::format!("a = {}", "ě".repeat(31)).as_bytes()),
            err(1, 35, LineTooLong),
            "multi-byte characters may fill the buffer first"
        );
        // Found by the `param` fuzz target: the error was in column 0.
        assert_eq!(read(&[0x88; 65]), err(1, 1, LineTooLong));
        assert_eq!(read(b"\x88 5\n"), err(1, 1, ExpectedKeyValue));
    }

    #[test]
    fn empty_value_points_past_the_equals_sign() {
        assert_eq!(
            read(b"tvar =  \n"),
            Ok(std::vec![item("tvar", "", 1, 1, 7)])
        );
    }

    #[test]
    fn column_counts_characters_of_czech_comments() {
        let text = "# poloměr\nž = 1".as_bytes();
        assert_eq!(read(text), Ok(std::vec![item("ž", "1", 2, 1, 5)]));
    }

    proptest! {
        #[test]
        fn written_lines_read_back(
            lines in proptest::collection::vec(
                ("[a-z_]{1,12}", "[0-9./]{0,8}", "[ \t]{0,2}", "[ \t]{0,2}", "(#[ -~]{0,10})?", proptest::bool::ANY),
                0..8,
            ),
            bom in proptest::bool::ANY,
        ) {
            let mut text = String::from(if bom { "\u{FEFF}" } else { "" });
            let mut expected = Vec::new();
            for (n, (key, value, pad1, pad2, comment, crlf)) in lines.iter().enumerate() {
                let line = std::format!("{pad1}{key}{pad2}={pad1}{value}{pad2}{comment}");
                let key_col = 1 + pad1.len() as u32;
                // An empty value is located right after the `=`.
                let value_pad = if value.is_empty() { 0 } else { pad1.len() };
                let value_col = key_col + (key.len() + pad2.len() + 1 + value_pad) as u32;
                expected.push(item(key, value, n as u32 + 1, key_col, value_col));
                text += &line;
                text += if *crlf { "\r\n" } else { "\n" };
            }
            prop_assert_eq!(read(text.as_bytes()), Ok(expected));
        }
    }
}
