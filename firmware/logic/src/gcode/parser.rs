//! The byte-level stage, Grbl's `protocol_main_loop` filter (`protocol.c`
//! lines 76–149): real-time bytes, line ends, comments `( … )` and `;`
//! thrown away as they come, whitespace and control bytes and Grbl's
//! ignored block delete `/` dropped, the length limit on what is kept,
//! a UTF-8 byte-order mark before a line's first character skipped, and
//! taut's `*` checksum. What remains of the line goes, one character at a
//! time, to the statement (G-code words or a `$` line), so nothing is
//! buffered.

use super::block::{Input, Realtime};
use super::error::{Error, ErrorKind};
use super::system::SystemBuilder;
use super::words::Words;
use crate::seed::SeedBuilder;

/// Most characters a line keeps (Grbl's `LINE_BUFFER_SIZE` of 80 with its
/// terminator): comments, spaces and control bytes do not count, so a
/// comment may be of any length.
pub const MAX_LINE: u8 = 79;

/// Put by the receive interrupt where a line's end was when bytes of that
/// line were lost (its ring was full): the line ends there and is answered
/// `error:11`, so a sender that waits for each line's reply gets one. Never
/// a byte of UTF-8, and the interrupt drops it from the wire.
pub const LINE_CUT: u8 = 0xFF;

/// Most characters of a `(MSG, …)` text kept; the rest is cut.
pub const MSG_LEN: usize = 40;

/// The text of a line's `(MSG, text)` comment: LinuxCNC's operator message,
/// which grblHAL and senders show as `[MSG:text]` (a plotter file's pen
/// change names the next pen so). Printable ASCII; another byte reads `?`.
#[derive(Clone, Copy, Debug, Eq)]
pub struct Message {
    len: u8,
    text: [u8; MSG_LEN],
}

impl Message {
    pub const NONE: Message = Message {
        len: 0,
        text: [0; MSG_LEN],
    };

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Emptied: the bytes past `len` mean nothing.
    fn clear(&mut self) {
        self.len = 0;
    }

    /// The text, printable ASCII, its trailing spaces cut (by hand: on
    /// the AVR `str`'s checks and trims bring tables into SRAM).
    pub fn text(&self) -> &[u8] {
        let mut len = usize::from(self.len);
        while len > 0 && self.text[len - 1] == b' ' {
            len -= 1;
        }
        &self.text[..len]
    }

    pub fn as_str(&self) -> &str {
        // Only printable ASCII is kept (`push`).
        core::str::from_utf8(self.text()).unwrap_or("")
    }

    fn push(&mut self, c: u8) {
        if usize::from(self.len) < MSG_LEN {
            self.text[usize::from(self.len)] = match c {
                b' '..=b'~' => c,
                _ => b'?',
            };
            self.len += 1;
        }
    }
}

/// Messages of the same text are equal, whatever bytes lie past it.
impl PartialEq for Message {
    fn eq(&self, other: &Message) -> bool {
        let len = usize::from(self.len);
        self.len == other.len && self.text[..len] == other.text[..len]
    }
}

/// How far a `( … )` comment matched `MSG,`.
const MSG_WORD: &[u8; 3] = b"MSG";
/// The comment is not a message.
const NOT_MSG: u8 = u8::MAX;
/// After `MSG,`: the text follows.
const MSG_TEXT: u8 = 4;

/// Every axis letter: a parser's before it is told the machine's.
const EVERY_AXIS: u8 = 0b1111;

/// The UTF-8 byte-order mark an editor may put before a file's first line.
const BOM: [u8; 3] = [0xEF, 0xBB, 0xBF];

/// Where in the line the next byte falls.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Lexeme {
    Code,
    /// Inside `( … )`.
    Comment,
    /// After `;`, to the end of the line.
    LineComment,
    /// Reading the digits after `*`.
    Checksum,
    /// After the checksum: only spaces and a `;` comment may follow.
    AfterChecksum,
    /// Past [`MAX_LINE`]: everything is dropped until the newline.
    Overflow,
}

/// The `*` of a line.
#[derive(Clone, Copy, Debug)]
struct Checksum {
    column: u8,
    /// Its digits' value (above 255 it cannot match), 0x100 past it.
    value: u16,
    digits: bool,
    /// Column of a character that spoils it; 0 = none.
    bad: u8,
}

#[derive(Clone, Debug)]
enum Statement {
    /// Only spaces and comments so far.
    Start,
    /// G-code words, or a jog's after `$J=`.
    GCode(Words),
    System(SystemBuilder),
    /// Seed 003's raw-step line (`+0615-0950n`, [`crate::seed`]).
    Seed(SeedBuilder),
}

/// The streaming command-line parser: push every received byte, act on
/// what comes out. Each line end — `\n`, `\r` or `\r\n` (PuTTY's Enter
/// sends a bare `\r`) — yields exactly one line result (`ok` or `error:`
/// for the host); realtime bytes yield at once.
#[derive(Clone, Debug)]
pub struct Parser {
    /// The last byte ended a line with `\r`: a `\n` now ends no other.
    after_cr: bool,
    /// Characters of this line so far = column of the last one.
    column: u8,
    /// Characters kept (Grbl's `char_counter`); the column where the
    /// limit was passed once it is.
    kept: u8,
    /// Bytes of a byte-order mark matched before the line's first.
    bom: u8,
    /// Axis letters the machine has (a bit per [`AxisWord`](super::AxisWord)).
    letters: u8,
    /// The line's first character kept (0: none yet).
    first: u8,
    /// XOR of the bytes before `*`.
    xor: u8,
    lexeme: Lexeme,
    checksum: Option<Checksum>,
    statement: Statement,
    /// In a `( … )` comment: letters of `MSG,` matched so far.
    msg_at: u8,
    message: Message,
}

/// What a byte did ([`Parser::read`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Read {
    /// Part of a line (or the `\n` of a `\r\n`).
    More,
    Realtime(Realtime),
    /// The line ended: take its result with [`Parser::take_line`].
    LineEnd,
}

impl Default for Parser {
    fn default() -> Self {
        Parser::new()
    }
}

impl Parser {
    pub const fn new() -> Parser {
        Parser {
            after_cr: false,
            column: 0,
            kept: 0,
            bom: 0,
            letters: EVERY_AXIS,
            first: 0,
            xor: 0,
            lexeme: Lexeme::Code,
            checksum: None,
            statement: Statement::Start,
            msg_at: NOT_MSG,
            message: Message::NONE,
        }
    }

    /// The `(MSG, …)` text of the line read so far, or of the line just
    /// taken until the next one begins (empty if none).
    pub fn message(&self) -> &Message {
        &self.message
    }

    /// Some of a line has been read, not yet its end.
    pub fn mid_line(&self) -> bool {
        self.column != 0
    }

    /// The first character the line kept (0 for an empty or comment-only
    /// line, `$` for a system line, `%` for a program delimiter); read
    /// before [`Parser::take_line`], which starts the next line.
    pub fn first_char(&self) -> u8 {
        self.first
    }

    /// The axis letters the machine has (a bit per
    /// [`AxisWord`](super::AxisWord)): another is a letter Grbl does not
    /// know (20), in the line's order.
    pub fn set_axis_letters(&mut self, letters: u8) {
        self.letters = letters;
    }

    /// Takes one received byte; returns what it completed, if anything.
    pub fn push(&mut self, byte: u8) -> Option<Result<Input, Error>> {
        match self.read(byte) {
            Read::More => None,
            Read::Realtime(r) => Some(Ok(Input::Realtime(r))),
            Read::LineEnd => Some(self.take_line()),
        }
    }

    /// [`Parser::push`] in two steps, for a small stack: the byte, then
    /// at [`Read::LineEnd`] the line's result ([`Parser::take_line`]).
    /// Every byte goes through here, so its frame stays a few bytes; the
    /// line's result (~100 B) is made only where it is used. Most bytes
    /// are digits of a word's number: they go straight to it.
    #[inline]
    pub fn read(&mut self, byte: u8) -> Read {
        if self.number_byte(byte) {
            return Read::More;
        }
        self.read_other(byte)
    }

    /// A digit or point of the number being read mid-line, as
    /// [`Parser::read`] and [`Parser::take`] would take it: kept (within
    /// [`MAX_LINE`]), in the checksum (code before a `*` has none yet),
    /// and to the word; false, touching nothing, for any other byte or
    /// state. After a line's first byte no `\r` is pending.
    #[inline]
    fn number_byte(&mut self, byte: u8) -> bool {
        if !(byte.is_ascii_digit() || byte == b'.')
            || self.column == 0
            || self.lexeme != Lexeme::Code
            || self.kept >= MAX_LINE
        {
            return false;
        }
        let Statement::GCode(words) = &mut self.statement else {
            return false;
        };
        if !words.number_byte(byte) {
            return false;
        }
        self.column = self.column.saturating_add(1);
        self.kept += 1;
        self.xor ^= byte;
        true
    }

    /// [`Parser::read`] of any byte. Out of line: the frame of the calls
    /// below stays off the caller's.
    #[inline(never)]
    fn read_other(&mut self, byte: u8) -> Read {
        if let Some(realtime) = Realtime::from_byte(byte) {
            if realtime == Realtime::Reset {
                // The line so far is dropped; where lines end is not.
                self.restart(self.after_cr);
            }
            return Read::Realtime(realtime);
        }
        let after_cr = core::mem::take(&mut self.after_cr);
        match byte {
            b'\n' if after_cr => Read::More,
            LINE_CUT => {
                // Bytes of this line were lost: Grbl's overflow (error 11).
                self.lexeme = Lexeme::Overflow;
                Read::LineEnd
            }
            b'\r' | b'\n' => {
                // Kept across `take_line`, which starts the next line.
                self.after_cr = byte == b'\r';
                Read::LineEnd
            }
            _ if self.column == 0 && BOM.get(self.bom as usize) == Some(&byte) => {
                self.bom = (self.bom + 1) % 3;
                Read::More
            }
            _ => {
                if self.column == 0 {
                    self.message.clear();
                }
                self.column = self.column.saturating_add(1);
                if self.lexeme != Lexeme::Overflow {
                    self.take(byte);
                }
                Read::More
            }
        }
    }

    /// The result of the line [`Parser::read`] ended; the parser is then
    /// ready for the next.
    #[inline(never)]
    pub fn take_line(&mut self) -> Result<Input, Error> {
        let line = self.finish();
        self.restart(self.after_cr);
        line
    }

    /// [`Parser::new`] but for `after_cr`, the axis letters and the
    /// message (it outlives the line's end: the console says it once the
    /// line is accepted; the next line's first byte clears it). Field by
    /// field: a whole new value is built on the stack and copied.
    fn restart(&mut self, after_cr: bool) {
        // Every field named: a new one must be thought of here.
        let Parser {
            after_cr: cr,
            column,
            kept,
            bom,
            letters: _,
            first,
            xor,
            lexeme,
            checksum,
            statement,
            msg_at,
            message: _,
        } = self;
        *cr = after_cr;
        *column = 0;
        *kept = 0;
        *bom = 0;
        *first = 0;
        *xor = 0;
        *lexeme = Lexeme::Code;
        *checksum = None;
        *statement = Statement::Start;
        *msg_at = NOT_MSG;
    }

    /// As [`Parser::new`], in place (no copy of a new one on the stack).
    pub fn clear(&mut self) {
        self.restart(false);
        self.letters = EVERY_AXIS;
        self.message = Message::NONE;
    }

    fn take(&mut self, c: u8) {
        let column = self.column;
        // Marlin's checksum covers every byte before the `*` (not the one
        // of `$RST=*`).
        let star = self.lexeme == Lexeme::Code
            && c == b'*'
            && !matches!(&self.statement, Statement::System(s) if s.restores());
        if self.checksum.is_none() && !star {
            self.xor ^= c;
        }
        match (self.lexeme, c) {
            (Lexeme::Code, b'(') => {
                self.lexeme = Lexeme::Comment;
                self.msg_at = 0;
            }
            (Lexeme::Code, b';') => self.lexeme = Lexeme::LineComment,
            // Whitespace and control bytes are dropped (a space still
            // reaches `M23`'s file name); `/` too (Grbl has no block
            // delete switch: the line runs).
            (Lexeme::Code, ..=b' ') => self.feed(b' ', column),
            (Lexeme::Code, b'/') => {}
            (Lexeme::Checksum | Lexeme::AfterChecksum, b';') => self.lexeme = Lexeme::LineComment,
            (Lexeme::Code, b'*') if star => {
                self.lexeme = Lexeme::Checksum;
                self.checksum = Some(Checksum {
                    column,
                    value: 0,
                    digits: false,
                    bad: 0,
                });
            }
            (Lexeme::Code, _) if self.kept >= MAX_LINE => self.lexeme = Lexeme::Overflow,
            (Lexeme::Code, _) => {
                self.kept += 1;
                self.feed(c, column)
            }
            (Lexeme::Comment, b')') => self.lexeme = Lexeme::Code,
            (Lexeme::Comment, _) if self.msg_at != NOT_MSG => self.message_byte(c),
            (Lexeme::Checksum, b' ' | b'\t') | (Lexeme::AfterChecksum, b' ' | b'\t') => {
                self.lexeme = Lexeme::AfterChecksum
            }
            (Lexeme::Checksum, _) | (Lexeme::AfterChecksum, _) => {
                if let Some(ck) = &mut self.checksum {
                    let spoilt = self.lexeme == Lexeme::AfterChecksum || !c.is_ascii_digit();
                    if !spoilt {
                        ck.value = (ck.value * 10 + (c - b'0') as u16).min(0x100);
                        ck.digits = true;
                    }
                    if spoilt && ck.bad == 0 {
                        ck.bad = column;
                    }
                }
            }
            (Lexeme::Comment, _) | (Lexeme::LineComment, _) | (Lexeme::Overflow, _) => {}
        }
    }

    /// A byte of a `( … )` comment: `MSG` (any case, spaces around it),
    /// `,`, then the text, its leading spaces dropped. A line's last
    /// message is the one kept.
    fn message_byte(&mut self, c: u8) {
        let at = self.msg_at;
        self.msg_at = match c {
            b' ' if at == 0 || at == 3 => at,
            b',' if at == 3 => {
                self.message = Message::NONE;
                MSG_TEXT
            }
            _ if at < 3 && c.to_ascii_uppercase() == MSG_WORD[usize::from(at)] => at + 1,
            _ if at == MSG_TEXT => {
                if c != b' ' || !self.message.is_empty() {
                    self.message.push(c);
                }
                MSG_TEXT
            }
            _ => NOT_MSG,
        };
    }

    /// Hands a character of the statement on; the first one decides
    /// whether the line is G-code or a `$` line.
    fn feed(&mut self, c: u8, column: u8) {
        match &mut self.statement {
            Statement::Start => match c {
                b' ' | b'\t' => {}
                _ if self.first == 0 => {
                    self.first = c;
                    self.feed(c, column)
                }
                b'$' => self.statement = Statement::System(SystemBuilder::new(column)),
                b'+' | b'-' => {
                    self.statement = Statement::Seed(SeedBuilder::new());
                    self.feed(c, column)
                }
                _ => {
                    self.start_words(false);
                    self.feed(c, column);
                }
            },
            Statement::GCode(words) => words.feed(c, column),
            Statement::Seed(seed) => seed.feed(c),
            Statement::System(system) => {
                system.feed(c, column);
                if system.jog_starts() {
                    self.start_words(true);
                }
            }
        }
    }

    /// A G-code line's words begin, or a jog's after `$J=`. Out of line:
    /// the words it makes stay off the frame that reads every byte.
    #[inline(never)]
    fn start_words(&mut self, jog: bool) {
        self.statement = Statement::GCode(Words::new(jog, self.letters));
    }

    /// The result of a complete line. Errors rank: overflow (the line was
    /// cut), then checksum (a corrupted byte explains any other error),
    /// then the first error in the text.
    fn finish(&mut self) -> Result<Input, Error> {
        let line_number = match &self.statement {
            Statement::GCode(words) => words.line_number(),
            _ => None,
        };
        // The error is changed in place: no move of a line's block.
        let mut line = self.result();
        if let Err(e) = &mut line {
            *e = e.with_line_number(line_number);
        }
        line
    }

    fn result(&mut self) -> Result<Input, Error> {
        if self.lexeme == Lexeme::Overflow {
            return Err(Error::new(ErrorKind::LineOverflow, 0));
        }
        let end = match self.checksum {
            Some(ck) => ck.column,
            None => self.column.saturating_add(1),
        };
        let checksum = match self.checksum {
            Some(ck) => {
                let bad = |column| Err(Error::new(ErrorKind::BadChecksum, column));
                if ck.bad != 0 {
                    return bad(ck.bad);
                }
                match ck.digits.then_some(ck.value) {
                    Some(v) if v == self.xor as u16 => Some(self.xor),
                    _ => return bad(ck.column),
                }
            }
            None => None,
        };
        // A line of only spaces and comments is an empty G-code line:
        // one way to make a line's result, not two.
        if let Statement::Start = self.statement {
            self.start_words(false);
        }
        match &mut self.statement {
            Statement::GCode(words) => words.finish(end, checksum),
            Statement::System(system) => system.finish(end).map(Input::System),
            Statement::Seed(seed) => Ok(Input::Seed(seed.finish())),
            // Made G-code above.
            Statement::Start => unreachable!(),
        }
    }
}
