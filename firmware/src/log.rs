//! Logging over the serial console: `error!`, `warn!`, `info!`, `debug!`.
//!
//! `info!("nail ", i, " of ", n)`: string literals are stored in flash (they
//! would otherwise cost SRAM for the firmware's whole life), other arguments
//! are printed with `ufmt`. Each line reads `[MSG:I 1234 module: text]`:
//! level, milliseconds since boot, module, in Grbl 1.1's message brackets,
//! which every sender shows and none takes for a reply, an error or an
//! alarm (grbl-streamer aborts a stream on a bare line holding "error"). A
//! line is built in the TX ring itself, part by part with out-of-line
//! calls, and queued whole; when the ring has no room it is dropped and
//! counted, and the count is reported on the next line that fits. Levels below `MAX_LEVEL`
//! (cargo feature `log-debug` lowers it) compile to nothing.

use crate::board::port::{self, Port};
use crate::board::{clock, flash::FlashStr};
use crate::rt::TaskCell;
use avr_device::interrupt::Mutex;
use core::cell::Cell;

#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Level {
    Error = 0,
    Warn = 1,
    Info = 2,
    Debug = 3,
}

pub const MAX_LEVEL: Level = if cfg!(feature = "log-debug") {
    Level::Debug
} else {
    Level::Info
};

/// Longest line, newline included; longer ones are cut and end in `~`.
pub const LINE: usize = 96;

static DROPPED: Mutex<Cell<u16>> = Mutex::new(Cell::new(0));

/// Lines dropped because the TX ring was full, since boot.
pub fn dropped() -> u16 {
    avr_device::interrupt::free(|cs| DROPPED.borrow(cs).get())
}

/// A piece's bytes, from SRAM or flash: one staging loop for both.
enum Bytes<'a> {
    Ram(core::slice::Iter<'a, u8>),
    /// The text and the next byte's index.
    Flash(FlashStr, usize),
}

impl Iterator for Bytes<'_> {
    type Item = u8;
    fn next(&mut self) -> Option<u8> {
        match self {
            Bytes::Ram(bytes) => bytes.next().copied(),
            Bytes::Flash(s, i) if *i < s.len() => {
                *i += 1;
                Some(s.byte(*i - 1))
            }
            Bytes::Flash(..) => None,
        }
    }
}

/// A line being written: a reply, a push message or a log line, staged
/// in the TX ring itself ([`Ring::stage`]) and queued whole at its end, so
/// that no 100-byte copy of it sits in a frame or a static. A line begun,
/// or bytes sent ([`Port::send`]), take the ring's free slots ([`Outbox`](crate::board::usart::Outbox)): a line
/// still open then is dropped whole (counted as refused), never mixed.
/// Replies and log lines share this type, so each value's `ufmt` code
/// exists once.
///
/// [`Ring::stage`]: crate::rt::Ring::stage
pub struct Line {
    /// The port whose TX ring it is staged in: a reply's is the line's it
    /// answers ([`port::answer`]), a log line's USB.
    port: Port,
    /// Its [`Outbox::begin_staging`](crate::board::usart::Outbox::begin_staging) number: another one means the slots
    /// are no longer its own.
    owner: u8,
    /// Bytes staged: a log line's note of dropped lines, then the line.
    at: u8,
    /// Where the line starts (after the note).
    start: u8,
    cut: bool,
    /// A byte did not fit, or the slots were taken: the line is dropped.
    lost: bool,
    /// A log line: closed by `]`.
    msg: bool,
}

impl ufmt::uWrite for Line {
    type Error = core::convert::Infallible;
    /// Inlined: a format string's one- and two-byte pieces (`":"`, `": "`) become a
    /// pushed constant instead of a string the AVR would keep in SRAM.
    #[inline(always)]
    fn write_str(&mut self, s: &str) -> Result<(), Self::Error> {
        match s.as_bytes() {
            [b] => self.push(*b),
            [a, b] => {
                self.push(*a);
                self.push(*b);
            }
            bytes => self.push_all(bytes),
        }
        Ok(())
    }
}

impl Line {
    /// A byte, staged if it fits the line (else the line is cut).
    #[inline(never)]
    fn push(&mut self, b: u8) {
        self.push_all(core::slice::from_ref(&b));
    }

    /// Bytes, staged as far as the line goes (the rest cut).
    #[inline(never)]
    pub fn push_all(&mut self, bytes: &[u8]) {
        self.stage(bytes.len(), Bytes::Ram(bytes.iter()));
    }

    /// A text from flash, read straight into the ring (no copy on the
    /// stack, as its `uDisplay` makes).
    #[inline(never)]
    fn push_text(&mut self, s: FlashStr) {
        self.stage(s.len(), Bytes::Flash(s, 0));
    }

    /// Stage the `n` bytes of `bytes` as far as the line goes (the rest
    /// cut): the port, the slots' owner and the room are looked up once
    /// for them all, not per byte.
    #[inline(never)]
    fn stage(&mut self, n: usize, bytes: Bytes) {
        let left = LINE as u8 - (self.at - self.start);
        let n = match u8::try_from(n) {
            Ok(n) if n <= left => n,
            _ => {
                self.cut = true;
                left
            }
        };
        self.lost |= !self.port.outbox().stage(self.owner, self.at, n, bytes);
        self.at += n;
    }

    /// A new line, the ring's free slots its own.
    fn new(msg: bool, port: Port) -> Line {
        Line {
            port,
            owner: port.outbox().begin_staging(),
            at: 0,
            start: 0,
            cut: false,
            lost: false,
            msg,
        }
    }

    /// A `[MSG:…]` push message in Grbl's form: no level, time or module;
    /// closed by `]` even when cut.
    #[inline(never)]
    pub fn message() -> Line {
        let mut l = Line::new(true, port::answer());
        l.push_text(crate::flash_str!("[MSG:"));
        l
    }

    /// A console reply: no level, time or module.
    pub fn bare() -> Line {
        Line::to(port::answer())
    }

    /// A reply on `port` (a status report to the port that asked).
    pub fn to(port: Port) -> Line {
        Line::new(false, port)
    }

    /// Queue a reply whole; the caller made room (`reply::room`).
    #[inline(never)]
    pub fn send(&mut self) {
        self.end();
        self.queue();
    }

    /// Queue what is staged; false (counted as refused) if it was lost.
    fn queue(&self) -> bool {
        self.port
            .publish(self.owner, usize::from(self.at), self.lost)
    }

    /// The newline, always, after a log line's `]`: a line that did not
    /// fit ends in `~` first.
    fn end(&mut self) {
        let close = usize::from(self.msg);
        if self.cut || usize::from(self.at - self.start) + close + 1 > LINE {
            self.at = self.start + (LINE - 2 - close) as u8;
            self.push(b'~');
        }
        // Never cut: with them the line is `LINE` bytes at most.
        if self.msg {
            self.push(b']');
        }
        self.push(b'\n');
    }

    /// A log line's start: `[MSG:` from flash (a format string's pieces
    /// would sit in SRAM, pushed bytes cost code), level, time, module.
    fn head(&mut self, level: Level, module: FlashStr) {
        self.push_text(crate::flash_str!("[MSG:"));
        // Immediates, not a byte string: that would be a copy in SRAM.
        #[allow(clippy::byte_char_slices)]
        self.push([b'E', b'W', b'I', b'D'][level as usize]);
        // The first 65 s in 16 bits: a digit of a 32-bit number costs a
        // 32-bit division, some 700 cycles.
        let ms = clock::millis();
        let _ = match u16::try_from(ms) {
            Ok(short) => ufmt::uwrite!(self, " {} ", short),
            Err(_) => ufmt::uwrite!(self, " {} ", ms),
        };
        self.push_text(module);
        let _ = ufmt::uwrite!(self, ": ");
    }

    /// A new log line; `n lines dropped` before it while lines were
    /// dropped (queued only together with it).
    #[inline(never)]
    fn begin(level: Level, module: FlashStr) -> Line {
        let mut l = Line::new(true, Port::Usb);
        let dropped = dropped();
        if dropped > 0 {
            l.head(Level::Warn, crate::flash_str!("log"));
            let _ = ufmt::uwrite!(l, "{}", dropped);
            l.push_text(crate::flash_str!(" lines dropped"));
            l.end();
            l.start = l.at;
            l.cut = false;
        }
        l.head(level, module);
        l
    }

    /// Queue the log line (and the note before it), or count it as
    /// dropped.
    fn emit(&mut self) {
        self.end();
        if !self.queue() {
            return count_drop();
        }
        if self.start > 0 {
            avr_device::interrupt::free(|cs| DROPPED.borrow(cs).set(0));
        }
    }
}

/// The log line being built. A log call begins it, appends each part and
/// queues it with out-of-line calls ([`start`], [`text`], [`part`],
/// [`finish`]): each value's formatting is one function, not repeated at
/// every call site. Only tasks log, one at a time, to completion, and a
/// line's parts only format. Zeroed: in `.bss`.
static LOG: TaskCell<Line> = TaskCell::zeroed();

/// A log line's start: level, time, module (`log!`).
#[doc(hidden)]
#[inline(never)]
pub fn start(level: Level, module: FlashStr) {
    LOG.with(|l| *l = Line::begin(level, module));
}

/// Append a text from flash to the log line (`log!`'s string literals).
#[doc(hidden)]
#[inline(never)]
pub fn text(s: FlashStr) {
    LOG.with(|l| l.push_text(s));
}

/// A log line of one text from flash (`log!` of a lone literal): one
/// call at each of its sites, not three.
#[doc(hidden)]
#[inline(never)]
pub fn just(level: Level, module: FlashStr, s: FlashStr) {
    start(level, module);
    text(s);
    finish();
}

/// Append a value to the log line: one function per type.
#[doc(hidden)]
#[inline(never)]
pub fn part<T: ufmt::uDisplay + ?Sized>(value: &T) {
    with_line(|l| {
        let _ = ufmt::uwrite!(l, "{}", value);
    });
}

/// `log!`'s parts by type, at the call site: a text from flash goes
/// straight into the ring ([`text`]), any other value through its
/// `uDisplay` ([`part`]). A method of `&FlashStr` is found before one of
/// `&&T`, so `(&value).log_part()` picks the first for a text.
#[doc(hidden)]
pub trait TextPart {
    fn log_part(&self);
}

impl TextPart for FlashStr {
    #[inline(always)]
    fn log_part(&self) {
        text(*self);
    }
}

#[doc(hidden)]
pub trait ValuePart {
    fn log_part(&self);
}

impl<T: ufmt::uDisplay + ?Sized> ValuePart for &T {
    #[inline(always)]
    fn log_part(&self) {
        part(*self);
    }
}

/// Append to the log line what `f` writes (a line put together by hand,
/// between [`start`] and [`finish`]).
pub fn with_line(f: impl FnOnce(&mut Line)) {
    LOG.with(f);
}

/// Queue the log line whole, or count it as dropped.
#[doc(hidden)]
#[inline(never)]
pub fn finish() {
    LOG.with(Line::emit);
}

fn count_drop() {
    avr_device::interrupt::free(|cs| {
        let d = DROPPED.borrow(cs);
        d.set(d.get().saturating_add(1));
    });
}

#[macro_export]
#[doc(hidden)]
macro_rules! __log_parts {
    () => {};
    ($s:literal $(, $($rest:tt)*)?) => {
        $crate::log::text($crate::flash_str!($s));
        $crate::__log_parts!($($($rest)*)?);
    };
    ($e:expr $(, $($rest:tt)*)?) => {
        {
            #[allow(unused_imports)]
            use $crate::log::{TextPart as _, ValuePart as _};
            let part = &$e;
            part.log_part();
        }
        $crate::__log_parts!($($($rest)*)?);
    };
}

#[macro_export]
macro_rules! log {
    ($level:expr, $s:literal $(,)?) => {
        if $level <= $crate::log::MAX_LEVEL {
            $crate::log::just($level, $crate::__log_module!(), $crate::flash_str!($s));
        }
    };
    ($level:expr, $($parts:tt)*) => {
        if $level <= $crate::log::MAX_LEVEL {
            $crate::log::start($level, $crate::__log_module!());
            $crate::__log_parts!($($parts)*);
            $crate::log::finish();
        }
    };
}

#[macro_export]
macro_rules! error { ($($p:tt)*) => { $crate::log!($crate::log::Level::Error, $($p)*) }; }
#[macro_export]
macro_rules! warn { ($($p:tt)*) => { $crate::log!($crate::log::Level::Warn, $($p)*) }; }
#[macro_export]
macro_rules! info { ($($p:tt)*) => { $crate::log!($crate::log::Level::Info, $($p)*) }; }
#[macro_export]
macro_rules! debug { ($($p:tt)*) => { $crate::log!($crate::log::Level::Debug, $($p)*) }; }
