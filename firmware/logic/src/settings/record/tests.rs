use super::*;
use crate::config::MachineConfig;
use crate::coords::{CoordData, Slot};
use crate::machine::Machine;
use crate::settings::eeprom::host::write;
use crate::settings::eeprom::*;
use crate::settings::grbl::{Extras, Numbered};
use crate::settings::{image, set};
use crate::units::Milli;
use std::vec;
use std::vec::Vec;

type Settings = (MachineConfig, Extras);

fn blank() -> Vec<u8> {
    vec![0xFF; crate::checkpoint::END as usize]
}

/// The settings the boot takes from `ee`, as the store reads them.
fn settings_of(ee: &[u8]) -> (Loaded, Option<Settings>) {
    let read = |a: u16| ee[a as usize];
    let mut out = None;
    let loaded = load(SETTINGS, &read, |c| {
        let mut cfg = MachineConfig::STRING_ART;
        let mut ex = Extras::DEFAULT;
        let ok =
            image::decode_into(|i| SETTINGS.payload_byte(c, i, &read), &mut cfg, &mut ex).is_ok();
        if ok {
            out = Some((cfg, ex));
        }
        ok
    });
    (loaded, out)
}

fn coords_of(ee: &[u8]) -> (Loaded, Option<CoordData>) {
    let read = |a: u16| ee[a as usize];
    let mut out = None;
    let loaded = load(COORDS, &read, |c| {
        out = Some(CoordData::decode(|i| COORDS.payload_byte(c, i, &read)));
        true
    });
    (loaded, out)
}

/// Writes `s` as the store would: into the copy not in force.
fn write_settings(ee: &mut [u8], s: &Settings) -> Vec<(u16, u8)> {
    let (copy, seq) = settings_of(ee).0.next();
    write(ee, Writer::new(SETTINGS, copy, seq), |k| {
        image::part(&s.0, &s.1, k)
    })
}

/// Every state a cut during `writes` (from `before`) can leave: each
/// prefix of the writes, and each with its next byte torn to a few values
/// (erased, zero, the committed mark, half of the new one, noise).
fn cuts(before: &[u8], writes: &[(u16, u8)]) -> Vec<Vec<u8>> {
    let mut states = Vec::new();
    let mut ee = before.to_vec();
    for &(at, b) in writes {
        states.push(ee.clone());
        for torn in [0xFF, 0x00, COMMITTED, b & 0xF0, b ^ 0x5A, !b] {
            let mut t = ee.clone();
            t[at as usize] = torn;
            states.push(t);
        }
        ee[at as usize] = b;
    }
    states.push(ee);
    states
}

/// After any cut, the values in force are the old or the new ones,
/// exactly, and the reading says nothing of corruption.
fn old_or_new<T: PartialEq + core::fmt::Debug>(
    before: &[u8],
    writes: &[(u16, u8)],
    read: impl Fn(&[u8]) -> (Loaded, Option<T>),
    old: Option<&T>,
    new: &T,
) {
    assert!(!writes.is_empty());
    let states = cuts(before, writes);
    let mut seen_new = false;
    for (i, s) in states.iter().enumerate() {
        let (loaded, got) = read(s);
        assert_ne!(loaded, Loaded::Corrupt, "state {i}");
        match got.as_ref() {
            Some(v) if v == new => seen_new = true,
            Some(v) => assert_eq!(Some(v), old, "state {i}"),
            None => {
                assert_eq!(old, None, "state {i}: the old values lost");
                assert_eq!(loaded, Loaded::Blank, "state {i}");
            }
        }
    }
    assert!(seen_new);
    assert_eq!(read(states.last().unwrap()).1.as_ref(), Some(new));
}

fn with(cfg: MachineConfig, changes: &[(&str, &str)]) -> Settings {
    apply((cfg, Extras::DEFAULT), changes)
}

fn apply(old: Settings, changes: &[(&str, &str)]) -> Settings {
    let (mut cfg, mut ex) = old;
    for (k, v) in changes {
        match Numbered::parse(k.as_bytes()) {
            Some(Some(n)) => n.set(&mut cfg, &mut ex, v.as_bytes()).unwrap(),
            _ => set(&mut cfg, k, v).unwrap(),
        }
    }
    (cfg, ex)
}

#[test]
fn every_cut_of_every_settings_write_leaves_the_old_or_the_new_values() {
    let mut ee = blank();
    // The first boot's defaults, on an erased chip.
    let defaults = with(MachineConfig::STRING_ART, &[]);
    let before = ee.clone();
    let writes = write_settings(&mut ee, &defaults);
    old_or_new(&before, &writes, settings_of, None, &defaults);
    // A `$n=` change (copy 1), another (back into copy 0, whose old
    // values must be uncommitted first), and a machine switch.
    let mut old = defaults;
    for changes in [
        &[("110", "2345")][..],
        &[("radial_accel", "750"), ("4", "0")],
        &[("machine", "flatbed")],
        &[("x_max_rate", "1500"), ("32", "1")],
    ] {
        let new = apply(old, changes);
        let before = ee.clone();
        let writes = write_settings(&mut ee, &new);
        assert!(writes.len() >= 6, "{writes:?}");
        old_or_new(&before, &writes, settings_of, Some(&old), &new);
        old = new;
    }
}

#[test]
fn every_cut_of_a_coordinate_write_leaves_the_old_or_the_new_data() {
    let mut ee = blank();
    let mut old = CoordData::ZERO;
    for (slot, x) in [
        (Slot::G54, 12_345),
        (Slot::G28, -7),
        (Slot::G54, 0),
        (Slot::G59, 1),
    ] {
        let mut new = old;
        new.set(slot, [Milli(x), Milli(-x), Milli(x / 2)]);
        let before = ee.clone();
        let (copy, seq) = coords_of(&ee).0.next();
        let writes = write(&mut ee, Writer::new(COORDS, copy, seq), |k| {
            new.part(k)
                .map(|b| ([b[0], b[1], b[2], b[3], 0, 0, 0, 0], 4))
        });
        let was = (old != CoordData::ZERO || seq > 1).then_some(&old);
        old_or_new(&before, &writes, coords_of, was, &new);
        old = new;
    }
}

#[test]
fn text_parts_fill_the_payload_with_zeros() {
    let parts: Vec<u8> = (0..)
        .map_while(|k| text_part(b"G20G90", k))
        .flat_map(|(b, n)| b.into_iter().take(n as usize))
        .collect();
    assert_eq!(parts.len(), LINES[0].payload as usize);
    assert_eq!(&parts[..7], b"G20G90\0");
    assert!(parts[6..].iter().all(|&b| b == 0));
    let long = [b'X'; 90];
    let cut: Vec<u8> = (0..)
        .map_while(|k| text_part(&long, k))
        .flat_map(|(b, n)| b.into_iter().take(n as usize))
        .collect();
    assert_eq!(cut.iter().filter(|&&b| b == b'X').count(), TEXT as usize);
}

#[test]
fn a_committed_copy_gone_bad_is_corruption_the_other_copy_holds() {
    let mut ee = blank();
    let a = with(MachineConfig::STRING_ART, &[("110", "3000")]);
    let b = with(MachineConfig::STRING_ART, &[("110", "2000")]);
    write_settings(&mut ee, &a);
    write_settings(&mut ee, &b);
    assert_eq!(
        settings_of(&ee),
        (Loaded::Taken { copy: 1, seq: 2 }, Some(b))
    );
    // Any byte of the newer copy flipped: the older one is in force.
    let copy1 = SETTINGS.copy(1) as usize..SETTINGS.end() as usize;
    for i in copy1.clone() {
        let mut bad = ee.clone();
        bad[i] ^= 0x10;
        assert_eq!(settings_of(&bad).1, Some(a), "byte {i}");
    }
    // Both bad: corruption, said so (not a blank chip).
    let mut both = ee.clone();
    both[SETTINGS.copy(0) as usize + 20] ^= 1;
    both[SETTINGS.copy(1) as usize + 20] ^= 1;
    assert_eq!(settings_of(&both), (Loaded::Corrupt, None));
    assert_eq!(settings_of(&blank()), (Loaded::Blank, None));
}

#[test]
fn the_marker_and_the_areas_in_flash_are_the_constants() {
    for i in 0..MARKER.len() {
        assert_eq!(marker_byte(i), MARKER[i]);
    }
    assert_eq!(
        [area(0), area(1), area(2), area(3), area(4)],
        [SETTINGS, COORDS, LINES[0], LINES[1], INFO]
    );
}

#[test]
fn sequence_numbers_wrap() {
    assert!(newer(1, 0));
    assert!(newer(0, u16::MAX));
    assert!(!newer(5, 5));
    assert!(!newer(u16::MAX, 0));
    let w = Loaded::Taken {
        copy: 1,
        seq: u16::MAX,
    };
    assert_eq!(w.next(), (0, 0));
}

#[test]
fn the_layout_marker_and_a_version_6_image() {
    let read = |e: &Vec<u8>| layout(&|a: u16| e[a as usize]);
    assert_eq!(read(&blank()), Layout::Blank);
    let mut e = blank();
    let v6: Vec<u8> = image::legacy::bytes(&MachineConfig::defaults(Machine::Drum)).collect();
    e[..v6.len()].copy_from_slice(&v6);
    assert_eq!(read(&e), Layout::Legacy);
    e[4] = 8;
    assert_eq!(read(&e), Layout::Current);
    // Layout 7 (the settings record without room): its records stand
    // elsewhere.
    e[4] = 7;
    assert_eq!(read(&e), Layout::Foreign);
    e[4] = 5;
    assert_eq!(read(&e), Layout::Foreign);
    // Grbl's own EEPROM: its version byte first.
    let mut grbl = blank();
    grbl[0] = 10;
    assert_eq!(read(&grbl), Layout::Foreign);
}

#[test]
fn the_records_fit_between_the_legacy_image_and_the_checkpoint() {
    assert!(SETTINGS.start as usize >= image::LEGACY_LEN);
    assert_eq!(COORDS.start, SETTINGS.end());
    assert_eq!(INFO.start, LINES[1].end());
    assert!(END <= crate::checkpoint::START);
    // The settings' room takes all there is: a setting added later moves
    // nothing.
    assert_eq!(END, crate::checkpoint::START);
    // A whole board's EEPROM as the host helper makes it reads back.
    let (mut cfg, mut ex) = (MachineConfig::defaults(Machine::Scara), Extras::DEFAULT);
    Numbered::MaxRate(0)
        .set(&mut cfg, &mut ex, b"2345")
        .unwrap();
    let mut coords = CoordData::ZERO;
    coords.set(Slot::G55, [Milli(1), Milli(2), Milli(3)]);
    let ee = host::eeprom(&cfg, &ex, &coords);
    assert_eq!(layout(&|a: u16| ee[a as usize]), Layout::Current);
    let (_, s) = settings_of(&ee);
    let (scara, _) = s.unwrap();
    assert_eq!(scara, cfg);
    assert_eq!(coords_of(&ee).1, Some(coords));
}
