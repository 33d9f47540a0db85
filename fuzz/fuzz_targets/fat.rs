//! Arbitrary bytes as a card: the FAT reader must never panic or loop,
//! whatever the MBR, boot sector, directory or FAT say, and a file it
//! opens reads back at most its size, in at most two device reads a block.
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
        let len = self.bytes.len().max(1);
        for (i, b) in buf.iter_mut().enumerate() {
            *b = *self.bytes.get((lba as usize * BLOCK + i) % len).unwrap_or(&0);
        }
        Ok(())
    }
}

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
        loop {
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
