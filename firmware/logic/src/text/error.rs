//! What can be wrong with a value the machine reads as text: in a job
//! file, a `machine.txt` override, a `$` setting, or the configuration as a
//! whole. Printed as the tail of the one-line messages.

use taut_progmem::{text, Text};
use ufmt::{uDisplay, uWrite, uwrite, Formatter};

/// What went wrong. Messages are short: on the AVR every string lives in SRAM.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorKind {
    /// No file of that name on the card (reported by the card reader).
    NotFound,
    /// Nothing but blanks and comments.
    Empty,
    /// A `key = value` line longer than [`crate::files::kv::MAX_LINE`].
    LineTooLong,
    /// A line that is neither blank, a comment nor `key = value`.
    ExpectedKeyValue,
    UnknownKey,
    /// `machine = ` names none of the five.
    UnknownMachine,
    DuplicateKey,
    /// A required key never appeared; carries its names as `name/alias`.
    MissingKey(taut_progmem::Text),
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
    Invalid(taut_progmem::Text),
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
        machine: crate::machine::Machine,
        max_us: u32,
    },
}

impl ErrorKind {
    /// The variant's number, in order of declaration: its message's lead
    /// in [`ErrorKind::lead`].
    fn index(&self) -> usize {
        use ErrorKind::*;
        match self {
            NotFound => 0,
            Empty => 1,
            LineTooLong => 2,
            ExpectedKeyValue => 3,
            UnknownKey => 4,
            UnknownMachine => 5,
            DuplicateKey => 6,
            MissingKey(_) => 7,
            NotANumber => 8,
            TooBig => 9,
            Range { .. } => 10,
            Shape { .. } => 11,
            RadiusTooSmall { .. } => 12,
            ExpectedComma => 13,
            Nail { .. } => 14,
            Count { .. } => 15,
            Invalid(_) => 16,
            Utf16 => 17,
            NotText { .. } => 18,
            PulseTooLong { .. } => 19,
        }
    }

    /// The message's text up to its figures (the whole of it for most): a
    /// flash table, not a `match` of texts (~15 bytes of code an arm).
    fn lead(&self) -> Text {
        taut_progmem::table!(Text; 20; [
            text!("file not found"),
            text!("empty file"),
            text!("line too long (max 64)"),
            text!("expected key = value"),
            text!("unknown key"),
            text!("unknown machine"),
            text!("duplicate key"),
            text!("missing key "),
            text!("expected a number"),
            text!("number too big"),
            text!("expected "),
            text!("expected 0 or 3 to "),
            text!("expected more than "),
            text!("expected ','"),
            text!("nail "),
            text!("declared "),
            text!("invalid "),
            text!("UTF-16 text: save it as UTF-8 or ASCII"),
            text!("not a text file (byte "),
            text!("pulse over half a step at "),
        ])
        .get(self.index())
    }
}

// Every literal through `text!`: kept in flash on the AVR.
impl uDisplay for ErrorKind {
    fn fmt<W: uWrite + ?Sized>(&self, f: &mut Formatter<'_, W>) -> Result<(), W::Error> {
        self.lead().fmt(f)?;
        match *self {
            ErrorKind::MissingKey(name) | ErrorKind::Invalid(name) => name.fmt(f),
            ErrorKind::Range { min, max } => uwrite!(f, "{}{}{}", min, text!(" to "), max),
            ErrorKind::Shape { max } => uwrite!(f, "{}", max),
            ErrorKind::RadiusTooSmall { above_um } => {
                write_um_as_cm(f, above_um)?;
                text!(" cm").fmt(f)
            }
            ErrorKind::Nail { index, nails } => uwrite!(
                f,
                "{}{}{}{}",
                index,
                text!(" out of range (nails: "),
                nails,
                text!(")")
            ),
            ErrorKind::Count { declared, found } => {
                uwrite!(f, "{}{}{}", declared, text!(" connections, found "), found)
            }
            ErrorKind::NotText { byte } => uwrite!(f, "{}{}", byte, text!(")")),
            ErrorKind::PulseTooLong {
                axis,
                machine,
                max_us,
            } => uwrite!(
                f,
                "{}{}{}{}",
                machine.channel(axis),
                text!("_max_rate: "),
                max_us,
                text!(" us at most")
            ),
            _ => Ok(()),
        }
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

    #[test]
    fn every_kind_has_its_message() {
        use crate::axis::Axis;
        use crate::machine::Machine;
        use ErrorKind::*;
        let name = text!("shape");
        let cases = [
            (NotFound, "file not found"),
            (Empty, "empty file"),
            (LineTooLong, "line too long (max 64)"),
            (ExpectedKeyValue, "expected key = value"),
            (UnknownKey, "unknown key"),
            (UnknownMachine, "unknown machine"),
            (DuplicateKey, "duplicate key"),
            (MissingKey(name), "missing key shape"),
            (NotANumber, "expected a number"),
            (TooBig, "number too big"),
            (Range { min: 1, max: 9 }, "expected 1 to 9"),
            (Shape { max: 8 }, "expected 0 or 3 to 8"),
            (
                RadiusTooSmall { above_um: 35_000 },
                "expected more than 3.5 cm",
            ),
            (ExpectedComma, "expected ','"),
            (
                Nail { index: 7, nails: 5 },
                "nail 7 out of range (nails: 5)",
            ),
            (
                Count {
                    declared: 3,
                    found: 2,
                },
                "declared 3 connections, found 2",
            ),
            (Invalid(name), "invalid shape"),
            (Utf16, "UTF-16 text: save it as UTF-8 or ASCII"),
            (NotText { byte: 0 }, "not a text file (byte 0)"),
            (
                PulseTooLong {
                    axis: Axis::Base,
                    machine: Machine::StringArt,
                    max_us: 4,
                },
                "pulse over half a step at base_max_rate: 4 us at most",
            ),
        ];
        for (i, (kind, message)) in cases.iter().enumerate() {
            assert_eq!(kind.index(), i);
            assert_eq!(show(kind), *message);
        }
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
