//! taut-logic's own FAT reader (`taut_logic::fat`, which the firmware uses
//! instead of embedded-sdmmc's VolumeManager) on card images built by
//! `sdimage`: every root file opens by any case of its 8.3 name and reads
//! back byte for byte, in FAT16 and FAT32 and with clusters of one and of
//! several blocks, with at most two device reads per block.

mod common;

use taut_logic::fat::{BlockRead, FatError, File, Volume, BLOCK};
use taut_simavr::sdimage::{build_image_with_layout, FatChoice, Layout};

/// A card image in memory, counting the blocks read.
struct Image {
    bytes: Vec<u8>,
    reads: u32,
}

impl BlockRead for Image {
    /// The block that does not exist.
    type Error = u32;

    fn read_block(&mut self, lba: u32, buf: &mut [u8; BLOCK]) -> Result<(), u32> {
        self.reads += 1;
        let at = lba as usize * BLOCK;
        let block = self.bytes.get(at..at + BLOCK).ok_or(lba)?;
        buf.copy_from_slice(block);
        Ok(())
    }
}

/// The whole file through `read_next`, checking that each call reads at
/// most two blocks and that `pos` follows.
fn read_all(vol: &Volume, image: &mut Image, file: &mut File) -> Vec<u8> {
    let mut out = Vec::new();
    let mut buf = [0u8; BLOCK];
    loop {
        let before = image.reads;
        let n = file.read_next(vol, image, &mut buf).unwrap();
        let reads = image.reads - before;
        if n == 0 {
            assert_eq!(reads, 0, "nothing is read at the end");
            return out;
        }
        assert!((1..=2).contains(&reads), "{reads} reads for one block");
        assert!(n == BLOCK || out.len() + n == file.size() as usize);
        out.extend_from_slice(&buf[..n]);
        assert_eq!(file.pos() as usize, out.len());
    }
}

fn check(fat: FatChoice, big_bytes: usize) -> Layout {
    let tag = format!("{fat:?}-{big_bytes}");
    let (dir, files) = common::job_folder(&tag, big_bytes);
    let (bytes, layout) = build_image_with_layout(&dir, fat).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    let mut image = Image { bytes, reads: 0 };
    let mut buf = [0u8; BLOCK];
    let vol = Volume::mount(&mut image, &mut buf).unwrap();
    assert_eq!(vol.is_fat32(), layout.fat32, "{tag}");
    assert_eq!(image.reads, 2, "{tag}: the MBR and the boot sector");
    let per_cluster = layout.bytes_per_cluster as usize / BLOCK;

    for (name, want) in files.iter().filter(|(name, _)| !name.contains('/')) {
        for asked in [name.to_lowercase(), name.to_uppercase()] {
            let mut file = vol
                .open(&mut image, &mut buf, asked.as_bytes())
                .unwrap_or_else(|e| panic!("{tag}: {asked}: {e:?}"));
            assert_eq!((file.size() as usize, file.pos()), (want.len(), 0));
            image.reads = 0;
            let back = read_all(&vol, &mut image, &mut file);
            assert!(back == *want, "{tag}: {asked} differs");
            // A data block each, and a FAT block whenever the chain leaves
            // the part of the FAT last read (the image's files are written
            // in one piece): one per FAT block the chain spans.
            let blocks = want.len().div_ceil(BLOCK);
            let boundaries = blocks.saturating_sub(1) / per_cluster;
            let per_fat_block = if layout.fat32 { 128 } else { 256 };
            let fat_reads = image.reads as usize - blocks;
            assert!(
                fat_reads >= boundaries.min(1)
                    && fat_reads <= boundaries.div_ceil(per_fat_block) + 1,
                "{tag}: {asked}: {fat_reads} FAT reads for {boundaries} cluster boundaries"
            );
            file.rewind();
            assert_eq!(file.pos(), 0);
            assert!(
                read_all(&vol, &mut image, &mut file) == *want,
                "{tag}: {asked} rewound"
            );
        }
    }

    // Rewinding in the middle of a file, after a cluster boundary.
    let mut file = vol.open(&mut image, &mut buf, b"big.bin").unwrap();
    for _ in 0..per_cluster + 1 {
        assert_eq!(file.read_next(&vol, &mut image, &mut buf), Ok(BLOCK));
    }
    file.rewind();
    image.reads = 0;
    assert_eq!(file.read_next(&vol, &mut image, &mut buf), Ok(BLOCK));
    assert_eq!(image.reads, 1);
    assert!(buf[..] == files["BIG.BIN"][..BLOCK], "{tag}");

    // The subfolder's file, the subfolder itself, the volume label and
    // names that are not there or not 8.3.
    for name in [
        &b"Part1.gco"[..],
        b"PART1.GCO",
        b"Gcode/Part1.gco",
        b"gcode",
        b"TAUT",
        b"missing.txt",
        b"param.tx",
        b"param.txt.bak",
        b"",
    ] {
        assert_eq!(
            vol.open(&mut image, &mut buf, name),
            Err(FatError::NotFound),
            "{tag}: {}",
            String::from_utf8_lossy(name)
        );
    }
    layout
}

#[test]
fn fat16_files_read_back() {
    let layout = check(FatChoice::Fat16, 700 * 1024 + 123);
    assert!(!layout.fat32);
}

#[test]
fn fat32_files_read_back() {
    let layout = check(FatChoice::Fat32, 700 * 1024 + 123);
    assert!(layout.fat32);
}

/// Enough data for `sdimage` to choose clusters of two blocks, so that
/// reads also stay inside a cluster.
#[test]
fn fat16_with_multi_block_clusters_reads_back() {
    let layout = check(FatChoice::Fat16, 26 << 20);
    assert!(layout.bytes_per_cluster > BLOCK as u32, "{layout:?}");
}

/// A file's first data block, as a card fault aimed at the file finds it.
#[test]
fn a_files_first_block_holds_its_first_bytes() {
    use taut_simavr::sdcard::SdImage;
    for fat in [FatChoice::Fat16, FatChoice::Fat32] {
        let (dir, files) = common::job_folder(&format!("first-{fat:?}"), 2000);
        let image = SdImage::from_bytes(build_image_with_layout(&dir, fat).unwrap().0);
        std::fs::remove_dir_all(&dir).unwrap();
        for name in ["param.txt", "PORADI.TXT", "big.bin"] {
            let lba = image.first_block_of(name).unwrap();
            let want = &files[if name == "big.bin" { "BIG.BIN" } else { name }];
            let n = want.len().min(BLOCK);
            assert_eq!(image.block(lba)[..n], want[..n], "{fat:?} {name}");
        }
        assert_eq!(image.first_block_of("EMPTY"), None, "no data block");
        assert_eq!(image.first_block_of("nothere.txt"), None);
    }
}
