//! The root directory, a block at a time: files by their 8.3 name and by
//! the long (VFAT) name that PCs, phones and `mkfs`-made cards give them
//! (`star.gcode` is stored as `STAR~1.GCO` plus long-name entries), for
//! opening by either and for listing (`M20`).
//!
//! A long name is kept only if it is ASCII and at most [`LONG`] characters
//! and its entries carry the checksum of the 8.3 name that follows them
//! (a long name left behind by a tool that knows only 8.3 names is not
//! believed); otherwise the file is known by its 8.3 name alone.

use super::{le16, le32, BlockRead, FatError, File, Volume, ATTR_DIR, ATTR_VOLUME, BLOCK};

/// Longest long name kept: two VFAT entries of 13 characters.
pub const LONG: usize = 26;
const PER_ENTRY: usize = 13;
const ATTR_LONG: u8 = 0x0F;
/// A directory holds at most 65536 entries of 32 bytes, so a longer one
/// (a FAT32 root chain in a loop) is corrupt.
const MAX_DIR_BLOCKS: u16 = 4096;

/// A name has [`LONG`] characters already.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Full;

/// A file name of up to [`LONG`] ASCII characters.
#[derive(Clone, Copy, Debug, Eq)]
pub struct Name {
    bytes: [u8; LONG],
    len: u8,
}

impl Name {
    pub const EMPTY: Name = Name {
        bytes: [0; LONG],
        len: 0,
    };

    /// `None` when too long.
    pub fn new(s: &[u8]) -> Option<Name> {
        let mut n = Name::EMPTY;
        for &c in s {
            n.push(c).ok()?;
        }
        Some(n)
    }

    pub fn push(&mut self, c: u8) -> Result<(), Full> {
        let slot = self.bytes.get_mut(usize::from(self.len)).ok_or(Full)?;
        *slot = c;
        self.len += 1;
        Ok(())
    }

    pub fn as_bytes(&self) -> &[u8] {
        &self.bytes[..usize::from(self.len)]
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Without spaces at its end.
    pub fn trimmed(mut self) -> Name {
        while self.len > 0 && self.bytes[usize::from(self.len) - 1] == b' ' {
            self.len -= 1;
        }
        self
    }
}

impl PartialEq for Name {
    fn eq(&self, other: &Name) -> bool {
        self.as_bytes() == other.as_bytes()
    }
}

impl ufmt::uDisplay for Name {
    fn fmt<W: ufmt::uWrite + ?Sized>(
        &self,
        f: &mut ufmt::Formatter<'_, W>,
    ) -> Result<(), W::Error> {
        // Byte by byte: `from_utf8` would bring its 256-byte table into
        // the AVR's SRAM. Only ASCII is pushed by the card reader and the
        // parser.
        for &c in self.as_bytes() {
            f.write_char(c as char)?;
        }
        Ok(())
    }
}

/// A file of the root directory.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Entry {
    /// As stored: base and extension padded with spaces.
    pub short: [u8; 11],
    /// Empty when the file has none (or one not kept).
    pub long: Name,
    pub size: u32,
    first: u32,
}

impl Entry {
    /// The 8.3 name as written: `STAR~1.GCO`.
    pub fn short_name(&self) -> Name {
        short_display(&self.short)
    }

    /// The name a user gave it: the long one if kept, else the 8.3 one.
    pub fn name(&self) -> Name {
        match self.long.is_empty() {
            true => self.short_name(),
            false => self.long,
        }
    }

    /// Whether `name` names this file, by either name, in any case.
    pub fn matches(&self, name: &[u8]) -> bool {
        super::short_name(name).is_some_and(|s| s.eq_ignore_ascii_case(&self.short))
            || (!self.long.is_empty() && self.long.as_bytes().eq_ignore_ascii_case(name))
    }

    /// A G-code file: `.gcode`, `.gco`, `.g` or `.nc`.
    pub fn is_gcode(&self) -> bool {
        let ext = |name: &[u8]| match name.iter().rposition(|&c| c == b'.') {
            Some(dot) => is_gcode_ext(&name[dot + 1..]),
            None => false,
        };
        ext(self.long.as_bytes()) || is_gcode_ext(trim(&self.short[8..]))
    }
}

fn is_gcode_ext(ext: &[u8]) -> bool {
    // Matched as array patterns: a table of strings would sit in the
    // AVR's SRAM.
    let mut lower = [0u8; 5];
    if ext.len() > lower.len() {
        return false;
    }
    lower[..ext.len()].copy_from_slice(ext);
    lower.make_ascii_lowercase();
    matches!(
        (ext.len(), lower),
        (5, [b'g', b'c', b'o', b'd', b'e'])
            | (3, [b'g', b'c', b'o', 0, 0])
            | (1, [b'g', 0, 0, 0, 0])
            | (2, [b'n', b'c', 0, 0, 0])
    )
}

fn trim(part: &[u8]) -> &[u8] {
    let end = part.iter().rposition(|&c| c != b' ').map_or(0, |i| i + 1);
    &part[..end]
}

/// `PARAM   TXT` → `PARAM.TXT`.
pub fn short_display(short: &[u8; 11]) -> Name {
    let mut n = Name::EMPTY;
    let (base, ext) = (trim(&short[..8]), trim(&short[8..]));
    // 8 + 1 + 3 characters always fit.
    for &c in base {
        let _ = n.push(c);
    }
    if !ext.is_empty() {
        let _ = n.push(b'.');
        for &c in ext {
            let _ = n.push(c);
        }
    }
    n
}

/// The checksum of an 8.3 name that its long-name entries carry.
fn checksum(short: &[u8]) -> u8 {
    short
        .iter()
        .fold(0u8, |sum, &c| sum.rotate_right(1).wrapping_add(c))
}

/// What one 32-byte directory entry is.
#[derive(Debug, PartialEq, Eq)]
pub enum Slot {
    /// No entries beyond.
    End,
    /// Deleted, a directory, the volume label, or part of a long name.
    Skip,
    File(Entry),
}

/// Reads entries in order, joining long names to their 8.3 entry.
#[derive(Clone, Copy, Debug)]
pub struct Scan {
    long: Name,
    /// The sequence number the next long-name entry must have; 0 when
    /// none is being read.
    next: u8,
    /// The long name is complete (its entry 1 was read) and kept.
    whole: bool,
    checksum: u8,
}

impl Default for Scan {
    fn default() -> Self {
        Scan::new()
    }
}

impl Scan {
    pub const fn new() -> Scan {
        Scan {
            long: Name::EMPTY,
            next: 0,
            whole: false,
            checksum: 0,
        }
    }

    pub fn take(&mut self, raw: &[u8]) -> Slot {
        match raw[0] {
            0x00 => return Slot::End,
            0xE5 => {
                *self = Scan::new();
                return Slot::Skip;
            }
            _ => {}
        }
        if raw[11] == ATTR_LONG {
            self.long_part(raw);
            return Slot::Skip;
        }
        let scan = core::mem::take(self);
        if raw[11] & (ATTR_VOLUME | ATTR_DIR) != 0 {
            return Slot::Skip;
        }
        let mut short = [0; 11];
        short.copy_from_slice(&raw[..11]);
        // 0x05 stands for a first byte of 0xE5 (a Kanji lead byte).
        if short[0] == 0x05 {
            short[0] = 0xE5;
        }
        let kept = scan.whole && scan.checksum == checksum(&raw[..11]);
        Slot::File(Entry {
            short,
            long: if kept { scan.long } else { Name::EMPTY },
            size: le32(raw, 28),
            first: u32::from(le16(raw, 20)) << 16 | u32::from(le16(raw, 26)),
        })
    }

    /// One long-name entry: 13 UCS-2 characters, the last part first.
    fn long_part(&mut self, raw: &[u8]) {
        let order = raw[0] & 0x1F;
        if raw[0] & 0x40 != 0 {
            *self = Scan {
                long: Name::EMPTY,
                next: order,
                whole: false,
                checksum: raw[13],
            };
            // Too long to keep: its 8.3 name will do.
            if usize::from(order) * PER_ENTRY > LONG {
                self.next = 0;
            }
        }
        if order == 0 || order != self.next || raw[13] != self.checksum {
            self.next = 0;
            return;
        }
        let at = (usize::from(order) - 1) * PER_ENTRY;
        let chars = (1..11)
            .step_by(2)
            .chain((14..26).step_by(2))
            .chain((28..32).step_by(2));
        for (i, o) in chars.enumerate() {
            let c = le16(raw, o);
            match c {
                0x0000 | 0xFFFF => {
                    // The name ends here (only in its last part).
                    if raw[0] & 0x40 != 0 && self.long.len == 0 {
                        self.long.len = (at + i) as u8;
                    }
                    break;
                }
                0x20..=0x7E => self.long.bytes[at + i] = c as u8,
                // Not ASCII: known by its 8.3 name.
                _ => {
                    self.next = 0;
                    return;
                }
            }
        }
        if raw[0] & 0x40 != 0 && self.long.len == 0 {
            self.long.len = (at + PER_ENTRY) as u8;
        }
        self.next -= 1;
        self.whole = self.next == 0;
    }
}

/// Where a walk of the root directory is: the run of consecutive blocks
/// left (FAT16's whole root, or one FAT32 cluster).
#[derive(Clone, Copy, Debug)]
pub struct Dir {
    cluster: u32,
    lba: u32,
    left: u16,
    read: u16,
}

impl Volume {
    /// A walk of the root directory from its start.
    pub fn root(&self) -> Dir {
        let (lba, left) = match self.fat32 {
            true => (self.cluster_lba(self.root_cluster), 1 << self.cluster_shift),
            false => (self.root_start, self.root_blocks),
        };
        Dir {
            cluster: self.root_cluster,
            lba,
            left,
            read: 0,
        }
    }

    /// Reads the directory's next block into `buf`; `false` past its end.
    pub fn read_dir<D: BlockRead>(
        &self,
        dir: &mut Dir,
        dev: &mut D,
        buf: &mut [u8; BLOCK],
    ) -> Result<bool, FatError<D::Error>> {
        if dir.read >= MAX_DIR_BLOCKS {
            return Err(FatError::BadChain);
        }
        if dir.left == 0 {
            if !self.fat32 {
                return Ok(false);
            }
            match self.next_cluster(dev, buf, dir.cluster)? {
                Some((next, _)) => dir.cluster = next,
                None => return Ok(false),
            }
            dir.lba = self.cluster_lba(dir.cluster);
            dir.left = 1 << self.cluster_shift;
        }
        dev.read_block(dir.lba, buf).map_err(FatError::Device)?;
        // Moved on only now, so that a failed read can be retried.
        dir.lba += 1;
        dir.left -= 1;
        dir.read += 1;
        Ok(true)
    }

    /// The first file of the root directory that `pick` wants.
    pub fn find<D: BlockRead>(
        &self,
        dev: &mut D,
        buf: &mut [u8; BLOCK],
        mut pick: impl FnMut(&Entry) -> bool,
    ) -> Result<Entry, FatError<D::Error>> {
        let mut dir = self.root();
        let mut scan = Scan::new();
        while self.read_dir(&mut dir, dev, buf)? {
            for raw in buf.chunks_exact(32) {
                match scan.take(raw) {
                    Slot::End => return Err(FatError::NotFound),
                    Slot::File(e) if pick(&e) => return Ok(e),
                    _ => {}
                }
            }
        }
        Err(FatError::NotFound)
    }

    /// Looks a file up in the root directory by its 8.3 or its long name,
    /// case-insensitively (`b"param.txt"` matches `PARAM.TXT`, `b"star.gcode"`
    /// matches `STAR~1.GCO` with that long name).
    pub fn open<D: BlockRead>(
        &self,
        dev: &mut D,
        buf: &mut [u8; BLOCK],
        name: &[u8],
    ) -> Result<File, FatError<D::Error>> {
        let e = self.find(dev, buf, |e| e.matches(name))?;
        self.file(&e)
    }

    /// The file an entry names, read from its start.
    pub fn file<E>(&self, e: &Entry) -> Result<File, FatError<E>> {
        let first = match self.fat32 {
            true => e.first,
            false => e.first & 0xFFFF,
        };
        if e.size > 0 && first.wrapping_sub(2) >= self.clusters {
            return Err(FatError::BadChain);
        }
        Ok(File {
            first,
            cluster: first,
            size: e.size,
            pos: 0,
            run_end: first,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::vec::Vec;

    /// The long-name entries and 8.3 entry a PC writes for `long`.
    fn entries(long: &str, short: &[u8; 11]) -> Vec<[u8; 32]> {
        let units: Vec<u16> = long.encode_utf16().collect();
        let parts = units.len().div_ceil(PER_ENTRY);
        let sum = checksum(short);
        let mut out = Vec::new();
        for k in (1..=parts).rev() {
            let mut e = [0u8; 32];
            e[0] = k as u8 | if k == parts { 0x40 } else { 0 };
            e[11] = ATTR_LONG;
            e[13] = sum;
            let offsets = (1..11)
                .step_by(2)
                .chain((14..26).step_by(2))
                .chain((28..32).step_by(2));
            for (i, o) in offsets.enumerate() {
                let at = (k - 1) * PER_ENTRY + i;
                let c = match at.cmp(&units.len()) {
                    core::cmp::Ordering::Less => units[at],
                    core::cmp::Ordering::Equal => 0,
                    core::cmp::Ordering::Greater => 0xFFFF,
                };
                e[o..o + 2].copy_from_slice(&c.to_le_bytes());
            }
            out.push(e);
        }
        let mut e = [0u8; 32];
        e[..11].copy_from_slice(short);
        e[11] = 0x20;
        e[26..28].copy_from_slice(&7u16.to_le_bytes());
        e[28..32].copy_from_slice(&1234u32.to_le_bytes());
        out.push(e);
        out
    }

    fn scan_all(raw: &[[u8; 32]]) -> Vec<Entry> {
        let mut scan = Scan::new();
        raw.iter()
            .filter_map(|r| match scan.take(r) {
                Slot::File(e) => Some(e),
                _ => None,
            })
            .collect()
    }

    #[test]
    fn long_names_join_their_short_entry() {
        for long in [
            "star.gcode",
            "a.nc",
            "exactly_thirteen",
            "twenty_six_characters_.gco",
        ] {
            let e = scan_all(&entries(long, b"STAR~1  GCO"));
            assert_eq!(e.len(), 1);
            assert_eq!(e[0].long.as_bytes(), long.as_bytes(), "{long}");
            assert_eq!(e[0].short_name().as_bytes(), b"STAR~1.GCO");
            assert_eq!(e[0].size, 1234);
            assert!(e[0].matches(long.to_uppercase().as_bytes()));
            assert!(e[0].matches(b"star~1.gco"));
            assert!(e[0].is_gcode());
        }
    }

    #[test]
    fn long_names_not_kept_leave_the_short_one() {
        // Too long, not ASCII, or orphaned by a tool that renamed the file.
        let too_long = entries("twenty_seven_characters_.gc", b"TWENTY~1GC ");
        let accented = entries("café.nc", b"CAF~1   NC ");
        let mut orphan = entries("star.gcode", b"STAR~1  GCO");
        orphan.last_mut().unwrap()[..11].copy_from_slice(b"OTHER   GCO");
        for raw in [too_long, accented, orphan] {
            let e = scan_all(&raw);
            assert_eq!(e.len(), 1);
            assert!(e[0].long.is_empty());
            assert_eq!(e[0].name(), e[0].short_name());
        }
        // A deleted long name does not stick to the next file.
        let mut raw = entries("star.gcode", b"STAR~1  GCO");
        raw[0][0] = 0xE5;
        assert!(scan_all(&raw)[0].long.is_empty());
    }

    #[test]
    fn gcode_files_by_either_name() {
        let gcode = |long: &str, short: &[u8; 11]| scan_all(&entries(long, short))[0].is_gcode();
        assert!(gcode("x", b"DRAW    NC "));
        assert!(gcode("drawing.G", b"DRAWING G  "));
        assert!(!gcode("param.txt", b"PARAM   TXT"));
        assert!(!gcode("gcode", b"GCODE      "));
    }

    #[test]
    fn names() {
        assert_eq!(short_display(b"PARAM   TXT").as_bytes(), b"PARAM.TXT");
        assert_eq!(short_display(b"EMPTY      ").as_bytes(), b"EMPTY");
        assert_eq!(Name::new(&[b'a'; LONG + 1]), None);
        assert_eq!(Name::new(b"a b  ").unwrap().trimmed().as_bytes(), b"a b");
    }
}
