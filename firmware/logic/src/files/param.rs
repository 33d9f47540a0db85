//! `param.txt`: the board's shape, its number of nails and its radius.
//!
//! ```text
//! tvar = 0               # shape: 0 circle, n >= 3 regular n-gon
//! pocet_hrebiku = 250    # number of nails
//! polomer_matrice = 40.2 # board radius in cm
//! ```
//! Keys are the original firmware's or their English aliases (`shape`,
//! `nails`, `radius_cm`), in any case. Each must appear exactly once.

use crate::files::error::{FileError, FileName};
use crate::files::kv::{Item, KvReader};
use crate::text::num::{parse_fixed, parse_u32};
use crate::text::ErrorKind;
use taut_progmem::{text, Text};

/// Most corners of a polygonal board.
pub const MAX_SHAPE: u16 = 1000;
/// Most nails on a board.
pub const MAX_NAILS: u16 = 10_000;
/// Largest board radius, µm (10 m).
pub const MAX_RADIUS_UM: u32 = 10_000_000;
/// Nails stand this far inside the board radius, µm.
pub const NAIL_MARGIN_UM: u32 = 15_000;
/// While winding, the needle goes this far inside the nail nearest the
/// centre, µm; that radius must stay positive.
pub const INNER_CLEARANCE_UM: u32 = 20_000;

const FILE: FileName = FileName::Param;

/// The job's board.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Params {
    /// 0 for a circle, n ≥ 3 for a regular n-gon.
    pub shape: u16,
    pub nails: u16,
    /// Board radius (circumradius of a polygon), µm.
    pub radius_um: u32,
}

/// The board radius must be more than this, µm, for the winding needle's
/// inner radius `(R − margin)·cos(π/n) − clearance` to be positive.
/// One cosine per file: not on any hot path.
pub fn radius_limit_um(shape: u16) -> u32 {
    let apothem_ratio = match shape {
        0 => 1.0,
        n => crate::fmath::sin_cos(core::f32::consts::PI / n as f32).1,
    };
    NAIL_MARGIN_UM + (INNER_CLEARANCE_UM as f32 / apothem_ratio) as u32
}

/// Names key `i` may have: the original's, its English alias, and both as
/// `missing key` prints them. Built by code from texts in flash: a table
/// would sit in the AVR's SRAM (130 bytes as strings).
fn key_names(i: usize) -> [Text; 3] {
    match i {
        0 => [text!("tvar"), text!("shape"), text!("tvar (shape)")],
        1 => [
            text!("pocet_hrebiku"),
            text!("nails"),
            text!("pocet_hrebiku (nails)"),
        ],
        _ => [
            text!("polomer_matrice"),
            text!("radius_cm"),
            text!("polomer_matrice (radius_cm)"),
        ],
    }
}

/// Number of keys.
const KEYS: usize = 3;

/// Values seen so far, by the index of their key in [`KEYS`].
#[derive(Default)]
struct Seen {
    shape: Option<u16>,
    nails: Option<u16>,
    /// The radius is checked at the end (its limit depends on the shape),
    /// so its position is kept.
    radius: Option<(u32, u32, u32)>,
    lines: bool,
}

/// Streaming parser of `param.txt`: `push` chunks, then `finish`.
pub struct ParamFile {
    kv: KvReader,
    seen: Seen,
}

impl Default for ParamFile {
    fn default() -> Self {
        Self::new()
    }
}

impl ParamFile {
    pub fn new() -> Self {
        ParamFile {
            kv: KvReader::new(FILE),
            seen: Seen::default(),
        }
    }

    pub fn push(&mut self, chunk: &[u8]) -> Result<(), FileError> {
        let seen = &mut self.seen;
        self.kv.push_chunk(chunk, &mut |item| seen.take(item))
    }

    /// The file ended: its values, checked as a whole.
    pub fn finish(&mut self) -> Result<Params, FileError> {
        if let Some(item) = self.kv.finish()? {
            self.seen.take(item)?;
        }
        let seen = core::mem::take(&mut self.seen);
        // One error built, whichever it is.
        let (line, col, kind) = match (seen.shape, seen.nails, seen.radius) {
            _ if !seen.lines => (0, 0, ErrorKind::Empty),
            (Some(shape), Some(nails), Some((radius_um, line, col))) => {
                let above_um = radius_limit_um(shape);
                if radius_um > above_um {
                    return Ok(Params {
                        shape,
                        nails,
                        radius_um,
                    });
                }
                (line, col, ErrorKind::RadiusTooSmall { above_um })
            }
            (shape, nails, _) => {
                let missing = match (shape, nails) {
                    (None, _) => 0,
                    (_, None) => 1,
                    _ => 2,
                };
                (0, 0, ErrorKind::MissingKey(key_names(missing)[2]))
            }
        };
        Err(FileError::at(FILE, line, col, kind))
    }
}

impl Seen {
    pub(super) fn take(&mut self, item: Item<'_>) -> Result<(), FileError> {
        self.lines = true;
        // One error built, wherever it came from.
        let (col, kind) = match self.take_value(&item) {
            Ok(()) => return Ok(()),
            Err(e) => e,
        };
        Err(FileError::at(FILE, item.line, col, kind))
    }

    /// Takes the line's value; on an error its column and kind.
    fn take_value(&mut self, item: &Item<'_>) -> Result<(), (u32, ErrorKind)> {
        let Some(key) = (0..KEYS).find(|&k| {
            let [name, alias, _] = key_names(k);
            name.eq_ignore_ascii_case(item.key) || alias.eq_ignore_ascii_case(item.key)
        }) else {
            return Err((item.key_col, ErrorKind::UnknownKey));
        };
        let already = match key {
            0 => self.shape.is_some(),
            1 => self.nails.is_some(),
            _ => self.radius.is_some(),
        };
        if already {
            return Err((item.key_col, ErrorKind::DuplicateKey));
        }
        // One number read for the three keys.
        let n = match key {
            2 => parse_fixed(item.value, 4),
            _ => parse_u32(item.value),
        };
        let n = n.map_err(|e| (item.value_col + e.at as u32, e.kind))?;
        let col = item.value_col;
        match key {
            0 => {
                if n == 1 || n == 2 || n > MAX_SHAPE as u32 {
                    let max = MAX_SHAPE as u32;
                    return Err((col, ErrorKind::Shape { max }));
                }
                self.shape = Some(n as u16);
            }
            1 => {
                if !(3..=MAX_NAILS as u32).contains(&n) {
                    let (min, max) = (3, MAX_NAILS as u32);
                    return Err((col, ErrorKind::Range { min, max }));
                }
                self.nails = Some(n as u16);
            }
            _ => {
                if n > MAX_RADIUS_UM {
                    return Err((col, ErrorKind::TooBig));
                }
                self.radius = Some((n, item.line, col));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::files::error::tests::in_every_chunking;
    use crate::text::error::tests::show;
    use proptest::prelude::*;
    use std::string::String;

    fn parse_in_chunks(text: &[u8], chunk: usize) -> Result<Params, FileError> {
        let mut p = ParamFile::new();
        for part in text.chunks(chunk) {
            p.push(part)?;
        }
        p.finish()
    }

    /// Parses whole and in chunks of every size; all must agree.
    fn parse(text: &str) -> Result<Params, String> {
        in_every_chunking(text, parse_in_chunks)
    }

    const fn params(shape: u16, nails: u16, radius_um: u32) -> Params {
        Params {
            shape,
            nails,
            radius_um,
        }
    }

    #[test]
    fn good_files() {
        let good: &[(&str, Params)] = &[
            (
                "tvar = 0               # shape: 0 circle, n >= 3 regular n-gon\n\
                 pocet_hrebiku = 250    # number of nails\n\
                 polomer_matrice = 40.2 # board radius in cm\n",
                params(0, 250, 402_000),
            ),
            (
                "\u{FEFF}# English\r\nSHAPE=4\r\n\r\nnails =\t300\r\nRadius_CM = 25",
                params(4, 300, 250_000),
            ),
            ("radius_cm=3.5001\nnails=3\nshape=0", params(0, 3, 35_001)),
            (
                "tvar=3\npocet_hrebiku=10000\npolomer_matrice=5.5001",
                params(3, 10_000, 55_001),
            ),
            (
                "tvar=1000\nnails=3\nradius_cm=1000",
                params(1000, 3, 10_000_000),
            ),
            // Lines ended by CR only (old Mac editors).
            (
                "tvar = 0\rpocet_hrebiku = 250\rpolomer_matrice = 40.2\r",
                params(0, 250, 402_000),
            ),
        ];
        for (text, expected) in good {
            assert_eq!(parse(text), Ok(*expected), "{text:?}");
        }
    }

    #[test]
    fn a_utf16_file_is_named_as_such() {
        for text in [&b"\xFF\xFEt\0v\0a\0r\0"[..], b"\xFE\xFF\0t\0v"] {
            for chunk in 1..text.len() {
                let e = parse_in_chunks(text, chunk).map_err(|e| show(&e));
                let utf16 = "param.txt:1:2: UTF-16 text: save it as UTF-8 or ASCII";
                assert_eq!(e, Err(utf16.into()), "chunk {chunk}");
            }
        }
    }

    #[test]
    fn bad_files_say_where_and_what() {
        let bad: &[(&str, &str)] = &[
            ("", "param.txt: empty file"),
            ("\u{FEFF}# nothing\r\n\r\n", "param.txt: empty file"),
            (
                "tvar = 0\npocet_hrebiku = 250\n",
                "param.txt: missing key polomer_matrice (radius_cm)",
            ),
            (
                "nails = 250\nradius_cm = 30",
                "param.txt: missing key tvar (shape)",
            ),
            (
                "tvar = 0\nradius_cm = 30",
                "param.txt: missing key pocet_hrebiku (nails)",
            ),
            ("tvar = 0\n  pocet = 250\n", "param.txt:2:3: unknown key"),
            ("tvar = 0\nshape = 4\n", "param.txt:2:1: duplicate key"),
            ("tvar = 1\n", "param.txt:1:8: expected 0 or 3 to 1000"),
            ("tvar = 2\n", "param.txt:1:8: expected 0 or 3 to 1000"),
            ("tvar = 1001\n", "param.txt:1:8: expected 0 or 3 to 1000"),
            ("tvar = -3\n", "param.txt:1:8: expected a number"),
            ("tvar = kruznice\n", "param.txt:1:8: expected a number"),
            ("tvar =\n", "param.txt:1:7: expected a number"),
            ("pocet_hrebiku = 2\n", "param.txt:1:17: expected 3 to 10000"),
            (
                "pocet_hrebiku = 10001\n",
                "param.txt:1:17: expected 3 to 10000",
            ),
            (
                "pocet_hrebiku = 99999999999\n",
                "param.txt:1:17: number too big",
            ),
            (
                "pocet_hrebiku = 250.0\n",
                "param.txt:1:20: expected a number",
            ),
            (
                "polomer_matrice = 40,2\n",
                "param.txt:1:21: expected a number",
            ),
            (
                "polomer_matrice = 1000.0001\n",
                "param.txt:1:19: number too big",
            ),
            ("tvar 0\n", "param.txt:1:1: expected key = value"),
            (
                "tvar = 0 # a comment that is far too long for a line of param.txt\n",
                "param.txt:1:65: line too long (max 64)",
            ),
            // The radius check waits for the shape, wherever it is.
            (
                "polomer_matrice = 3.5\npocet_hrebiku = 250\ntvar = 0\n",
                "param.txt:1:19: expected more than 3.5 cm",
            ),
            (
                "polomer_matrice = 0\npocet_hrebiku = 250\ntvar = 0\n",
                "param.txt:1:19: expected more than 3.5 cm",
            ),
            (
                "tvar = 3\nnails = 250\nradius_cm = 5.5",
                "param.txt:3:13: expected more than 5.5 cm",
            ),
            (
                "tvar = 4\nnails = 250\nradius_cm = 4.3284",
                "param.txt:3:13: expected more than 4.3284 cm",
            ),
            (
                "tvar = 0\rnails = 25O\r",
                "param.txt:2:11: expected a number",
            ),
            (
                "tvar = 0\n\x01\x02",
                "param.txt:2:1: not a text file (byte 1)",
            ),
        ];
        for (text, message) in bad {
            assert_eq!(parse(text), Err(String::from(*message)), "{text:?}");
        }
    }

    #[test]
    fn square_board_limit_is_just_above_the_exact_value() {
        // 1.5 + 2.0 / cos(45°) = 4.32842… cm.
        assert_eq!(radius_limit_um(4), 43_284);
        assert!(parse("tvar=4\nnails=4\nradius_cm=4.3285").is_ok());
    }

    proptest! {
        #[test]
        fn written_params_read_back(
            shape in prop_oneof![Just(0u16), 3u16..=MAX_SHAPE],
            nails in 3u16..=MAX_NAILS,
            radius_um in 0u32..=MAX_RADIUS_UM,
            order in Just([0usize, 1, 2]).prop_shuffle(),
            english in proptest::bool::ANY,
            crlf in proptest::bool::ANY,
            chunk in 1usize..80,
        ) {
            let values = [
                std::format!("{shape}"),
                std::format!("{nails}"),
                std::format!("{}.{:04}", radius_um / 10_000, radius_um % 10_000),
            ];
            let mut text = String::new();
            for k in order {
                let key = key_names(k)[usize::from(english)];
                text += &std::format!("{key} = {}{}", values[k], if crlf { "\r\n" } else { "\n" });
            }
            let result = parse_in_chunks(text.as_bytes(), chunk);
            if radius_um > radius_limit_um(shape) {
                prop_assert_eq!(result, Ok(params(shape, nails, radius_um)));
            } else {
                prop_assert_eq!(result.unwrap_err().kind, ErrorKind::RadiusTooSmall { above_um: radius_limit_um(shape) });
            }
        }

        #[test]
        fn chunk_boundaries_never_change_the_verdict(
            text in "(tvar|nails|radius_cm|x|[ =.0-9#\r\n\t\u{FEFF}]){0,40}",
            chunk in 1usize..40,
        ) {
            let whole = parse_in_chunks(text.as_bytes(), text.len().max(1));
            prop_assert_eq!(parse_in_chunks(text.as_bytes(), chunk), whole);
        }
    }
}
