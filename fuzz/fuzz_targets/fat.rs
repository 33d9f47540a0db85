//! Arbitrary bytes as a card: the FAT reader must never panic or loop,
//! whatever the MBR, boot sector, directory or FAT say, and a file it
//! opens reads back at most its size, in at most two device reads a block
//! (checked over its first 256 blocks).
#![no_main]

use libfuzzer_sys::fuzz_target;
use taut_logic::fat::{BlockRead, Volume, BLOCK};

struct Image<'a> {
    bytes: &'a [u8],
    reads: u32,
}

impl BlockRead for Image<'_> {
    type Error = ();
    fn read_block(&mut self, lba: u32, buf: &mut [u8; BLOCK]) -> Result<(), ()> {
        self.reads += 1;
        // Blocks past the input repeat it: small inputs still give deep trees.
        // (Copied a run at a time: a byte-wise modulo made this the bottleneck.)
        if self.bytes.is_empty() {
            buf.fill(0);
            return Ok(());
        }
        let mut at = (lba as usize * BLOCK) % self.bytes.len();
        let mut out = &mut buf[..];
        while !out.is_empty() {
            let n = out.len().min(self.bytes.len() - at);
            out[..n].copy_from_slice(&self.bytes[at..at + n]);
            out = &mut out[n..];
            at = 0;
        }
        Ok(())
    }
}

const MAX_BLOCKS: u32 = 256;

fuzz_target!(|data: &[u8]| {
    let mut image = Image { bytes: data, reads: 0 };
    let mut buf = [0u8; BLOCK];
    let Ok(volume) = Volume::mount(&mut image, &mut buf) else {
        return;
    };
    for name in [&b"param.txt"[..], b"PORADI.TXT", b"x"] {
        let Ok(mut file) = volume.open(&mut image, &mut buf, name) else {
            continue;
        };
        let mut total = 0u64;
        // The first MAX_BLOCKS blocks of a file are enough: past them a file
        // of up to 4 GiB (its FAT chain repeating with the input) would keep
        // one run reading for minutes.
        for _ in 0..MAX_BLOCKS {
            image.reads = 0;
            match file.read_next(&volume, &mut image, &mut buf) {
                Ok(0) | Err(_) => break,
                Ok(n) => total += n as u64,
            }
            assert!(image.reads <= 2);
        }
        assert!(total <= u64::from(file.size()));
    }
});
