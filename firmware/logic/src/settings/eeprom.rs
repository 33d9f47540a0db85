//! The EEPROM's map: where each record lives ([`SETTINGS`], [`COORDS`],
//! [`LINES`], [`INFO`]), the layout marker ([`MARKER`]) that says whose
//! data it holds, and on the host whole EEPROMs written as the store
//! writes them. Each record is kept in two copies ([`super::record`]).

use super::image;
use super::record::{Area, Part, HEAD, TAIL};

/// `taut` and the layout's version (8: the settings record's room), at
/// byte 0 (where the settings image of version 6 began: its magic and
/// version byte). Written last on a new
/// or an upgraded chip, once every record below is: until then a record
/// that fails its checks is stale data of an older layout, not corruption.
pub const MARKER: [u8; 5] = *b"taut\x08";
/// The settings image of version 6 (one copy, at byte 0) ends below this:
/// read once to migrate it.
pub const LEGACY_END: u16 = 256;

/// Grbl's numbered settings and taut's named ones
/// ([`super::image`]).
pub const SETTINGS: Area = Area {
    start: LEGACY_END,
    kind: b'S',
    // 8: a fixed room, the count of named settings first (7 had no room:
    // a setting added moved every record after it).
    version: 8,
    payload: image::PAYLOAD,
};

/// The work coordinate data ([`crate::coords`]).
pub const COORDS: Area = Area {
    start: SETTINGS.end(),
    kind: b'C',
    version: 1,
    payload: crate::coords::PAYLOAD,
};

/// Longest startup line or build info line kept, characters (Grbl's
/// `EEPROM_LINE_SIZE`, 80, holds `$N0=` and the line's end too).
pub const TEXT: u16 = 75;
/// A text's payload: the characters, then zeros.
const TEXT_PAYLOAD: u16 = TEXT + 1;

/// `$N0` and `$N1`.
pub const LINES: [Area; 2] = [
    Area {
        start: COORDS.end(),
        kind: b'N',
        version: 1,
        payload: TEXT_PAYLOAD,
    },
    Area {
        start: COORDS.end() + 2 * (HEAD + TEXT_PAYLOAD + TAIL),
        kind: b'M',
        version: 1,
        payload: TEXT_PAYLOAD,
    },
];

/// `$I=`'s line.
pub const INFO: Area = Area {
    start: LINES[1].end(),
    kind: b'I',
    version: 1,
    payload: TEXT_PAYLOAD,
};

/// Part `k` of a text's payload: its characters, then zeros to
/// [`TEXT`] + 1 bytes (a text longer than [`TEXT`] is cut there).
pub fn text_part(text: &[u8], k: u8) -> Option<Part> {
    let from = k as usize * 8;
    let len = TEXT_PAYLOAD as usize;
    if from >= len {
        return None;
    }
    let mut b = [0u8; 8];
    for (i, x) in b.iter_mut().enumerate() {
        let at = from + i;
        if at < TEXT as usize {
            *x = text.get(at).copied().unwrap_or(0);
        }
    }
    Some((b, (len - from).min(8) as u8))
}

/// Every record's bytes end below this (the string-art checkpoint begins
/// there).
pub const END: u16 = INFO.end();
const _: () = assert!(END <= crate::checkpoint::START);
const _: () = assert!(LINES[0].end() == LINES[1].start);
const _: () = assert!(image::LEGACY_LEN <= LEGACY_END as usize);

/// Host helpers: an EEPROM written as the store writes it (the HIL tests
/// make boards' EEPROMs with them).
#[cfg(not(target_arch = "avr"))]
pub mod host {
    extern crate std;
    use super::*;
    use crate::config::MachineConfig;
    use crate::coords::CoordData;
    use crate::settings::grbl::Extras;
    use crate::settings::record::{load, Step, Writer};
    use std::vec::Vec;

    /// Writes a copy through `w` into `eeprom` a byte at a time, as the
    /// store task does; the writes in order.
    pub fn write(
        eeprom: &mut [u8],
        mut w: Writer,
        part: impl Fn(u8) -> Option<Part>,
    ) -> Vec<(u16, u8)> {
        let mut writes = Vec::new();
        loop {
            let step = w.step(|a| eeprom[a as usize], &part, 8);
            match step {
                Step::Write(a, b) => {
                    eeprom[a as usize] = b;
                    writes.push((a, b));
                }
                Step::More => {}
                Step::Done => return writes,
            }
        }
    }

    /// A whole EEPROM as a board that kept `cfg`, `ex` and `coords` (no
    /// startup lines) holds it: every record's copy 0, the marker, no
    /// checkpoint.
    pub fn eeprom(cfg: &MachineConfig, ex: &Extras, coords: &CoordData) -> Vec<u8> {
        let mut e = std::vec![0xFF; crate::checkpoint::END as usize];
        write(&mut e, Writer::new(SETTINGS, 0, 1), |k| {
            crate::settings::image::part(cfg, ex, k)
        });
        write(&mut e, Writer::new(COORDS, 0, 1), |k| {
            coords
                .part(k)
                .map(|b| ([b[0], b[1], b[2], b[3], 0, 0, 0, 0], 4))
        });
        for area in [LINES[0], LINES[1], INFO] {
            write(&mut e, Writer::new(area, 0, 1), |k| text_part(&[], k));
        }
        e[..MARKER.len()].copy_from_slice(&MARKER);
        e
    }

    /// The settings an EEPROM holds, as the firmware's boot reads them
    /// (a version-6 image too); `None`: the defaults would be taken.
    pub fn settings(eeprom: &[u8]) -> Option<(MachineConfig, Extras)> {
        use crate::settings::image;
        let read = |a: u16| eeprom.get(a as usize).copied().unwrap_or(0xFF);
        let mut out = None;
        load(SETTINGS, &read, |c| {
            let (mut cfg, mut ex) = (MachineConfig::STRING_ART, Extras::DEFAULT);
            let ok = image::decode_into(|i| SETTINGS.payload_byte(c, i, &read), &mut cfg, &mut ex)
                .is_ok();
            if ok {
                out = Some((cfg, ex));
            }
            ok
        });
        out.or_else(|| {
            let mut cfg = MachineConfig::STRING_ART;
            image::legacy::decode_into(read, &mut cfg).ok()?;
            Some((cfg, Extras::DEFAULT))
        })
    }

    /// The work coordinate data an EEPROM holds.
    pub fn coords(eeprom: &[u8]) -> Option<CoordData> {
        let read = |a: u16| eeprom.get(a as usize).copied().unwrap_or(0xFF);
        let mut out = None;
        load(COORDS, &read, |c| {
            out = Some(CoordData::decode(|i| COORDS.payload_byte(c, i, &read)));
            true
        });
        out
    }
}

/// Whose data the EEPROM holds, by its first five bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// This layout's, written whole ([`MARKER`]).
    Current,
    /// Erased: a new chip (or its first boot's writes cut short).
    Blank,
    /// A settings image of version 6 (a board flashed before): read
    /// once, then the marker.
    Legacy,
    /// Another firmware's, or an older taut's.
    Foreign,
}

/// Byte `i` of [`MARKER`], read from flash (an array would be copied
/// into the AVR's SRAM).
pub fn marker_byte(i: usize) -> u8 {
    taut_progmem::text!("taut\x08").byte(i)
}

/// Record `i`: 0 the settings, 1 the coordinates, 2 and 3 the startup
/// lines, 4 the build info; from a table in flash (each constant would be
/// copied into the AVR's SRAM where it is taken by reference).
pub fn area(i: u8) -> Area {
    taut_progmem::table!(Area; RECORDS; [SETTINGS, COORDS, LINES[0], LINES[1], INFO])
        .get(i as usize)
}

/// Records kept.
pub const RECORDS: usize = 5;

/// The layout byte 0… says.
pub fn layout(read: &impl Fn(u16) -> u8) -> Layout {
    if (0..MARKER.len()).all(|i| read(i as u16) == marker_byte(i)) {
        return Layout::Current;
    }
    if (0..MARKER.len()).all(|i| read(i as u16) == 0xFF) {
        return Layout::Blank;
    }
    match image::legacy::version(read) {
        Some(image::legacy::VERSION) => Layout::Legacy,
        _ => Layout::Foreign,
    }
}
