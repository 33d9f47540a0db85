//! Arbitrary bytes as `poradi.txt`: the check must never panic, must give
//! the same answer whatever the chunk size, and whenever it accepts a file
//! the winding reader must yield exactly that many indices, all in range.
#![no_main]

use libfuzzer_sys::fuzz_target;
use taut_logic::files::poradi::{PoradiCheck, PoradiReader};
use taut_logic::files::FileError;

fn check(text: &[u8], nails: u16, chunk: usize) -> Result<u32, FileError> {
    let mut c = PoradiCheck::new(nails);
    for part in text.chunks(chunk) {
        c.push(part)?;
    }
    c.finish()
}

fuzz_target!(|data: &[u8]| {
    let [n0, n1, chunk, text @ ..] = data else {
        return;
    };
    let nails = u16::from_le_bytes([*n0, *n1]) % 10_000 + 3;
    let chunk = *chunk as usize % 64 + 1;
    let whole = check(text, nails, text.len().max(1));
    assert_eq!(check(text, nails, chunk), whole);
    let Ok(count) = whole else {
        return;
    };
    let mut reader = PoradiReader::new(nails);
    let mut read = 0u32;
    for mut part in text.chunks(chunk) {
        while !part.is_empty() {
            let (used, nail) = reader.next(part).expect("the check accepted the file");
            assert!(used > 0);
            if let Some(n) = nail {
                assert!(n < nails);
                read += 1;
            }
            part = &part[used..];
        }
    }
    read += reader
        .finish()
        .expect("the check accepted the file")
        .is_some() as u32;
    assert_eq!(read, count);
});
