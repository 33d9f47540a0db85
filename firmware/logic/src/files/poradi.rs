//! `poradi.txt`: the winding order. The first number is the count of
//! connections C, then C nail indices follow, each below the number of
//! nails. Checked completely in one streaming pass before anything moves
//! ([`PoradiCheck`]), then streamed again while winding ([`PoradiReader`]):
//! O(C) reads in all, O(1) memory.

use crate::files::error::{FileError, FileName};
use crate::files::list::{List, Number};
use crate::text::ErrorKind;

/// Most connections a job may declare.
pub const MAX_CONNECTIONS: u32 = 1_000_000;

const FILE: FileName = FileName::Poradi;

/// The rules both passes share: count first, then indices in range.
struct Sequence {
    list: List,
    nails: u16,
    declared: Option<Number>,
    found: u32,
}

impl Sequence {
    const fn new(nails: u16) -> Self {
        Sequence {
            list: List::new(FILE),
            nails,
            declared: None,
            found: 0,
        }
    }

    /// Takes a number of the list; returns it if it is a nail index.
    fn take(&mut self, n: Number) -> Result<Option<u16>, FileError> {
        // No closure: called, its error would be a constant in SRAM. One
        // error built, for either case.
        let kind = match self.declared {
            None if (1..=MAX_CONNECTIONS).contains(&n.value) => {
                self.declared = Some(n);
                return Ok(None);
            }
            None => ErrorKind::Range {
                min: 1,
                max: MAX_CONNECTIONS,
            },
            Some(_) => {
                self.found += 1;
                if n.value < self.nails as u32 {
                    return Ok(Some(n.value as u16));
                }
                ErrorKind::Nail {
                    index: n.value,
                    nails: self.nails,
                }
            }
        };
        Err(FileError::at(FILE, n.line, n.col, kind))
    }

    fn push(&mut self, b: u8) -> Result<Option<u16>, FileError> {
        match self.list.push(b)? {
            Some(n) => self.take(n),
            None => Ok(None),
        }
    }

    /// End of file: the last index, if nothing followed it; then the count
    /// must match (reported at the count).
    fn finish(&mut self) -> Result<Option<u16>, FileError> {
        let last = match self.list.finish()? {
            Some(n) => self.take(n)?,
            None => None,
        };
        // A list that is not empty has a first number, the count. One
        // error built, for either case.
        let (line, col, kind) = match self.declared {
            None => (0, 0, ErrorKind::Empty),
            Some(d) if self.found != d.value => {
                let (declared, found) = (d.value, self.found);
                (d.line, d.col, ErrorKind::Count { declared, found })
            }
            Some(_) => return Ok(last),
        };
        Err(FileError::at(FILE, line, col, kind))
    }
}

/// The first pass: syntax, count and range, without keeping anything.
pub struct PoradiCheck {
    seq: Sequence,
}

impl PoradiCheck {
    pub const fn new(nails: u16) -> Self {
        PoradiCheck {
            seq: Sequence::new(nails),
        }
    }

    pub fn push(&mut self, chunk: &[u8]) -> Result<(), FileError> {
        for &b in chunk {
            self.seq.push(b)?;
        }
        Ok(())
    }

    /// The whole file was good: returns the number of connections.
    pub fn finish(&mut self) -> Result<u32, FileError> {
        self.seq.finish()?;
        Ok(self.seq.found)
    }
}

/// The second pass: the nail indices one by one, for winding.
pub struct PoradiReader {
    seq: Sequence,
}

impl PoradiReader {
    pub const fn new(nails: u16) -> Self {
        PoradiReader {
            seq: Sequence::new(nails),
        }
    }

    /// Reads `buf` up to the end of the next nail index: returns the bytes
    /// used and the index, or `None` if `buf` ran out first. Indices past
    /// the count are not refused here: the winder stops after the count
    /// [`PoradiCheck`] returned.
    pub fn next(&mut self, buf: &[u8]) -> Result<(usize, Option<u16>), FileError> {
        for (i, &b) in buf.iter().enumerate() {
            if let Some(nail) = self.seq.push(b)? {
                return Ok((i + 1, Some(nail)));
            }
        }
        Ok((buf.len(), None))
    }

    /// End of file: the last index if the file ends right after it.
    pub fn finish(&mut self) -> Result<Option<u16>, FileError> {
        self.seq.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text::error::tests::show;
    use proptest::prelude::*;
    use std::string::String;
    use std::vec::Vec;

    /// `text` cut at the given positions (taken modulo its length).
    fn pieces<'a>(text: &'a [u8], cuts: &[usize]) -> Vec<&'a [u8]> {
        let mut at: Vec<usize> = cuts.iter().map(|c| c % (text.len() + 1)).collect();
        at.extend([0, text.len()]);
        at.sort();
        at.windows(2).map(|w| &text[w[0]..w[1]]).collect()
    }

    fn check_pieces(pieces: &[&[u8]], nails: u16) -> Result<u32, FileError> {
        let mut c = PoradiCheck::new(nails);
        for part in pieces {
            c.push(part)?;
        }
        c.finish()
    }

    /// Reads all indices with the reader, fed piece by piece.
    fn read_pieces(pieces: &[&[u8]], nails: u16) -> Result<Vec<u16>, FileError> {
        let mut r = PoradiReader::new(nails);
        let mut out = Vec::new();
        for &(mut part) in pieces {
            while !part.is_empty() {
                let (used, nail) = r.next(part)?;
                out.extend(nail);
                part = &part[used..];
            }
        }
        out.extend(r.finish()?);
        Ok(out)
    }

    fn check_in_chunks(text: &[u8], nails: u16, chunk: usize) -> Result<u32, FileError> {
        check_pieces(&text.chunks(chunk).collect::<Vec<_>>(), nails)
    }

    fn read_in_chunks(text: &[u8], nails: u16, chunk: usize) -> Result<Vec<u16>, FileError> {
        read_pieces(&text.chunks(chunk).collect::<Vec<_>>(), nails)
    }

    /// Checks whole and in chunks of every size; all must agree.
    fn check(text: &str, nails: u16) -> Result<u32, String> {
        let whole = check_in_chunks(text.as_bytes(), nails, text.len().max(1));
        for chunk in 1..text.len() {
            assert_eq!(
                check_in_chunks(text.as_bytes(), nails, chunk),
                whole,
                "chunk {chunk}"
            );
        }
        whole.map_err(|e| show(&e))
    }

    #[test]
    fn good_files() {
        let good: &[(&str, u32)] = &[
            ("3,0,159,249", 3),
            ("3,0,159,249,", 3),
            ("\u{FEFF}3,\r\n0, 159 ,\r\n\t249 ,\r\n", 3),
            ("1\n,\n0\n", 1),
            ("  2 , 007 , 1  ", 2),
        ];
        for (text, count) in good {
            assert_eq!(check(text, 250), Ok(*count), "{text:?}");
        }
        let indices = read_in_chunks(b"\xEF\xBB\xBF3,\r\n0, 159 ,\r\n\t249", 250, 5);
        assert_eq!(indices, Ok(std::vec![0, 159, 249]));
    }

    #[test]
    fn bad_files_say_where_and_what() {
        let bad: &[(&str, &str)] = &[
            ("", "poradi.txt: empty file"),
            ("\u{FEFF} \r\n\r\n", "poradi.txt: empty file"),
            (
                "3000,0,159,251,56",
                "poradi.txt:1:12: nail 251 out of range (nails: 250)",
            ),
            (
                "3,\r\n0,\r\n  250",
                "poradi.txt:3:3: nail 250 out of range (nails: 250)",
            ),
            ("3,0,1", "poradi.txt:1:1: declared 3 connections, found 2"),
            (
                "\n 2,0,1,2,3,",
                "poradi.txt:2:2: declared 2 connections, found 4",
            ),
            ("5", "poradi.txt:1:1: declared 5 connections, found 0"),
            ("0", "poradi.txt:1:1: expected 1 to 1000000"),
            ("2,0,,1", "poradi.txt:1:5: expected a number"),
            (",2,0,1", "poradi.txt:1:1: expected a number"),
            ("2,0,-1", "poradi.txt:1:5: expected a number"),
            ("2,0,1,,", "poradi.txt:1:7: expected a number"),
            ("2,0 1", "poradi.txt:1:5: expected ','"),
            ("2,0\n1", "poradi.txt:2:1: expected ','"),
            ("2,0,1.5", "poradi.txt:1:6: expected ','"),
            ("2,0;1", "poradi.txt:1:4: expected ','"),
            ("2,0,12x", "poradi.txt:1:7: expected ','"),
            ("2,0,99999999999", "poradi.txt:1:5: number too big"),
            ("\u{FEFF}\u{FEFF}1,0", "poradi.txt:1:1: expected a number"),
            ("\u{EF}1,0", "poradi.txt:1:1: expected a number"),
        ];
        for (text, message) in bad {
            assert_eq!(check(text, 250), Err(String::from(*message)), "{text:?}");
        }
    }

    #[test]
    fn reader_stops_at_the_first_bad_index() {
        let err = read_in_chunks(b"3,1,2,250", 250, 2).unwrap_err();
        assert_eq!(
            show(&err),
            "poradi.txt:1:7: nail 250 out of range (nails: 250)"
        );
        let err = read_in_chunks(b"3,1,2", 250, 2).unwrap_err();
        assert_eq!(
            show(&err),
            "poradi.txt:1:1: declared 3 connections, found 2"
        );
    }

    /// A file as a generator would write it: random blanks and line breaks
    /// around the commas, CRLF or LF, maybe a mark and a trailing comma.
    fn written(indices: &[u16], gaps: &[(u8, u8)], bom: bool, trailing: bool) -> String {
        const BLANKS: [&str; 6] = ["", " ", "\n", "\r\n", "\t", "  \r\n "];
        let mut text = String::from(if bom { "\u{FEFF}" } else { "" });
        let count = indices.len().to_string();
        let numbers = core::iter::once(count).chain(indices.iter().map(|i| i.to_string()));
        for (k, number) in numbers.enumerate() {
            let (before, after) = gaps[k % gaps.len()];
            if k > 0 {
                text += BLANKS[before as usize % BLANKS.len()];
                text += ",";
            }
            text += BLANKS[after as usize % BLANKS.len()];
            text += &number;
        }
        if trailing {
            text += ",\r\n";
        }
        text
    }

    use std::string::ToString;

    proptest! {
        #[test]
        fn written_sequences_read_back(
            nails in 3u16..=10_000,
            raw in proptest::collection::vec(any::<u16>(), 1..200),
            gaps in proptest::collection::vec((any::<u8>(), any::<u8>()), 1..20),
            bom in proptest::bool::ANY,
            trailing in proptest::bool::ANY,
            cuts in proptest::collection::vec(any::<usize>(), 0..40),
        ) {
            let indices: Vec<u16> = raw.iter().map(|i| i % nails).collect();
            let text = written(&indices, &gaps, bom, trailing);
            let pieces = pieces(text.as_bytes(), &cuts);
            prop_assert_eq!(check_pieces(&pieces, nails), Ok(indices.len() as u32));
            prop_assert_eq!(read_pieces(&pieces, nails), Ok(indices));
        }

        #[test]
        fn chunk_boundaries_never_change_the_verdict(
            text in "[0-9, \r\n.x]{0,40}",
            nails in 3u16..300,
            cuts in proptest::collection::vec(any::<usize>(), 0..10),
        ) {
            let whole = check_in_chunks(text.as_bytes(), nails, text.len().max(1));
            let pieces = pieces(text.as_bytes(), &cuts);
            prop_assert_eq!(check_pieces(&pieces, nails), whole);
            // Both passes agree on every file the check accepts.
            if let Ok(count) = whole {
                let read = read_pieces(&pieces, nails).unwrap();
                prop_assert_eq!(read.len() as u32, count);
            }
        }
    }
}
