//! Where in a file a byte is: 1-based line and column, a UTF-8 byte-order
//! mark at the very start skipped. Shared by every job-file tokenizer, so
//! chunk boundaries cannot change a reported position.

const BOM: [u8; 3] = [0xEF, 0xBB, 0xBF];

/// What to do with a byte fed to the [`Cursor`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Feed {
    /// Part of the byte-order mark: drop it.
    Skip,
    /// Process these bytes held back as a possible mark (they were not one),
    /// then the byte itself.
    Pass { held: &'static [u8] },
}

#[derive(Clone, Copy, Debug)]
pub struct Cursor {
    /// Bytes of the mark matched so far; `u8::MAX` once past the start.
    bom: u8,
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
            line: 1,
            col: 0,
        }
    }

    /// First look at a byte from the file: is it part of the leading mark?
    pub fn feed(&mut self, b: u8) -> Feed {
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
        if starts_char(b, self.col) {
            self.col += 1;
        }
        let here = (self.line, self.col);
        if b == b'\n' {
            self.line += 1;
            self.col = 0;
        }
        here
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
