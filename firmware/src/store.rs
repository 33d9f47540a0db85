//! The EEPROM's one writer, and the keeper of what it holds: the machine's
//! settings (`taut_logic::settings`, named and Grbl's numbered, with the
//! [`Extras`] kept here), the work coordinate data (`taut_logic::coords`,
//! kept here), the two startup lines and the build info line (read from
//! EEPROM when wanted), each in two copies (`taut_logic::settings::record`:
//! a cut at any byte leaves the previous values), and the string-art
//! job's checkpoint (`taut_logic::checkpoint`).
//!
//! One byte per run (a byte takes 3.4 ms: the task comes back rather than
//! wait); only bytes that differ are written. A checkpoint write goes
//! first: the job waits for it ([`Store::saving`]).
//!
//! The G-code executor reads the coordinate data with [`Store::coords`]
//! and changes it with [`Store::set_coords`] (`G10 L2`/`L20`, `G28.1`,
//! `G30.1`): written in the background, in force at once.

use crate::board::eeprom::Eeprom;
use crate::board::port::Port;
use crate::queues::Signal;
use crate::rt::Poll;
use crate::{flash_str, info, warn};
use taut_logic::axis::AXES;
use taut_logic::checkpoint::{
    self, Found, Header, PlotHeader, PlotRecord, PlotSaved, Record, HEADER_BYTES,
};
use taut_logic::config::MachineConfig;
use taut_logic::coords::{CoordData, Slot};
use taut_logic::files::check::CardId;
use taut_logic::machine::Machine;
use taut_logic::settings::eeprom::{self, area, marker_byte, text_part, Layout, MARKER, TEXT};
use taut_logic::settings::grbl::Extras;
use taut_logic::settings::image::{self, legacy, Unusable};
use taut_logic::settings::record::{self, Loaded, Part, Step, Writer};
use taut_logic::stringart::job::Phase;
use taut_logic::units::Milli;

/// Parts compared per run (up to 8 bytes each, ~0.04 ms): the run stays
/// short, as every task waits behind it.
const PARTS_PER_RUN: u8 = 2;

/// The records, by index ([`eeprom::area`]): a bit each in
/// [`Store::due`].
const RECORDS: usize = eeprom::RECORDS;
const SETTINGS_I: u8 = 0;
const COORDS_I: u8 = 1;
/// The layout marker: written last on a new or upgraded chip.
const MARKER_BIT: u8 = 1 << RECORDS;

/// Byte `i` of the stored text at `at` ([`Store::text_addr`]), 0 past its
/// end. Read while a byte write is under way, it waits for it (≤ 3.4 ms).
pub fn stored_text(at: u16, i: u8) -> u8 {
    match (i as u16) < TEXT {
        true => !crate::board::eeprom::peek(at + i as u16),
        false => 0,
    }
}

/// A text the EEPROM keeps: `$N0`, `$N1`, `$I=`'s.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Text {
    Startup(u8),
    Info,
}

impl Text {
    fn record(self) -> u8 {
        match self {
            Text::Startup(n) => 2 + n,
            Text::Info => 4,
        }
    }
}

/// What the boot found that a warning line must say, once there is room.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Note {
    Settings(Unusable),
    /// Carried over from a version-6 image.
    Migrated,
    /// A record went bad in both copies: the coordinates (zeros) or a
    /// text (empty).
    Corrupt(u8),
}

pub struct Store {
    eeprom: Eeprom,
    /// To say once there is room for the line (it must not be dropped,
    /// and the boot fills the TX ring); then the next.
    notes: [Option<Note>; 2],
    /// Records still to write, a bit each, and [`MARKER_BIT`].
    due: u8,
    /// Changed again after their write's commit was asked for: written
    /// once more after it.
    again: u8,
    /// Each record's copy in force.
    loaded: [Loaded; RECORDS],
    /// The record being written, and how far.
    writer: Option<(u8, Writer)>,
    /// The EEPROM held another layout at boot: what fails its checks is
    /// stale data, not corruption.
    upgrading: bool,
    extras: Extras,
    coords: CoordData,
    /// A text staged or being written, and the record it goes to.
    text: [u8; TEXT as usize],
    text_len: u8,
    text_for: Option<u8>,
    /// The staged text passed its check and is to be written; until then
    /// it is only held, and a write of its record writes what was kept.
    text_saved: bool,
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
            notes: [None; 2],
            due: 0,
            again: 0,
            loaded: [Loaded::Blank; RECORDS],
            writer: None,
            upgrading: false,
            extras: Extras {
                bytes: [0; taut_logic::settings::grbl::BYTES],
                spindle: [0; 2],
                typed: [0; taut_logic::settings::grbl::TYPED],
            },
            coords: CoordData::ZERO,
            text: [0; TEXT as usize],
            text_len: 0,
            text_for: None,
            text_saved: false,
            seq: 0,
            buf: [0; HEADER_BYTES as usize],
            at: 0,
            len: 0,
            done: 0,
        }
    }

    /// The records in EEPROM: the settings onto `cfg` (the defaults, in
    /// place), the extras and the coordinates into the store. What cannot
    /// be used is replaced by its defaults and written back; the task's
    /// first runs say why, a line each. True when the task must run.
    #[inline(never)]
    pub fn load(&mut self, cfg: &mut MachineConfig) -> bool {
        // Into the fields in place: copies on the stack would be the
        // boot's stack peak.
        let Store {
            eeprom,
            notes,
            due,
            loaded,
            upgrading,
            extras,
            coords,
            ..
        } = self;
        let read = |a: u16| eeprom.read(a);
        // A payload's bytes from `at` on, stored inverted or not: one
        // closure type, so the settings' reading is one copy in flash for
        // the records and the version-6 image.
        let from =
            |at: u16, inverted: bool| move |i: u16| read(at + i) ^ if inverted { 0xFF } else { 0 };
        let layout = eeprom::layout(&read);
        let current = layout == Layout::Current;
        *upgrading = !current;
        extras.reset();
        let settings_area = area(SETTINGS_I);
        loaded[0] = record::load(settings_area, &read, |c| {
            cfg.load_defaults(Machine::StringArt);
            extras.reset();
            let payload = settings_area.copy(c) + record::HEAD;
            image::decode_into(from(payload, true), cfg, extras).is_ok()
        });
        if !matches!(loaded[0], Loaded::Taken { .. }) {
            cfg.load_defaults(Machine::StringArt);
            extras.reset();
            let why = match (layout, loaded[0]) {
                (Layout::Legacy, _) => match legacy::check(&read)
                    .and_then(|()| image::take_named(&from(legacy::BODY, false), image::V6, cfg))
                {
                    Ok(()) => None,
                    Err(why) => {
                        cfg.load_defaults(Machine::StringArt);
                        Some(why)
                    }
                },
                (_, Loaded::Corrupt) => Some(Unusable::Checksum),
                (Layout::Foreign, _) => Some(Unusable::OtherVersion(read(4))),
                _ => Some(Unusable::Blank),
            };
            notes[0] = Some(why.map_or(Note::Migrated, Note::Settings));
        }
        for i in COORDS_I..RECORDS as u8 {
            let a = area(i);
            loaded[i as usize] = record::load(a, &read, |c| {
                if i == COORDS_I {
                    coords.decode_into(|k| a.payload_byte(c, k, &read));
                }
                true
            });
            if current && loaded[i as usize] == Loaded::Corrupt && notes[1].is_none() {
                notes[1] = Some(Note::Corrupt(i));
            }
        }
        for (i, l) in loaded.iter().enumerate() {
            if !matches!(l, Loaded::Taken { .. }) {
                *due |= 1 << i;
            }
        }
        if !current {
            *due |= MARKER_BIT;
        }
        *due != 0
    }

    /// The job's checkpoint as the last power-off left it. A corrupt one
    /// is retired at once (an idle header after it): it is never used.
    /// On a chip of another layout whatever stands there is stale: retired
    /// without a word.
    pub fn load_checkpoint(&mut self) -> Found {
        let found = self.scan();
        self.seq = found.next_seq().wrapping_sub(1);
        if let Found::Corrupt { .. } = found {
            self.forget();
            if self.upgrading {
                return Found::Blank;
            }
        }
        found
    }

    /// Grbl's settings beside the named ones. Call [`Store::settings_changed`]
    /// after a change through [`Store::extras_mut`].
    pub fn extras(&self) -> &Extras {
        &self.extras
    }

    pub fn extras_mut(&mut self) -> &mut Extras {
        &mut self.extras
    }

    /// A `$` change came: write the settings' record (the extras with it).
    pub fn settings_changed(&mut self) {
        self.changed(SETTINGS_I);
    }

    /// The work coordinate data in force.
    pub fn coords(&self) -> &CoordData {
        &self.coords
    }

    /// `G10 L2`/`L20`, `G28.1`, `G30.1`: a slot's values, in force at
    /// once, in EEPROM soon (cut-safe).
    pub fn set_coords(&mut self, slot: Slot, values: [Milli; AXES]) {
        if self.coords.get(slot) != values {
            self.coords.set(slot, values);
            self.changed(COORDS_I);
        }
    }

    /// `$RST=#`: every slot zero.
    pub fn clear_coords(&mut self) {
        self.coords = CoordData::ZERO;
        self.changed(COORDS_I);
    }

    /// Where the copy in force of a stored text begins (`None`: never
    /// written, empty), for [`stored_text`].
    /// A text being written (cleared, or a `$N0=` the console waits for)
    /// reads as empty until it is.
    pub fn text_addr(&self, t: Text) -> Option<u16> {
        let r = t.record();
        if self.due & 1 << r != 0 {
            return None;
        }
        match self.loaded[r as usize] {
            Loaded::Taken { copy, .. } => Some(area(r).copy(copy) + record::HEAD),
            _ => None,
        }
    }

    /// A startup line is kept (not empty).
    pub fn has_startup_lines(&self) -> bool {
        (0..2).any(|n| {
            self.text_addr(Text::Startup(n))
                .is_some_and(|at| stored_text(at, 0) != 0)
        })
    }

    /// A byte write is under way: reads would wait for it.
    pub fn busy(&self) -> bool {
        self.eeprom.busy()
    }

    /// Hold `text` for `t` (the console checks it before it is written
    /// with [`Store::save_staged`]; a write of its record under way goes
    /// on with what was kept before). False when it is longer than a text
    /// is kept (Grbl's error 14), or while a saved text is still being
    /// written (its bytes are these).
    /// Capitals, as Grbl's reader leaves every line.
    pub fn stage(&mut self, t: Text, text: &[u8]) -> bool {
        if text.len() > TEXT as usize || self.text_saving() {
            return false;
        }
        for (to, b) in self.text.iter_mut().zip(text) {
            *to = b.to_ascii_uppercase();
        }
        self.text_len = text.len() as u8;
        self.text_for = Some(t.record());
        self.text_saved = false;
        true
    }

    /// The staged text's byte `i`, `None` past its end.
    pub fn staged_byte(&self, i: u8) -> Option<u8> {
        (i < self.text_len).then(|| self.text[i as usize])
    }

    /// Write the staged text.
    pub fn save_staged(&mut self) {
        if let Some(r) = self.text_for {
            self.text_saved = true;
            self.changed(r);
        }
    }

    /// Drop the staged text (it failed its check).
    pub fn drop_staged(&mut self) {
        if !self.text_saved {
            self.text_for = None;
        }
    }

    /// Empty a stored text (`$RST=*`): a text still to be written to it
    /// (a `$N0=` whose answer a Ctrl-X dropped) is dropped too.
    pub fn clear_text(&mut self, t: Text) {
        if self.text_for == Some(t.record()) {
            self.text_for = None;
            self.text_saved = false;
        }
        self.changed(t.record());
    }

    /// A text write is still under way: `$N0=` is answered after it, and
    /// the console reads no line until then.
    pub fn text_saving(&self) -> bool {
        self.text_saved
    }

    /// `$RST=*`'s rest: the texts empty, the extras Grbl's defaults.
    pub fn wipe(&mut self) {
        self.extras.reset();
        for t in [Text::Startup(0), Text::Startup(1), Text::Info] {
            self.clear_text(t);
        }
        self.clear_coords();
        self.settings_changed();
    }

    /// Record `r` changed: write it (again).
    fn changed(&mut self, r: u8) {
        let bit = 1 << r;
        self.due |= bit;
        if let Some((w, writer)) = self.writer.as_mut() {
            if *w == r && !writer.restart() {
                self.again |= bit;
            }
        }
    }

    /// Work is due: the task should run.
    pub fn wants_run(&self) -> bool {
        self.due != 0 || self.saving()
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

    /// A plotter's print from the card starts: its header (the file).
    #[inline(never)]
    pub fn plot_begin(&mut self, short: [u8; 11], size: u32, at: [i32; 2]) {
        self.seq = self.seq.wrapping_add(1);
        let h = PlotHeader {
            seq: self.seq,
            short,
            size,
            at,
        };
        self.start(Header::address(self.seq), &h.encode());
    }

    /// The line at this record's offset is moving.
    #[inline(never)]
    pub fn plot_record(&mut self, r: PlotRecord) {
        self.start(PlotRecord::address(r.n), &r.encode(self.seq));
    }

    /// The print a power cut stopped, read again from EEPROM (kept there
    /// rather than in RAM until it is resumed or discarded).
    #[inline(never)]
    pub fn plot_saved(&self) -> Option<PlotSaved> {
        match self.scan() {
            Found::Plot(p) => Some(p),
            _ => None,
        }
    }

    /// The checkpoint area read (one copy of the scan for every caller).
    #[inline(never)]
    fn scan(&self) -> Found {
        checkpoint::scan(|a| self.eeprom.read(a))
    }

    /// No job under way any more: an idle header.
    pub fn forget(&mut self) {
        self.seq = self.seq.wrapping_add(1);
        self.start(Header::address(self.seq), &Header::idle(self.seq).encode());
    }

    #[inline(never)]
    fn say(note: Note) {
        let why = match note {
            Note::Settings(Unusable::Blank) => flash_str!("blank"),
            Note::Settings(Unusable::OtherVersion(_)) => {
                flash_str!("from another firmware version")
            }
            Note::Settings(Unusable::Checksum) | Note::Corrupt(_) => {
                flash_str!("corrupt (checksum)")
            }
            Note::Settings(Unusable::Refused(_) | Unusable::Inconsistent) => {
                flash_str!("holding values this firmware refuses")
            }
            Note::Migrated => {
                return info!("settings: carried over from format version 6");
            }
        };
        let (what, instead) = match note {
            Note::Corrupt(COORDS_I) => (flash_str!("coordinates"), flash_str!("zeros")),
            Note::Corrupt(_) => (flash_str!("startup lines"), flash_str!("empty")),
            _ => (flash_str!("settings"), flash_str!("defaults")),
        };
        warn!(what, ": EEPROM ", why, ": ", instead);
    }

    /// Payload part `k` of record `r`. Out of line: the settings' parts
    /// alone are hundreds of bytes.
    #[inline(never)]
    fn part(&self, r: u8, cfg: &MachineConfig, k: u8) -> Option<Part> {
        match r {
            SETTINGS_I => image::part(cfg, &self.extras, k),
            COORDS_I => self
                .coords
                .part(k)
                .map(|b| ([b[0], b[1], b[2], b[3], 0, 0, 0, 0], 4)),
            _ if self.text_saved && self.text_for == Some(r) => {
                text_part(&self.text[..self.text_len as usize], k)
            }
            _ => text_part(&[], k),
        }
    }

    /// Write the next checkpoint byte, else the next byte of a record
    /// that differs from the EEPROM, else the marker; `Wait(Settings)`
    /// once all agree.
    pub fn poll(&mut self, cfg: &MachineConfig) -> Poll<Signal> {
        if let Some(note) = self.notes[0] {
            if Port::Usb.tx_free() < crate::log::LINE {
                return Poll::After(5);
            }
            self.notes = [self.notes[1], None];
            Self::say(note);
            // A line is a run's worth.
            return Poll::Again;
        }
        if self.eeprom.busy() {
            return Poll::After(4);
        }
        while self.done < self.len {
            let (at, b) = (self.at + self.done as u16, self.buf[self.done as usize]);
            self.done += 1;
            if self.eeprom.read(at) != b {
                self.eeprom.start_write(at, b);
                return Poll::After(4);
            }
        }
        let Some((r, mut w)) = self.writer.or_else(|| self.next_writer()) else {
            return self.marker();
        };
        let step = w.step(
            |a| self.eeprom.read(a),
            |k| self.part(r, cfg, k),
            PARTS_PER_RUN,
        );
        self.writer = Some((r, w));
        match step {
            Step::Write(at, b) => {
                self.eeprom.start_write(at, b);
                Poll::After(4)
            }
            Step::More => Poll::Again,
            Step::Done => {
                self.writer = None;
                self.loaded[r as usize] = Loaded::Taken {
                    copy: w.copy(),
                    seq: w.seq(),
                };
                let bit = 1 << r;
                match self.again & bit != 0 {
                    true => self.again &= !bit,
                    false => {
                        self.due &= !bit;
                        if self.text_saved && self.text_for == Some(r) {
                            self.text_for = None;
                            self.text_saved = false;
                        }
                    }
                }
                Poll::Again
            }
        }
    }

    /// A write of the first record due, into its copy not in force.
    fn next_writer(&self) -> Option<(u8, Writer)> {
        let r = (0..RECORDS as u8).find(|r| self.due & 1 << r != 0)?;
        let (copy, seq) = self.loaded[r as usize].next();
        Some((r, Writer::new(area(r), copy, seq)))
    }

    /// Every record written: the layout marker, if due.
    fn marker(&mut self) -> Poll<Signal> {
        if self.due & MARKER_BIT != 0 {
            for i in 0..MARKER.len() {
                let b = marker_byte(i);
                if self.eeprom.read(i as u16) != b {
                    self.eeprom.start_write(i as u16, b);
                    return Poll::After(4);
                }
            }
            self.due = 0;
            self.upgrading = false;
        }
        Poll::Wait(Signal::Settings)
    }
}
