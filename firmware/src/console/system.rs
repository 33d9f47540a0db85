//! Grbl's `$` commands (`system.c`), carried out for the console: help,
//! the settings (`$$`, `$<n>=`, taut's `$<name>=`), the startup lines
//! (`$N`, `$N0=`, run at boot and after a reset as Grbl runs them, each
//! answered `>line:ok`), the build info (`$I`, `$I=`), `$RST=`, `$C`,
//! `$SLP`, `$X`, `$H`, and taut's own (`$Q`, `$S`, `$T`, the job's
//! tools). What they keep, the store keeps (`crate::store`).

use super::{message, Console, Listing, Owner, Sleep, Source};
use crate::board::usart;
use crate::motion::Motion;
use crate::reply;
use crate::rt::stack;
use crate::store::{self, Store, Text};
use crate::{flash_str, tools};
use taut_logic::axis::AXES;
use taut_logic::config::MachineConfig;
use taut_logic::gcode::{Error, ErrorKind, Read, Restore, SystemLine};
use taut_logic::interp::{axis_letters, coords};
use taut_logic::settings;
use taut_logic::settings::grbl::{Numbered, SetError};
use taut_progmem::text;
use ufmt::{uDisplay, uWrite, uwrite, Formatter};

/// Both startup lines, a bit each.
pub(super) const STARTUP: u8 = 0b11;

impl Console {
    #[inline(never)]
    #[optimize(size)]
    pub(super) fn system(
        &mut self,
        s: &SystemLine,
        m: &mut Motion,
        cfg: &mut MachineConfig,
        owner: Owner,
        store: &mut Store,
    ) {
        match s {
            SystemLine::Help => help(),
            SystemLine::PrintSettings => {
                self.listing = Some(Listing::Settings(0));
                return;
            }
            SystemLine::QueueStats => {
                self.listing = Some(Listing::Queues(0));
                return;
            }
            SystemLine::Stack => {
                let mut r = reply::line();
                let _ = uwrite!(
                    r,
                    "{}{}{}{}{}",
                    flash_str!("[stack peak "),
                    stack::peak(),
                    flash_str!(" B, headroom "),
                    stack::headroom(),
                    flash_str!(" B]")
                );
                r.send();
            }
            SystemLine::Unlock
            | SystemLine::Home
            | SystemLine::Pattern(_)
            | SystemLine::Set { .. }
            | SystemLine::Restore(_)
            | SystemLine::Sleep
                if self.printing_from_serial() =>
            {
                return self.error(&Error::new(ErrorKind::Printing, 0));
            }
            // The job's tools: it answers them itself, in its log (and
            // refuses them while it moves).
            SystemLine::Set { key, value } if tools::is_tool(key) => {
                if let Err(col) = tools::send(&self.job, key, value) {
                    return self.error(&Error::new(ErrorKind::InvalidStatement, col));
                }
            }
            // What moves the machine or changes what it keeps: not while a
            // job owns it; in check mode Grbl's "not idle".
            SystemLine::Home
            | SystemLine::Pattern(_)
            | SystemLine::Set { .. }
            | SystemLine::Restore(_)
            | SystemLine::Sleep
                if owner == Owner::Job =>
            {
                return self.error(&Error::new(ErrorKind::JobOwnsMotion, 0));
            }
            SystemLine::Home
            | SystemLine::Pattern(_)
            | SystemLine::Set { .. }
            | SystemLine::Restore(_)
            | SystemLine::Sleep
                if self.checking =>
            {
                return self.error(&Error::new(ErrorKind::NotIdle, 0));
            }
            // Grbl's "IDLE/ALARM" commands (`system.c`): refused while
            // motion is queued, settings written with the planner empty.
            SystemLine::Home
            | SystemLine::Set { .. }
            | SystemLine::Restore(_)
            | SystemLine::Sleep
            | SystemLine::Offsets
            | SystemLine::BuildInfo
            | SystemLine::StartupLines
                if !m.is_idle() =>
            {
                return self.error(&Error::new(ErrorKind::NotIdle, 0));
            }
            // Grbl prints the caution only when it leaves the alarm.
            SystemLine::Unlock => {
                if !m.position_known() {
                    m.unlock();
                    message(text!("Caution: Unlocked"));
                }
            }
            SystemLine::BuildInfo => build_info(cfg, store),
            SystemLine::ParserState => {
                let mut r = reply::line();
                let _ = uwrite!(r, "[GC:{}]", self.interp.parser_state(cfg.report_inches));
                r.send();
            }
            SystemLine::Offsets => {
                self.listing = Some(Listing::Offsets(0));
                return;
            }
            SystemLine::StartupLines => {
                self.listing = Some(Listing::Startup(0));
                return;
            }
            SystemLine::Home if !store.extras().homing_enabled(cfg) => {
                return self.error(&Error::new(ErrorKind::NoHoming, 0));
            }
            SystemLine::Home => return self.start_homing(cfg.homing.axes, m, true),
            // Answered at its end.
            SystemLine::Pattern(n) => {
                self.pattern = taut_logic::patterns::pattern(*n).map(|t| (t, 0));
                return;
            }
            SystemLine::Set { key, value } => {
                if let Some(t) = text_key(key) {
                    return self.keep_text(t, value.as_bytes(), m, store);
                }
                return self.set(key, value, m, cfg, store);
            }
            SystemLine::Restore(what) => return self.restore(*what, m, cfg, store),
            // Asleep once it stands (`poll`).
            SystemLine::Sleep => {
                m.cancel();
                self.sleep = Sleep::Falling;
            }
            // Grbl leaves check mode with a soft reset: the modal state
            // afresh, the position read back, the greeting.
            SystemLine::CheckMode if self.checking => {
                self.checking = false;
                message(text!("Disabled"));
                return self.soft_reset(m, store);
            }
            SystemLine::CheckMode if owner == Owner::Job || !m.is_idle() || !m.position_known() => {
                return self.error(&Error::new(ErrorKind::NotIdle, 0));
            }
            SystemLine::CheckMode => {
                self.checking = true;
                message(text!("Enabled"));
            }
        }
        self.ok();
    }

    /// `$<n>=` or `$<name>=`: the setting, then the machine reconfigured.
    #[inline(never)]
    fn set(
        &mut self,
        key: &str,
        value: &str,
        m: &mut Motion,
        cfg: &mut MachineConfig,
        store: &mut Store,
    ) {
        let machine = cfg.machine;
        let set = match Numbered::parse(key.as_bytes()) {
            Some(Some(n)) => n.set(cfg, store.extras_mut(), value.as_bytes()),
            // A number Grbl has no setting of (`settings.c`: 3).
            Some(None) => Err(SetError {
                code: ErrorKind::InvalidStatement,
                at: 0,
                why: None,
            }),
            // In force from the next reset (Ctrl-X) or power-on: the
            // `ok` goes out at the rate the sender speaks.
            None if settings::is_uart1_baud(key.as_bytes()) => store
                .extras_mut()
                .set_uart1_baud(value.as_bytes())
                .map_err(|e| SetError {
                    code: ErrorKind::InvalidStatement,
                    at: e.at,
                    why: Some(e.kind),
                }),
            None if settings::is_flow(key.as_bytes()) => {
                let set = store.extras_mut().set_flow(value.as_bytes());
                usart::set_xonxoff(store.extras().xonxoff());
                set.map_err(|e| SetError {
                    code: ErrorKind::InvalidStatement,
                    at: e.at,
                    why: Some(e.kind),
                })
            }
            None => settings::set(cfg, key, value).map_err(|e| SetError {
                code: ErrorKind::InvalidStatement,
                at: e.at,
                why: Some(e.kind),
            }),
        };
        if let Err(e) = set {
            // `$key=value`: the value starts after `$`, the key, `=`.
            let col = (key.len() + 2 + e.at).min(u8::MAX as usize - 1) as u8 + 1;
            return self.error_because(&Error::new(e.code, col), e.why);
        }
        m.configure(cfg);
        if cfg.machine != machine {
            // Another machine: where it stands is its zero, and its modal
            // state starts afresh. The work coordinate data stays (one
            // record written, whole or not at all; `$RST=#` clears it).
            m.set_position([0; AXES]);
            self.interp.reset(&coords::stored(store.coords(), 0));
            // Its words from the next line on (read before it is taken).
            self.parser
                .set_axis_letters(axis_letters(&cfg.machine.words()));
            self.resync_next_run(m);
        }
        self.settings_changed = true;
        store.settings_changed();
        self.ok();
    }

    /// `$RST=`: Grbl's `settings_restore`, then its soft reset.
    #[inline(never)]
    fn restore(
        &mut self,
        what: Restore,
        m: &mut Motion,
        cfg: &mut MachineConfig,
        store: &mut Store,
    ) {
        if what != Restore::Offsets {
            cfg.load_defaults(cfg.machine);
            m.configure(cfg);
            store.extras_mut().reset();
            usart::set_xonxoff(false);
            store.settings_changed();
            self.settings_changed = true;
        }
        match what {
            Restore::All => store.wipe(),
            Restore::Offsets => store.clear_coords(),
            Restore::Settings => {}
        }
        message(text!("Restoring defaults"));
        self.soft_reset(m, store);
    }

    /// Grbl's `mc_reset` after `$RST=` and `$C`: `ok`, the modal state
    /// afresh, the position read back, the greeting, the startup lines.
    fn soft_reset(&mut self, m: &Motion, store: &Store) {
        self.ok();
        self.interp.reset(&coords::stored(store.coords(), 0));
        self.resync_next_run(m);
        self.startup = STARTUP;
        reply::banner();
    }

    /// `$N0=`, `$N1=` (a G-code line, carried out first as Grbl's
    /// `gc_execute_line` does, and kept if it passes) and `$I=` (any
    /// text): kept, then answered once written.
    #[inline(never)]
    fn keep_text(&mut self, t: Text, value: &[u8], m: &Motion, store: &mut Store) {
        // Grbl stores startup lines only when idle, not in alarm.
        if matches!(t, Text::Startup(_)) && !m.position_known() {
            return self.error(&Error::new(ErrorKind::NotIdle, 0));
        }
        if !store.stage(t, value) {
            return self.error(&Error::new(ErrorKind::LineLengthExceeded, 0));
        }
        if matches!(t, Text::Info) || value.is_empty() {
            store.save_staged();
            self.saving = true;
            return;
        }
        // The line read as if it came in: Grbl keeps it as its reader
        // left it, capitals, no spaces.
        for i in 0.. {
            let Some(b) = store.staged_byte(i) else { break };
            self.parser.read(b.to_ascii_uppercase());
        }
        if self.parser.read(b'\n') == Read::LineEnd {
            // Taken as a line in the next run (`take`).
            self.line_ready = true;
            self.storing = true;
        }
    }

    /// A `$N0=` line's check ended (`take`): kept if it passed, and
    /// answered once written.
    pub(super) fn stored_checked(&mut self, passed: bool, store: &mut Store) {
        self.storing = false;
        match passed {
            true => {
                store.save_staged();
                self.saving = true;
            }
            false => store.drop_staged(),
        }
    }

    /// The next startup line, read from EEPROM as if it came in; its
    /// answer is `>line:ok` (`report_execute_startup_message`). Grbl runs
    /// none in alarm (they wait for `$H`).
    pub(super) fn next_startup_line(&mut self, m: &Motion, store: &Store) -> bool {
        if !m.position_known() {
            self.startup = 0;
            return false;
        }
        let n = (self.startup & 1 == 0) as u8;
        self.startup &= !(1 << n);
        let Some(at) = store.text_addr(Text::Startup(n)) else {
            return false;
        };
        if store::stored_text(at, 0) == 0 {
            return false;
        }
        self.echo = at;
        self.source = Some(Source::Startup);
        for i in 0.. {
            match store::stored_text(at, i) {
                0 => break,
                b => {
                    self.parser.read(b);
                }
            }
        }
        self.parser.read(b'\n') == Read::LineEnd
    }

    /// One line of a `$` listing per call: the TX ring never overflows.
    #[inline(never)]
    pub(super) fn list(&mut self, listing: Listing, cfg: &MachineConfig, store: &Store) {
        self.listing = match listing {
            Listing::Settings(next) => settings::listed(next, cfg, store.extras()).map(|line| {
                let mut r = reply::line();
                let _ = uwrite!(r, "{}", line);
                r.send();
                Listing::Settings(next + 1)
            }),
            Listing::Queues(line) => {
                crate::report::queue_line(line).then_some(Listing::Queues(line + 1))
            }
            Listing::Offsets(line) => self
                .offsets_line(line, cfg, store.coords())
                .then_some(Listing::Offsets(line + 1)),
            // `report_startup_line`: `$N0=G20G90`.
            Listing::Startup(n) if n < 2 => {
                let mut r = reply::line();
                let at = store.text_addr(Text::Startup(n));
                let _ = uwrite!(r, "{}{}={}", flash_str!("$N"), n, Stored(at));
                r.send();
                Some(Listing::Startup(n + 1))
            }
            Listing::Startup(_) => None,
        };
        if self.listing.is_none() {
            reply::ok();
        }
    }
}

/// The text a `$N0=`, `$N1=` or `$I=` keeps.
fn text_key(key: &str) -> Option<Text> {
    match key.as_bytes() {
        [b'N' | b'n', b'0'] => Some(Text::Startup(0)),
        [b'N' | b'n', b'1'] => Some(Text::Startup(1)),
        [b'I' | b'i'] => Some(Text::Info),
        _ => None,
    }
}

/// A kept text, read from EEPROM as it is printed (`None`: empty).
struct Stored(Option<u16>);

impl uDisplay for Stored {
    fn fmt<W: uWrite + ?Sized>(&self, f: &mut Formatter<'_, W>) -> Result<(), W::Error> {
        let Some(at) = self.0 else { return Ok(()) };
        for i in 0.. {
            match store::stored_text(at, i) {
                0 => break,
                b => f.write_char(b as char)?,
            }
        }
        Ok(())
    }
}

/// A startup line's answer: `>G20G90:ok`, `>G1X10:error:22`.
pub(super) fn startup_reply(at: u16, error: Option<&Error>) {
    let mut r = reply::line();
    let _ = uwrite!(r, ">{}:", Stored(Some(at)));
    let _ = match error {
        None => uwrite!(r, "ok"),
        Some(e) => uwrite!(r, "{}{}", flash_str!("error:"), e.code()),
    };
    r.send();
}

/// `$`: Grbl 1.1's help line (`report_grbl_help`), as it prints it.
fn help() {
    let mut r = reply::line();
    let _ = uwrite!(
        r,
        "{}",
        flash_str!("[HLP:$$ $# $G $I $N $x=val $Nx=line $J=line $SLP $C $X $H ~ ! ? ctrl-x]")
    );
    r.send();
}

/// `$I`: `[VER:1.1h.taut-0.1.0:<info>]`, the info line `$I=` keeps (by
/// default the machine's name; UGS wants `[VER:1.1`), and
/// `[OPT:,<planner blocks>,<receive bytes>]`.
#[inline(never)]
fn build_info(cfg: &MachineConfig, store: &Store) {
    let mut r = reply::line();
    let _ = uwrite!(
        r,
        "{}",
        flash_str!(concat!("[VER:1.1h.taut-", env!("CARGO_PKG_VERSION"), ":"))
    );
    let at = store
        .text_addr(Text::Info)
        .filter(|&a| store::stored_text(a, 0) != 0);
    let _ = match at {
        Some(_) => uwrite!(r, "{}]", Stored(at)),
        None => uwrite!(r, "{}]", cfg.machine.name()),
    };
    r.send();
    let mut r = reply::line();
    let _ = uwrite!(
        r,
        "{}{},{}]",
        flash_str!("[OPT:,"),
        taut_logic::planner::PLANNER_BLOCKS,
        crate::board::port::answer().rx_capacity()
    );
    r.send();
}
