use super::*;
use crate::settings::set;
use std::vec;
use std::vec::Vec;

const BASE: MachineConfig = MachineConfig::STRING_ART;

fn image(cfg: &MachineConfig) -> Vec<u8> {
    bytes(cfg).collect()
}

fn read(img: &[u8]) -> Result<MachineConfig, Unusable> {
    decode(|i| img[i], &BASE)
}

#[test]
fn an_image_reads_back_as_the_settings_it_was_made_of() {
    let mut cfg = BASE;
    set(&mut cfg, "base_max_rate", "1500").unwrap();
    set(&mut cfg, "drill_steps_per_unit", "1600/10").unwrap();
    set(&mut cfg, "radial_travel_min", "-201.5").unwrap();
    set(&mut cfg, "step_pulse_us", "7").unwrap();
    let img = image(&cfg);
    assert_eq!(img.len(), len());
    assert_eq!(len(), HEADER + all().map(width).sum::<usize>() + 2);
    assert_eq!(&img[..4], b"taut");
    assert_eq!(read(&img), Ok(cfg));
    assert_eq!(read(&image(&BASE)), Ok(BASE));
}

#[test]
fn blank_other_and_corrupt_images_give_reasons_not_garbage() {
    assert_eq!(read(&[0xFF; 512]), Err(Unusable::Blank));
    let mut img = image(&BASE);
    img[4] = VERSION + 1;
    assert_eq!(read(&img), Err(Unusable::OtherVersion(VERSION + 1)));
    // Any single byte changed, or two swapped, is caught.
    let good = image(&BASE);
    for i in 5..good.len() {
        let mut bad = good.clone();
        bad[i] ^= 0x10;
        assert_eq!(read(&bad), Err(Unusable::Checksum), "byte {i}");
    }
    let mut swapped = good.clone();
    swapped.swap(10, 20);
    assert_eq!(read(&swapped), Err(Unusable::Checksum));
    // A cut mid-write: the first half new, the rest old.
    let mut new = BASE;
    set(&mut new, "base_accel", "750").unwrap();
    let newer = image(&new);
    let mut half: Vec<u8> = newer[..30].to_vec();
    half.extend_from_slice(&good[30..]);
    assert_ne!(half, good);
    assert_eq!(read(&half), Err(Unusable::Checksum));
}

#[test]
fn a_consistent_image_with_a_refused_value_is_refused() {
    // Hand-made: a max rate of 0, with a checksum that matches.
    let mut body: Vec<u8> = image(&BASE);
    body.truncate(len() - 2);
    let at = 5 + 8; // base_max_rate follows base_steps_per_unit (8 bytes)
    body[at..at + 4].copy_from_slice(&0u32.to_le_bytes());
    let mut sum = Fletcher::new();
    body.iter().for_each(|&b| sum.add(b));
    body.extend_from_slice(&sum.value().to_le_bytes());
    assert!(matches!(read(&body), Err(Unusable::Refused(_))));
    // In place: a refused value leaves every setting as it was, those
    // before it in the image too.
    let mut cfg = BASE;
    set(&mut cfg, "radial_accel", "321").unwrap();
    let before = cfg;
    let found = decode_into(|i| body[i], &mut cfg);
    assert!(matches!(found, Err(Unusable::Refused(_))));
    assert_eq!(cfg, before);
    assert_eq!(decode_into(|i| image(&before)[i], &mut cfg), Ok(()));
    assert_eq!(cfg, before);
}

#[test]
fn the_machine_and_its_geometry_are_kept() {
    let mut cfg = BASE;
    set(&mut cfg, "machine", "scara").unwrap();
    set(&mut cfg, "length_2", "120").unwrap();
    set(&mut cfg, "crosstalk", "62/20").unwrap();
    set(&mut cfg, "elbow_max_rate", "1500").unwrap();
    assert_eq!(read(&image(&cfg)), Ok(cfg));
    // A machine number no firmware has: refused whole.
    let mut img = image(&cfg);
    img[HEADER] = 9;
    let n = img.len();
    let mut sum = Fletcher::new();
    img[..n - 2].iter().for_each(|&b| sum.add(b));
    img[n - 2..].copy_from_slice(&sum.value().to_le_bytes());
    assert!(matches!(read(&img), Err(Unusable::Refused(_))));
}

/// What `bytes` says differs first, the slow way.
fn first_difference_by_bytes(cfg: &MachineConfig, eeprom: &[u8]) -> Option<(usize, u8)> {
    bytes(cfg).enumerate().find(|&(i, b)| eeprom[i] != b)
}

/// A scan run to its first difference (or its end), `parts` at a time.
fn first_difference(cfg: &MachineConfig, eeprom: &[u8], parts: u8) -> Option<(usize, u8)> {
    let mut scan = Scan::new();
    loop {
        match scan.step(cfg, |i| eeprom[i], parts) {
            Step::Write(i, b) => return Some((i, b)),
            Step::More => {}
            Step::Same => return None,
        }
    }
}

#[test]
fn the_first_difference_is_the_image_s_and_writing_it_converges() {
    use crate::machine::Machine;
    let mut tuned = BASE;
    set(&mut tuned, "base_max_rate", "1500").unwrap();
    set(&mut tuned, "step_pulse_us", "7").unwrap();
    let configs: Vec<MachineConfig> = Machine::ALL
        .into_iter()
        .map(MachineConfig::defaults)
        .chain([tuned])
        .collect();
    for cfg in &configs {
        let mut eeproms = vec![vec![0xFF; len()], image(&BASE), image(cfg)];
        for i in 0..len() {
            let mut flipped = image(cfg);
            flipped[i] ^= 0x41;
            eeproms.push(flipped);
        }
        for (k, mut eeprom) in eeproms.into_iter().enumerate() {
            let want = first_difference_by_bytes(cfg, &eeprom);
            for parts in [1, 3, u8::MAX] {
                assert_eq!(first_difference(cfg, &eeprom, parts), want);
            }
            // The store task: a bounded part a run, resumed, writing each
            // difference as it comes, until they agree.
            let mut scan = Scan::new();
            let (mut writes, mut runs) = (0, 0);
            loop {
                match scan.step(cfg, |i| eeprom[i], 1 + k as u8 % 4) {
                    Step::Write(i, b) => {
                        eeprom[i] = b;
                        writes += 1;
                    }
                    Step::More => {}
                    Step::Same => break,
                }
                runs += 1;
                assert!(writes <= len() && runs < 10 * len(), "never converges");
            }
            assert_eq!(eeprom, image(cfg));
            assert_eq!(scan.step(cfg, |i| eeprom[i], 1), Step::Same);
        }
    }
}
