//! The words of a G-code line: letters with their numbers, collected into a
//! [`Line`] with Grbl's checks (repeated words, modal groups, words the
//! command cannot use). The first error is kept; the rest of the line is
//! then only skipped.

use super::error::{Error, ErrorKind};
use super::line::{AxisWord, CardLine, Command, Distance, Input, Line, Plane, Units};
use super::number::Number;
use crate::units::{MaybeMilli, Milli};

/// Largest line number, as in Grbl.
const MAX_LINE_NUMBER: u32 = 9_999_999;

/// A letter whose number is being read.
#[derive(Clone, Copy, Debug)]
struct Word {
    letter: u8,
    column: u8,
    number: Number,
}

#[derive(Clone, Debug)]
pub(super) struct Words {
    line: Line,
    word: Option<Word>,
    error: Option<Error>,
    // Columns of words checked once the line is complete; 0 = absent.
    command_column: u8,
    axis_column: u8,
    p_column: u8,
    s_column: u8,
    /// The first `I J K R`.
    arc_column: u8,
    /// A card command (`M20`…) in place of the line's command; `M23`
    /// collects the rest of the line as its file name.
    card: Option<CardLine>,
    /// A jog's words (after `$J=`).
    jog: bool,
}

impl Words {
    pub(super) const fn new(jog: bool) -> Words {
        Words {
            line: Line::empty(),
            word: None,
            error: None,
            command_column: 0,
            axis_column: 0,
            p_column: 0,
            s_column: 0,
            arc_column: 0,
            card: None,
            jog,
        }
    }

    pub(super) fn is_jog(&self) -> bool {
        self.jog
    }

    pub(super) fn line_number(&self) -> Option<u32> {
        self.line.n
    }

    /// One character outside comments; a comment arrives as a space.
    pub(super) fn feed(&mut self, c: u8, column: u8) {
        if self.error.is_none() {
            if let Err(e) = self.take(c, column) {
                self.error = Some(e);
            }
        }
    }

    fn take(&mut self, c: u8, column: u8) -> Result<(), Error> {
        if self.naming() {
            return self.name_char(c, column);
        }
        match c {
            // A space ends a number but may sit between letter and number.
            b' ' | b'\t' => match self.word {
                Some(w) if w.number.has_digits() => self.close(column),
                _ => Ok(()),
            },
            b'a'..=b'z' | b'A'..=b'Z' => {
                self.close(column)?;
                if self.naming() {
                    return self.name_char(c, column);
                }
                let letter = c.to_ascii_uppercase();
                let number = match letter {
                    b'N' => Number::integer(MAX_LINE_NUMBER),
                    _ => Number::fixed(),
                };
                self.word = Some(Word {
                    letter,
                    column,
                    number,
                });
                Ok(())
            }
            _ => match &mut self.word {
                Some(w) => w.number.push(c).map_err(|()| {
                    let kind = match w.letter {
                        b'N' => ErrorKind::InvalidLineNumber,
                        _ => ErrorKind::BadNumberFormat,
                    };
                    Error::new(kind, column)
                }),
                None => Err(Error::new(ErrorKind::ExpectedCommandLetter, column)),
            },
        }
    }

    /// After `M23`: the characters are its file name.
    fn naming(&self) -> bool {
        matches!(self.card, Some(CardLine::Select(_))) && self.word.is_none()
    }

    fn name_char(&mut self, c: u8, column: u8) -> Result<(), Error> {
        let Some(CardLine::Select(name)) = &mut self.card else {
            return Ok(());
        };
        if c == b' ' && name.is_empty() {
            return Ok(());
        }
        // No file on the card has a longer name that can be selected.
        name.push(c)
            .map_err(|_| Error::new(ErrorKind::FileNotFound, column))
    }

    /// Ends the word being read at the character in `column`.
    fn close(&mut self, column: u8) -> Result<(), Error> {
        let Some(w) = self.word.take() else {
            return Ok(());
        };
        let applied = match w.letter {
            b'N' => w.number.value().map(|n| self.set_line_number(n)),
            letter => w.number.milli().map(|v| self.apply(letter, w.column, v)),
        };
        // One error built, wherever it came from.
        let (kind, at) = match applied {
            Some(Ok(())) => return Ok(()),
            Some(Err(kind)) => (kind, w.column),
            None => (ErrorKind::BadNumberFormat, column),
        };
        Err(Error::new(kind, at))
    }

    fn set_line_number(&mut self, n: u32) -> Result<(), ErrorKind> {
        if self.line.n.is_some() {
            return Err(ErrorKind::RepeatedWord);
        }
        self.line.n = Some(n);
        Ok(())
    }

    /// Takes the word `letter` of `value` at `column`; the error's kind
    /// (at the word's column).
    fn apply(&mut self, letter: u8, column: u8, value: Milli) -> Result<(), ErrorKind> {
        if let Some(word) = AxisWord::from_letter(letter) {
            let slot = &mut self.line.axes[word.index()];
            if slot.is_some() {
                return Err(ErrorKind::RepeatedWord);
            }
            *slot = MaybeMilli::new(Some(value));
            if self.axis_column == 0 {
                self.axis_column = column;
            }
            return Ok(());
        }
        match letter {
            b'G' if value.0 == 90_000 || value.0 == 91_000 => {
                let d = match value.0 {
                    90_000 => Distance::Absolute,
                    _ => Distance::Relative,
                };
                modal(&mut self.line.distance, d)
            }
            // Machine coordinates: taut keeps no work offsets, so every
            // position is one already.
            b'G' if value.0 == 53_000 => Ok(()),
            b'G' if matches!(value.0, 17_000..=19_000) && value.0 % 1000 == 0 => {
                let p = match value.0 {
                    17_000 => Plane::Xy,
                    18_000 => Plane::Zx,
                    _ => Plane::Yz,
                };
                modal(&mut self.line.plane, p)
            }
            b'G' if value.0 == 20_000 || value.0 == 21_000 => {
                let u = match value.0 {
                    20_000 => Units::Inch,
                    _ => Units::Mm,
                };
                modal(&mut self.line.units, u)
            }
            b'I' | b'J' | b'K' | b'R' => {
                let slot = match letter {
                    b'R' => &mut self.line.r,
                    b'I' => &mut self.line.offsets[0],
                    b'J' => &mut self.line.offsets[1],
                    _ => &mut self.line.offsets[2],
                };
                if slot.is_some() {
                    return Err(ErrorKind::RepeatedWord);
                }
                *slot = MaybeMilli::new(Some(value));
                if self.arc_column == 0 {
                    self.arc_column = column;
                }
                Ok(())
            }
            b'M' if CardLine::from_number(value).is_some() => {
                if self.command_column != 0 {
                    return Err(ErrorKind::ModalGroupViolation);
                }
                self.command_column = column;
                self.card = CardLine::from_number(value);
                Ok(())
            }
            b'G' | b'M' => {
                if self.card.is_some() {
                    return Err(ErrorKind::ModalGroupViolation);
                }
                let Some(command) = Command::from_word(letter, value) else {
                    return Err(ErrorKind::UnsupportedCommand);
                };
                if self.command_column != 0 {
                    // G92 with G0/G1: different groups, but both want the
                    // axis words. Anything else is one group here.
                    let previous = self.line.command;
                    let set_position = |c| c == Command::SetPosition;
                    let axis_conflict = command.uses_axes()
                        && previous.uses_axes()
                        && set_position(command) != set_position(previous);
                    return Err(if axis_conflict {
                        ErrorKind::AxisWordConflict
                    } else {
                        ErrorKind::ModalGroupViolation
                    });
                }
                self.command_column = column;
                self.line.command = command;
                Ok(())
            }
            b'F' | b'P' | b'S' => {
                let slot = match letter {
                    b'F' => &mut self.line.f,
                    b'P' => {
                        self.p_column = column;
                        &mut self.line.p
                    }
                    _ => {
                        self.s_column = column;
                        &mut self.line.s
                    }
                };
                if slot.is_some() {
                    return Err(ErrorKind::RepeatedWord);
                }
                if value.0 < 0 {
                    return Err(ErrorKind::NegativeValue);
                }
                *slot = MaybeMilli::new(Some(value));
                Ok(())
            }
            _ => Err(ErrorKind::UnsupportedCommand),
        }
    }

    /// The line, once its last character (before `column`) has been read.
    pub(super) fn finish(&mut self, column: u8) -> Result<Input, Error> {
        if let Some(e) = self.error {
            return Err(e);
        }
        self.close(column)?;
        let line = &self.line;
        let fail = |kind, column| Err(Error::new(kind, column));
        let has_axes = self.axis_column != 0;
        if let Some(card) = self.card {
            let value_column = [self.p_column, self.s_column, self.arc_column]
                .into_iter()
                .find(|&c| c != 0);
            return match card {
                _ if has_axes => fail(ErrorKind::UnusedAxisWords, self.axis_column),
                _ if value_column.is_some() || line.f.is_some() => fail(
                    ErrorKind::UnusedValueWords,
                    value_column.unwrap_or(self.command_column),
                ),
                CardLine::Select(name) if name.is_empty() => {
                    fail(ErrorKind::ValueWordMissing, self.command_column)
                }
                CardLine::Select(name) => Ok(Input::Card(CardLine::Select(name.trimmed()))),
                _ => Ok(Input::Card(card)),
            };
        }
        match line.command {
            Command::Dwell if has_axes => {
                return fail(ErrorKind::UnusedAxisWords, self.axis_column)
            }
            Command::Dwell if !line.p.is_some() => {
                return fail(ErrorKind::ValueWordMissing, self.command_column)
            }
            Command::SetPosition if !has_axes => {
                return fail(ErrorKind::NoAxisWords, self.command_column)
            }
            Command::Servo if line.s.get().is_none() => {
                return fail(ErrorKind::ValueWordMissing, self.command_column)
            }
            Command::EnableDrivers
            | Command::DisableDrivers
            | Command::ReportPosition
            | Command::WaitIdle
            | Command::Home
            | Command::Pause
            | Command::PenDown
            | Command::PenUp
            | Command::Servo
                if has_axes =>
            {
                return fail(ErrorKind::UnusedAxisWords, self.axis_column)
            }
            _ => {}
        }
        if line.p.is_some() && line.command != Command::Dwell {
            return fail(ErrorKind::UnusedValueWords, self.p_column);
        }
        // `S` is the pen's angle, or `M18 S`'s seconds (Marlin).
        if line.s.is_some()
            && !matches!(
                line.command,
                Command::PenDown | Command::Servo | Command::DisableDrivers
            )
        {
            return fail(ErrorKind::UnusedValueWords, self.s_column);
        }
        // Arc words only with an arc (or axis words in an arc's modal
        // mode: the interpreter decides), and `R` or `I J K`, not both.
        let arc = matches!(
            line.command,
            Command::ArcCw | Command::ArcCcw | Command::Empty
        );
        let offsets = line.offsets.iter().any(|o| o.is_some());
        if self.arc_column != 0 && (!arc || (offsets && line.r.is_some())) {
            return fail(ErrorKind::UnusedValueWords, self.arc_column);
        }
        Ok(Input::Line(self.line))
    }
}

impl Words {
    /// Why a jog's words (after `$J=`) are no jog, before the line ends:
    /// a command, a plane or a value word other than `F` and `N` (Grbl's
    /// error 16). Its own errors come first.
    pub(super) fn jog_error(&self) -> Option<Error> {
        if !self.jog || self.error.is_some() {
            return None;
        }
        let open = self.word.map_or(0, |w| match w.letter {
            b'M' | b'P' | b'S' | b'I' | b'J' | b'K' | b'R' => w.column,
            _ => 0,
        });
        let commands = self.line.command != Command::Empty || self.card.is_some();
        let column = match commands || self.line.plane.is_some() {
            true => self.command_column.max(1),
            false => [self.p_column, self.s_column, self.arc_column, open]
                .into_iter()
                .find(|&c| c != 0)?,
        };
        Some(Error::new(ErrorKind::InvalidJogCommand, column))
    }
}

/// A jog's line once read whole: a `G1` to its axis words at its `F`
/// (Grbl's error 16 for a command or plane its last word brought, 26
/// without an axis word, 22 without `F`); `end` is the line's end.
pub(super) fn jog_line(line: Line, end: u8) -> Result<Line, Error> {
    let fail = |kind| Err(Error::new(kind, end));
    if line.command != Command::Empty || line.plane.is_some() || line.has_arc_words() {
        return fail(ErrorKind::InvalidJogCommand);
    }
    if !line.has_axes() {
        return fail(ErrorKind::NoAxisWords);
    }
    if line.f.get().is_none() {
        return fail(ErrorKind::UndefinedFeedRate);
    }
    Ok(Line {
        command: Command::Linear,
        ..line
    })
}

/// A modal word (`G90`, `G17`, `G20`…): one of its group per line (Grbl's
/// error 21).
fn modal<T>(slot: &mut Option<T>, value: T) -> Result<(), ErrorKind> {
    if slot.is_some() {
        return Err(ErrorKind::ModalGroupViolation);
    }
    *slot = Some(value);
    Ok(())
}
