//! Where the console's lines come from: the serial ports (USB, UART1),
//! or a plotter's card print (its buttons, its messages and its
//! `M20`…`M27` lines), a serial line going by between the card's. A
//! serial line is read whole from the port it began on
//! (`port::next_line`) and answered there.

use super::{Console, Source};
use crate::board::port;
use crate::motion::Motion;
use crate::store::Store;
use taut_logic::checkpoint::plot::ResumeAction;
use taut_logic::config::MachineConfig;
use taut_logic::gcode::{CardLine, Error, ErrorKind};
use taut_logic::interp::motor_channels;
use taut_logic::kinematics::Kinematics;
use taut_logic::pinmap::Button;

impl Console {
    /// The next byte of the line being read: a line from the card, or
    /// from the serial line once it has arrived whole while a print runs
    /// (its lines are not cut into by the card's). Most bytes are the
    /// rest of a port's line: taken here, the rest out of line.
    #[inline]
    pub(super) fn next_byte(&mut self) -> Option<u8> {
        if !self.parser.mid_line() || self.source == Some(Source::Card) {
            return self.next_byte_other();
        }
        let byte = port::answer().receive();
        if byte.is_none() {
            self.print.finished();
        }
        byte
    }

    /// [`Console::next_byte`] between lines or from the card.
    #[inline(never)]
    fn next_byte_other(&mut self) -> Option<u8> {
        if self.source == Some(Source::Card) && !self.print.running() {
            // The print stopped mid-line: the part read is dropped (a lost
            // print reads the line again).
            self.parser.clear();
            self.source = None;
        }
        let mut port = Some(port::answer());
        if !self.parser.mid_line() {
            self.source = Some(match self.print.running() && !serial_line_waits() {
                true => Source::Card,
                false => Source::Serial,
            });
            if self.source == Some(Source::Serial) {
                port = port::next_line();
            }
        }
        let byte = match self.source {
            Some(Source::Card) => self.print.next_byte(),
            _ => port.and_then(port::Port::receive),
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
    pub(super) fn card_news(&mut self, m: &mut Motion, cfg: &MachineConfig, store: &Store) -> bool {
        while let Some(event) = self.presses.pop() {
            if self.print.offered() && event.is_short_press(Button::Confirm) {
                let _ = self.recover(m, cfg, store);
                continue;
            }
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
    pub(super) fn card_line(
        &mut self,
        c: CardLine,
        m: &mut Motion,
        cfg: &MachineConfig,
        store: &Store,
    ) {
        if cfg.machine.is_string_art() || self.source == Some(Source::Card) {
            return self.error(&Error::new(ErrorKind::UnsupportedCommand, 1));
        }
        let done = match c {
            CardLine::Recover => self.recover(m, cfg, store),
            c => self.print.command(c, m),
        };
        match done {
            Err(kind) => self.error(&Error::new(kind, 0)),
            // Answered when the reader has.
            Ok(()) if self.print.waiting() => {}
            Ok(()) => self.ok(),
        }
    }
}

impl Console {
    /// `M1000` or green with a power cut's print offered: home (a machine
    /// with switches), then the file opens and its lines before the
    /// checkpoint are taken without moving.
    #[inline(never)]
    fn recover(
        &mut self,
        m: &mut Motion,
        cfg: &MachineConfig,
        store: &Store,
    ) -> Result<(), ErrorKind> {
        let homes = cfg.homing.axes != 0 && store.extras().homing_enabled(cfg);
        match self.print.recover(store, homes)? {
            ResumeAction::Home => self.start_homing(cfg.homing.axes, m, false),
            _ => self.print.open_saved(store),
        }
        Ok(())
    }

    /// A card's line read whole: taken now (`true`), or held while a
    /// resume places the executor where the print began, lifts the pen
    /// and moves back to where the line starts.
    #[inline(never)]
    pub(super) fn card_line_goes(
        &mut self,
        m: &Motion,
        kin: &impl Kinematics,
        cfg: &MachineConfig,
        store: &Store,
    ) -> bool {
        let up = cfg.pen.up_deg;
        match self.print.line_ready() {
            ResumeAction::Place => {
                if let Some(p) = store.plot_saved() {
                    let mut at = m.target();
                    (at[0], at[1]) = (p.header.at[0], p.header.at[1]);
                    self.interp.resync(&kin.forward(&at), motor_channels(cfg));
                }
            }
            ResumeAction::Travel => self.interp.travel_back(&kin.forward(&m.target()), up),
            // Up over the blocks drawn before the cut: down after them.
            ResumeAction::Pen => {}
            _ => return true,
        }
        false
    }
}

impl Console {
    /// A card's line was taken: its checkpoint candidate, with the
    /// number of its first block, if it starts one.
    #[inline(never)]
    pub(super) fn card_line_taken(&mut self, m: &Motion) {
        let first = self.interp.blocks_before();
        self.print
            .line_taken(first.map(|b| m.next_block().wrapping_add(b)));
    }
}

/// A whole line has arrived on a serial port.
pub(super) fn serial_line_waits() -> bool {
    port::any_line_waits()
}
