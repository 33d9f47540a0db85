//! A fault scenario as `taut-sim` takes it from its command line: bytes sent
//! to the console at set simulated times, the card pulled and put back,
//! card faults. Only the parsing: `Sim::uart_send_at`, `Sim::sd_remove_at`,
//! `Sim::sd_reinsert_at`, `Sim::sd_fault_at` and `SdCard::inject` carry
//! them out.

use crate::sdcard::{CardFault, SdImage};
use std::str::FromStr;
use std::time::Duration;

/// A simulated time since power-on, in seconds (`3`, `0.25`).
pub fn seconds(text: &str) -> Result<Duration, String> {
    let s: f64 = text
        .parse()
        .map_err(|_| format!("{text:?} is not a number of seconds"))?;
    Duration::try_from_secs_f64(s)
        .map_err(|_| format!("{text:?}: seconds must be finite and not negative"))
}

/// The bytes of `text` with C-style escapes decoded: `\xHH` (two hex
/// digits), `\n`, `\r`, `\t`, `\0`, `\\`. Any other character stands for
/// its UTF-8 bytes.
pub fn unescape(text: &str) -> Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(text.len());
    let mut chars = text.chars();
    while let Some(c) = chars.next() {
        if c != '\\' {
            out.extend_from_slice(c.encode_utf8(&mut [0; 4]).as_bytes());
            continue;
        }
        let byte = match chars.next() {
            Some('n') => b'\n',
            Some('r') => b'\r',
            Some('t') => b'\t',
            Some('0') => 0,
            Some('\\') => b'\\',
            Some('x') => {
                let hex: String = chars.by_ref().take(2).collect();
                match u8::from_str_radix(&hex, 16) {
                    Ok(b) if hex.len() == 2 => b,
                    _ => return Err(format!("\\x{hex}: \\x takes two hex digits")),
                }
            }
            Some(other) => return Err(format!("unknown escape \\{other}")),
            None => return Err("a lone \\ at the end".into()),
        };
        out.push(byte);
    }
    Ok(out)
}

/// `SECONDS:BYTES` (`--at`): bytes for the console at a simulated time.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TimedBytes {
    pub at: Duration,
    pub bytes: Vec<u8>,
}

impl FromStr for TimedBytes {
    type Err = String;

    fn from_str(spec: &str) -> Result<TimedBytes, String> {
        let (at, bytes) = spec
            .split_once(':')
            .ok_or_else(|| format!("{spec:?}: expected SECONDS:BYTES"))?;
        let bytes = unescape(bytes).map_err(|e| format!("{spec:?}: {e}"))?;
        if bytes.is_empty() {
            return Err(format!("{spec:?}: no bytes to send"));
        }
        Ok(TimedBytes {
            at: seconds(at)?,
            bytes,
        })
    }
}

/// The block a block fault hits.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum BlockRef {
    /// A block number (LBA: block 0 is the card's first).
    Lba(u32),
    /// The first data block of a file in the card's root folder.
    File(String),
}

impl BlockRef {
    /// A number (decimal, or hex after `0x`) is a block; anything else a
    /// file name.
    fn parse(text: &str) -> Result<BlockRef, String> {
        if text.is_empty() {
            return Err("a block number or a file name is missing".into());
        }
        let number = match text.strip_prefix("0x") {
            Some(hex) => u32::from_str_radix(hex, 16).ok(),
            None => text.parse().ok(),
        };
        Ok(number.map_or_else(|| BlockRef::File(text.to_string()), BlockRef::Lba))
    }

    fn lba(&self, image: &SdImage) -> Result<u32, String> {
        match self {
            BlockRef::Lba(lba) if *lba < image.blocks() => Ok(*lba),
            BlockRef::Lba(lba) => Err(format!(
                "block {lba} is past the card's end ({} blocks)",
                image.blocks()
            )),
            BlockRef::File(name) => image
                .first_block_of(name)
                .ok_or_else(|| format!("{name}: no such file with data on the card")),
        }
    }
}

/// A card fault (`--card-fault`):
/// - `crc-once:LBA|FILE`: the next read of that block (a file: its first
///   data block) carries a bad CRC16, once; later reads are fine.
/// - `bad-block:LBA|FILE`: every read of that block fails as a worn-out
///   block does: R1 fine, then data error token 0x04 (card ECC failed).
/// - `crc-once-at:SECONDS`: the first data block the card sends after that
///   simulated time carries a bad CRC16.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum FaultSpec {
    CrcOnce(BlockRef),
    BadBlock(BlockRef),
    CrcOnceAt(Duration),
}

impl FromStr for FaultSpec {
    type Err = String;

    fn from_str(spec: &str) -> Result<FaultSpec, String> {
        let bad = |e: String| format!("--card-fault {spec}: {e}");
        let (kind, arg) = spec
            .split_once(':')
            .ok_or_else(|| bad("expected KIND:ARGUMENT".into()))?;
        match kind {
            "crc-once" => BlockRef::parse(arg).map(FaultSpec::CrcOnce),
            "bad-block" => BlockRef::parse(arg).map(FaultSpec::BadBlock),
            "crc-once-at" => seconds(arg).map(FaultSpec::CrcOnceAt),
            _ => Err(format!(
                "unknown kind {kind:?} (crc-once, bad-block, crc-once-at)"
            )),
        }
        .map_err(bad)
    }
}

impl FaultSpec {
    /// The fault for `image`'s card, and the simulated time it is planned
    /// for (`None`: the card has it from the start).
    pub fn resolve(&self, image: &SdImage) -> Result<(Option<Duration>, CardFault), String> {
        Ok(match self {
            FaultSpec::CrcOnce(block) => (None, CardFault::CrcOnce(block.lba(image)?)),
            FaultSpec::BadBlock(block) => (None, CardFault::BadBlock(block.lba(image)?)),
            FaultSpec::CrcOnceAt(at) => (Some(*at), CardFault::CrcNext),
        })
    }

    /// When the fault is planned for, if at a time.
    pub fn at(&self) -> Option<Duration> {
        match self {
            FaultSpec::CrcOnceAt(at) => Some(*at),
            _ => None,
        }
    }
}

/// Checks the card's comings and goings make sense: it goes in at power-on
/// or at `insert_at`; each pull finds it in, each re-insertion finds it
/// out. (At the same time, an insertion comes first, then pulls, then
/// re-insertions: the order `taut-sim` plans them in.)
pub fn check_card_plan(
    insert_at: Option<Duration>,
    pulls: &[Duration],
    reinserts: &[Duration],
) -> Result<(), String> {
    #[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
    enum Event {
        Insert,
        Pull,
        Reinsert,
    }
    let mut events: Vec<(Duration, Event)> =
        insert_at.iter().map(|&at| (at, Event::Insert)).collect();
    events.extend(pulls.iter().map(|&at| (at, Event::Pull)));
    events.extend(reinserts.iter().map(|&at| (at, Event::Reinsert)));
    events.sort_unstable();
    let mut card_in = insert_at.is_none();
    for (at, event) in events {
        let s = at.as_secs_f64();
        card_in = match (event, card_in) {
            (Event::Pull, false) => {
                return Err(format!("--pull-card-at {s}: the card is not in then"))
            }
            (Event::Reinsert, true) => {
                return Err(format!(
                    "--reinsert-at {s}: the card is in then (pull it first)"
                ))
            }
            (Event::Pull, true) => false,
            (Event::Insert | Event::Reinsert, _) => true,
        };
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn secs(s: f64) -> Duration {
        Duration::from_secs_f64(s)
    }

    #[test]
    fn seconds_are_plain_non_negative_numbers() {
        assert_eq!(seconds("2"), Ok(secs(2.0)));
        assert_eq!(seconds("0.25"), Ok(secs(0.25)));
        for bad in ["", "-1", "inf", "NaN", "2s", " 2"] {
            assert!(seconds(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn escapes_are_decoded() {
        assert_eq!(unescape(r"\x18"), Ok(vec![0x18]));
        assert_eq!(unescape(r"G0 X1\r\n"), Ok(b"G0 X1\r\n".to_vec()));
        assert_eq!(unescape(r"\\\t\0?"), Ok(b"\\\t\0?".to_vec()));
        assert_eq!(unescape(r"\xfF!"), Ok(vec![0xFF, b'!']));
        assert_eq!(unescape("µ"), Ok("µ".as_bytes().to_vec()));
        for bad in [r"\x1", r"\xg0", r"\q", "\\", r"\x"] {
            assert!(unescape(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn timed_bytes_split_at_the_first_colon() {
        let t: TimedBytes = r"1.5:\x18".parse().unwrap();
        assert_eq!((t.at, t.bytes), (secs(1.5), vec![0x18]));
        let t: TimedBytes = "3:G4 P0.5:x\n".parse().unwrap();
        assert_eq!(t.bytes, b"G4 P0.5:x\n");
        for bad in ["?", "3:", "x:?", r"3:\z"] {
            assert!(bad.parse::<TimedBytes>().is_err(), "{bad:?}");
        }
    }

    #[test]
    fn fault_specs_name_a_block_a_file_or_a_time() {
        let parse = |s: &str| s.parse::<FaultSpec>();
        assert_eq!(
            parse("crc-once:2051"),
            Ok(FaultSpec::CrcOnce(BlockRef::Lba(2051)))
        );
        assert_eq!(
            parse("bad-block:0x803"),
            Ok(FaultSpec::BadBlock(BlockRef::Lba(0x803)))
        );
        assert_eq!(
            parse("crc-once:poradi.txt"),
            Ok(FaultSpec::CrcOnce(BlockRef::File("poradi.txt".into())))
        );
        assert_eq!(
            parse("crc-once-at:12.5"),
            Ok(FaultSpec::CrcOnceAt(secs(12.5)))
        );
        for bad in ["crc-once", "crc-once:", "crc-once-at:x", "flip:3"] {
            let e = parse(bad).unwrap_err();
            assert!(e.starts_with(&format!("--card-fault {bad}: ")), "{e}");
        }
    }

    #[test]
    fn faults_resolve_on_the_image() {
        let image = SdImage::blank(100);
        let resolve = |s: &str| s.parse::<FaultSpec>().unwrap().resolve(&image);
        assert_eq!(resolve("crc-once:7"), Ok((None, CardFault::CrcOnce(7))));
        assert_eq!(resolve("bad-block:99"), Ok((None, CardFault::BadBlock(99))));
        assert_eq!(
            resolve("crc-once-at:3"),
            Ok((Some(secs(3.0)), CardFault::CrcNext))
        );
        assert!(resolve("bad-block:100").is_err(), "past the end");
        assert!(resolve("crc-once:param.txt").is_err(), "no FAT: no files");
        assert_eq!(
            "crc-once:0xZZ".parse::<FaultSpec>(),
            Ok(FaultSpec::CrcOnce(BlockRef::File("0xZZ".into()))),
            "not a number: a file name, found or not on the card"
        );
    }

    #[test]
    fn the_card_must_be_in_to_be_pulled_and_out_to_go_back() {
        let s = |v: &[f64]| v.iter().map(|&x| secs(x)).collect::<Vec<_>>();
        assert_eq!(check_card_plan(None, &[], &[]), Ok(()));
        assert_eq!(check_card_plan(None, &s(&[2.0, 6.0]), &s(&[4.0])), Ok(()));
        assert_eq!(
            check_card_plan(Some(secs(3.0)), &s(&[3.0]), &s(&[3.0])),
            Ok(()),
            "in, out and back at the same time"
        );
        assert!(check_card_plan(Some(secs(3.0)), &s(&[2.0]), &[]).is_err());
        assert!(check_card_plan(None, &s(&[2.0, 3.0]), &[]).is_err());
        assert!(check_card_plan(None, &[], &s(&[1.0])).is_err());
        assert!(check_card_plan(None, &s(&[2.0]), &s(&[1.0])).is_err());
    }
}
