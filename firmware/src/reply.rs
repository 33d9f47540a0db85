//! Console replies: `ok`, `error:<code>` after its message, reports. A reply line is
//! assembled on the stack and queued whole, never cut: it runs only once
//! the TX ring has [`ROOM`] free bytes, and no reply is longer.

use crate::board::port::{self, Port};
use crate::log::Line;
use crate::{flash_str, texts};
use taut_logic::gcode::Error;
use taut_logic::text::ErrorKind;
use ufmt::{uWrite, uwrite};

/// Room for the longest reply, newlines included: a line (`M114` at the
/// extremes of three axes is 93 bytes), or an error's message line and
/// its `error:<code>` line.
pub const ROOM: usize = crate::log::LINE + "error:255\n".len();

/// A reply line being assembled (the log's line type: see `Line::bare`).
pub type Reply = Line;

pub fn line() -> Reply {
    Line::bare()
}

/// There is room in the answered port's TX ring for any reply.
pub fn room() -> bool {
    room_on(port::answer())
}

/// There is room in `port`'s TX ring for any reply.
pub fn room_on(port: Port) -> bool {
    port.tx_free() >= ROOM
}

/// Grbl 1.1's greeting, at power-on and after Ctrl-X: what senders wait
/// for (grbl-streamer looks for `Grbl `, UGS and CNCjs for the version).
/// On every port: a reset concerns both senders.
pub fn banner() {
    Port::each(|port| {
        let mut r = Line::to(port);
        let _ = uwrite!(r, "{}", flash_str!("Grbl 1.1h ['$' for help]"));
        r.send();
    });
}

/// `ALARM:<n>`, Grbl's alarm numbers (3: reset while in motion), on
/// every port: the machine is locked for both senders.
pub fn alarm(n: u8) {
    Port::each(|port| {
        let mut r = Line::to(port);
        let _ = uwrite!(r, "{}{}", flash_str!("ALARM:"), n);
        r.send();
    });
}

pub fn ok() {
    port::answer().send(b"ok\n");
}

/// `error:<code> <text> (col <c>)`.
pub fn error(e: &Error) {
    error_because(e, None);
}

/// `[MSG:<text>[: <why>] (col <c>)]`, then Grbl's bare `error:<code>`:
/// senders read the code from a line of its own (CNCjs takes the rest of
/// the line as the number), people the message; `why` from the settings'
/// and job files' own errors. Both fit in [`ROOM`].
#[inline(never)]
pub fn error_because(e: &Error, why: Option<ErrorKind>) {
    let mut r = Line::message();
    let _ = uwrite!(r, "{}", texts::error(e.kind()));
    if let Some(why) = why {
        let _ = uwrite!(r, ": {}", why);
    }
    if let Some(c) = e.column() {
        let _ = uwrite!(r, "{}{})", flash_str!(" (col "), c);
    }
    r.send();
    let mut r = line();
    let _ = uwrite!(r, "{}{}", flash_str!("error:"), e.code());
    r.send();
}

/// `error:<code> <text>[: <why>]`: an error as the console and a card
/// print's log both word it.
pub struct Because<'a>(pub &'a Error, pub Option<ErrorKind>);

impl ufmt::uDisplay for Because<'_> {
    fn fmt<W: uWrite + ?Sized>(&self, f: &mut ufmt::Formatter<'_, W>) -> Result<(), W::Error> {
        let Because(e, why) = self;
        uwrite!(
            f,
            "{}{} {}",
            flash_str!("error:"),
            e.code(),
            texts::error(e.kind())
        )?;
        match why {
            Some(why) => uwrite!(f, ": {}", why),
            None => Ok(()),
        }
    }
}
