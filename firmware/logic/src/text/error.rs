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

// Every literal through `text!`: kept in flash on the AVR.
impl uDisplay for ErrorKind {
    fn fmt<W: uWrite + ?Sized>(&self, f: &mut Formatter<'_, W>) -> Result<(), W::Error> {
        let t = |f: &mut Formatter<'_, W>, t: Text| t.fmt(f);
        match *self {
            ErrorKind::NotFound => t(f, text!("file not found")),
            ErrorKind::Empty => t(f, text!("empty file")),
            ErrorKind::LineTooLong => t(f, text!("line too long (max 64)")),
            ErrorKind::ExpectedKeyValue => t(f, text!("expected key = value")),
            ErrorKind::UnknownKey => t(f, text!("unknown key")),
            ErrorKind::UnknownMachine => t(f, text!("unknown machine")),
            ErrorKind::DuplicateKey => t(f, text!("duplicate key")),
            ErrorKind::MissingKey(key) => uwrite!(f, "{}{}", text!("missing key "), key),
            ErrorKind::NotANumber => t(f, text!("expected a number")),
            ErrorKind::TooBig => t(f, text!("number too big")),
            ErrorKind::Range { min, max } => {
                uwrite!(f, "{}{}{}{}", text!("expected "), min, text!(" to "), max)
            }
            ErrorKind::Shape { max } => uwrite!(f, "{}{}", text!("expected 0 or 3 to "), max),
            ErrorKind::RadiusTooSmall { above_um } => {
                t(f, text!("expected more than "))?;
                write_um_as_cm(f, above_um)?;
                t(f, text!(" cm"))
            }
            ErrorKind::ExpectedComma => t(f, text!("expected ','")),
            ErrorKind::Nail { index, nails } => uwrite!(
                f,
                "{}{}{}{}{}",
                text!("nail "),
                index,
                text!(" out of range (nails: "),
                nails,
                text!(")")
            ),
            ErrorKind::Count { declared, found } => uwrite!(
                f,
                "{}{}{}{}",
                text!("declared "),
                declared,
                text!(" connections, found "),
                found
            ),
            ErrorKind::Invalid(field) => uwrite!(f, "{}{}", text!("invalid "), field),
            ErrorKind::Utf16 => t(f, text!("UTF-16 text: save it as UTF-8 or ASCII")),
            ErrorKind::NotText { byte } => {
                uwrite!(
                    f,
                    "{}{}{}",
                    text!("not a text file (byte "),
                    byte,
                    text!(")")
                )
            }
            ErrorKind::PulseTooLong {
                axis,
                machine,
                max_us,
            } => uwrite!(
                f,
                "{}{}{}{}{}",
                text!("pulse over half a step at "),
                machine.channel(axis),
                text!("_max_rate: "),
                max_us,
                text!(" us at most")
            ),
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
    fn centimetres_print_only_needed_decimals() {
        let cm = |um| show(&ErrorKind::RadiusTooSmall { above_um: um });
        assert_eq!(cm(35_000), "expected more than 3.5 cm");
        assert_eq!(cm(43_284), "expected more than 4.3284 cm");
        assert_eq!(cm(40_000), "expected more than 4 cm");
        assert_eq!(cm(40_010), "expected more than 4.001 cm");
    }
}
