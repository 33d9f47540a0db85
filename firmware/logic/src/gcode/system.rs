//! `$` lines (Grbl's system commands, `system.c`): spaces are ignored,
//! every error is Grbl's 3 "Invalid statement".

use super::error::{Error, ErrorKind};
use heapless::String;

/// Longest `$` key, characters.
pub const SYSTEM_TEXT: usize = 24;
/// Longest `$` value: a startup line (`$N0=`) as Grbl keeps one
/// (`EEPROM_LINE_SIZE`, 80, with `$N0=` and its end).
pub const SYSTEM_VALUE: usize = 75;

/// A key of a `$` line.
pub type SystemText = String<SYSTEM_TEXT, u8>;
/// A value of a `$` line.
pub type SystemValue = String<SYSTEM_VALUE, u8>;

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SystemLine {
    /// `$`: Grbl's help line (`[HLP:…]`).
    Help,
    /// `$$`: print the settings.
    PrintSettings,
    /// `$Q`: planner queue statistics.
    QueueStats,
    /// `$S`: stack high-water mark.
    Stack,
    /// `$X`: take the position as known again after a stop at once
    /// (Grbl's alarm unlock).
    Unlock,
    /// `$H`: home (Grbl's homing cycle).
    Home,
    /// `$T<n>`: seed 001's test pattern `n`.
    Pattern(u8),
    /// `$I`: the build (`[VER:…]`, `[OPT:…]`), as Grbl 1.1.
    BuildInfo,
    /// `$G`: the parser's modal state (`[GC:…]`).
    ParserState,
    /// `$#`: the coordinate offsets (`[G54:…]` … `[PRB:…]`).
    Offsets,
    /// `$<key>=<value>`, both as typed (spaces and comments dropped); the
    /// settings module interprets them (e.g. with
    /// [`parse_milli`](super::parse_milli)). `$N0=`, `$N1=` (a startup
    /// line) and `$I=` (the build info line) may have an empty value.
    Set { key: SystemText, value: SystemValue },
    /// `$N`: the startup lines.
    StartupLines,
    /// `$C`: check mode on, or off (with a soft reset).
    CheckMode,
    /// `$SLP`: the drivers off until a reset.
    Sleep,
    /// `$RST=$`, `$RST=#`, `$RST=*`: Grbl's defaults back.
    Restore(Restore),
}

/// What `$RST=` restores.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Restore {
    /// `$`: the settings (the machine's defaults).
    Settings,
    /// `#`: the work coordinate data.
    Offsets,
    /// `*`: both.
    All,
}

/// A `$` line being read.
#[derive(Clone, Debug)]
pub(super) struct SystemBuilder {
    /// Column of the `$`: where errors found at the end point.
    dollar: u8,
    key: SystemText,
    value: SystemValue,
    equals: bool,
    error: Option<Error>,
}

impl SystemBuilder {
    pub(super) fn new(dollar: u8) -> SystemBuilder {
        SystemBuilder {
            dollar,
            key: String::new(),
            value: String::new(),
            equals: false,
            error: None,
        }
    }

    pub(super) fn feed(&mut self, c: u8, column: u8) {
        if self.error.is_none() && !matches!(c, b' ' | b'\t') && self.take(c).is_err() {
            // A text to keep longer than is kept: Grbl's 14.
            let kind =
                match self.equals && may_be_empty(&self.key) && self.value.len() == SYSTEM_VALUE {
                    true => ErrorKind::LineLengthExceeded,
                    false => ErrorKind::InvalidStatement,
                };
            self.error = Some(Error::new(kind, column));
        }
    }

    fn take(&mut self, c: u8) -> Result<(), ()> {
        if self.equals {
            return if c.is_ascii_graphic() {
                self.value.push(c as char).map_err(drop)
            } else {
                Err(())
            };
        }
        let key_char = c.is_ascii_alphanumeric()
            || c == b'_'
            || (matches!(c, b'$' | b'#') && self.key.is_empty());
        if self.key == "$" {
            Err(()) // nothing may follow `$$`
        } else if c == b'=' && !self.key.is_empty() {
            self.equals = true;
            Ok(())
        } else if key_char {
            self.key.push(c as char).map_err(drop)
        } else {
            Err(())
        }
    }

    /// `$RST=` has just been read: its `*` is no checksum.
    pub(super) fn restores(&self) -> bool {
        self.equals && self.value.is_empty() && is_rst(&self.key)
    }

    /// `$J=` has just been read: the rest is a jog's G-code.
    pub(super) fn jog_starts(&self) -> bool {
        self.equals && self.value.is_empty() && self.key.eq_ignore_ascii_case("J")
    }

    pub(super) fn finish(&mut self, end: u8) -> Result<SystemLine, Error> {
        if let Some(e) = self.error {
            return Err(e);
        }
        if self.equals && is_rst(&self.key) {
            return match self.value.as_bytes() {
                [b'$'] => Ok(SystemLine::Restore(Restore::Settings)),
                [b'#'] => Ok(SystemLine::Restore(Restore::Offsets)),
                [b'*'] => Ok(SystemLine::Restore(Restore::All)),
                _ => Err(Error::new(ErrorKind::InvalidStatement, self.dollar + 5)),
            };
        }
        if self.equals {
            return if self.value.is_empty() && !may_be_empty(&self.key) {
                Err(Error::new(ErrorKind::InvalidStatement, end))
            } else {
                Ok(SystemLine::Set {
                    key: core::mem::take(&mut self.key),
                    value: core::mem::take(&mut self.value),
                })
            };
        }
        // Byte patterns, not string ones: those compare with constant
        // strings, which the AVR keeps in SRAM.
        match self.key.as_bytes() {
            [] => Ok(SystemLine::Help),
            [b'$'] => Ok(SystemLine::PrintSettings),
            [b'Q' | b'q'] => Ok(SystemLine::QueueStats),
            [b'S' | b's'] => Ok(SystemLine::Stack),
            [b'X' | b'x'] => Ok(SystemLine::Unlock),
            [b'H' | b'h'] => Ok(SystemLine::Home),
            [b'I' | b'i'] => Ok(SystemLine::BuildInfo),
            [b'G' | b'g'] => Ok(SystemLine::ParserState),
            [b'#'] => Ok(SystemLine::Offsets),
            [b'N' | b'n'] => Ok(SystemLine::StartupLines),
            [b'C' | b'c'] => Ok(SystemLine::CheckMode),
            [b'S', b'L', b'P'] | [b's', b'l', b'p'] => Ok(SystemLine::Sleep),
            [b'T', n] | [b't', n] if matches!(n, b'1' | b'5' | b'6' | b'7') => {
                Ok(SystemLine::Pattern(n - b'0'))
            }
            _ => Err(Error::new(ErrorKind::InvalidStatement, self.dollar)),
        }
    }
}

/// `N0`, `N1` and `I`: a text to keep, which may be empty (Grbl clears it
/// so).
fn may_be_empty(key: &str) -> bool {
    matches!(key.as_bytes(), [b'N' | b'n', b'0' | b'1'] | [b'I' | b'i'])
}

/// `RST`, in any case (compared with a text in flash).
fn is_rst(key: &str) -> bool {
    taut_progmem::text!("RST").eq_ignore_ascii_case(key.as_bytes())
}
