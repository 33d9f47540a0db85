//! The string-art job's checkpoint in EEPROM: where a power
//! cut, a brown-out or a watchdog reset left the job, so that the next
//! boot can offer to go on from there.
//!
//! Layout, above the settings' records (`settings::record`, bytes 0..END):
//!
//! | bytes | what |
//! | --- | --- |
//! | `START .. START+64` | two header slots of 32 bytes: the job (phase, nails, connections, the card's identity) under a sequence number; a new header goes into the slot of the older one |
//! | `RING ..` 4096 | `SLOTS` records of 8 bytes: `n` (u32), `gap` (u16), CRC-16 |
//!
//! Record number `n` lives in slot `n % SLOTS`: the slot is implied by the
//! number (a stale record in a slot fails the residue check) and the ring
//! wears every cell alike. Each record's CRC covers the header's sequence
//! number: records written under another header (an earlier phase or
//! job) never pass as this one's.
//!
//! Torn writes: a record is written byte by byte (3.4 ms each). A cut in
//! the middle leaves that one record bad, and the scan falls back to the
//! one before, which the job made durable before starting the motion the
//! torn one was about (`stringart::job` writes record n+1 only after n is
//! out, and moves on only once n+1 is; while winding, record n+1 is
//! written as the machine moves towards its crossing — started only once
//! the crossing n was about is done — and that crossing is handed to the
//! planner only once the record is durable). A header cut mid-write leaves the
//! older header, which is consistent with its own records. Anything else
//! wrong — a record missing or bad between the oldest one still expected
//! and the newest — is corruption: [`Found::Corrupt`], never trusted.

use crate::files::check::{CardId, FileSum};
use crate::stringart::Phase;

pub mod plot;

pub use plot::{PlotHeader, PlotRecord, PlotSaved};

/// First byte of the checkpoint area (the settings' records end below it).
pub const START: u16 = 1536;
/// The ATmega2560's EEPROM size.
pub const END: u16 = 4096;
pub const HEADER_BYTES: u16 = 32;
pub const RECORD_BYTES: u16 = 8;
/// First record slot.
pub const RING: u16 = START + 2 * HEADER_BYTES;
/// Record slots in the ring.
pub const SLOTS: u16 = (END - RING) / RECORD_BYTES;

const MAGIC: u8 = b'K';
const VERSION: u8 = 1;

/// CRC-16/CCITT-FALSE (polynomial 0x1021, start 0xFFFF), bit by bit: no
/// table, so nothing in the AVR's SRAM.
pub fn crc16(crc: u16, bytes: &[u8]) -> u16 {
    let mut crc = crc;
    for &b in bytes {
        crc ^= (b as u16) << 8;
        for _ in 0..8 {
            crc = if crc & 0x8000 != 0 {
                (crc << 1) ^ 0x1021
            } else {
                crc << 1
            };
        }
    }
    crc
}

pub const CRC_START: u16 = 0xFFFF;

/// The job a checkpoint belongs to: written when a phase starts, and with
/// `phase: None` when the job ends (or its checkpoint is discarded).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Header {
    /// Newer headers have higher numbers (wrapping).
    pub seq: u16,
    pub phase: Option<Phase>,
    pub nails: u16,
    pub count: u32,
    pub id: CardId,
}

impl Header {
    /// No job: what the job's end and a discard write.
    pub fn idle(seq: u16) -> Header {
        Header {
            seq,
            phase: None,
            nails: 0,
            count: 0,
            id: CardId::default(),
        }
    }

    /// The header slot this one goes to: the two alternate.
    pub fn address(seq: u16) -> u16 {
        START + (seq & 1) * HEADER_BYTES
    }

    pub fn encode(&self) -> [u8; HEADER_BYTES as usize] {
        let mut b = [0u8; HEADER_BYTES as usize];
        b[0] = MAGIC;
        b[1] = VERSION;
        b[2..4].copy_from_slice(&self.seq.to_le_bytes());
        b[4] = match self.phase {
            None => 0,
            Some(Phase::Drilling) => 1,
            Some(Phase::Winding) => 2,
        };
        b[5..7].copy_from_slice(&self.nails.to_le_bytes());
        b[7..11].copy_from_slice(&self.count.to_le_bytes());
        b[11..19].copy_from_slice(&self.id.param.to_bytes());
        b[19..27].copy_from_slice(&self.id.poradi.to_bytes());
        // 27..30 spare, zero.
        let crc = crc16(CRC_START, &b[..30]);
        b[30..].copy_from_slice(&crc.to_le_bytes());
        b
    }

    pub fn decode(b: &[u8; HEADER_BYTES as usize]) -> Option<Header> {
        let crc = u16::from_le_bytes([b[30], b[31]]);
        if b[0] != MAGIC || b[1] != VERSION || crc16(CRC_START, &b[..30]) != crc {
            return None;
        }
        let sum = |at: usize| {
            let mut x = [0u8; 8];
            x.copy_from_slice(&b[at..at + 8]);
            FileSum::from_bytes(x)
        };
        Some(Header {
            seq: u16::from_le_bytes([b[2], b[3]]),
            phase: match b[4] {
                0 => None,
                1 => Some(Phase::Drilling),
                2 => Some(Phase::Winding),
                _ => return None,
            },
            nails: u16::from_le_bytes([b[5], b[6]]),
            count: u32::from_le_bytes([b[7], b[8], b[9], b[10]]),
            id: CardId {
                param: sum(11),
                poradi: sum(19),
            },
        })
    }
}

/// How far the phase got: record `n` of the header's phase. Drilling:
/// `n` holes are drilled (the next is hole `n`). Winding: `n / 2` wraps
/// are wound, and the needle, outside the ring, goes back in through the
/// gap after nail `gap` (`n` odd: the next wrap's first gap, where its
/// needle was about to go out; `n` even: the last wrap's closing gap).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Record {
    pub n: u32,
    pub gap: u16,
}

impl Record {
    /// The slot of record `n`.
    pub fn address(n: u32) -> u16 {
        RING + (n % SLOTS as u32) as u16 * RECORD_BYTES
    }

    pub fn encode(&self, seq: u16) -> [u8; RECORD_BYTES as usize] {
        let mut b = [0u8; RECORD_BYTES as usize];
        b[..4].copy_from_slice(&self.n.to_le_bytes());
        b[4..6].copy_from_slice(&self.gap.to_le_bytes());
        let crc = crc16(crc16(CRC_START, &seq.to_le_bytes()), &b[..6]);
        b[6..].copy_from_slice(&crc.to_le_bytes());
        b
    }

    /// The record, if its CRC holds under header `seq`.
    pub fn decode(b: &[u8; RECORD_BYTES as usize], seq: u16) -> Option<Record> {
        let crc = crc16(crc16(CRC_START, &seq.to_le_bytes()), &b[..6]);
        (crc == u16::from_le_bytes([b[6], b[7]])).then(|| Record {
            n: u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            gap: u16::from_le_bytes([b[4], b[5]]),
        })
    }
}

/// A job that was under way: its header and its last durable record
/// (`None`: none yet, the phase is at its start).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Saved {
    pub header: Header,
    pub last: Option<Record>,
}

impl Saved {
    pub fn phase(&self) -> Phase {
        self.header.phase.unwrap_or(Phase::Drilling)
    }

    pub fn n(&self) -> u32 {
        self.last.map_or(0, |r| r.n)
    }

    /// Holes drilled or wraps wound.
    pub fn done(&self) -> u32 {
        match self.phase() {
            Phase::Drilling => self.n(),
            Phase::Winding => self.n() / 2,
        }
    }
}

/// What the EEPROM holds, and the sequence number the next header takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Found {
    /// Never written (a new board: every byte 0xFF).
    Blank,
    /// No job under way.
    Idle {
        seq: u16,
    },
    Job(Saved),
    /// A plotter's print from the card (`plot`).
    Plot(PlotSaved),
    /// Bad headers or records: ignored, with a warning.
    Corrupt {
        seq: u16,
    },
}

impl Found {
    /// The number for the next header written.
    pub fn next_seq(&self) -> u16 {
        match self {
            Found::Blank => 1,
            Found::Idle { seq } | Found::Corrupt { seq } => seq.wrapping_add(1),
            Found::Job(s) => s.header.seq.wrapping_add(1),
            Found::Plot(p) => p.header.seq.wrapping_add(1),
        }
    }
}

fn read_n<const N: usize>(read: &mut impl FnMut(u16) -> u8, at: u16) -> [u8; N] {
    let mut b = [0u8; N];
    for (i, x) in b.iter_mut().enumerate() {
        *x = read(at + i as u16);
    }
    b
}

/// A header slot's contents: a string-art job's or a print's.
#[derive(Clone, Copy)]
enum Head {
    Job(Header),
    Plot(PlotHeader),
}

impl Head {
    fn seq(&self) -> u16 {
        match self {
            Head::Job(h) => h.seq,
            Head::Plot(h) => h.seq,
        }
    }
}

/// `a` is newer than `b`, sequence numbers wrapping.
fn newer(a: u16, b: u16) -> bool {
    (a.wrapping_sub(b) as i16) > 0
}

/// Reads the checkpoint through `read` (an EEPROM byte by address).
// Out of line, as `settings::image::decode_into`.
#[inline(never)]
pub fn scan(mut read: impl FnMut(u16) -> u8) -> Found {
    let slots: [Option<Head>; 2] = [0, 1].map(|i| {
        let b = read_n(&mut read, START + i * HEADER_BYTES);
        Header::decode(&b)
            .map(Head::Job)
            .or_else(|| PlotHeader::decode(&b).map(Head::Plot))
    });
    let header = match slots {
        [Some(a), Some(b)] => Some(if newer(b.seq(), a.seq()) { b } else { a }),
        [Some(h), None] | [None, Some(h)] => Some(h),
        [None, None] => None,
    };
    let header = match header {
        Some(Head::Job(h)) => Some(h),
        Some(Head::Plot(h)) => return Found::Plot(plot::scan_records(&mut read, h)),
        None => None,
    };
    let Some(header) = header else {
        let blank = (START..RING).all(|i| read(i) == 0xFF);
        return if blank {
            Found::Blank
        } else {
            Found::Corrupt { seq: 0 }
        };
    };
    let seq = header.seq;
    if header.phase.is_none() {
        return Found::Idle { seq };
    }
    let record = |read: &mut dyn FnMut(u16) -> u8, slot: u16| {
        let at = RING + slot * RECORD_BYTES;
        let mut b = [0u8; RECORD_BYTES as usize];
        for (i, x) in b.iter_mut().enumerate() {
            *x = read(at + i as u16);
        }
        Record::decode(&b, seq)
    };
    // The newest record; any that sits in another number's slot is bad.
    let mut last: Option<Record> = None;
    for slot in 0..SLOTS {
        if let Some(r) = record(&mut read, slot) {
            if r.n % SLOTS as u32 != slot as u32 {
                return Found::Corrupt { seq };
            }
            if last.is_none_or(|l| r.n > l.n) {
                last = Some(r);
            }
        }
    }
    // Every record from the oldest the ring still holds up to the newest
    // (record 0 is never written: it is the phase's start). The slot after
    // the newest may be torn.
    if let Some(l) = last {
        let oldest = (l.n + 2).saturating_sub(SLOTS as u32).max(1);
        for n in oldest..l.n {
            let slot = (n % SLOTS as u32) as u16;
            if record(&mut read, slot).is_none_or(|r| r.n != n) {
                return Found::Corrupt { seq };
            }
        }
    }
    Found::Job(Saved { header, last })
}

/// Wear: most writes any one cell takes in a job of `holes` holes and
/// `wraps` wraps (one record per hole, two per wrap, each phase's records
/// numbered from 1, so the low slots get the remainder of both phases).
pub fn cell_writes_per_job(holes: u32, wraps: u32) -> u32 {
    let per = |records: u32| records.div_ceil(SLOTS as u32);
    per(holes) + per(2 * wraps)
}

/// Bytes written into the EEPROM by one job: every record whole (at most:
/// bytes equal to the slot's old contents are passed over), and three
/// headers (drilling, winding, end).
pub fn byte_writes_per_job(holes: u32, wraps: u32) -> u32 {
    (holes + 2 * wraps) * RECORD_BYTES as u32 + 3 * HEADER_BYTES as u32
}

/// Jobs before the most-written cell reaches `endurance` writes (the
/// datasheet's 100 000).
pub fn jobs_before_wear_out(holes: u32, wraps: u32, endurance: u32) -> u32 {
    endurance / cell_writes_per_job(holes, wraps).max(1)
}

#[cfg(test)]
mod tests;
