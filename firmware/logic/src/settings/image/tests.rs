use super::*;
use crate::settings::grbl::Numbered;
use crate::settings::set;
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
    assert_eq!(NAMED_BYTES, all().map(width).sum::<usize>());
    assert_eq!(read(&p), Ok((cfg, ex)));
    assert_eq!(
        read(&payload(&BASE, &Extras::DEFAULT)),
        Ok((BASE, Extras::DEFAULT))
    );
}

#[test]
fn a_payload_with_a_refused_value_is_refused() {
    // A max rate of 0: the base's, after the machine (4 bytes) and the
    // base's steps per unit (8).
    let mut p = payload(&BASE, &Extras::DEFAULT);
    p[12..16].copy_from_slice(&0u32.to_le_bytes());
    assert!(matches!(read(&p), Err(Unusable::Refused(_))));
    // Each value fine, the set not: a pulse too long for the rate.
    let mut p = payload(&BASE, &Extras::DEFAULT);
    let pulse = 4 + 3 * (8 + 8 * 4);
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
