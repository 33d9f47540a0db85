//! Two copies of each record the EEPROM keeps (the settings, the work
//! coordinates, the startup lines, the build info line), so that a cut at
//! any byte of a write leaves the previous values in force, never the
//! defaults. A change is written into the copy not in force; it counts
//! only once its last byte is.
//!
//! A copy, [`HEAD`] + payload + [`TAIL`] bytes:
//!
//! | byte | what |
//! | --- | --- |
//! | 0 | state: [`COMMITTED`], or anything else (0xFF: erased) |
//! | 1, 2 | the record's kind and format version |
//! | 3, 4 | sequence number: of two committed copies the higher (wrapping) is in force |
//! | 5 … | payload, every byte stored inverted: zeros are erased cells, which a new chip need not write |
//! | last 2 | CRC-16 of bytes 1 … (kind to payload) |
//!
//! The writer ([`Writer`]) first erases the state byte of the copy it is
//! about to change (if it was committed), then writes the bytes that
//! differ, in order, and the state byte last. A cut before that last byte
//! leaves a copy that is not committed, which is never read: the other
//! copy is in force, whatever the torn bytes hold. The CRC is for worn
//! cells and stray writes: a committed copy that fails it is corruption.
//!
//! Where each record lives ([`SETTINGS`], [`COORDS`], [`LINES`], [`INFO`])
//! and the layout marker ([`MARKER`]) are at the end of this file.

use crate::checkpoint::{crc16, CRC_START};

/// A committed copy's first byte.
pub const COMMITTED: u8 = 0xA5;
/// Bytes before the payload: state, kind, version, sequence number.
pub const HEAD: u16 = 5;
/// The CRC after it.
pub const TAIL: u16 = 2;

/// Up to 8 payload bytes, and how many of them count.
pub type Part = ([u8; 8], u8);

/// A record's place in EEPROM: two copies, one after the other.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Area {
    /// Copy 0's first byte.
    pub start: u16,
    pub kind: u8,
    pub version: u8,
    /// Payload bytes.
    pub payload: u16,
}

/// `a` is newer than `b`, sequence numbers wrapping.
pub fn newer(a: u16, b: u16) -> bool {
    (a.wrapping_sub(b) as i16) > 0
}

impl Area {
    pub const fn copy_len(self) -> u16 {
        HEAD + self.payload + TAIL
    }

    /// Copy `c`'s (0 or 1) first byte.
    pub const fn copy(self, c: u8) -> u16 {
        self.start + c as u16 * self.copy_len()
    }

    /// The byte after copy 1.
    pub const fn end(self) -> u16 {
        self.start + 2 * self.copy_len()
    }

    /// Copy `c`'s sequence number, if it is committed whole: its state,
    /// kind, version and CRC right.
    pub fn check(self, c: u8, read: &impl Fn(u16) -> u8) -> Option<u16> {
        let at = self.copy(c);
        if read(at) != COMMITTED || read(at + 1) != self.kind || read(at + 2) != self.version {
            return None;
        }
        let n = self.copy_len();
        let mut crc = CRC_START;
        for i in 1..n - TAIL {
            crc = crc16(crc, &[read(at + i)]);
        }
        let stored = u16::from_le_bytes([read(at + n - 2), read(at + n - 1)]);
        (crc == stored).then(|| u16::from_le_bytes([read(at + 3), read(at + 4)]))
    }

    /// The copies that pass [`Area::check`], newest first: `(copy, seq)`.
    /// The caller takes the first whose payload it accepts.
    pub fn copies(self, read: &impl Fn(u16) -> u8) -> [Option<(u8, u16)>; 2] {
        let a = self.check(0, read).map(|s| (0, s));
        let b = self.check(1, read).map(|s| (1, s));
        match (a, b) {
            (Some((_, sa)), Some((_, sb))) if newer(sb, sa) => [b, a],
            (None, Some(_)) => [b, None],
            _ => [a, b],
        }
    }

    /// A copy's state byte says committed. When no copy is taken, this
    /// tells corruption (a committed copy went bad) from a write that
    /// never finished or never began.
    pub fn any_committed(self, read: &impl Fn(u16) -> u8) -> bool {
        read(self.copy(0)) == COMMITTED || read(self.copy(1)) == COMMITTED
    }

    /// Byte `i` of copy `c`'s payload, as it was given.
    pub fn payload_byte(self, c: u8, i: u16, read: &impl Fn(u16) -> u8) -> u8 {
        !read(self.copy(c) + HEAD + i)
    }
}

/// What the boot found of an area.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Loaded {
    /// Copy `copy`, numbered `seq`, is in force.
    Taken { copy: u8, seq: u16 },
    /// No copy was ever committed: a new chip, or a first write cut short.
    Blank,
    /// A committed copy went bad, and no other holds.
    Corrupt,
}

impl Loaded {
    /// The copy the next write goes to, and its number: the one not in
    /// force.
    pub fn next(self) -> (u8, u16) {
        match self {
            Loaded::Taken { copy, seq } => (1 - copy, seq.wrapping_add(1)),
            _ => (0, 1),
        }
    }
}

/// Reads `area`: its committed copies newest first, each offered to
/// `take(copy)`, which reads the payload and says whether it takes it.
pub fn load(area: Area, read: &impl Fn(u16) -> u8, mut take: impl FnMut(u8) -> bool) -> Loaded {
    for (copy, seq) in area.copies(read).into_iter().flatten() {
        if take(copy) {
            return Loaded::Taken { copy, seq };
        }
    }
    match area.any_committed(read) {
        true => Loaded::Corrupt,
        false => Loaded::Blank,
    }
}

/// Whose data the EEPROM holds, by its first five bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// This layout's, written whole ([`MARKER`]).
    Current,
    /// Erased: a new chip (or its first boot's writes cut short).
    Blank,
    /// A settings image of version 6 (a board flashed before): read
    /// once, then the marker.
    Legacy,
    /// Another firmware's, or an older taut's.
    Foreign,
}

/// Byte `i` of [`MARKER`], read from flash (an array would be copied
/// into the AVR's SRAM).
pub fn marker_byte(i: usize) -> u8 {
    taut_progmem::text!("taut\x08").byte(i)
}

/// Record `i`: 0 the settings, 1 the coordinates, 2 and 3 the startup
/// lines, 4 the build info; from a table in flash (each constant would be
/// copied into the AVR's SRAM where it is taken by reference).
pub fn area(i: u8) -> Area {
    taut_progmem::table!(Area; RECORDS; [SETTINGS, COORDS, LINES[0], LINES[1], INFO])
        .get(i as usize)
}

/// Records kept.
pub const RECORDS: usize = 5;

/// The layout byte 0… says.
pub fn layout(read: &impl Fn(u16) -> u8) -> Layout {
    if (0..MARKER.len()).all(|i| read(i as u16) == marker_byte(i)) {
        return Layout::Current;
    }
    if (0..MARKER.len()).all(|i| read(i as u16) == 0xFF) {
        return Layout::Blank;
    }
    match super::image::legacy::version(read) {
        Some(super::image::legacy::VERSION) => Layout::Legacy,
        _ => Layout::Foreign,
    }
}

/// Where a write of one copy stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage {
    /// The state byte, erased if it was committed.
    Uncommit,
    /// Kind, version and number.
    Head,
    Payload,
    Crc,
    /// The state byte, committed: asked for, then read back.
    Commit,
    Done,
}

/// What [`Writer::step`] found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// Byte `.0` of the EEPROM must become `.1`; the writer compares it
    /// again next, and goes on once it holds it.
    Write(u16, u8),
    /// More to compare.
    More,
    /// The copy is committed whole.
    Done,
}

/// A write of one copy of an area, resumable: [`Writer::step`] compares a
/// few parts a call (the EEPROM takes 3.4 ms a byte: the store task asks
/// for one byte and comes back), with the CRC summed so far.
#[derive(Clone, Copy, Debug)]
pub struct Writer {
    area: Area,
    copy: u8,
    seq: u16,
    stage: Stage,
    /// The next byte compared.
    at: u16,
    /// The payload's next part.
    part: u8,
    crc: u16,
}

impl Writer {
    /// A write of `area`'s copy `copy`, numbered `seq`.
    pub const fn new(area: Area, copy: u8, seq: u16) -> Writer {
        Writer {
            area,
            copy,
            seq,
            stage: Stage::Uncommit,
            at: 0,
            part: 0,
            crc: CRC_START,
        }
    }

    pub fn area(&self) -> Area {
        self.area
    }

    pub fn copy(&self) -> u8 {
        self.copy
    }

    pub fn seq(&self) -> u16 {
        self.seq
    }

    /// The data changed: compare from the first byte again. False once the
    /// state byte's commit has been asked for (the copy then holds the
    /// data as it was, whole): the caller lets it end and writes the other
    /// copy next.
    pub fn restart(&mut self) -> bool {
        if matches!(self.stage, Stage::Commit | Stage::Done) {
            return false;
        }
        *self = Writer::new(self.area, self.copy, self.seq);
        true
    }

    /// Compares up to `parts` parts of the copy with what `read(address)`
    /// holds; the payload's part `k` is `part(k)` (`None` past the last).
    /// Out of line: one copy, not one in each caller.
    #[inline(never)]
    pub fn step(
        &mut self,
        read: impl Fn(u16) -> u8,
        part: impl Fn(u8) -> Option<Part>,
        parts: u8,
    ) -> Step {
        let state = self.area.copy(self.copy);
        for _ in 0..parts {
            let (buf, n) = match self.stage {
                Stage::Uncommit => {
                    if read(state) == COMMITTED {
                        return Step::Write(state, 0xFF);
                    }
                    self.stage = Stage::Head;
                    self.at = state + 1;
                    continue;
                }
                Stage::Head => {
                    let s = self.seq.to_le_bytes();
                    let a = self.area;
                    ([a.kind, a.version, s[0], s[1], 0, 0, 0, 0], 4)
                }
                Stage::Payload => match part(self.part) {
                    Some((b, n)) => (b.map(|x| !x), n),
                    None => {
                        self.stage = Stage::Crc;
                        continue;
                    }
                },
                Stage::Crc => {
                    let c = self.crc.to_le_bytes();
                    ([c[0], c[1], 0, 0, 0, 0, 0, 0], 2)
                }
                Stage::Commit => {
                    if read(state) != COMMITTED {
                        return Step::Write(state, COMMITTED);
                    }
                    self.stage = Stage::Done;
                    return Step::Done;
                }
                Stage::Done => return Step::Done,
            };
            // The CRC is not summed over itself: its bytes compare plainly.
            let mut crc = self.crc;
            for (k, &b) in buf[..n as usize].iter().enumerate() {
                let at = self.at + k as u16;
                if read(at) != b {
                    return Step::Write(at, b);
                }
                crc = crc16(crc, &[b]);
            }
            self.at += n as u16;
            match self.stage {
                Stage::Head => {
                    self.crc = crc;
                    self.stage = Stage::Payload;
                }
                Stage::Payload => {
                    self.crc = crc;
                    self.part += 1;
                }
                _ => self.stage = Stage::Commit,
            }
        }
        Step::More
    }
}

/// `taut` and the layout's version (8: the settings record's room), at
/// byte 0 (where the settings image of version 6 began: its magic and
/// version byte). Written last on a new
/// or an upgraded chip, once every record below is: until then a record
/// that fails its checks is stale data of an older layout, not corruption.
pub const MARKER: [u8; 5] = *b"taut\x08";
/// The settings image of version 6 (one copy, at byte 0) ends below this:
/// read once to migrate it.
pub const LEGACY_END: u16 = 256;

/// Grbl's numbered settings and taut's named ones
/// ([`super::image`]).
pub const SETTINGS: Area = Area {
    start: LEGACY_END,
    kind: b'S',
    // 8: a fixed room, the count of named settings first (7 had no room:
    // a setting added moved every record after it).
    version: 8,
    payload: super::image::PAYLOAD,
};

/// The work coordinate data ([`crate::coords`]).
pub const COORDS: Area = Area {
    start: SETTINGS.end(),
    kind: b'C',
    version: 1,
    payload: crate::coords::PAYLOAD,
};

/// Longest startup line or build info line kept, characters (Grbl's
/// `EEPROM_LINE_SIZE`, 80, holds `$N0=` and the line's end too).
pub const TEXT: u16 = 75;
/// A text's payload: the characters, then zeros.
const TEXT_PAYLOAD: u16 = TEXT + 1;

/// `$N0` and `$N1`.
pub const LINES: [Area; 2] = [
    Area {
        start: COORDS.end(),
        kind: b'N',
        version: 1,
        payload: TEXT_PAYLOAD,
    },
    Area {
        start: COORDS.end() + 2 * (HEAD + TEXT_PAYLOAD + TAIL),
        kind: b'M',
        version: 1,
        payload: TEXT_PAYLOAD,
    },
];

/// `$I=`'s line.
pub const INFO: Area = Area {
    start: LINES[1].end(),
    kind: b'I',
    version: 1,
    payload: TEXT_PAYLOAD,
};

/// Part `k` of a text's payload: its characters, then zeros to
/// [`TEXT`] + 1 bytes (a text longer than [`TEXT`] is cut there).
pub fn text_part(text: &[u8], k: u8) -> Option<Part> {
    let from = k as usize * 8;
    let len = TEXT_PAYLOAD as usize;
    if from >= len {
        return None;
    }
    let mut b = [0u8; 8];
    for (i, x) in b.iter_mut().enumerate() {
        let at = from + i;
        if at < TEXT as usize {
            *x = text.get(at).copied().unwrap_or(0);
        }
    }
    Some((b, (len - from).min(8) as u8))
}

/// Every record's bytes end below this (the string-art checkpoint begins
/// there).
pub const END: u16 = INFO.end();
const _: () = assert!(END <= crate::checkpoint::START);
const _: () = assert!(LINES[0].end() == LINES[1].start);
const _: () = assert!(super::image::LEGACY_LEN <= LEGACY_END as usize);

/// Host helpers: an EEPROM written as the store writes it (the HIL tests
/// make boards' EEPROMs with them).
#[cfg(not(target_arch = "avr"))]
pub mod host {
    extern crate std;
    use super::*;
    use crate::config::MachineConfig;
    use crate::coords::CoordData;
    use crate::settings::grbl::Extras;
    use std::vec::Vec;

    /// Writes a copy through `w` into `eeprom` a byte at a time, as the
    /// store task does; the writes in order.
    pub fn write(
        eeprom: &mut [u8],
        mut w: Writer,
        part: impl Fn(u8) -> Option<Part>,
    ) -> Vec<(u16, u8)> {
        let mut writes = Vec::new();
        loop {
            let step = w.step(|a| eeprom[a as usize], &part, 8);
            match step {
                Step::Write(a, b) => {
                    eeprom[a as usize] = b;
                    writes.push((a, b));
                }
                Step::More => {}
                Step::Done => return writes,
            }
        }
    }

    /// A whole EEPROM as a board that kept `cfg`, `ex` and `coords` (no
    /// startup lines) holds it: every record's copy 0, the marker, no
    /// checkpoint.
    pub fn eeprom(cfg: &MachineConfig, ex: &Extras, coords: &CoordData) -> Vec<u8> {
        let mut e = std::vec![0xFF; crate::checkpoint::END as usize];
        write(&mut e, Writer::new(SETTINGS, 0, 1), |k| {
            crate::settings::image::part(cfg, ex, k)
        });
        write(&mut e, Writer::new(COORDS, 0, 1), |k| {
            coords
                .part(k)
                .map(|b| ([b[0], b[1], b[2], b[3], 0, 0, 0, 0], 4))
        });
        for area in [LINES[0], LINES[1], INFO] {
            write(&mut e, Writer::new(area, 0, 1), |k| text_part(&[], k));
        }
        e[..MARKER.len()].copy_from_slice(&MARKER);
        e
    }

    /// The settings an EEPROM holds, as the firmware's boot reads them
    /// (a version-6 image too); `None`: the defaults would be taken.
    pub fn settings(eeprom: &[u8]) -> Option<(MachineConfig, Extras)> {
        use crate::settings::image;
        let read = |a: u16| eeprom.get(a as usize).copied().unwrap_or(0xFF);
        let mut out = None;
        load(SETTINGS, &read, |c| {
            let (mut cfg, mut ex) = (MachineConfig::STRING_ART, Extras::DEFAULT);
            let ok = image::decode_into(|i| SETTINGS.payload_byte(c, i, &read), &mut cfg, &mut ex)
                .is_ok();
            if ok {
                out = Some((cfg, ex));
            }
            ok
        });
        out.or_else(|| {
            let mut cfg = MachineConfig::STRING_ART;
            image::legacy::decode_into(read, &mut cfg).ok()?;
            Some((cfg, Extras::DEFAULT))
        })
    }

    /// The work coordinate data an EEPROM holds.
    pub fn coords(eeprom: &[u8]) -> Option<CoordData> {
        let read = |a: u16| eeprom.get(a as usize).copied().unwrap_or(0xFF);
        let mut out = None;
        load(COORDS, &read, |c| {
            out = Some(CoordData::decode(|i| COORDS.payload_byte(c, i, &read)));
            true
        });
        out
    }
}

#[cfg(test)]
mod tests;
