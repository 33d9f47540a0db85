//! The one error type of every job file: which file, where, and what was
//! expected, printed as a single log line `file:line:col: message`.

use crate::text::ErrorKind;
use taut_progmem::{text, Text};
use ufmt::{uDisplay, uWrite, uwrite, Formatter};

/// The files the machine reads from the card.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileName {
    Param,
    Poradi,
    Machine,
}

impl FileName {
    /// The 8.3 name on the card (matched case-insensitively); in flash.
    pub fn name(self) -> Text {
        match self {
            FileName::Param => text!("param.txt"),
            FileName::Poradi => text!("poradi.txt"),
            FileName::Machine => text!("machine.txt"),
        }
    }
}

/// An error in a job file. `line == 0` means the whole file (no position).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FileError {
    pub file: FileName,
    /// 1-based line; 0 for errors about the whole file.
    pub line: u32,
    /// 1-based column in characters.
    pub col: u32,
    pub kind: ErrorKind,
}

impl FileError {
    #[inline(always)]
    pub const fn at(file: FileName, line: u32, col: u32, kind: ErrorKind) -> Self {
        FileError {
            file,
            line,
            col,
            kind,
        }
    }

    /// An error about the whole file, printed without line and column.
    #[inline(always)]
    pub const fn whole(file: FileName, kind: ErrorKind) -> Self {
        Self::at(file, 0, 0, kind)
    }
}

impl uDisplay for FileError {
    fn fmt<W: uWrite + ?Sized>(&self, f: &mut Formatter<'_, W>) -> Result<(), W::Error> {
        uwrite!(f, "{}", self.file.name())?;
        if self.line != 0 {
            uwrite!(f, ":{}:{}", self.line, self.col)?;
        }
        // Not `": "`: a string constant would sit in SRAM on the AVR.
        f.write_char(':')?;
        f.write_char(' ')?;
        uwrite!(f, "{}", self.kind)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::text::error::tests::show;
    use std::string::String;

    /// Parses `text` whole and in chunks of every size with
    /// `parse_in_chunks(bytes, chunk)`; all must agree. Errors as printed.
    pub fn in_every_chunking<T: PartialEq + core::fmt::Debug>(
        text: &str,
        parse_in_chunks: impl Fn(&[u8], usize) -> Result<T, FileError>,
    ) -> Result<T, String> {
        let whole = parse_in_chunks(text.as_bytes(), text.len().max(1));
        for chunk in 1..text.len() {
            assert_eq!(
                parse_in_chunks(text.as_bytes(), chunk),
                whole,
                "chunk {chunk}"
            );
        }
        whole.map_err(|e| show(&e))
    }

    #[test]
    fn one_line_per_error() {
        let e = FileError::at(
            FileName::Poradi,
            3,
            14,
            ErrorKind::Nail {
                index: 251,
                nails: 250,
            },
        );
        assert_eq!(
            show(&e),
            "poradi.txt:3:14: nail 251 out of range (nails: 250)"
        );
        let e = FileError::whole(FileName::Param, ErrorKind::Empty);
        assert_eq!(show(&e), "param.txt: empty file");
    }
}
