//! The serial command line: a streaming G-code parser, Grbl's dialect with
//! Marlin's line numbers and checksums.
//!
//! [`Parser::push`] takes one received byte at a time and holds no line
//! buffer: a line is parsed as it arrives, so the only cost of a long line
//! is the [`MAX_LINE`] limit. No heap, no floats: numbers become
//! [`Milli`](crate::units::Milli) digit by digit.
//!
//! The dialect:
//! - A line ends at `\n`; `\r` is ignored. Longer than [`MAX_LINE`]
//!   characters → error 11, and the rest is dropped up to the newline.
//! - Letters are case-insensitive. Spaces may stand between words and
//!   between a letter and its number (`G1X10 Y-2.5F600`, `X 10`), but end a
//!   number (`X1 0` is an error, unlike Grbl). `;` to the end of the line
//!   and `( … )` are comments and also end a number.
//! - Numbers: optional sign, digits, optional point; three decimals kept,
//!   the fourth rounds half away from zero; beyond ±2147483.647 → error 2.
//! - `N` (0..=9 999 999) may stand anywhere. `*<0..=255>` is Marlin's
//!   checksum, the XOR of every byte before it; after it only spaces and a
//!   `;` comment may follow.
//! - G/M numbers are matched exactly in thousandths: `G1` = `G01` =
//!   `G1.0`; `G38.2` and other unknown numbers → error 20.
//! - One command per line, plus `G90`/`G91` (see [`Line`]).
//! - A line whose first character is `$` is a [`SystemLine`].
//! - `?`, `!`, `~` and Ctrl-X are [`Realtime`] wherever they appear.
//!
//! Errors carry Grbl's numbers (see [`ErrorKind`]) and the column of the
//! offending character.

mod error;
mod line;
mod number;
mod parser;
mod status;
mod system;
mod words;

#[cfg(test)]
mod tests;

pub use error::{Error, ErrorKind, MIN_FEED};
pub use line::{
    AxisWord, CardLine, Command, Distance, Input, Line, Plane, Realtime, Units, AXIS_WORDS,
};
pub use number::parse_milli;
pub use parser::{Parser, Read, MAX_LINE};
pub use status::{Extra, Overrides, Refresh, State, Status, OVERRIDE_BYTES};
pub use system::{Restore, SystemLine, SystemText, SystemValue, SYSTEM_TEXT, SYSTEM_VALUE};
