//! Where the console's lines come from: the serial line, or a plotter's
//! card print (its buttons, its messages and its `M20`…`M27` lines), a
//! serial line going by between the card's.

use super::{Console, Source};
use crate::board::usart;
use crate::motion::Motion;
use crate::queues::{BUTTONS, RX};
use taut_logic::config::MachineConfig;
use taut_logic::gcode::{CardLine, Error, ErrorKind, Parser, LINE_CUT};

impl Console {
    /// The next byte of the line being read: a line from the card, or
    /// from the serial line once it has arrived whole while a print runs
    /// (its lines are not cut into by the card's).
    #[inline(never)]
    pub(super) fn next_byte(&mut self) -> Option<u8> {
        if self.source == Some(Source::Card) && !self.print.running() {
            // The print stopped mid-line: the part read is dropped (a lost
            // print reads the line again).
            self.parser = Parser::new();
            self.source = None;
        }
        if !self.parser.mid_line() {
            self.source = Some(match self.print.running() && !serial_line_waits() {
                true => Source::Card,
                false => Source::Serial,
            });
        }
        let byte = match self.source {
            Some(Source::Card) => self.print.next_byte(),
            _ => usart::receive(),
        };
        if byte.is_none() {
            self.print.finished();
        }
        byte
    }

    /// A serial line while a print runs.
    pub(super) fn printing_from_serial(&self) -> bool {
        self.print.busy() && self.source != Some(Source::Card)
    }

    /// A plotter's buttons and card messages; `true` while a card command
    /// still waits for the reader.
    #[inline(never)]
    pub(super) fn card_news(&mut self, m: &mut Motion) -> bool {
        while let Some(event) = BUTTONS.pop() {
            self.print.button(event, m);
        }
        let waited = self.print.waiting();
        match self.print.take_messages() {
            Some(Ok(())) => self.ok(),
            Some(Err(kind)) => self.error(&Error::new(kind, 0)),
            None => return waited,
        }
        false
    }

    /// `M20`, `M23`…: a plotter's card print (the string-art job owns the
    /// card on its machine; a file cannot run card commands).
    #[inline(never)]
    pub(super) fn card_line(&mut self, c: CardLine, m: &mut Motion, cfg: &MachineConfig) {
        if cfg.machine.is_string_art() || self.source == Some(Source::Card) {
            return self.error(&Error::new(ErrorKind::UnsupportedCommand, 1));
        }
        match self.print.command(c, m) {
            Err(kind) => self.error(&Error::new(kind, 0)),
            // Answered when the reader has.
            Ok(()) if self.print.waiting() => {}
            Ok(()) => self.ok(),
        }
    }
}

/// A whole line has arrived on the serial line.
pub(super) fn serial_line_waits() -> bool {
    RX.any(|&b| b == b'\n' || b == b'\r' || b == LINE_CUT)
}
