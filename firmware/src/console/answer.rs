//! The console's answers: `ok` or `error:<code>` to a line (to the
//! sender, a startup line's echo, or the card print's log), and a line's
//! own `[MSG:…]`.

use super::{system, Console, Source};
use crate::reply;
use taut_logic::gcode::Error;

impl Console {
    /// An accepted line's `(MSG, …)` text, as grblHAL says it: before
    /// the line's `ok` (a pen change's `M0` names the next pen so).
    #[inline(never)]
    pub(super) fn say_message(&self) {
        let text = self.parser.message().text();
        if !text.is_empty() {
            let mut r = crate::log::Line::message();
            r.push_all(text);
            r.send();
        }
    }

    /// `ok` to a line, unless it is a pattern's (answered at its end) or
    /// the card's.
    pub(super) fn ok(&self) {
        if self.pattern.is_none() && self.source != Some(Source::Card) {
            self.answer_ok();
        }
    }

    /// `ok`, or a startup line's `>line:ok`.
    pub(super) fn answer_ok(&self) {
        match self.source {
            Some(Source::Startup) => system::startup_reply(self.echo, None),
            _ => reply::ok(),
        }
    }

    /// An error: the answer to the line, or to the pattern, which stops,
    /// or in the log with the card's file and line.
    pub(super) fn error(&mut self, e: &Error) {
        self.error_because(e, None);
    }

    pub(super) fn error_because(&mut self, e: &Error, why: Option<taut_logic::text::ErrorKind>) {
        self.pattern = None;
        match self.source {
            Some(Source::Card) => self.print.line_failed(e, why),
            Some(Source::Startup) => system::startup_reply(self.echo, Some(e)),
            _ => reply::error_because(e, why),
        }
    }
}
