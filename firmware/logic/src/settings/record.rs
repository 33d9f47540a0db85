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
//! Where each record lives and the layout marker: [`super::eeprom`].

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

#[cfg(test)]
mod tests;
