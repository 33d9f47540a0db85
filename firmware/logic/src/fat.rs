//! A read-only FAT16/FAT32 file reader over a device of 512-byte blocks: one
//! partition (MBR entry 0, or a partition-less "superfloppy"), files in the
//! root directory by 8.3 or long name ([`dir`]), read sequentially a block
//! at a time.
//!
//! Written for the AVR: the caller owns the one block buffer, nothing is
//! allocated, and the only divisions are shifts (sectors per cluster is a
//! power of two; a u32 division costs ~1300 cycles there).

/// Bytes per block, the only sector size supported.
pub const BLOCK: usize = 512;

/// A device of 512-byte blocks.
pub trait BlockRead {
    type Error;
    fn read_block(&mut self, lba: u32, buf: &mut [u8; BLOCK]) -> Result<(), Self::Error>;
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FatError<E> {
    Device(E),
    /// Neither a FAT boot sector at block 0 nor a FAT partition in the MBR's first entry.
    NoFilesystem,
    /// FAT12, or sectors that are not 512 bytes.
    Unsupported,
    NotFound,
    /// A cluster chain that leaves the volume or ends before the file's size.
    BadChain,
}

/// A mounted volume: where its FAT, root directory and clusters are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Volume {
    fat32: bool,
    /// log2 of the blocks per cluster.
    cluster_shift: u8,
    /// Absolute LBA of the first FAT (the others are copies).
    fat_start: u32,
    /// FAT16: the fixed root directory's first block and length.
    root_start: u32,
    root_blocks: u16,
    /// FAT32: the root directory's first cluster.
    root_cluster: u32,
    /// Absolute LBA of cluster 2, the first one.
    data_start: u32,
    /// Clusters 2 ..= clusters + 1 exist.
    clusters: u32,
}

/// An open file, read sequentially.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct File {
    first: u32,
    cluster: u32,
    size: u32,
    pos: u32,
    /// Clusters `cluster..=run_end` follow each other on the disk (seen in
    /// the last FAT block read): no FAT read until `run_end`.
    run_end: u32,
}

const ATTR_VOLUME: u8 = 0x08;
const ATTR_DIR: u8 = 0x10;

mod dir;
pub use dir::{short_display, Dir, Entry, Name, Scan, Slot, LONG};

fn le16(b: &[u8], at: usize) -> u16 {
    u16::from_le_bytes([b[at], b[at + 1]])
}

fn le32(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

fn has_signature(buf: &[u8; BLOCK]) -> bool {
    buf[510] == 0x55 && buf[511] == 0xAA
}

impl Volume {
    /// Reads block 0 (MBR or a partition-less "superfloppy" boot sector) and the boot sector (BPB).
    pub fn mount<D: BlockRead>(
        dev: &mut D,
        buf: &mut [u8; BLOCK],
    ) -> Result<Volume, FatError<D::Error>> {
        dev.read_block(0, buf).map_err(FatError::Device)?;
        if !has_signature(buf) {
            return Err(FatError::NoFilesystem);
        }
        let is_bpb = matches!(buf[0], 0xEB | 0xE9) && le16(buf, 11) == BLOCK as u16;
        let start = if is_bpb {
            0
        } else {
            let entry = &buf[446..462];
            // FAT12, FAT16 (<32 MiB, CHS, LBA), FAT32 (CHS, LBA).
            if !matches!(entry[4], 0x01 | 0x04 | 0x06 | 0x0E | 0x0B | 0x0C) {
                return Err(FatError::NoFilesystem);
            }
            let start = le32(entry, 8);
            dev.read_block(start, buf).map_err(FatError::Device)?;
            if !has_signature(buf) {
                return Err(FatError::NoFilesystem);
            }
            start
        };
        Self::parse_bpb(buf, start)
    }

    /// The volume described by the boot sector in `b`, which is at `start`.
    fn parse_bpb<E>(b: &[u8; BLOCK], start: u32) -> Result<Volume, FatError<E>> {
        if le16(b, 11) != BLOCK as u16 {
            return Err(FatError::Unsupported);
        }
        let per_cluster = b[13];
        let reserved = u32::from(le16(b, 14));
        let fats = u32::from(b[16]);
        let root_entries = le16(b, 17);
        // The 16-bit counts, or when 0 (too small) the 32-bit ones.
        let wide = |at16, at32| match le16(b, at16) {
            0 => le32(b, at32),
            n => u32::from(n),
        };
        let (total, fat_blocks) = (wide(19, 32), wide(22, 36));
        if !per_cluster.is_power_of_two() || reserved == 0 || fats == 0 || fat_blocks == 0 {
            return Err(FatError::NoFilesystem);
        }
        // 16 entries of 32 bytes per block; FAT32 has none (its root is a chain).
        let root_blocks = root_entries.div_ceil(16);
        // Checked once here so that no LBA computed later can overflow.
        let data_blocks = fats
            .checked_mul(fat_blocks)
            .and_then(|f| f.checked_add(reserved + u32::from(root_blocks)))
            .and_then(|meta| total.checked_sub(meta))
            .filter(|_| start.checked_add(total).is_some())
            .ok_or(FatError::NoFilesystem)?;
        let cluster_shift = per_cluster.trailing_zeros() as u8;
        let clusters = data_blocks >> cluster_shift;
        // The FAT type follows from the cluster count alone (Microsoft's spec).
        if clusters < 4085 {
            return Err(FatError::Unsupported);
        }
        let fat32 = clusters >= 65525;
        let root_cluster = if fat32 { le32(b, 44) } else { 0 };
        if fat32 && root_cluster.wrapping_sub(2) >= clusters {
            return Err(FatError::NoFilesystem);
        }
        let data_start = start + total - data_blocks;
        Ok(Volume {
            fat32,
            cluster_shift,
            fat_start: start + reserved,
            root_start: data_start - u32::from(root_blocks),
            root_blocks,
            root_cluster,
            data_start,
            clusters,
        })
    }

    pub fn is_fat32(&self) -> bool {
        self.fat32
    }

    /// The block after the volume's last cluster: a card with fewer blocks
    /// holds a partition made for a bigger one (an image written to a
    /// smaller card), whose files may lie past its end.
    pub fn end(&self) -> u32 {
        self.data_start + (self.clusters << self.cluster_shift)
    }

    fn cluster_lba(&self, cluster: u32) -> u32 {
        self.data_start + ((cluster - 2) << self.cluster_shift)
    }

    /// The cluster after `cluster` from the FAT (read into `buf`), or None
    /// at the end of the chain.
    /// The cluster after `cluster`, and the last cluster of the
    /// contiguous run it starts, as far as this FAT block tells: files are
    /// mostly written in one piece, so most cluster steps need no FAT read.
    fn next_cluster<D: BlockRead>(
        &self,
        dev: &mut D,
        buf: &mut [u8; BLOCK],
        cluster: u32,
    ) -> Result<Option<(u32, u32)>, FatError<D::Error>> {
        // 256 two-byte or 128 four-byte entries per block.
        let per_block_shift = if self.fat32 { 7 } else { 8 };
        let block = cluster >> per_block_shift;
        dev.read_block(self.fat_start + block, buf)
            .map_err(FatError::Device)?;
        let entry = |c: u32| {
            let i = (c & ((1 << per_block_shift) - 1)) as usize;
            if self.fat32 {
                le32(buf, i * 4) & 0x0FFF_FFFF
            } else {
                u32::from(le16(buf, i * 2))
            }
        };
        let next = entry(cluster);
        let end = if self.fat32 { 0x0FFF_FFF8 } else { 0xFFF8 };
        if next >= end {
            return Ok(None);
        }
        // Below 2 (free, reserved) wraps round to a huge value too; bad
        // cluster marks (…F7) lie beyond every volume's last cluster.
        let valid = |c: u32| c.wrapping_sub(2) < self.clusters;
        if !valid(next) {
            return Err(FatError::BadChain);
        }
        let mut run_end = next;
        while run_end >> per_block_shift == block
            && valid(run_end + 1)
            && entry(run_end) == run_end + 1
        {
            run_end += 1;
        }
        Ok(Some((next, run_end)))
    }
}

/// `name` as the 11 bytes of a directory entry: base and extension padded
/// with spaces, upper case. None for what cannot be an 8.3 name.
fn short_name(name: &[u8]) -> Option<[u8; 11]> {
    let (base, ext) = match name.iter().position(|&c| c == b'.') {
        Some(dot) => (&name[..dot], &name[dot + 1..]),
        None => (name, &[][..]),
    };
    let valid = |part: &[u8]| !part.iter().any(|&c| c <= b' ' || b"./\\".contains(&c));
    if base.is_empty() || base.len() > 8 || ext.len() > 3 || !valid(base) || !valid(ext) {
        return None;
    }
    let mut out = [b' '; 11];
    out[..base.len()].copy_from_slice(base);
    out[8..8 + ext.len()].copy_from_slice(ext);
    out.make_ascii_uppercase();
    Some(out)
}

impl File {
    pub fn size(&self) -> u32 {
        self.size
    }

    /// Bytes already delivered by read_next.
    pub fn pos(&self) -> u32 {
        self.pos
    }

    /// Reads the next block of the file into `buf` and returns how many of its bytes belong
    /// to the file (512, fewer in the last block, 0 at the end of the file — then nothing is read).
    /// At most two device reads per call: one FAT block when crossing into the next cluster, then the data block.
    pub fn read_next<D: BlockRead>(
        &mut self,
        vol: &Volume,
        dev: &mut D,
        buf: &mut [u8; BLOCK],
    ) -> Result<usize, FatError<D::Error>> {
        if self.pos >= self.size {
            return Ok(0);
        }
        // `pos` is a whole number of blocks here: only the last read is short.
        let in_cluster = (self.pos >> 9) & ((1 << vol.cluster_shift) - 1);
        let (mut cluster, mut run_end) = (self.cluster, self.run_end);
        if in_cluster == 0 && self.pos != 0 {
            if cluster < run_end {
                cluster += 1;
            } else {
                (cluster, run_end) = vol
                    .next_cluster(dev, buf, cluster)?
                    .ok_or(FatError::BadChain)?;
            }
        }
        dev.read_block(vol.cluster_lba(cluster) + in_cluster, buf)
            .map_err(FatError::Device)?;
        // Committed only now, so that a failed read can be retried.
        let n = (self.size - self.pos).min(BLOCK as u32);
        self.cluster = cluster;
        self.run_end = run_end;
        self.pos += n;
        Ok(n as usize)
    }

    /// Back to the start of the file (no device access).
    pub fn rewind(&mut self) {
        self.cluster = self.first;
        self.run_end = self.first;
        self.pos = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    /// A sparse in-memory disk: unwritten blocks read as zeros.
    #[derive(Default)]
    struct Disk {
        blocks: BTreeMap<u32, [u8; BLOCK]>,
        reads: u32,
        fail: Option<u32>,
    }

    impl Disk {
        fn block(&mut self, lba: u32) -> &mut [u8; BLOCK] {
            self.blocks.entry(lba).or_insert([0; BLOCK])
        }
    }

    impl BlockRead for Disk {
        type Error = u32;
        fn read_block(&mut self, lba: u32, buf: &mut [u8; BLOCK]) -> Result<(), u32> {
            self.reads += 1;
            if self.fail == Some(lba) {
                return Err(lba);
            }
            *buf = self.blocks.get(&lba).copied().unwrap_or([0; BLOCK]);
            Ok(())
        }
    }

    type Res<T> = Result<T, FatError<u32>>;

    struct Geometry {
        per_cluster: u8,
        reserved: u16,
        fats: u8,
        root_entries: u16,
        fat_blocks: u32,
        clusters: u32,
    }

    const FAT16: Geometry = Geometry {
        per_cluster: 4,
        reserved: 1,
        fats: 2,
        root_entries: 32,
        fat_blocks: 20,
        clusters: 5000,
    };
    // FAT16 layout at LBA 0: FATs at 1 and 21, root at 41..43, cluster 2 at 43.
    const FAT16_ROOT: u32 = 41;
    const FAT32: Geometry = Geometry {
        per_cluster: 1,
        reserved: 32,
        fats: 1,
        root_entries: 0,
        fat_blocks: 547,
        clusters: 70_000,
    };
    // FAT32 layout at LBA 0: FAT at 32, cluster 2 at 579.
    const FAT32_DATA: u32 = 579;

    /// Writes a boot sector at `start` for `g`, a FAT32 one if `g` has no
    /// fixed root directory (its root at cluster 2).
    fn format(disk: &mut Disk, start: u32, g: &Geometry) {
        let root_blocks = u32::from(g.root_entries).div_ceil(16);
        let total = u32::from(g.reserved)
            + u32::from(g.fats) * g.fat_blocks
            + root_blocks
            + g.clusters * u32::from(g.per_cluster);
        let b = disk.block(start);
        b[0] = 0xEB;
        b[11..13].copy_from_slice(&512u16.to_le_bytes());
        b[13] = g.per_cluster;
        b[14..16].copy_from_slice(&g.reserved.to_le_bytes());
        b[16] = g.fats;
        b[17..19].copy_from_slice(&g.root_entries.to_le_bytes());
        b[32..36].copy_from_slice(&total.to_le_bytes());
        if g.root_entries == 0 {
            b[36..40].copy_from_slice(&g.fat_blocks.to_le_bytes());
            b[44..48].copy_from_slice(&2u32.to_le_bytes());
        } else {
            b[22..24].copy_from_slice(&(g.fat_blocks as u16).to_le_bytes());
        }
        b[510] = 0x55;
        b[511] = 0xAA;
    }

    fn set_fat16(disk: &mut Disk, cluster: u32, next: u16) {
        let at = (cluster as usize & 0xFF) * 2;
        disk.block(1 + (cluster >> 8))[at..at + 2].copy_from_slice(&next.to_le_bytes());
    }

    fn set_fat32(disk: &mut Disk, cluster: u32, next: u32) {
        let at = (cluster as usize & 0x7F) * 4;
        disk.block(32 + (cluster >> 7))[at..at + 4].copy_from_slice(&next.to_le_bytes());
    }

    /// Directory entry `index` of block `lba`.
    fn entry(
        disk: &mut Disk,
        lba: u32,
        index: usize,
        name: &[u8; 11],
        attr: u8,
        first: u32,
        size: u32,
    ) {
        let e = &mut disk.block(lba)[index * 32..][..32];
        e[..11].copy_from_slice(name);
        e[11] = attr;
        e[20..22].copy_from_slice(&((first >> 16) as u16).to_le_bytes());
        e[26..28].copy_from_slice(&(first as u16).to_le_bytes());
        e[28..32].copy_from_slice(&size.to_le_bytes());
    }

    /// Every byte of the file, checking the sizes read_next reports.
    fn read_all(vol: &Volume, disk: &mut Disk, file: &mut File) -> Res<std::vec::Vec<u8>> {
        let mut out = std::vec::Vec::new();
        let mut buf = [0; BLOCK];
        loop {
            let n = file.read_next(vol, disk, &mut buf)?;
            if n == 0 {
                return Ok(out);
            }
            out.extend_from_slice(&buf[..n]);
            assert_eq!(file.pos() as usize, out.len());
        }
    }

    #[test]
    fn short_names() {
        assert_eq!(short_name(b"param.txt"), Some(*b"PARAM   TXT"));
        assert_eq!(short_name(b"EMPTY"), Some(*b"EMPTY      "));
        assert_eq!(short_name(b"A.B"), Some(*b"A       B  "));
        for bad in [
            &b""[..],
            b".txt",
            b"toolongname.txt",
            b"a.text",
            b"a.b.c",
            b"dir/a.txt",
            b"a b",
        ] {
            assert_eq!(short_name(bad), None, "{:?}", bad);
        }
    }

    #[test]
    fn a_volume_ends_after_its_last_cluster() {
        let mut disk = Disk::default();
        format(&mut disk, 0, &FAT16);
        let v = Volume::mount(&mut disk, &mut [0; BLOCK]).unwrap();
        assert_eq!(v.end(), FAT16_ROOT + 2 + 5000 * 4);
        let mut disk = Disk::default();
        format(&mut disk, 0, &FAT32);
        let v = Volume::mount(&mut disk, &mut [0; BLOCK]).unwrap();
        assert_eq!(v.end(), FAT32_DATA + 70_000);
    }

    #[test]
    fn without_a_signature_there_is_no_filesystem() {
        let mut disk = Disk::default();
        format(&mut disk, 0, &FAT16);
        disk.block(0)[510] = 0;
        assert_eq!(
            Volume::mount(&mut disk, &mut [0; BLOCK]),
            Res::Err(FatError::NoFilesystem)
        );
    }

    #[test]
    fn an_mbr_without_a_fat_partition_is_no_filesystem() {
        let mut disk = Disk::default();
        let mbr = disk.block(0);
        mbr[446 + 4] = 0x83;
        mbr[446 + 8] = 100;
        mbr[510..].copy_from_slice(&[0x55, 0xAA]);
        format(&mut disk, 100, &FAT16);
        assert_eq!(
            Volume::mount(&mut disk, &mut [0; BLOCK]),
            Res::Err(FatError::NoFilesystem)
        );
    }

    #[test]
    fn fat12_and_big_sectors_are_unsupported() {
        let mut disk = Disk::default();
        format(
            &mut disk,
            0,
            &Geometry {
                clusters: 4084,
                ..FAT16
            },
        );
        assert_eq!(
            Volume::mount(&mut disk, &mut [0; BLOCK]),
            Res::Err(FatError::Unsupported)
        );
        // Behind an MBR, where block 0 cannot tell the sector size.
        let mut disk = Disk::default();
        let mbr = disk.block(0);
        mbr[446 + 4] = 0x06;
        mbr[446 + 8] = 63;
        mbr[510..].copy_from_slice(&[0x55, 0xAA]);
        format(&mut disk, 63, &FAT16);
        disk.block(63)[12] = 4; // 1024 bytes per sector
        assert_eq!(
            Volume::mount(&mut disk, &mut [0; BLOCK]),
            Res::Err(FatError::Unsupported)
        );
    }

    /// A FAT16 volume of 4-block clusters with `A.TXT` (3000 bytes from
    /// cluster 2) in the root's second block, after the volume label, a
    /// long-name entry, a deleted `A.TXT`, a directory `B` and more deleted
    /// entries.
    fn fat16_disk() -> Disk {
        let mut disk = Disk::default();
        format(&mut disk, 0, &FAT16);
        entry(&mut disk, FAT16_ROOT, 0, b"TAUT       ", ATTR_VOLUME, 0, 0);
        entry(&mut disk, FAT16_ROOT, 1, b"Ba\0.\0t\0x\0t\0", 0x0F, 0, 0);
        entry(&mut disk, FAT16_ROOT, 2, b"\xE5       TXT", 0, 9, 5);
        entry(&mut disk, FAT16_ROOT, 3, b"B          ", ATTR_DIR, 7, 0);
        for i in 4..16 {
            entry(&mut disk, FAT16_ROOT, i, b"\xE5       TXT", 0, 0, 0);
        }
        entry(&mut disk, FAT16_ROOT + 1, 0, b"A       TXT", 0x20, 2, 3000);
        set_fat16(&mut disk, 2, 3);
        set_fat16(&mut disk, 3, 0xFFFF);
        for block in 0..6u32 {
            disk.block(43 + block).fill(block as u8 + 1);
        }
        disk
    }

    #[test]
    fn fat16_file_reads_across_clusters_and_rewinds() {
        let mut disk = fat16_disk();
        let mut buf = [0; BLOCK];
        let vol = Volume::mount(&mut disk, &mut buf).unwrap();
        assert!(!vol.is_fat32());
        let mut file = vol.open(&mut disk, &mut buf, b"a.txt").unwrap();
        assert_eq!((file.size(), file.pos()), (3000, 0));
        let mut want = std::vec::Vec::new();
        for block in 0..6u8 {
            want.extend_from_slice(&[block + 1; BLOCK]);
        }
        want.truncate(3000);
        disk.reads = 0;
        assert_eq!(read_all(&vol, &mut disk, &mut file), Ok(want.clone()));
        // Six data blocks and one FAT block, at the cluster boundary.
        assert_eq!(disk.reads, 7);
        file.rewind();
        assert_eq!(read_all(&vol, &mut disk, &mut file), Ok(want));
    }

    #[test]
    fn a_fragmented_chain_reads_the_fat_only_where_the_run_breaks() {
        let mut disk = fat16_disk();
        entry(&mut disk, FAT16_ROOT + 1, 1, b"F       TXT", 0x20, 2, 8000);
        // 2 → 3 → 6 → 7: two runs; clusters of 4 blocks from block 43.
        set_fat16(&mut disk, 3, 6);
        set_fat16(&mut disk, 6, 7);
        set_fat16(&mut disk, 7, 0xFFFF);
        let mut want = std::vec::Vec::new();
        for (i, cluster) in [2u32, 3, 6, 7].into_iter().enumerate() {
            for b in 0..4 {
                let fill = (i * 4 + b) as u8 + 1;
                disk.block(43 + (cluster - 2) * 4 + b as u32).fill(fill);
                want.extend_from_slice(&[fill; BLOCK]);
            }
        }
        want.truncate(8000);
        let mut buf = [0; BLOCK];
        let vol = Volume::mount(&mut disk, &mut buf).unwrap();
        let mut file = vol.open(&mut disk, &mut buf, b"f.txt").unwrap();
        disk.reads = 0;
        let back = read_all(&vol, &mut disk, &mut file).unwrap();
        assert!(back == want, "the fragmented file reads back");
        // Sixteen data blocks; the FAT at 2 → 3 and at 3 → 6, not at 6 → 7.
        assert_eq!(disk.reads, 18);
    }

    #[test]
    fn missing_names_deleted_entries_and_directories_are_not_found() {
        let mut disk = fat16_disk();
        let mut buf = [0; BLOCK];
        let vol = Volume::mount(&mut disk, &mut buf).unwrap();
        for name in [&b"b"[..], b"taut", b"c.txt", b"b.txt", b"a"] {
            assert_eq!(
                vol.open(&mut disk, &mut buf, name),
                Res::Err(FatError::NotFound)
            );
        }
    }

    #[test]
    fn chains_that_leave_the_volume_or_end_early_are_bad() {
        for (next, size) in [
            (5002u16, 3000u32),
            (1, 3000),
            (0, 3000),
            (0xFFF7, 3000),
            (0xFFF8, 2049),
        ] {
            let mut disk = fat16_disk();
            set_fat16(&mut disk, 2, next);
            entry(&mut disk, FAT16_ROOT + 1, 0, b"A       TXT", 0, 2, size);
            let mut buf = [0; BLOCK];
            let vol = Volume::mount(&mut disk, &mut buf).unwrap();
            let mut file = vol.open(&mut disk, &mut buf, b"A.TXT").unwrap();
            assert_eq!(
                read_all(&vol, &mut disk, &mut file),
                Err(FatError::BadChain),
                "{next}"
            );
        }
        // The last cluster is 5001.
        let mut disk = fat16_disk();
        set_fat16(&mut disk, 2, 5001);
        set_fat16(&mut disk, 5001, 0xFFF8);
        let mut buf = [0; BLOCK];
        let vol = Volume::mount(&mut disk, &mut buf).unwrap();
        let mut file = vol.open(&mut disk, &mut buf, b"A.TXT").unwrap();
        assert_eq!(
            read_all(&vol, &mut disk, &mut file).map(|v| v.len()),
            Ok(3000)
        );
        // A first cluster outside the volume, or none for a non-empty file.
        for first in [0, 1, 5002] {
            entry(&mut disk, FAT16_ROOT + 1, 0, b"A       TXT", 0, first, 10);
            assert_eq!(
                vol.open(&mut disk, &mut buf, b"a.txt"),
                Res::Err(FatError::BadChain)
            );
        }
    }

    #[test]
    fn a_failed_read_can_be_retried() {
        let mut disk = fat16_disk();
        let mut buf = [0; BLOCK];
        let vol = Volume::mount(&mut disk, &mut buf).unwrap();
        let mut file = vol.open(&mut disk, &mut buf, b"A.TXT").unwrap();
        for _ in 0..4 {
            assert_eq!(file.read_next(&vol, &mut disk, &mut buf), Ok(512));
        }
        disk.fail = Some(47); // the first block of cluster 3
        assert_eq!(
            file.read_next(&vol, &mut disk, &mut buf),
            Err(FatError::Device(47))
        );
        assert_eq!(file.pos(), 2048);
        disk.fail = None;
        assert_eq!(file.read_next(&vol, &mut disk, &mut buf), Ok(512));
        assert_eq!(buf[0], 5);
    }

    #[test]
    fn an_empty_file_reads_nothing() {
        let mut disk = fat16_disk();
        entry(&mut disk, FAT16_ROOT + 1, 1, b"EMPTY      ", 0x20, 0, 0);
        let mut buf = [0; BLOCK];
        let vol = Volume::mount(&mut disk, &mut buf).unwrap();
        let mut file = vol.open(&mut disk, &mut buf, b"empty").unwrap();
        disk.reads = 0;
        assert_eq!(file.read_next(&vol, &mut disk, &mut buf), Ok(0));
        assert_eq!(disk.reads, 0);
    }

    #[test]
    fn fat32_root_directory_follows_its_chain() {
        let mut disk = Disk::default();
        format(&mut disk, 0, &FAT32);
        // Root: cluster 2 full of long-name entries, then cluster 9.
        for i in 0..16 {
            entry(&mut disk, FAT32_DATA, i, b"Ap\0a\0r\0a\0m\0", 0x0F, 0, 0);
        }
        set_fat32(&mut disk, 2, 0xF000_0009); // the top four bits are reserved
        set_fat32(&mut disk, 9, 0x0FFF_FFFF);
        // A file past cluster 65535, whose number needs the high word.
        entry(
            &mut disk,
            FAT32_DATA + 7,
            0,
            b"PARAM   TXT",
            0x20,
            0x1_0005,
            600,
        );
        set_fat32(&mut disk, 0x1_0005, 0x1_0006);
        set_fat32(&mut disk, 0x1_0006, 0x0FFF_FFF8);
        disk.block(FAT32_DATA + 0x1_0003).fill(b'a');
        disk.block(FAT32_DATA + 0x1_0004).fill(b'b');
        let mut buf = [0; BLOCK];
        let vol = Volume::mount(&mut disk, &mut buf).unwrap();
        assert!(vol.is_fat32());
        let mut file = vol.open(&mut disk, &mut buf, b"Param.Txt").unwrap();
        let data = read_all(&vol, &mut disk, &mut file).unwrap();
        assert!(data[..512].iter().all(|&b| b == b'a') && data[512..] == [b'b'; 88]);
        assert_eq!(
            vol.open(&mut disk, &mut buf, b"x"),
            Res::Err(FatError::NotFound)
        );
        // A root chain that loops is corrupt, not endless.
        for i in 0..16 {
            entry(
                &mut disk,
                FAT32_DATA + 7,
                i,
                b"Ap\0a\0r\0a\0m\0",
                0x0F,
                0,
                0,
            );
        }
        set_fat32(&mut disk, 9, 2);
        assert_eq!(
            vol.open(&mut disk, &mut buf, b"x"),
            Res::Err(FatError::BadChain)
        );
    }

    /// Blocks repeating `bytes` (as the fuzz target's card): small inputs
    /// still give deep structures.
    struct Noise(std::vec::Vec<u8>);

    impl BlockRead for Noise {
        type Error = ();
        fn read_block(&mut self, lba: u32, buf: &mut [u8; BLOCK]) -> Result<(), ()> {
            let len = self.0.len().max(1);
            for (i, b) in buf.iter_mut().enumerate() {
                *b = *self.0.get((lba as usize * BLOCK + i) % len).unwrap_or(&0);
            }
            Ok(())
        }
    }

    proptest::proptest! {
        /// Whatever the card holds, the reader ends without panicking and
        /// never delivers more than a file's size.
        #[test]
        fn any_card_is_read_safely(bytes in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..2048),
                                   mbr in proptest::prelude::any::<bool>()) {
            let mut bytes = bytes;
            if mbr && bytes.len() >= 512 {
                bytes[510] = 0x55;
                bytes[511] = 0xAA;
            }
            let mut card = Noise(bytes);
            let mut buf = [0u8; BLOCK];
            if let Ok(vol) = Volume::mount(&mut card, &mut buf) {
                if let Ok(mut file) = vol.open(&mut card, &mut buf, b"param.txt") {
                    let mut total = 0u64;
                    while let Ok(n @ 1..) = file.read_next(&vol, &mut card, &mut buf) {
                        total += n as u64;
                    }
                    proptest::prop_assert!(total <= u64::from(file.size()));
                }
            }
        }
    }
}
