//! The EEPROM's one writer: the machine's settings
//! (`taut_logic::settings::image`), read at power-on and written back after
//! a `$` change, and the string-art job's checkpoint
//! (`taut_logic::checkpoint`), scanned at power-on and written as the job
//! goes. One byte per run (a byte takes 3.4 ms: the task comes back rather
//! than wait); only bytes that differ are written. A checkpoint write goes
//! before the settings: the job waits for it ([`Store::saving`]).
#![deny(unsafe_code)]

use crate::board::eeprom::Eeprom;
use crate::queues::{Signal, TX};
use crate::rt::Poll;
use crate::{flash_str, warn};
use taut_logic::checkpoint::{self, Found, Header, Record, HEADER_BYTES};
use taut_logic::config::MachineConfig;
use taut_logic::files::check::CardId;
use taut_logic::machine::Machine;
use taut_logic::settings::image::{self, Scan, Step, Unusable};
use taut_logic::stringart::job::Phase;

/// Settings compared per run (each ~0.05 ms): the run stays short, as
/// every task waits behind it.
const SETTINGS_PER_RUN: u8 = 8;

pub struct Store {
    eeprom: Eeprom,
    /// Why the stored settings were not used, to say once there is room
    /// for the line (it must not be dropped, and the boot fills the TX
    /// ring).
    unusable: Option<Unusable>,
    /// A `$` change (or the defaults after an unusable image) is still to
    /// be written. Only then are the settings compared: a card's
    /// `machine.txt` figures are the job's, not kept.
    settings_due: bool,
    /// How far the settings' image has been compared with the EEPROM.
    scan: Scan,
    /// The checkpoint header in force (its number mixes into records).
    seq: u16,
    /// The checkpoint bytes being written: where, how many, how far.
    buf: [u8; HEADER_BYTES as usize],
    at: u16,
    len: u8,
    done: u8,
}

impl Store {
    pub fn new(eeprom: Eeprom) -> Store {
        Store {
            eeprom,
            unusable: None,
            settings_due: false,
            scan: Scan::new(),
            seq: 0,
            buf: [0; HEADER_BYTES as usize],
            at: 0,
            len: 0,
            done: 0,
        }
    }

    /// The settings in EEPROM onto `cfg`, the defaults, in place; the
    /// defaults when they cannot be used: the task's first run then says
    /// why in one warning line and writes them. True when the task must
    /// run.
    pub fn load(&mut self, cfg: &mut MachineConfig) -> bool {
        let why = match image::decode_into(|i| self.eeprom.read(i as u16), cfg) {
            Ok(()) => return false,
            Err(why) => why,
        };
        if why == Unusable::Inconsistent {
            cfg.load_defaults(Machine::StringArt);
        }
        self.unusable = Some(why);
        self.settings_due = true;
        true
    }

    /// The job's checkpoint as the last power-off left it. A corrupt one
    /// is retired at once (an idle header after it): it is never used.
    pub fn load_checkpoint(&mut self) -> Found {
        let found = checkpoint::scan(|a| self.eeprom.read(a));
        self.seq = found.next_seq().wrapping_sub(1);
        if let Found::Corrupt { .. } = found {
            self.forget();
        }
        found
    }

    /// A `$` change came: write the settings' image back.
    pub fn settings_changed(&mut self) {
        self.settings_due = true;
        // Bytes already compared may differ now.
        self.scan = Scan::new();
    }

    /// A checkpoint write is under way (its last byte included): the job
    /// waits before moving on.
    pub fn saving(&self) -> bool {
        self.done < self.len || self.eeprom.busy()
    }

    fn start(&mut self, at: u16, bytes: &[u8]) {
        self.buf[..bytes.len()].copy_from_slice(bytes);
        self.at = at;
        self.len = bytes.len() as u8;
        self.done = 0;
    }

    /// A phase of the job starts: a new header, its records after it.
    /// Out of line (also `record`): inlined into the job task, their frames
    /// would add to its own (the stack peak).
    #[inline(never)]
    pub fn begin(&mut self, phase: Phase, (nails, count, id): (u16, u32, CardId)) {
        self.seq = self.seq.wrapping_add(1);
        let h = Header {
            seq: self.seq,
            phase: Some(phase),
            nails,
            count,
            id,
        };
        self.start(Header::address(self.seq), &h.encode());
    }

    #[inline(never)]
    pub fn record(&mut self, r: Record) {
        self.start(Record::address(r.n), &r.encode(self.seq));
    }

    /// No job under way any more: an idle header.
    pub fn forget(&mut self) {
        self.seq = self.seq.wrapping_add(1);
        self.start(Header::address(self.seq), &Header::idle(self.seq).encode());
    }

    fn warn(why: Unusable) {
        let text = match why {
            Unusable::Blank => flash_str!("blank"),
            Unusable::OtherVersion(_) => flash_str!("from another firmware version"),
            Unusable::Checksum => flash_str!("corrupt (checksum)"),
            Unusable::Refused(_) | Unusable::Inconsistent => {
                flash_str!("holding values this firmware refuses")
            }
        };
        warn!("settings: EEPROM ", text, ": defaults");
    }

    /// Write the next checkpoint byte, else the next byte of `cfg`'s image
    /// that differs from the EEPROM; `Wait(Settings)` once all agree.
    pub fn poll(&mut self, cfg: &MachineConfig) -> Poll<Signal> {
        if let Some(why) = self.unusable {
            if TX.free() < crate::log::LINE {
                return Poll::After(5);
            }
            self.unusable = None;
            Self::warn(why);
        }
        if self.eeprom.busy() {
            return Poll::After(4);
        }
        while self.saving() {
            let (at, b) = (self.at + self.done as u16, self.buf[self.done as usize]);
            self.done += 1;
            if self.eeprom.read(at) != b {
                self.eeprom.start_write(at, b);
                return Poll::After(4);
            }
        }
        if !self.settings_due {
            return Poll::Wait(Signal::Settings);
        }
        match self
            .scan
            .step(cfg, |i| self.eeprom.read(i as u16), SETTINGS_PER_RUN)
        {
            Step::Write(i, b) => {
                self.eeprom.start_write(i as u16, b);
                Poll::After(4)
            }
            Step::More => Poll::Again,
            Step::Same => {
                self.settings_due = false;
                self.scan = Scan::new();
                Poll::Wait(Signal::Settings)
            }
        }
    }
}
