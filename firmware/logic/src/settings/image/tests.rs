use super::*;
use crate::settings::grbl::Numbered;
use crate::settings::{all, set};
use std::vec::Vec;

const BASE: MachineConfig = MachineConfig::STRING_ART;

fn payload(cfg: &MachineConfig, ex: &Extras) -> Vec<u8> {
    (0..)
        .map_while(|k| part(cfg, ex, k))
        .flat_map(|(b, n)| b.into_iter().take(n as usize))
        .collect()
}

fn read(p: &[u8]) -> Result<(MachineConfig, Extras), Unusable> {
    let (mut cfg, mut ex) = (BASE, Extras::DEFAULT);
    decode_into(|i| p[i as usize], &mut cfg, &mut ex).map(|()| (cfg, ex))
}

#[test]
fn a_payload_reads_back_as_the_settings_it_was_made_of() {
    let mut cfg = BASE;
    let mut ex = Extras::DEFAULT;
    set(&mut cfg, "base_max_rate", "1500").unwrap();
    set(&mut cfg, "drill_steps_per_unit", "1600/10").unwrap();
    set(&mut cfg, "radial_travel_min", "-201.5").unwrap();
    set(&mut cfg, "step_pulse_us", "7").unwrap();
    Numbered::MaxRate(0)
        .set(&mut cfg, &mut ex, b"2345")
        .unwrap();
    Numbered::SpindleMax
        .set(&mut cfg, &mut ex, b"24000")
        .unwrap();
    Numbered::HardLimits.set(&mut cfg, &mut ex, b"1").unwrap();
    let p = payload(&cfg, &ex);
    assert_eq!(p.len(), PAYLOAD as usize);
    for n in [V6, STORED] {
        let widths = (0..n).map(|k| width(stored(k).unwrap())).sum::<usize>();
        assert_eq!(named_bytes(n), widths);
    }
    assert_eq!(read(&p), Ok((cfg, ex)));
    assert_eq!(
        read(&payload(&BASE, &Extras::DEFAULT)),
        Ok((BASE, Extras::DEFAULT))
    );
}

#[test]
fn a_payload_with_a_refused_value_is_refused() {
    // A max rate of 0: the base's, after the count, the extras, the
    // machine (4 bytes) and the base's steps per unit (8).
    let named = NAMED_AT as usize;
    let mut p = payload(&BASE, &Extras::DEFAULT);
    p[named + 12..named + 16].copy_from_slice(&0u32.to_le_bytes());
    assert!(matches!(read(&p), Err(Unusable::Refused(_))));
    // Each value fine, the set not: a pulse too long for the rate.
    let mut p = payload(&BASE, &Extras::DEFAULT);
    let pulse = named + 4 + 3 * (8 + 7 * 4);
    p[pulse..pulse + 4].copy_from_slice(&255u32.to_le_bytes());
    assert_eq!(read(&p), Err(Unusable::Inconsistent));
}

#[test]
fn a_version_6_image_is_carried_over() {
    let mut cfg = BASE;
    set(&mut cfg, "base_accel", "750").unwrap();
    set(&mut cfg, "machine", "flatbed").unwrap();
    set(&mut cfg, "x_travel_max", "150").unwrap();
    let img: Vec<u8> = legacy::bytes(&cfg).collect();
    assert_eq!(img.len(), legacy::len());
    assert_eq!(img.len(), 215, "what boards flashed before hold");
    let decode = |img: &[u8]| {
        let mut out = BASE;
        legacy::decode_into(|i| img.get(i as usize).copied().unwrap_or(0xFF), &mut out)
            .map(|()| out)
    };
    assert_eq!(decode(&img), Ok(cfg));
    assert_eq!(decode(&[0xFF; 300]), Err(Unusable::Blank));
    let mut other = img.clone();
    other[4] = 5;
    assert_eq!(decode(&other), Err(Unusable::OtherVersion(5)));
    for i in 5..img.len() {
        let mut bad = img.clone();
        bad[i] ^= 0x10;
        assert_eq!(decode(&bad), Err(Unusable::Checksum), "byte {i}");
    }
    // The version-6 firmware drove STEP/DIR drivers, always on: a drum
    // carried over keeps that, not the coils and idle delay of today's
    // drum defaults.
    let drum = MachineConfig::defaults(Machine::Drum);
    let mut was = drum;
    for a in &mut was.axes {
        a.driver = crate::config::Driver::StepDir;
    }
    was.idle_delay_ms = crate::config::KEEP_DRIVERS_ON;
    let img: Vec<u8> = legacy::bytes(&drum).collect();
    assert_eq!(img.len(), 215);
    assert_eq!(decode(&img), Ok(was));
}

#[test]
fn every_setting_is_stored_once() {
    let mut seen: Vec<Setting> = (0..STORED).map(|k| stored(k).unwrap()).collect();
    assert_eq!(stored(STORED), None);
    // Version 6's in its own order (`$$`'s as it was then), whatever
    // `$$` lists since.
    use crate::axis::Axis;
    use crate::settings::{AxisField as A, GlobalField as G};
    for (k, s) in [
        (0, Setting::Global(G::Machine)),
        (1, Setting::Axis(Axis::Base, A::StepsPerUnit)),
        (8, Setting::Axis(Axis::Base, A::TravelMax)),
        (9, Setting::Axis(Axis::Radial, A::StepsPerUnit)),
        (24, Setting::Axis(Axis::Drill, A::TravelMax)),
        (25, Setting::Global(G::StepPulseUs)),
        (47, Setting::Global(G::NeedleDiameter)),
        (48, Setting::Global(G::PenMaxFeed)),
        (49, Setting::Global(G::PenAccel)),
        (50, Setting::Axis(Axis::Base, A::Driver)),
        (52, Setting::Axis(Axis::Drill, A::Driver)),
        (53, Setting::Global(G::StepIdleDelay)),
    ] {
        assert_eq!(seen[k], s, "setting {k}");
    }
    seen.sort_by_key(|s| s.index());
    seen.dedup();
    assert_eq!(seen.len(), crate::settings::COUNT);
    assert!(all().all(|s| seen.contains(&s)));
}

#[test]
fn a_record_written_before_a_setting_was_added_gives_it_the_machines_default() {
    // A whiteboard record as a firmware with only version 6's settings
    // wrote it: the count says 48, zeros after them.
    let mut cfg = MachineConfig::defaults(Machine::Whiteboard);
    set(&mut cfg, "left_max_rate", "1500").unwrap();
    let mut p = payload(&cfg, &Extras::DEFAULT);
    p[0] = V6 as u8;
    let end = named_bytes(V6) + NAMED_AT as usize;
    p[end..].fill(0);
    let got = read(&p).unwrap().0;
    assert_eq!(got, cfg);
    assert_eq!(
        got.pen_accel, 50,
        "the whiteboard's, not the string-art machine's"
    );
    // A newer firmware's record with a setting this one does not know:
    // the known ones are read, the rest left.
    let mut p = payload(&cfg, &Extras::DEFAULT);
    p[0] = STORED as u8 + 1;
    assert_eq!(read(&p).unwrap().0, cfg);
    // A count the room cannot hold.
    p[0] = 200;
    assert_eq!(read(&p), Err(Unusable::Checksum));
}

#[test]
fn a_version_6_image_is_read_with_version_6_settings_only() {
    let mut cfg = MachineConfig::defaults(Machine::Scara);
    set(&mut cfg, "shoulder_accel", "30").unwrap();
    let img: Vec<u8> = legacy::bytes(&cfg).collect();
    assert_eq!(img.len(), 215);
    let mut out = BASE;
    legacy::decode_into(|i| img.get(i as usize).copied().unwrap_or(0xFF), &mut out).unwrap();
    assert_eq!(out, cfg);
    assert_eq!(
        out.pen_max_feed,
        MachineConfig::defaults(Machine::Scara).pen_max_feed
    );
}

#[test]
fn a_record_without_the_driver_settings_keeps_the_drivers_its_firmware_drove() {
    // A drum record as a firmware with the pen's limits but no driver
    // settings wrote it (the count 50): that firmware drove STEP/DIR
    // drivers, always on, not today's drum's coils.
    let mut cfg = MachineConfig::defaults(Machine::Drum);
    set(&mut cfg, "pen_accel", "40").unwrap();
    let pens = V6 + 2;
    let mut p = payload(&cfg, &Extras::DEFAULT);
    p[0] = pens as u8;
    p[named_bytes(pens) + NAMED_AT as usize..].fill(0);
    let mut was = cfg;
    for a in &mut was.axes {
        a.driver = crate::config::Driver::StepDir;
    }
    was.idle_delay_ms = crate::config::KEEP_DRIVERS_ON;
    assert_ne!(was, cfg);
    assert_eq!(read(&p).unwrap().0, was);
    // A whole record keeps the drum's own.
    assert_eq!(read(&payload(&cfg, &Extras::DEFAULT)).unwrap().0, cfg);
}
