//! The serial command line: a streaming G-code parser, Grbl 1.1's dialect
//! (`protocol.c` and the first steps of `gcode.c`) with Marlin's line
//! checksums.
//!
//! [`Parser::push`] takes one received byte at a time and holds no line
//! buffer: a line is gathered word by word as it arrives. No heap, no
//! floats: numbers keep their digits and become nanometres or thousandths
//! once, when their word ends.
//!
//! The dialect, as Grbl reads it:
//! - A line ends at `\n`, `\r` or `\r\n`. Comments `( … )` and `;` to
//!   the end of the line are thrown away as they come, of any length; so
//!   are spaces, control bytes and `/` (Grbl's block delete, not
//!   supported: the line runs). More than [`MAX_LINE`] characters kept →
//!   error 11, after the line's end. A UTF-8 byte-order mark before a
//!   line's first character is skipped.
//! - Letters are case-insensitive; spaces count for nothing (`X1 0` is
//!   `X10`). A word is a letter and a number: an optional sign, digits,
//!   one point. `%` is no letter (error 1, as Grbl answers it).
//! - Words are gathered into a [`Block`] with Grbl's checks in the
//!   line's order: supported commands (20), whole numbers (23), two axis
//!   commands (24), modal groups (21), repeated words (25), negative
//!   `F N P S T` (4), `T` ≤ 255 (38), `N` ≤ 10 000 000 (27). The checks
//!   that need the modal state are the executor's
//!   ([`crate::interp`]).
//! - `*<0..=255>` is Marlin's checksum, the XOR of every byte before it;
//!   after it only spaces and a `;` comment may follow.
//! - A line whose first character is `$` is a [`SystemLine`]; `$J=` a jog;
//!   `+` or `-`, seed 003's raw-step line ([`crate::seed`]).
//! - `?`, `!`, `~` and Ctrl-X are [`Realtime`] wherever they appear.
//!
//! Errors carry Grbl's numbers (see [`ErrorKind`]) and, where the parser
//! finds them, the column of the offending character.

mod block;
mod error;
mod number;
mod parser;
mod status;
mod system;
mod words;

#[cfg(test)]
mod tests;

pub use block::{
    group, word, AxisCommand, AxisWord, Block, CardLine, Coolant, Distance, FeedMode, Flow, Input,
    MotionMode, NonModal, Plane, Realtime, Spindle, TautCode, ToolLength, Units, AXIS_WORDS,
};
pub use error::{Error, ErrorKind, MIN_FEED};
pub use number::{parse_milli, NANO_LIMIT};
pub use parser::{Message, Parser, Read, LINE_CUT, MAX_LINE, MSG_LEN};
pub use status::{coord_value, Extra, Overrides, Places, Refresh, State, Status, OVERRIDE_BYTES};
pub use system::{Restore, SystemLine, SystemText, SystemValue, SYSTEM_TEXT, SYSTEM_VALUE};
