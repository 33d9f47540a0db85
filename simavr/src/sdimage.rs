//! SD card images built from a folder: an MBR with one FAT16 or FAT32
//! partition holding the folder's files and subfolders, made with the
//! `fatfs` crate. `embedded-sdmmc` mounts MBR partition 0, and the same bytes
//! written to a real card with `dd` give the same card.
//!
//! Images are deterministic (fixed timestamps and volume id) and mostly
//! zeros: the partition starts at 1 MiB, as card formatters align it.

use fatfs::{FatType, FileSystem, FormatVolumeOptions, FsOptions};
use std::io::{self, Cursor, Write};
use std::path::{Path, PathBuf};

const SECTOR: u64 = 512;
const MIB: u64 = 1 << 20;
/// First sector of the partition: 1 MiB in.
const PARTITION_START: u64 = MIB / SECTOR;
/// FAT16 images up to this size; FAT32 beyond (and always when asked).
const FAT16_MAX: u64 = 64 * MIB;
/// Smallest volumes: FAT16 needs 4085 clusters, FAT32 65525.
const FAT16_MIN: u64 = 8 * MIB;
const FAT32_MIN: u64 = 40 * MIB;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FatChoice {
    /// FAT16 while the files fit in 64 MiB, FAT32 beyond.
    Auto,
    Fat16,
    Fat32,
}

/// What a built image holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    pub fat32: bool,
    /// Whole image, MBR and alignment gap included.
    pub image_bytes: u64,
    pub bytes_per_cluster: u32,
}

/// A card image of `dir`'s files and subfolders.
pub fn build_image(dir: &Path, fat: FatChoice) -> io::Result<Vec<u8>> {
    build_image_with_layout(dir, fat).map(|(image, _)| image)
}

/// `build_image`, also telling the layout chosen.
pub fn build_image_with_layout(dir: &Path, fat: FatChoice) -> io::Result<(Vec<u8>, Layout)> {
    let entries = walk(dir)?;
    let layout = layout_for(content_bytes(&entries), fat)?;
    let part_bytes = layout.image_bytes - PARTITION_START * SECTOR;
    let mut part = vec![0u8; part_bytes as usize];
    let fat_type = if layout.fat32 {
        FatType::Fat32
    } else {
        FatType::Fat16
    };
    fatfs::format_volume(
        Cursor::new(&mut part[..]),
        FormatVolumeOptions::new()
            .fat_type(fat_type)
            .bytes_per_cluster(layout.bytes_per_cluster)
            .volume_id(0x7A07_5D00)
            .volume_label(*b"TAUT       "),
    )?;
    let fs = FileSystem::new(
        Cursor::new(&mut part[..]),
        FsOptions::new().time_provider(&FIXED_TIME),
    )?;
    for entry in &entries {
        let path = entry.rel.to_string_lossy().replace('\\', "/");
        if entry.is_dir {
            fs.root_dir().create_dir(&path)?;
        } else {
            let mut file = fs.root_dir().create_file(&path)?;
            file.write_all(&std::fs::read(dir.join(&entry.rel))?)?;
        }
    }
    // Counting the free clusters records them in FAT32's FSInfo sector,
    // which would otherwise say "unknown".
    fs.stats()?;
    fs.unmount()?;
    let mut image = mbr(layout.fat32, part_bytes / SECTOR).to_vec();
    image.resize((PARTITION_START * SECTOR) as usize, 0);
    image.extend_from_slice(&part);
    Ok((image, layout))
}

struct Entry {
    rel: PathBuf,
    is_dir: bool,
    size: u64,
}

/// Every file and folder under `root`, parents before children, sorted by
/// name so that images are reproducible.
fn walk(root: &Path) -> io::Result<Vec<Entry>> {
    let mut out = Vec::new();
    let mut pending = vec![PathBuf::new()];
    while let Some(rel) = pending.pop() {
        let mut children: Vec<_> = std::fs::read_dir(root.join(&rel))?.collect::<Result<_, _>>()?;
        children.sort_by_key(|c| c.file_name());
        let mut subdirs = Vec::new();
        for child in children {
            let meta = child.metadata()?;
            let rel = rel.join(child.file_name());
            if meta.is_dir() {
                subdirs.push(rel.clone());
            }
            out.push(Entry {
                rel,
                is_dir: meta.is_dir(),
                size: meta.len(),
            });
        }
        pending.extend(subdirs.into_iter().rev());
    }
    Ok(out)
}

/// Room the entries take: each file and folder rounded up to 4 KiB (the
/// largest cluster used for small volumes) plus its directory entries.
fn content_bytes(entries: &[Entry]) -> u64 {
    entries
        .iter()
        .map(|e| e.size.div_ceil(4096).max(1) * 4096 + 32 * 4)
        .sum()
}

fn layout_for(content: u64, fat: FatChoice) -> io::Result<Layout> {
    // A quarter spare plus a MiB for the FATs and root directory.
    let need = (content + content / 4 + MIB).div_ceil(MIB) * MIB;
    let fat32 = match fat {
        FatChoice::Fat32 => true,
        FatChoice::Fat16 => false,
        FatChoice::Auto => need.max(FAT16_MIN) > FAT16_MAX,
    };
    let volume = need.max(if fat32 { FAT32_MIN } else { FAT16_MIN });
    let bytes_per_cluster = if fat32 {
        // Largest cluster up to 4 KiB that still gives FAT32 enough clusters.
        [4096u32, 2048, 1024, 512]
            .into_iter()
            .find(|&c| volume / u64::from(c) >= 66_000)
            .unwrap_or(512)
    } else {
        // Smallest cluster that keeps FAT16 under its cluster limit.
        (9..=15)
            .map(|shift| 1u32 << shift)
            .find(|&c| volume / u64::from(c) <= 65_000)
            .ok_or_else(|| io::Error::other("files too large for FAT16 (over 2 GiB)"))?
    };
    Ok(Layout {
        fat32,
        image_bytes: PARTITION_START * SECTOR + volume,
        bytes_per_cluster,
    })
}

/// A master boot record with one partition from `PARTITION_START` of
/// `sectors` sectors: type 0x0C (FAT32, LBA) or 0x0E (FAT16, LBA).
fn mbr(fat32: bool, sectors: u64) -> [u8; 512] {
    let mut mbr = [0u8; 512];
    mbr[0x1B8..0x1BC].copy_from_slice(&0x7A07_5D00u32.to_le_bytes());
    let entry = &mut mbr[0x1BE..0x1CE];
    let last = PARTITION_START + sectors - 1;
    entry[1..4].copy_from_slice(&chs(PARTITION_START));
    entry[4] = if fat32 { 0x0C } else { 0x0E };
    entry[5..8].copy_from_slice(&chs(last));
    entry[8..12].copy_from_slice(&(PARTITION_START as u32).to_le_bytes());
    entry[12..16].copy_from_slice(&(sectors as u32).to_le_bytes());
    mbr[510] = 0x55;
    mbr[511] = 0xAA;
    mbr
}

/// Cylinder-head-sector bytes of a sector in the usual 255-head,
/// 63-sector geometry, saturating at the CHS limit.
fn chs(lba: u64) -> [u8; 3] {
    let cylinder = lba / (255 * 63);
    if cylinder > 1023 {
        return [254, 0xFF, 0xFF];
    }
    let head = (lba / 63) % 255;
    let sector = lba % 63 + 1;
    [
        head as u8,
        (sector as u8) | ((cylinder >> 2) as u8 & 0xC0),
        cylinder as u8,
    ]
}

/// Every timestamp in built images: 2025-01-01 00:00.
#[derive(Debug)]
struct FixedTime;

static FIXED_TIME: FixedTime = FixedTime;

impl fatfs::TimeProvider for FixedTime {
    fn get_current_date(&self) -> fatfs::Date {
        fatfs::Date {
            year: 2025,
            month: 1,
            day: 1,
        }
    }

    fn get_current_date_time(&self) -> fatfs::DateTime {
        fatfs::DateTime {
            date: self.get_current_date(),
            time: fatfs::Time {
                hour: 0,
                min: 0,
                sec: 0,
                millis: 0,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layouts_fit_their_fat_type() {
        let small = layout_for(10_000, FatChoice::Auto).unwrap();
        assert_eq!(
            small,
            Layout {
                fat32: false,
                image_bytes: MIB + 8 * MIB,
                bytes_per_cluster: 512
            }
        );
        let forced = layout_for(10_000, FatChoice::Fat32).unwrap();
        assert!(forced.fat32 && forced.image_bytes == MIB + 40 * MIB);
        assert_eq!(forced.bytes_per_cluster, 512);
        let big = layout_for(100 * MIB, FatChoice::Auto).unwrap();
        assert!(big.fat32 && big.image_bytes >= 125 * MIB);
        assert_eq!(big.bytes_per_cluster, 1024);
        let fat16 = layout_for(100 * MIB, FatChoice::Fat16).unwrap();
        assert_eq!(fat16.bytes_per_cluster, 2048);
        assert!(layout_for(3 << 30, FatChoice::Fat16).is_err());
    }

    #[test]
    fn chs_of_known_sectors() {
        assert_eq!(chs(0), [0, 1, 0]);
        assert_eq!(chs(2048), [32, 33, 0]);
        assert_eq!(chs(255 * 63 * 1023 + 62), [0, 63 | 0xC0, 0xFF]);
        assert_eq!(chs(255 * 63 * 1024), [254, 0xFF, 0xFF]);
    }

    #[test]
    fn mbr_names_one_lba_partition() {
        let m = mbr(true, 81_920);
        assert_eq!(m[0x1C2], 0x0C);
        assert_eq!(
            u32::from_le_bytes(m[0x1C6..0x1CA].try_into().unwrap()),
            2048
        );
        assert_eq!(
            u32::from_le_bytes(m[0x1CA..0x1CE].try_into().unwrap()),
            81_920
        );
        assert_eq!(&m[510..], &[0x55, 0xAA]);
        assert_eq!(mbr(false, 16_384)[0x1C2], 0x0E);
    }
}
