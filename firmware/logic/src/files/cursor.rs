//! Where in a file a byte is: 1-based line and column, a UTF-8 byte-order
//! mark at the very start skipped, lines ended by LF, CR or CRLF (files
//! saved on old Macs end lines in CR only). Shared by every job-file
//! tokenizer, so chunk boundaries cannot change a reported position. It
//! also tells a text file from what is not one: UTF-16 (a byte-order mark
//! `FF FE` / `FE FF`), or a control byte no text file holds.

use crate::text::ErrorKind;

const BOM: [u8; 3] = [0xEF, 0xBB, 0xBF];

/// What to do with a byte fed to the [`Cursor`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Feed {
    /// Part of the byte-order mark: drop it.
    Skip,
    /// Process these bytes held back as a possible mark (they were not one),
    /// then the byte itself.
    Pass { held: &'static [u8] },
    /// Not a text file this machine reads: stop at this byte.
    Bad(ErrorKind),
}

#[derive(Clone, Copy, Debug)]
pub struct Cursor {
    /// Bytes of the mark matched so far; `u8::MAX` once past the start.
    bom: u8,
    /// The first byte of the file, while the second is awaited.
    first: Option<u8>,
    /// The last byte processed was a CR: a LF now ends no other line.
    after_cr: bool,
    line: u32,
    /// Characters seen on this line; the column of the last one.
    col: u32,
}

impl Default for Cursor {
    fn default() -> Self {
        Self::new()
    }
}

impl Cursor {
    pub const fn new() -> Self {
        Cursor {
            bom: 0,
            first: None,
            after_cr: false,
            line: 1,
            col: 0,
        }
    }

    /// First look at a byte from the file: is it part of the leading mark,
    /// or a sign that this is no text file?
    pub fn feed(&mut self, b: u8) -> Feed {
        let utf16 = matches!(
            (self.first.take(), b),
            (Some(0xFF), 0xFE) | (Some(0xFE), 0xFF)
        );
        if self.line == 1 && self.col == 0 && self.bom == 0 {
            self.first = Some(b);
        }
        if utf16 {
            return Feed::Bad(ErrorKind::Utf16);
        }
        if b < 0x20 && !matches!(b, b'\t' | b'\n' | b'\r') {
            return Feed::Bad(ErrorKind::NotText { byte: b });
        }
        let matched = self.bom as usize;
        if matched < BOM.len() {
            if b == BOM[matched] {
                self.bom += 1;
                return Feed::Skip;
            }
            self.bom = u8::MAX;
            return Feed::Pass {
                held: &BOM[..matched],
            };
        }
        Feed::Pass { held: &[] }
    }

    /// Account for a byte being processed; returns its (line, column).
    /// Columns count characters: UTF-8 continuation bytes share their
    /// character's column (see [`starts_char`]), so no byte is in column 0.
    pub fn advance(&mut self, b: u8) -> (u32, u32) {
        let crlf = core::mem::replace(&mut self.after_cr, b == b'\r') && b == b'\n';
        if crlf {
            // The LF of a CRLF: the line ended at its CR.
            return (self.line - 1, 0);
        }
        if starts_char(b, self.col) {
            self.col += 1;
        }
        let here = (self.line, self.col);
        if Self::ends_line(b) {
            self.line += 1;
            self.col = 0;
        }
        here
    }

    /// `b` ends a line (a CR, or a LF that follows none).
    pub fn ends_line(b: u8) -> bool {
        matches!(b, b'\n' | b'\r')
    }

    /// Where the next byte would be: the end-of-file position at the end.
    pub fn next_pos(&self) -> (u32, u32) {
        (self.line, self.col + 1)
    }
}

/// Whether byte `b`, after `col` characters of its line, starts a character:
/// any byte but a UTF-8 continuation byte, and also a stray continuation byte
/// at the start of a line (invalid UTF-8; it has no character to join).
pub fn starts_char(b: u8, col: u32) -> bool {
    b & 0xC0 != 0x80 || col == 0
}

/// The number of characters in `line`, the start of a line.
pub fn chars(line: &[u8]) -> u32 {
    line.iter()
        .fold(0, |n, &b| n + u32::from(starts_char(b, n)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::vec::Vec;

    /// Feeds a whole file; returns the bytes processed with their positions.
    fn run(bytes: &[u8]) -> Vec<(u8, u32, u32)> {
        let mut c = Cursor::new();
        let mut out = Vec::new();
        for &b in bytes {
            if let Feed::Pass { held } = c.feed(b) {
                for &h in held.iter().chain(core::iter::once(&b)) {
                    let (line, col) = c.advance(h);
                    out.push((h, line, col));
                }
            }
        }
        out
    }

    #[test]
    fn bom_is_skipped_only_at_the_start() {
        let out = run(b"\xEF\xBB\xBFa\n\xEF\xBB\xBF");
        assert_eq!(out[0], (b'a', 1, 1));
        assert_eq!(out[1], (b'\n', 1, 2));
        assert_eq!(out.len(), 5, "a mark after the start is data");
        assert_eq!(out[2], (0xEF, 2, 1));
    }

    #[test]
    fn broken_bom_is_replayed_as_data() {
        let out = run(b"\xEF\xBBx");
        let bytes: Vec<u8> = out.iter().map(|o| o.0).collect();
        assert_eq!(bytes, b"\xEF\xBBx");
        assert_eq!(out[2], (b'x', 1, 2), "0xEF 0xBB is one (broken) character");
    }

    #[test]
    fn lf_cr_and_crlf_each_end_one_line() {
        let out = run(b"a\nb\rc\r\nd");
        let at = |ch: u8| out.iter().find(|o| o.0 == ch).map(|o| (o.1, o.2));
        assert_eq!(at(b'b'), Some((2, 1)));
        assert_eq!(at(b'c'), Some((3, 1)));
        assert_eq!(at(b'd'), Some((4, 1)));
    }

    #[test]
    fn utf16_and_control_bytes_are_not_text() {
        let mut c = Cursor::new();
        assert!(matches!(c.feed(0xFF), Feed::Pass { .. }));
        assert_eq!(c.feed(0xFE), Feed::Bad(ErrorKind::Utf16));
        let mut c = Cursor::new();
        assert_eq!(c.feed(b'1'), Feed::Pass { held: &[] });
        assert_eq!(c.feed(0), Feed::Bad(ErrorKind::NotText { byte: 0 }));
        // `FF FE` after the start is just bad UTF-8, left to the parser.
        let mut c = Cursor::new();
        c.feed(b'a');
        c.advance(b'a');
        c.feed(0xFF);
        assert!(matches!(c.feed(0xFE), Feed::Pass { .. }));
    }

    #[test]
    fn columns_count_characters() {
        let out = run("ě=1".as_bytes());
        assert_eq!(out[2], (b'=', 1, 2));
        assert_eq!(chars("ě=1".as_bytes()), 3);
    }

    #[test]
    fn stray_continuation_bytes_start_a_line_in_column_1() {
        let out = run(b"a\n\x88\x88=");
        assert_eq!(out[2], (0x88, 2, 1));
        assert_eq!(out[3], (0x88, 2, 1));
        assert_eq!(out[4], (b'=', 2, 2));
        assert_eq!(chars(b"\x88\x88="), 2);
    }
}
