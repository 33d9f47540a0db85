//! Logging over the serial console: `error!`, `warn!`, `info!`, `debug!`.
//!
//! `info!("nail ", i, " of ", n)`: string literals are stored in flash (they
//! would otherwise cost SRAM for the firmware's whole life), other arguments
//! are printed with `ufmt`. Each line reads `[MSG:I 1234 module: text]`:
//! level, milliseconds since boot, module, in Grbl 1.1's message brackets,
//! which every sender shows and none takes for a reply, an error or an
//! alarm (grbl-streamer aborts a stream on a bare line holding "error"). A
//! line is built in one static line, [`LOG`], part by part with out-of-line
//! calls, and queued whole; when the TX ring has no room it is dropped and counted, and the
//! count is reported on the next line that fits. Levels below `MAX_LEVEL`
//! (cargo feature `log-debug` lowers it) compile to nothing.

use crate::board::{clock, flash::FlashStr, usart};
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

pub struct Line {
    buf: heapless::Vec<u8, LINE>,
    cut: bool,
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
    fn push(&mut self, b: u8) {
        if self.buf.push(b).is_err() {
            self.cut = true;
        }
    }

    #[inline(never)]
    fn push_all(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.push(b);
        }
    }

    /// A log line's start; what the line held before is dropped (the
    /// static [`LOG`] is begun again for each line). `[MSG:` from flash:
    /// a format string's pieces would sit in SRAM, pushed bytes cost code.
    #[inline(never)]
    pub fn begin(&mut self, level: Level, module: FlashStr) {
        self.buf.clear();
        self.cut = false;
        self.msg = true;
        let _ = ufmt::uwrite!(self, "{}", crate::flash_str!("[MSG:"));
        // Immediates, not a byte string: that would be a copy in SRAM.
        #[allow(clippy::byte_char_slices)]
        self.push([b'E', b'W', b'I', b'D'][level as usize]);
        let _ = ufmt::uwrite!(self, " {} {}: ", clock::millis(), module);
    }

    /// A `[MSG:…]` push message in Grbl's form: no level, time or module;
    /// closed by `]` even when cut. Its bytes pushed here, not by a call
    /// taking the line by reference: the line would then be built apart
    /// and copied into the caller's, two lines in its frame.
    pub fn message() -> Line {
        let mut l = Line::bare();
        l.msg = true;
        #[allow(clippy::byte_char_slices)] // (as in `begin`)
        for c in [b'[', b'M', b'S', b'G', b':'] {
            let _ = l.buf.push(c);
        }
        l
    }

    /// A console reply: no level, time or module. Replies and log lines
    /// share this type, so each value's `ufmt` code exists once.
    pub fn bare() -> Line {
        Line {
            buf: heapless::Vec::new(),
            cut: false,
            msg: false,
        }
    }

    /// Queue a reply whole; the caller made room (`reply::room`). By
    /// reference: a line moved into the call can be copied first, a
    /// second line in the caller's frame.
    pub fn send(&mut self) {
        self.end();
        usart::send(&self.buf);
    }

    /// The newline, always, after a log line's `]`: a line that did not
    /// fit ends in `~` first.
    fn end(&mut self) {
        let close = usize::from(self.msg);
        if self.cut || self.buf.len() + close + 1 > LINE {
            self.buf.truncate(LINE - 2 - close);
            let _ = self.buf.push(b'~');
        }
        if self.msg {
            let _ = self.buf.push(b']');
        }
        let _ = self.buf.push(b'\n');
    }

    /// Queue the line, or count it as dropped. By reference: a line moved
    /// into the call would be copied on the caller's stack, beside it.
    fn emit(&mut self) {
        self.end();
        let dropped = dropped();
        if dropped > 0 && !note_dropped(dropped, self.buf.len()) {
            return count_drop();
        }
        if !usart::send(&self.buf) {
            count_drop();
        }
    }
}

/// `n lines dropped`, queued if it fits with the `then` bytes of the line
/// that follows it. Out of line: its line is on the stack only while
/// there is a count to tell, not beside every line emitted.
#[inline(never)]
#[cold]
fn note_dropped(dropped: u16, then: usize) -> bool {
    let mut note = Line::bare();
    note.begin(Level::Warn, crate::flash_str!("log"));
    let _ = ufmt::uwrite!(note, "{}{}", dropped, crate::flash_str!(" lines dropped"));
    note.end();
    if note.buf.len() + then > crate::queues::TX.free() {
        return false;
    }
    usart::send(&note.buf);
    avr_device::interrupt::free(|cs| DROPPED.borrow(cs).set(0));
    true
}

/// The log line being built. A log call begins it, appends each part and
/// queues it with out-of-line calls ([`start`], [`text`], [`part`],
/// [`finish`]): its caller's frame holds no 100-byte line, which pushed
/// the caller's other stack slots past the AVR's 63-byte `ldd`/`std`
/// reach (each access then costs pointer arithmetic), and each value's
/// formatting is one function, not repeated at every call site. One line
/// serves all: only tasks log, and they run one at a time, to completion.
/// Zeroed (an empty line): in `.bss`, no flash.
static LOG: TaskCell<Line> = TaskCell::zeroed();

/// A log line's start: level, time, module (`log!`).
#[doc(hidden)]
#[inline(never)]
pub fn start(level: Level, module: FlashStr) {
    LOG.with(|l| l.begin(level, module));
}

/// Append a text from flash to the log line (`log!`'s string literals).
#[doc(hidden)]
#[inline(never)]
pub fn text(s: FlashStr) {
    LOG.with(|l| {
        let _ = ufmt::uwrite!(l, "{}", s);
    });
}

/// Append a value to the log line: one function per type.
#[doc(hidden)]
#[inline(never)]
pub fn part<T: ufmt::uDisplay + ?Sized>(value: &T) {
    with_line(|l| {
        let _ = ufmt::uwrite!(l, "{}", value);
    });
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

/// The module path without the crate name, at compile time, in flash.
#[macro_export]
#[doc(hidden)]
macro_rules! __log_module {
    () => {{
        const FULL: &str = module_path!();
        const SKIP: usize = $crate::board::flash::after_crate_name(FULL);
        const LEN: usize = FULL.len() - SKIP;
        // Allowed here: the modules using the macro deny unsafe code.
        #[allow(unsafe_code)]
        #[link_section = ".progmem.data"]
        static S: [u8; LEN] = $crate::board::flash::bytes::<LEN>(FULL, SKIP);
        #[allow(unsafe_code)]
        // SAFETY: S is a progmem static of LEN bytes.
        let s = unsafe { $crate::board::flash::FlashStr::from_static(&S) };
        s
    }};
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
        $crate::log::part(&$e);
        $crate::__log_parts!($($($rest)*)?);
    };
}

#[macro_export]
macro_rules! log {
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
