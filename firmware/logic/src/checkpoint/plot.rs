//! A plotter's card print in the checkpoint area: which file, and the
//! byte offset of the line whose moves the steppers were making, so that
//! the next power-on can offer to go on from that line (Marlin's
//! power-loss recovery, without its extra hardware).
//!
//! The header slot holds the file (its 8.3 name and size) under kind
//! [`KIND`]; the ring's [`PLOT_RECORD_BYTES`]-byte records hold `n` (u16,
//! its slot `n % PLOT_SLOTS`), the line's offset (u32), how many of its
//! blocks were drawn (u16), where the motors stood (two i32 steps) and a
//! CRC-16 over them and the header's sequence number. The newest record whose CRC holds is the checkpoint:
//! a record torn by a cut fails its CRC and the one before it stands
//! (earlier: more is drawn again, nothing is skipped).
//!
//! The modal state the line needs (units, distance mode, feed, offsets,
//! the pen) is not stored: the file's lines before it are read again on
//! resume, checked and taken without moving (as `$C` does), from where
//! the motors stood when the print began (the header keeps it: a file's
//! `G92` "here is X40 Y-5" and its relative moves count from there),
//! which leaves the executor exactly as they left it when the line was
//! first read.
//!
//! [`Tracker`] says which line is moving, and how far: each planned block
//! is counted by the step interrupt as it begins, and a line's first block
//! has number `begun + unbegun` when the line is read (`Motion::unbegun`).
//! Once the steppers have begun that block, every line before it is
//! drawn; once they have begun its `k + 1`-th, its first `k` blocks are
//! (an arc's chords, a path's pieces): a resumed print goes over those
//! with the pen up, moves on along the block that was moving to where the
//! motors stood, and puts the pen down there.

use super::{crc16, newer, CRC_START, END, HEADER_BYTES, MAGIC, RING, START};

/// Header byte 4 of a print's checkpoint (the string-art phases are 1
/// and 2, none 0).
pub const KIND: u8 = 3;
const VERSION: u8 = 2;

/// A record's bytes: `n`, the offset, the blocks drawn, the motors'
/// steps, the CRC.
pub const PLOT_RECORD_BYTES: u16 = 18;
/// Record slots in the ring.
pub const PLOT_SLOTS: u16 = (END - RING) / PLOT_RECORD_BYTES;

/// Records at most this often while the machine moves: after a cut, the
/// drawing goes on from where it stood at the last record, at most this
/// long before the cut; the ring's cells last [`hours_before_wear_out`]
/// of printing.
pub const RECORD_EVERY_MS: u32 = 500;

/// The print: its file, and the sequence number records are written
/// under.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlotHeader {
    pub seq: u16,
    /// The 8.3 name as the directory holds it (`STARDR~1GCO`).
    pub short: [u8; 11],
    pub size: u32,
    /// Where the motors stood when it began, steps.
    pub at: [i32; 2],
}

impl PlotHeader {
    pub fn encode(&self) -> [u8; HEADER_BYTES as usize] {
        let mut b = [0u8; HEADER_BYTES as usize];
        b[0] = MAGIC;
        b[1] = VERSION;
        b[2..4].copy_from_slice(&self.seq.to_le_bytes());
        b[4] = KIND;
        b[5..16].copy_from_slice(&self.short);
        b[16..20].copy_from_slice(&self.size.to_le_bytes());
        b[20..24].copy_from_slice(&self.at[0].to_le_bytes());
        b[24..28].copy_from_slice(&self.at[1].to_le_bytes());
        let crc = crc16(CRC_START, &b[..30]);
        b[30..].copy_from_slice(&crc.to_le_bytes());
        b
    }

    /// The header, if `b` is a print's whose CRC holds.
    pub fn decode(b: &[u8; HEADER_BYTES as usize]) -> Option<PlotHeader> {
        let crc = u16::from_le_bytes([b[30], b[31]]);
        if b[0] != MAGIC || b[1] != VERSION || b[4] != KIND || crc16(CRC_START, &b[..30]) != crc {
            return None;
        }
        let mut short = [0u8; 11];
        short.copy_from_slice(&b[5..16]);
        let word = |i: usize| [b[i], b[i + 1], b[i + 2], b[i + 3]];
        Some(PlotHeader {
            seq: u16::from_le_bytes([b[2], b[3]]),
            short,
            size: u32::from_le_bytes(word(16)),
            at: [i32::from_le_bytes(word(20)), i32::from_le_bytes(word(24))],
        })
    }
}

/// Record `n`: the line starting at byte `pos` was moving, its first
/// `done` blocks drawn, the next one's up to the motors' steps `at`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlotRecord {
    pub n: u16,
    pub pos: u32,
    pub done: u16,
    pub at: [i32; 2],
}

type RecordBytes = [u8; PLOT_RECORD_BYTES as usize];

impl PlotRecord {
    pub fn address(n: u16) -> u16 {
        RING + (n % PLOT_SLOTS) * PLOT_RECORD_BYTES
    }

    pub fn encode(&self, seq: u16) -> RecordBytes {
        let mut b = [0u8; PLOT_RECORD_BYTES as usize];
        b[..2].copy_from_slice(&self.n.to_le_bytes());
        b[2..6].copy_from_slice(&self.pos.to_le_bytes());
        b[6..8].copy_from_slice(&self.done.to_le_bytes());
        b[8..12].copy_from_slice(&self.at[0].to_le_bytes());
        b[12..16].copy_from_slice(&self.at[1].to_le_bytes());
        let crc = crc16(crc16(CRC_START, &seq.to_le_bytes()), &b[..16]);
        b[16..].copy_from_slice(&crc.to_le_bytes());
        b
    }

    pub fn decode(b: &RecordBytes, seq: u16) -> Option<PlotRecord> {
        let crc = crc16(crc16(CRC_START, &seq.to_le_bytes()), &b[..16]);
        let i32_at = |i: usize| i32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
        (crc == u16::from_le_bytes([b[16], b[17]])).then(|| PlotRecord {
            n: u16::from_le_bytes([b[0], b[1]]),
            pos: u32::from_le_bytes([b[2], b[3], b[4], b[5]]),
            done: u16::from_le_bytes([b[6], b[7]]),
            at: [i32_at(8), i32_at(12)],
        })
    }
}

/// A print a cut stopped: the file, and its newest record (`None`: none
/// yet, the print goes on from the file's start).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlotSaved {
    pub header: PlotHeader,
    pub last: Option<PlotRecord>,
}

impl PlotSaved {
    /// Where the print goes on: the start of the line that was moving.
    pub fn pos(&self) -> u32 {
        self.last.map_or(0, |r| r.pos)
    }

    /// That line's blocks already drawn.
    pub fn done(&self) -> u16 {
        self.last.map_or(0, |r| r.done)
    }

    /// The next record's number.
    pub fn next_n(&self) -> u16 {
        self.last.map_or(1, |r| r.n.wrapping_add(1))
    }
}

/// The newest record under `header` (a record in another number's slot
/// is stale or foreign: passed over).
pub(super) fn scan_records(read: &mut impl FnMut(u16) -> u8, header: PlotHeader) -> PlotSaved {
    let mut last: Option<PlotRecord> = None;
    for slot in 0..PLOT_SLOTS {
        let at = RING + slot * PLOT_RECORD_BYTES;
        let mut b = [0u8; PLOT_RECORD_BYTES as usize];
        for (i, x) in b.iter_mut().enumerate() {
            *x = read(at + i as u16);
        }
        let Some(r) = PlotRecord::decode(&b, header.seq) else {
            continue;
        };
        if r.n % PLOT_SLOTS != slot {
            continue;
        }
        // Numbers wrap; all those under one header lie within a ring.
        if last.is_none_or(|l| newer(r.n, l.n)) {
            last = Some(r);
        }
    }
    PlotSaved { header, last }
}

/// Lines followed at once: spread over the blocks in flight, the newest
/// begun of them is a block or two behind the one moving.
pub const FOLLOWED: usize = 7;

/// Which line of a print is moving, how far, and when its record is due.
///
/// The planner and the step queue hold a score of blocks, and the file's
/// lines are read as far ahead: the line read is not the one moving. A
/// few lines read are kept with the number of their first block, spread
/// over the blocks in flight; once blocks up to one of them have begun,
/// that line is moving (or done), and every line before it is drawn. The
/// oldest one's blocks begun are then counted on (past the block
/// numbers' wrap): a record names the line and its blocks drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Tracker {
    /// The oldest followed line's offset, the others' as bytes after it;
    /// before any is followed, where a resumed print goes on.
    base: u32,
    /// Lines followed, oldest first: offset after `base`, number of the
    /// first block.
    lines: [(u16, u8); FOLLOWED],
    len: u8,
    /// The oldest line's blocks begun (0: none yet), up to when `begun`
    /// was `counted`.
    into: u16,
    counted: u8,
    /// The machine moved since the last record (none is written while
    /// it stands).
    moved: bool,
    /// When the last record was asked for (ms, wrapping: a record at most
    /// [`RECORD_EVERY_MS`] late after a minute without one).
    last_ms: u16,
    /// The next record's number.
    next: u16,
}

impl Tracker {
    /// A new print.
    pub const fn new() -> Tracker {
        Tracker {
            base: 0,
            lines: [(0, 0); FOLLOWED],
            len: 0,
            into: 0,
            counted: 0,
            moved: false,
            last_ms: 0,
            next: 1,
        }
    }

    /// A print going on after a cut from the line at `saved.pos()`, its
    /// records numbered on.
    pub fn resuming(saved: &PlotSaved) -> Tracker {
        let mut t = Tracker::new();
        t.base = saved.pos();
        t.next = saved.next_n();
        t
    }

    /// Before any line is followed: where a resumed print goes on.
    pub fn resume_at(&self) -> u32 {
        self.base
    }

    /// A line of the file is about to be carried out: it starts at byte
    /// `pos`, and its first block (if it has any) will be block number
    /// `first` (blocks begun + blocks queued and not begun, read in that
    /// order: a block begun between the reads makes `first` one too
    /// high, which only waits a block longer). A line whose first block
    /// is the last followed line's, not begun, takes its place: the
    /// earlier one queued no block (`M3`, `G4`), and the pen and modes it
    /// set are taken again on resume. Not followed: a line 64 KiB past
    /// the oldest. With all places taken, the line closest after another
    /// gives its place up.
    pub fn line(&mut self, pos: u32, first: u8) {
        let len = self.len as usize;
        if len == 0 {
            self.base = pos;
        }
        let Ok(after) = u16::try_from(pos.wrapping_sub(self.base)) else {
            return;
        };
        if len > 0 && self.lines[len - 1].1 == first && (len > 1 || self.into == 0) {
            match len {
                1 => self.base = pos,
                _ => self.lines[len - 1].0 = after,
            }
            return;
        }
        if len == FOLLOWED {
            // The place whose line follows its neighbour's most closely
            // (never the oldest: it is the next to begin).
            let mut drop = len - 1;
            let mut gap = first.wrapping_sub(self.lines[len - 1].1);
            for i in 1..len {
                let g = self.lines[i].1.wrapping_sub(self.lines[i - 1].1);
                if g < gap {
                    (drop, gap) = (i, g);
                }
            }
            self.lines.copy_within(drop + 1..len, drop);
            self.len -= 1;
        }
        self.lines[self.len as usize] = (after, first);
        self.len += 1;
    }

    /// The lines before the `k`-th followed one (`0 < k < len`) are
    /// drawn: it is the oldest now.
    fn drop_oldest(&mut self, k: usize) {
        let len = (self.len as usize).min(FOLLOWED);
        let shift = self.lines[k].0;
        self.base = self.base.wrapping_add(u32::from(shift));
        for i in k..len {
            self.lines[i - k] = (self.lines[i].0 - shift, self.lines[i].1);
        }
        self.len -= k as u8;
    }

    /// The record to write now: the newest followed line whose first
    /// block has begun (`begun` blocks so far) and its blocks before the
    /// one moving, once the last record is [`RECORD_EVERY_MS`] old and
    /// the machine moved since (`running`: it moves now). `writing`: the
    /// last record is not yet durable (the next waits). Its `at` is the
    /// caller's: where the motors stand, read while block `begun - 1` is
    /// still the one moving.
    pub fn due(
        &mut self,
        begun: u8,
        running: bool,
        writing: bool,
        now_ms: u32,
    ) -> Option<PlotRecord> {
        let len = (self.len as usize).min(FOLLOWED);
        let has_begun = |first: u8| (begun.wrapping_sub(first) as i8) >= 1;
        // The newest followed line begun after the oldest: the older ones
        // are drawn, it stands for them.
        let mut newest = 0;
        for i in 1..len {
            if has_begun(self.lines[i].1) {
                newest = i;
            }
        }
        if newest > 0 {
            self.drop_oldest(newest);
            self.into = 0;
        }
        let more = begun.wrapping_sub(self.counted);
        if self.into > 0 {
            self.into = self.into.saturating_add(u16::from(more));
        } else if len > 0 && has_begun(self.lines[0].1) {
            self.into = u16::from(begun.wrapping_sub(self.lines[0].1));
            self.moved = true;
        } else {
            return None;
        }
        self.counted = begun;
        self.moved |= more > 0 || running;
        let rested = (now_ms as u16).wrapping_sub(self.last_ms) >= RECORD_EVERY_MS as u16;
        if writing || !rested || !self.moved {
            return None;
        }
        self.moved = false;
        self.last_ms = now_ms as u16;
        let r = PlotRecord {
            n: self.next,
            pos: self.base,
            // The block moving: drawn up to `at`.
            done: self.into - 1,
            at: [0; 2],
        };
        self.next = self.next.wrapping_add(1);
        Some(r)
    }
}

/// Going on with a print a cut stopped, step by step: offered at
/// power-on; taken (`M1000`, green), the machine homes if it has
/// switches, the file opens from its start, the executor is placed where
/// the print began, the lines before the checkpoint's are read and taken
/// without moving, then the pen goes up,
/// the machine moves to where the checkpoint's line starts, the pen goes
/// as it was there, and the print goes on with that line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Resume {
    /// `M1000` or green resumes, `M1000 C` or green held 2 s discards.
    Offered,
    Homing,
    Opening,
    /// The file is open: the executor goes where the print began.
    Placing,
    /// Lines before the checkpoint's offset: checked and taken, no motion.
    Replaying,
    /// The pen up and the move back to the line's start.
    Travel,
    /// The pen as the lines before left it.
    Pen,
}

/// What happened, for [`Resume::on`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ResumeEvent {
    /// `M1000` or green; `homes`: the machine has homing switches.
    Take { homes: bool },
    /// `M1000 C`, green held, or another print started.
    Discard,
    /// Homing is done (or not needed).
    Homed,
    /// The file is open from its start.
    Opened,
    /// A line of the file starting at this offset was read whole.
    Line(u32),
    /// The travel or the pen is done.
    Done,
}

/// What the firmware does next.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ResumeAction {
    None,
    /// Home the machine (`$H`).
    Home,
    /// Open the file from its start, as a print.
    Open,
    /// Program the executor where the motors stood when the print began.
    Place,
    /// Take the line without moving (as `$C`).
    Check,
    /// Hold the line: pen up, then a rapid to the executor's position.
    Travel,
    /// The pen as the executor's state has it.
    Pen,
    /// Carry out the held line and the rest as a print.
    Go,
    /// Write an idle header: the checkpoint is done with.
    Forget,
}

impl Resume {
    /// The next state (`None`: no resume under way) and what to do, the
    /// checkpoint's line starting at byte `at`.
    pub fn on(self, e: ResumeEvent, at: u32) -> (Option<Resume>, ResumeAction) {
        use Resume as S;
        use ResumeAction as A;
        use ResumeEvent as E;
        match (self, e) {
            (S::Offered, E::Take { homes: true }) => (Some(S::Homing), A::Home),
            (S::Offered, E::Take { homes: false }) | (S::Homing, E::Homed) => {
                (Some(S::Opening), A::Open)
            }
            (S::Offered, E::Discard) => (None, A::Forget),
            (S::Opening, E::Opened) => (Some(S::Placing), A::None),
            (S::Placing, E::Line(_)) => (Some(S::Replaying), A::Place),
            (S::Replaying, E::Line(pos)) if pos < at => (Some(S::Replaying), A::Check),
            (S::Replaying, E::Line(_)) => (Some(S::Travel), A::Travel),
            (S::Travel, E::Done) => (Some(S::Pen), A::Pen),
            (S::Pen, E::Done) => (None, A::Go),
            (s, _) => (Some(s), A::None),
        }
    }
}

/// Wear: hours of printing before the most-written cell of the ring
/// reaches `endurance` writes, a record every [`RECORD_EVERY_MS`].
pub fn hours_before_wear_out(endurance: u32) -> u32 {
    let lap_ms = u64::from(PLOT_SLOTS) * u64::from(RECORD_EVERY_MS);
    (u64::from(endurance) * lap_ms / 3_600_000) as u32
}

const _: () = assert!(RING + PLOT_SLOTS * PLOT_RECORD_BYTES <= END && START < RING);

#[cfg(test)]
mod tests;
