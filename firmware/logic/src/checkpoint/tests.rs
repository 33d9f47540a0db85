use super::*;
use crate::files::check::FileSum;
use std::vec;
use std::vec::Vec;

fn id(x: u8) -> CardId {
    let mut param = FileSum::new();
    param.add(&[x, 1, 2, 3]);
    let mut poradi = FileSum::new();
    poradi.add(&[3, 2, 1, x]);
    CardId { param, poradi }
}

fn header(seq: u16, phase: Phase) -> Header {
    Header {
        seq,
        phase: Some(phase),
        nails: 24,
        count: 30,
        id: id(7),
    }
}

/// The EEPROM as the firmware's writer leaves it (also the print's
/// checkpoint tests').
pub(super) struct Eeprom(pub(super) Vec<u8>);

impl Eeprom {
    pub(super) fn blank() -> Self {
        Eeprom(vec![0xFF; END as usize])
    }
    pub(super) fn write(&mut self, at: u16, bytes: &[u8]) {
        self.0[at as usize..at as usize + bytes.len()].copy_from_slice(bytes);
    }
    fn header(&mut self, h: Header) {
        self.write(Header::address(h.seq), &h.encode());
    }
    fn record(&mut self, seq: u16, r: Record) {
        self.write(Record::address(r.n), &r.encode(seq));
    }
    pub(super) fn scan(&self) -> Found {
        scan(|a| self.0[a as usize])
    }
}

#[test]
fn crc16_is_ccitt_false() {
    // The standard check value of "123456789".
    assert_eq!(crc16(CRC_START, b"123456789"), 0x29B1);
}

#[test]
fn layout_fits_above_the_settings_and_in_the_eeprom() {
    const { assert!(crate::settings::eeprom::END <= START) };
    assert_eq!(SLOTS, 312);
    const { assert!(RING + SLOTS * RECORD_BYTES <= END) };
}

#[test]
fn header_and_record_round_trip() {
    for phase in [None, Some(Phase::Drilling), Some(Phase::Winding)] {
        let h = Header {
            phase,
            ..header(0xBEEF, Phase::Winding)
        };
        assert_eq!(Header::decode(&h.encode()), Some(h));
    }
    let r = Record {
        n: 1_999_999,
        gap: 311,
    };
    assert_eq!(Record::decode(&r.encode(5), 5), Some(r));
    // Another header's sequence number: not this job's record.
    assert_eq!(Record::decode(&r.encode(5), 6), None);
    assert_eq!(Record::decode(&[0xFF; 8], 5), None);
}

#[test]
fn every_single_bit_flip_is_caught() {
    let h = header(3, Phase::Drilling).encode();
    for bit in 0..h.len() * 8 {
        let mut b = h;
        b[bit / 8] ^= 1 << (bit % 8);
        assert_eq!(Header::decode(&b), None, "header bit {bit}");
    }
    let r = Record { n: 77, gap: 3 }.encode(3);
    for bit in 0..r.len() * 8 {
        let mut b = r;
        b[bit / 8] ^= 1 << (bit % 8);
        assert_eq!(Record::decode(&b, 3), None, "record bit {bit}");
    }
}

#[test]
fn blank_idle_and_a_phase_at_its_start() {
    let mut e = Eeprom::blank();
    assert_eq!(e.scan(), Found::Blank);
    assert_eq!(e.scan().next_seq(), 1);
    e.header(Header::idle(1));
    assert_eq!(e.scan(), Found::Idle { seq: 1 });
    e.header(header(2, Phase::Drilling));
    let Found::Job(s) = e.scan() else { panic!() };
    assert_eq!((s.header.seq, s.last, s.done()), (2, None, 0));
    assert_eq!(e.scan().next_seq(), 3);
}

#[test]
fn the_newest_record_counts_and_the_ring_wraps() {
    let mut e = Eeprom::blank();
    e.header(header(9, Phase::Winding));
    let total = 3 * SLOTS as u32 + 17;
    for n in 1..=total {
        e.record(
            9,
            Record {
                n,
                gap: n as u16 % 24,
            },
        );
        // Scanning is slow in a debug build: near the ends and a sample.
        if n > 40 && n < total - 40 && n % 97 != 0 {
            continue;
        }
        let Found::Job(s) = e.scan() else {
            panic!("after record {n}")
        };
        assert_eq!(s.last.map(|r| r.n), Some(n));
        assert_eq!(s.done(), n / 2);
    }
}

#[test]
fn a_phase_change_retires_the_old_records() {
    let mut e = Eeprom::blank();
    e.header(header(4, Phase::Drilling));
    for n in 1..=24 {
        e.record(4, Record { n, gap: 0 });
    }
    e.header(header(5, Phase::Winding));
    let Found::Job(s) = e.scan() else { panic!() };
    assert_eq!((s.phase(), s.last), (Phase::Winding, None));
    e.record(5, Record { n: 1, gap: 23 });
    let Found::Job(s) = e.scan() else { panic!() };
    assert_eq!(s.last, Some(Record { n: 1, gap: 23 }));
    // The end of the job.
    e.header(Header::idle(6));
    assert_eq!(e.scan(), Found::Idle { seq: 6 });
}

/// A cut at any byte of a record's write: the scan gives the record
/// before it, or the new one once it is whole, never anything else —
/// whatever the torn byte holds (erased, half written).
#[test]
fn torn_record_writes_fall_back_to_the_record_before() {
    for base in [5u32, SLOTS as u32 - 3, 2 * SLOTS as u32 + 100] {
        let mut e = Eeprom::blank();
        e.header(header(11, Phase::Winding));
        for n in 1..=base {
            e.record(11, Record { n, gap: 1 });
        }
        let new = Record {
            n: base + 1,
            gap: 2,
        }
        .encode(11);
        let at = Record::address(base + 1);
        for cut in 0..RECORD_BYTES as usize {
            for torn in [0xFF, 0x00, new[cut] ^ 0x10, new[cut] & 0xF0] {
                let mut t = Eeprom(e.0.clone());
                t.write(at, &new[..cut]);
                t.write(at + cut as u16, &[torn]);
                let Found::Job(s) = t.scan() else {
                    panic!("cut at byte {cut} of record {}", base + 1)
                };
                let n = s.last.unwrap().n;
                let whole = cut == RECORD_BYTES as usize - 1 && torn == new[cut];
                assert_eq!(n, if whole { base + 1 } else { base }, "cut {cut}");
            }
        }
    }
}

/// A cut in a header's write leaves the other header, with its records.
#[test]
fn torn_header_writes_keep_the_older_header() {
    let mut e = Eeprom::blank();
    e.header(header(20, Phase::Drilling));
    for n in 1..=10 {
        e.record(20, Record { n, gap: 0 });
    }
    let new = header(21, Phase::Winding).encode();
    for cut in 0..HEADER_BYTES as usize {
        let mut t = Eeprom(e.0.clone());
        t.write(Header::address(21), &new[..cut]);
        t.write(Header::address(21) + cut as u16, &[new[cut] ^ 0x80]);
        let Found::Job(s) = t.scan() else { panic!() };
        assert_eq!((s.header.seq, s.done()), (20, 10), "cut at {cut}");
    }
    // Sequence numbers wrap.
    let mut e = Eeprom::blank();
    e.header(header(0xFFFF, Phase::Drilling));
    e.header(header(0, Phase::Winding));
    let Found::Job(s) = e.scan() else { panic!() };
    assert_eq!(s.header.seq, 0);
}

/// Bit flips that a torn write cannot explain: the checkpoint is not used.
#[test]
fn corrupt_checkpoints_are_never_trusted() {
    let mut e = Eeprom::blank();
    e.header(header(30, Phase::Winding));
    for n in 1..=60 {
        e.record(30, Record { n, gap: 4 });
    }
    // A record in the middle.
    let mut t = Eeprom(e.0.clone());
    t.0[Record::address(30) as usize + 2] ^= 0x04;
    assert_eq!(t.scan(), Found::Corrupt { seq: 30 });
    // A valid record in the wrong slot.
    let mut t = Eeprom(e.0.clone());
    t.write(Record::address(12), &Record { n: 13, gap: 4 }.encode(30));
    assert_eq!(t.scan(), Found::Corrupt { seq: 30 });
    // Both headers.
    let mut t = Eeprom(e.0.clone());
    t.0[START as usize + 3] ^= 1;
    t.0[(START + HEADER_BYTES) as usize + 9] ^= 0x40;
    assert_eq!(t.scan(), Found::Corrupt { seq: 0 });
    assert_eq!(t.scan().next_seq(), 1);
}

#[test]
fn wear_of_a_3000_wrap_job() {
    // 300 holes and 3000 wraps: 6 300 records over 312 slots.
    assert_eq!(cell_writes_per_job(300, 3000), 1 + 20);
    assert_eq!(jobs_before_wear_out(300, 3000, 100_000), 4761);
    assert_eq!(byte_writes_per_job(300, 3000), 6300 * 8 + 96);
    // A 10 000-wrap job still leaves a thousand jobs and more.
    assert_eq!(jobs_before_wear_out(300, 10_000, 100_000), 1515);
}
