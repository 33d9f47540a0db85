//! The disk image behind a virtual card: whole 512-byte blocks in memory,
//! loaded from and saved to a file (the same bytes `dd` puts on a real card).

use std::io;
use std::path::Path;
use taut_logic::fat::{BlockRead, Volume};

pub const BLOCK: usize = 512;

#[derive(Clone, PartialEq, Eq)]
pub struct SdImage {
    bytes: Vec<u8>,
}

impl std::fmt::Debug for SdImage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "SdImage({} blocks)", self.blocks())
    }
}

impl SdImage {
    /// An image of these bytes, padded with zeros to whole blocks.
    pub fn from_bytes(mut bytes: Vec<u8>) -> SdImage {
        bytes.resize(bytes.len().div_ceil(BLOCK) * BLOCK, 0);
        SdImage { bytes }
    }

    /// A blank (all zero) image of `blocks` blocks.
    pub fn blank(blocks: u32) -> SdImage {
        SdImage::from_bytes(vec![0; blocks as usize * BLOCK])
    }

    pub fn open(path: &Path) -> io::Result<SdImage> {
        Ok(SdImage::from_bytes(std::fs::read(path)?))
    }

    /// A FAT image of a folder's files (see `sdimage::build_image`).
    pub fn from_dir(dir: &Path, fat: crate::sdimage::FatChoice) -> io::Result<SdImage> {
        crate::sdimage::build_image(dir, fat).map(SdImage::from_bytes)
    }

    /// A card from `path`: a folder is imaged on the fly, anything else is
    /// read as an image file.
    pub fn from_path(path: &Path) -> io::Result<SdImage> {
        if path.is_dir() {
            SdImage::from_dir(path, crate::sdimage::FatChoice::Auto)
        } else {
            SdImage::open(path)
        }
    }

    pub fn save(&self, path: &Path) -> io::Result<()> {
        std::fs::write(path, &self.bytes)
    }

    pub fn bytes(&self) -> &[u8] {
        &self.bytes
    }

    pub fn into_bytes(self) -> Vec<u8> {
        self.bytes
    }

    pub fn blocks(&self) -> u32 {
        (self.bytes.len() / BLOCK) as u32
    }

    pub fn len(&self) -> u64 {
        self.bytes.len() as u64
    }

    pub fn is_empty(&self) -> bool {
        self.bytes.is_empty()
    }

    /// Block `n`; blocks past the end of the image read as zeros.
    pub fn block(&self, n: u32) -> [u8; BLOCK] {
        let mut out = [0; BLOCK];
        let start = n as usize * BLOCK;
        if start < self.bytes.len() {
            out.copy_from_slice(&self.bytes[start..start + BLOCK]);
        }
        out
    }

    /// A file of the root directory (8.3 name, any case), read with the
    /// firmware's own FAT reader (`taut_logic::fat`); `None` if missing.
    pub fn read_file(&self, name: &str) -> Option<Vec<u8>> {
        let (mut dev, mut buf) = (Blocks::new(self), [0; BLOCK]);
        let volume = Volume::mount(&mut dev, &mut buf).ok()?;
        let mut file = volume.open(&mut dev, &mut buf, name.as_bytes()).ok()?;
        let mut out = Vec::new();
        loop {
            match file.read_next(&volume, &mut dev, &mut buf).ok()? {
                0 => return Some(out),
                n => out.extend_from_slice(&buf[..n]),
            }
        }
    }

    /// The LBA of a root file's first data block (8.3 name, any case): the
    /// block a fault aimed at the file hits. `None` for a missing or empty
    /// file.
    pub fn first_block_of(&self, name: &str) -> Option<u32> {
        let (mut dev, mut buf) = (Blocks::new(self), [0; BLOCK]);
        let volume = Volume::mount(&mut dev, &mut buf).ok()?;
        let mut file = volume.open(&mut dev, &mut buf, name.as_bytes()).ok()?;
        // The first block of a file is read alone, without a FAT lookup.
        match file.read_next(&volume, &mut dev, &mut buf).ok()? {
            0 => None,
            _ => dev.last,
        }
    }

    /// Writes block `n`, growing the image when it lies past the end.
    pub fn write_block(&mut self, n: u32, data: &[u8; BLOCK]) {
        let start = n as usize * BLOCK;
        if start >= self.bytes.len() {
            self.bytes.resize(start + BLOCK, 0);
        }
        self.bytes[start..start + BLOCK].copy_from_slice(data);
    }
}

/// The image as the FAT reader's device, noting the last block read.
struct Blocks<'a> {
    image: &'a SdImage,
    last: Option<u32>,
}

impl<'a> Blocks<'a> {
    fn new(image: &'a SdImage) -> Blocks<'a> {
        Blocks { image, last: None }
    }
}

impl BlockRead for Blocks<'_> {
    type Error = std::convert::Infallible;
    fn read_block(&mut self, lba: u32, buf: &mut [u8; BLOCK]) -> Result<(), Self::Error> {
        *buf = self.image.block(lba);
        self.last = Some(lba);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn padded_to_blocks_and_zero_past_the_end() {
        let mut image = SdImage::from_bytes(vec![7; 600]);
        assert_eq!(image.len(), 1024);
        assert_eq!(image.block(1)[87], 7);
        assert_eq!(image.block(1)[88], 0);
        assert_eq!(image.block(5), [0; BLOCK]);
        image.write_block(3, &[9; BLOCK]);
        assert_eq!(image.blocks(), 4);
        assert_eq!(image.block(3), [9; BLOCK]);
    }
}
