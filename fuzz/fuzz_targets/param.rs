//! Arbitrary bytes as `param.txt`: the parser must never panic, must give
//! the same answer whatever the chunk size, and anything it accepts must
//! be a board the machine can wind.
#![no_main]

use libfuzzer_sys::fuzz_target;
use taut_logic::files::param::{radius_limit_um, ParamFile, Params, MAX_NAILS, MAX_SHAPE};
use taut_logic::files::FileError;

fn parse(text: &[u8], chunk: usize) -> Result<Params, FileError> {
    let mut p = ParamFile::new();
    for part in text.chunks(chunk) {
        p.push(part)?;
    }
    p.finish()
}

fuzz_target!(|data: &[u8]| {
    let Some((&chunk, text)) = data.split_first() else {
        return;
    };
    let whole = parse(text, text.len().max(1));
    assert_eq!(parse(text, chunk as usize % 64 + 1), whole);
    match whole {
        Ok(p) => {
            assert!(p.shape == 0 || (3..=MAX_SHAPE).contains(&p.shape));
            assert!((3..=MAX_NAILS).contains(&p.nails));
            assert!(p.radius_um > radius_limit_um(p.shape));
        }
        Err(e) => assert_eq!(e.line == 0, e.col == 0, "{e:?}"),
    }
});
