//! The words of a G-code line gathered into a [`Block`] as Grbl's
//! `gc_execute_line` gathers them (its step 2, `gcode.c` lines 116–345):
//! each word as it ends, in the order of the text, with the checks that
//! need nothing but the line — a supported command (20), a whole command
//! number (23), two axis commands (24), one command per modal group (21),
//! a word given once (25), no negative `F N P S T` (4), `T` ≤ 255 (38).
//! The first error is kept and the rest of the line skipped. Whatever
//! needs the modal state (step 3) is the executor's.

use super::block::{
    group, word, AxisCommand, AxisWord, Block, CardLine, Coolant, Distance, FeedMode, Flow, Input,
    MotionMode, NonModal, Plane, Spindle, TautCode, ToolLength, Units,
};
use super::error::{Error, ErrorKind};
use super::number::Number;

/// Largest line number, as Grbl's `MAX_LINE_NUMBER`.
const MAX_LINE_NUMBER: u32 = 10_000_000;

/// A letter whose number is being read.
#[derive(Clone, Copy, Debug)]
struct Word {
    letter: u8,
    column: u8,
    number: Number,
}

#[derive(Clone, Debug)]
pub(super) struct Words {
    block: Block,
    word: Option<Word>,
    error: Option<Error>,
    /// Axis letters (bits [`AxisWord::bit`] >> [`word::C`]) the machine
    /// has: another is a letter Grbl does not know (20).
    letters: u8,
    /// A card command (`M20`…) in place of the line's commands; `M23`
    /// collects the rest of the line as its file name.
    card: Option<CardLine>,
    /// A jog's words (after `$J=`).
    jog: bool,
}

impl Words {
    pub(super) const fn new(jog: bool, letters: u8) -> Words {
        let mut block = Block::empty();
        if jog {
            // Grbl reads a jog as a `G1` in `G94` (`gcode.c` line 89).
            block.motion = MotionMode::Linear;
        }
        Words {
            block,
            word: None,
            error: None,
            letters,
            card: None,
            jog,
        }
    }

    pub(super) fn line_number(&self) -> Option<u32> {
        self.block.line_number()
    }

    /// A digit or point of the word being read, taken if its number
    /// takes it (else [`Words::feed`] has it); once the line has an error,
    /// any character is, as `feed` skips it.
    #[inline]
    pub(super) fn number_byte(&mut self, c: u8) -> bool {
        if self.error.is_some() {
            return true;
        }
        match &mut self.word {
            Some(w) => w.number.push(c).is_ok(),
            None => false,
        }
    }

    /// One character outside comments, upper case; spaces are passed
    /// only for `M23`'s file name (Grbl drops them: `X1 0` is `X10`).
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
        if c == b' ' {
            return Ok(());
        }
        if let Some(w) = &mut self.word {
            if w.number.push(c).is_ok() {
                return Ok(());
            }
            // Not the number's: the word ends here (Grbl's `read_float`
            // stops), and a letter must follow.
            self.close(column)?;
            if self.naming() {
                return self.name_char(c, column);
            }
        }
        match c.to_ascii_uppercase() {
            letter @ b'A'..=b'Z' => {
                self.word = Some(Word {
                    letter,
                    column,
                    number: Number::new(),
                });
                Ok(())
            }
            _ => Err(Error::new(ErrorKind::ExpectedCommandLetter, column)),
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

    /// Ends the word being read at `column`: its number needs a digit (2).
    fn close(&mut self, column: u8) -> Result<(), Error> {
        let Some(w) = self.word.take() else {
            return Ok(());
        };
        if !w.number.has_digits() {
            return Err(Error::new(ErrorKind::BadNumberFormat, column));
        }
        self.apply(w.letter, &w.number)
            .map_err(|kind| Error::new(kind, w.column))
    }

    /// Takes the word `letter` of `n` (`gcode.c` lines 143–345).
    fn apply(&mut self, letter: u8, n: &Number) -> Result<(), ErrorKind> {
        match letter {
            b'G' | b'M' => self.command(letter, n),
            _ => self.value(letter, n),
        }
    }

    /// A `G` or `M` word: its group and meaning.
    fn command(&mut self, letter: u8, n: &Number) -> Result<(), ErrorKind> {
        let b = &mut self.block;
        let code = n.code();
        if n.is_negative() {
            return Err(ErrorKind::UnsupportedCommand);
        }
        let mut hundredths = code.hundredths;
        let bit = if letter == b'G' {
            let bit = match code.int {
                10 | 28 | 30 | 92 | 4 | 53 => {
                    if matches!(code.int, 10 | 28 | 30 | 92) && hundredths == 0 {
                        axis_command(b, AxisCommand::NonModal)?;
                    }
                    b.non_modal = match (code.int, hundredths) {
                        (4, _) => NonModal::Dwell,
                        (10, _) => NonModal::SetCoordData,
                        (53, _) => NonModal::AbsoluteOverride,
                        (28, 0) => NonModal::GoHome0,
                        (28, 10) => NonModal::SetHome0,
                        (30, 0) => NonModal::GoHome1,
                        (30, 10) => NonModal::SetHome1,
                        (92, 0) => NonModal::SetCoordOffset,
                        (92, 10) => NonModal::ResetCoordOffset,
                        _ => return Err(ErrorKind::UnsupportedCommand),
                    };
                    if matches!(code.int, 28 | 30 | 92) {
                        hundredths = 0;
                    }
                    group::NON_MODAL
                }
                0..=3 | 38 | 80 => {
                    if code.int != 80 {
                        axis_command(b, AxisCommand::Motion)?;
                    }
                    b.motion = match code.int {
                        0 => MotionMode::Seek,
                        1 => MotionMode::Linear,
                        2 => MotionMode::CwArc,
                        3 => MotionMode::CcwArc,
                        80 => MotionMode::None,
                        // G38.x probing: taut has no probe input.
                        _ => return Err(ErrorKind::UnsupportedCommand),
                    };
                    group::MOTION
                }
                17..=19 => {
                    b.plane = match code.int {
                        17 => Plane::Xy,
                        18 => Plane::Zx,
                        _ => Plane::Yz,
                    };
                    group::PLANE
                }
                90 | 91 if hundredths == 0 => {
                    b.distance = match code.int {
                        90 => Distance::Absolute,
                        _ => Distance::Relative,
                    };
                    group::DISTANCE
                }
                90 | 91 => {
                    // G91.1: arc offsets relative, Grbl's only mode.
                    if hundredths != 10 || code.int == 90 {
                        return Err(ErrorKind::UnsupportedCommand);
                    }
                    hundredths = 0;
                    group::ARC_DISTANCE
                }
                93 | 94 => {
                    b.feed_mode = match code.int {
                        93 => FeedMode::InverseTime,
                        _ => FeedMode::PerMinute,
                    };
                    group::FEED_MODE
                }
                20 | 21 => {
                    b.units = match code.int {
                        20 => Units::Inch,
                        _ => Units::Mm,
                    };
                    group::UNITS
                }
                40 => group::CUTTER,
                43 | 49 => {
                    axis_command(b, AxisCommand::ToolLength)?;
                    b.tool_length = match (code.int, hundredths) {
                        (49, _) => ToolLength::Cancel,
                        (_, 10) => ToolLength::Dynamic,
                        _ => return Err(ErrorKind::UnsupportedCommand),
                    };
                    hundredths = 0;
                    group::TOOL_LENGTH
                }
                54..=59 => {
                    b.coord = (code.int - 54) as u8;
                    group::COORD
                }
                61 if hundredths != 0 => return Err(ErrorKind::UnsupportedCommand),
                61 => group::CONTROL,
                _ => return Err(ErrorKind::UnsupportedCommand),
            };
            if hundredths > 0 {
                return Err(ErrorKind::CommandValueNotInteger);
            }
            bit
        } else {
            if hundredths > 0 {
                return Err(ErrorKind::CommandValueNotInteger);
            }
            if let Some(card) = CardLine::from_number(code.int) {
                if b.groups != 0 || self.card.is_some() {
                    return Err(ErrorKind::ModalGroupViolation);
                }
                self.card = Some(card);
                return Ok(());
            }
            match code.int {
                0 | 1 | 2 | 30 => {
                    b.flow = match code.int {
                        0 => Flow::Pause,
                        1 => Flow::OptionalStop,
                        2 => Flow::End,
                        _ => Flow::EndRewind,
                    };
                    group::STOPPING
                }
                3..=5 => {
                    b.spindle = match code.int {
                        3 => Spindle::Cw,
                        4 => Spindle::Ccw,
                        _ => Spindle::Off,
                    };
                    group::SPINDLE
                }
                7..=9 => {
                    b.coolant = match code.int {
                        7 => Coolant::Mist,
                        8 => Coolant::Flood,
                        _ => Coolant::Off,
                    };
                    group::COOLANT
                }
                17 | 18 | 84 | 114 | 300 | 400 => {
                    b.taut = match code.int {
                        17 => TautCode::EnableDrivers,
                        114 => TautCode::ReportPosition,
                        300 => TautCode::Servo,
                        400 => TautCode::WaitIdle,
                        _ => TautCode::DisableDrivers,
                    };
                    group::TAUT
                }
                _ => return Err(ErrorKind::UnsupportedCommand),
            }
        };
        if b.groups & bit != 0 || self.card.is_some() {
            return Err(ErrorKind::ModalGroupViolation);
        }
        b.groups |= bit;
        Ok(())
    }

    /// A value or axis word (`gcode.c` lines 305–343).
    fn value(&mut self, letter: u8, n: &Number) -> Result<(), ErrorKind> {
        let b = &mut self.block;
        let milli = || n.milli().unwrap_or_default();
        let bit = match letter {
            b'F' => {
                b.f = milli();
                word::F
            }
            b'I' | b'J' | b'K' => {
                b.ijk[(letter - b'I') as usize] = milli();
                word::I + (letter - b'I')
            }
            b'L' => {
                b.l = n.whole().min(u8::MAX as u32) as u8;
                word::L
            }
            b'N' => {
                b.n = n.whole();
                word::N
            }
            b'P' => {
                b.p = milli();
                word::P
            }
            b'R' => {
                b.r = milli();
                word::R
            }
            b'S' => {
                b.s = milli();
                word::S
            }
            b'T' => {
                // Grbl compares the value, fraction and all, with 255.
                let whole = n.whole();
                if !n.is_negative() && (whole > 255 || (whole == 255 && n.code().hundredths > 0)) {
                    return Err(ErrorKind::MaxValueExceeded);
                }
                b.t = whole.min(255) as u8;
                word::T
            }
            _ => match AxisWord::from_letter(letter) {
                Some(w) if self.letters >> w.index() & 1 != 0 => {
                    b.axes[w.index()] = n.nano().unwrap_or_default();
                    word::C + w.index() as u8
                }
                _ => return Err(ErrorKind::UnsupportedCommand),
            },
        };
        // One shift by a variable amount (a loop on the AVR), not three.
        let mask = 1u16 << bit;
        if b.words & mask != 0 {
            return Err(ErrorKind::RepeatedWord);
        }
        const UNSIGNED: u16 =
            1 << word::F | 1 << word::N | 1 << word::P | 1 << word::S | 1 << word::T;
        if UNSIGNED & mask != 0 && n.is_negative() {
            return Err(ErrorKind::NegativeValue);
        }
        b.words |= mask;
        Ok(())
    }

    /// The line, once its last character (before `column`) has been read:
    /// a block with the line's matched `checksum`, or a jog's. Made in
    /// the result's place: each move of a block (~90 B) is ~450 cycles.
    pub(super) fn finish(&mut self, column: u8, checksum: Option<u8>) -> Result<Input, Error> {
        if let Some(e) = self.error {
            return Err(e);
        }
        self.close(column)?;
        let b = &self.block;
        // The first of step 3's checks (`gcode.c` line 362), needing no
        // modal state.
        if b.has_word(word::N) && b.n > MAX_LINE_NUMBER {
            return Err(Error::new(ErrorKind::InvalidLineNumber, 0));
        }
        let Some(card) = self.card else {
            if self.jog {
                return Ok(Input::Jog(self.block));
            }
            self.block.checksum = checksum;
            return Ok(Input::Block(self.block));
        };
        // A card command takes no other word (Marlin's lines stand alone).
        let line = match card {
            _ if b.words & !(1 << word::N) != 0 => Err(Error::new(ErrorKind::UnusedWords, column)),
            CardLine::Select(name) if name.is_empty() => {
                Err(Error::new(ErrorKind::ValueWordMissing, column))
            }
            CardLine::Select(name) => Ok(Input::Card(CardLine::Select(name.trimmed()))),
            _ => Ok(Input::Card(card)),
        };
        match line {
            Ok(_) if self.jog => Err(Error::new(ErrorKind::InvalidJogCommand, column)),
            line => line,
        }
    }
}

/// Grbl's `axis_command` for a command that takes the axis words: a
/// second one on the line is error 24.
fn axis_command(b: &mut Block, what: AxisCommand) -> Result<(), ErrorKind> {
    if b.axis_command != AxisCommand::None {
        return Err(ErrorKind::AxisCommandConflict);
    }
    b.axis_command = what;
    Ok(())
}
