//! The one error type of every job file: which file, where, and what was
//! expected, printed as a single log line `file:line:col: message`.

use ufmt::{uDisplay, uWrite, uwrite, Formatter};

/// The files the machine reads from the card.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileName {
    Param,
    Poradi,
    Machine,
}

impl FileName {
    /// The 8.3 name on the card (matched case-insensitively).
    pub const fn name(self) -> &'static str {
        match self {
            FileName::Param => "param.txt",
            FileName::Poradi => "poradi.txt",
            FileName::Machine => "machine.txt",
        }
    }
}

/// What went wrong. Messages are short: on the AVR every string lives in SRAM.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorKind {
    /// No file of that name on the card (reported by the card reader).
    NotFound,
    /// Nothing but blanks and comments.
    Empty,
    /// A `key = value` line longer than [`crate::job::kv::MAX_LINE`].
    LineTooLong,
    /// A line that is neither blank, a comment nor `key = value`.
    ExpectedKeyValue,
    UnknownKey,
    DuplicateKey,
    /// A required key never appeared; carries its names as `name/alias`.
    MissingKey(&'static str),
    NotANumber,
    /// More digits than the value's type holds.
    TooBig,
    /// A whole number outside `min..=max`.
    Range {
        min: u32,
        max: u32,
    },
    /// A shape that is neither 0 (circle) nor a polygon with 3..=max corners.
    Shape {
        max: u32,
    },
    /// A board radius that leaves no room for the nail margin and the
    /// winding needle: it must be more than `above_um`.
    RadiusTooSmall {
        above_um: u32,
    },
    /// Numbers in `poradi.txt` are separated by commas.
    ExpectedComma,
    /// A nail index not below the number of nails.
    Nail {
        index: u32,
        nails: u16,
    },
    /// The first number of `poradi.txt` does not match the indices that follow.
    Count {
        declared: u32,
        found: u32,
    },
    /// The machine configuration as a whole is inconsistent (names the field).
    Invalid(&'static str),
    /// The file is UTF-16 (starts with its byte-order mark).
    Utf16,
    /// A control byte no text file holds (a binary file, or UTF-16
    /// without its mark).
    NotText {
        byte: u8,
    },
    /// The step pulse does not fit half the step period at an axis's
    /// highest rate: at most `max_us`.
    PulseTooLong {
        axis: crate::axis::Axis,
        max_us: u32,
    },
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
    pub const fn at(file: FileName, line: u32, col: u32, kind: ErrorKind) -> Self {
        FileError {
            file,
            line,
            col,
            kind,
        }
    }

    /// An error about the whole file, printed without line and column.
    pub const fn whole(file: FileName, kind: ErrorKind) -> Self {
        Self::at(file, 0, 0, kind)
    }
}

impl uDisplay for ErrorKind {
    fn fmt<W: uWrite + ?Sized>(&self, f: &mut Formatter<'_, W>) -> Result<(), W::Error> {
        match *self {
            ErrorKind::NotFound => f.write_str("file not found"),
            ErrorKind::Empty => f.write_str("empty file"),
            ErrorKind::LineTooLong => f.write_str("line too long (max 64)"),
            ErrorKind::ExpectedKeyValue => f.write_str("expected key = value"),
            ErrorKind::UnknownKey => f.write_str("unknown key"),
            ErrorKind::DuplicateKey => f.write_str("duplicate key"),
            ErrorKind::MissingKey(key) => uwrite!(f, "missing key {}", key),
            ErrorKind::NotANumber => f.write_str("expected a number"),
            ErrorKind::TooBig => f.write_str("number too big"),
            ErrorKind::Range { min, max } => uwrite!(f, "expected {} to {}", min, max),
            ErrorKind::Shape { max } => uwrite!(f, "expected 0 or 3 to {}", max),
            ErrorKind::RadiusTooSmall { above_um } => {
                f.write_str("expected more than ")?;
                write_um_as_cm(f, above_um)?;
                f.write_str(" cm")
            }
            ErrorKind::ExpectedComma => f.write_str("expected ','"),
            ErrorKind::Nail { index, nails } => {
                uwrite!(f, "nail {} out of range (nails: {})", index, nails)
            }
            ErrorKind::Count { declared, found } => {
                uwrite!(f, "declared {} connections, found {}", declared, found)
            }
            ErrorKind::Invalid(field) => uwrite!(f, "invalid {}", field),
            ErrorKind::Utf16 => f.write_str("UTF-16 text: save it as UTF-8 or ASCII"),
            ErrorKind::NotText { byte } => uwrite!(f, "not a text file (byte {})", byte),
            ErrorKind::PulseTooLong { axis, max_us } => uwrite!(
                f,
                "pulse over half a step at {}_max_rate: {} us at most",
                axis.name(),
                max_us
            ),
        }
    }
}

impl uDisplay for FileError {
    fn fmt<W: uWrite + ?Sized>(&self, f: &mut Formatter<'_, W>) -> Result<(), W::Error> {
        f.write_str(self.file.name())?;
        if self.line != 0 {
            uwrite!(f, ":{}:{}", self.line, self.col)?;
        }
        uwrite!(f, ": {}", self.kind)
    }
}

/// `40.2` for 402000 µm: whole centimetres, then only the decimals needed.
fn write_um_as_cm<W: uWrite + ?Sized>(f: &mut Formatter<'_, W>, um: u32) -> Result<(), W::Error> {
    uwrite!(f, "{}", um / 10_000)?;
    let mut frac = um % 10_000;
    if frac != 0 {
        f.write_char('.')?;
        let mut digit = 1000;
        while frac != 0 {
            f.write_char((b'0' + (frac / digit) as u8) as char)?;
            frac %= digit;
            digit /= 10;
        }
    }
    Ok(())
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::string::String;

    /// Collects ufmt output for assertions.
    pub struct Text(pub String);

    impl uWrite for Text {
        type Error = core::convert::Infallible;
        fn write_str(&mut self, s: &str) -> Result<(), Self::Error> {
            self.0.push_str(s);
            Ok(())
        }
    }

    pub fn show<T: uDisplay>(value: &T) -> String {
        let mut t = Text(String::new());
        uwrite!(t, "{}", value).unwrap();
        t.0
    }

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

    #[test]
    fn centimetres_print_only_needed_decimals() {
        let cm = |um| show(&ErrorKind::RadiusTooSmall { above_um: um });
        assert_eq!(cm(35_000), "expected more than 3.5 cm");
        assert_eq!(cm(43_284), "expected more than 4.3284 cm");
        assert_eq!(cm(40_000), "expected more than 4 cm");
        assert_eq!(cm(40_010), "expected more than 4.001 cm");
    }
}
