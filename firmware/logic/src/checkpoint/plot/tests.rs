use super::super::tests::Eeprom;
use super::super::{Found, Header, Record};
use super::*;
use crate::stringart::Phase;
use std::eprintln;
use std::vec::Vec;

const SHORT: [u8; 11] = *b"STARDR~1GCO";

fn header(seq: u16) -> PlotHeader {
    PlotHeader {
        seq,
        short: SHORT,
        size: 2316,
        at: [-4_000, 123_456],
    }
}

/// The print's header and records into the string-art tests' EEPROM.
trait Plot {
    fn header(&mut self, h: PlotHeader);
    fn record(&mut self, seq: u16, r: PlotRecord);
}

impl Plot for Eeprom {
    fn header(&mut self, h: PlotHeader) {
        self.write(Header::address(h.seq), &h.encode());
    }
    fn record(&mut self, seq: u16, r: PlotRecord) {
        self.write(PlotRecord::address(r.n), &r.encode(seq));
    }
}

#[test]
fn header_and_record_round_trip_and_a_flipped_bit_fails() {
    let h = header(7);
    assert_eq!(PlotHeader::decode(&h.encode()), Some(h));
    // A string-art header is not a print's, nor the other way round.
    assert_eq!(Header::decode(&h.encode()), None);
    assert_eq!(PlotHeader::decode(&Header::idle(7).encode()), None);
    let r = PlotRecord {
        n: 513,
        pos: 98_765,
        done: 4321,
        at: [-123_456, 7_890_123],
    };
    assert_eq!(PlotRecord::decode(&r.encode(7), 7), Some(r));
    // Under another header's number it is stale.
    assert_eq!(PlotRecord::decode(&r.encode(7), 8), None);
    for bit in 0..144 {
        let mut b = r.encode(7);
        b[bit / 8] ^= 1 << (bit % 8);
        assert_eq!(PlotRecord::decode(&b, 7), None, "bit {bit}");
        let mut b = h.encode();
        b[bit / 8] ^= 1 << (bit % 8);
        assert_eq!(PlotHeader::decode(&b), None, "bit {bit}");
    }
}

#[test]
fn a_print_with_no_record_goes_on_from_the_file_s_start() {
    let mut e = Eeprom::blank();
    e.header(header(3));
    let Found::Plot(p) = e.scan() else {
        panic!("{:?}", e.scan())
    };
    assert_eq!(
        (p.header, p.last, p.pos(), p.next_n()),
        (header(3), None, 0, 1)
    );
    assert_eq!(e.scan().next_seq(), 4);
}

#[test]
fn the_newest_record_wins_across_laps_of_the_ring_and_number_wraps() {
    let mut e = Eeprom::blank();
    e.header(header(9));
    // Three laps and a bit, numbers wrapping past u16::MAX.
    let start = u16::MAX - 2 * PLOT_SLOTS;
    let mut n = start;
    for k in 0..(3 * PLOT_SLOTS as u32 + 17) {
        let r = PlotRecord {
            n,
            pos: 1000 + k,
            done: k as u16,
            at: [0, 0],
        };
        e.record(9, r);
        let Found::Plot(p) = e.scan() else { panic!() };
        assert_eq!(p.last, Some(r));
        assert_eq!((p.pos(), p.done()), (1000 + k, k as u16));
        assert_eq!(p.next_n(), n.wrapping_add(1));
        n = n.wrapping_add(1);
    }
}

#[test]
fn a_record_torn_at_any_byte_leaves_the_one_before() {
    for torn in 0..PLOT_RECORD_BYTES as usize {
        for erased in [0xFF, 0x00] {
            let mut e = Eeprom::blank();
            e.header(header(1));
            for n in 1..=(PLOT_SLOTS + 4) {
                e.record(
                    1,
                    PlotRecord {
                        n,
                        pos: 10 * n as u32,
                        done: n,
                        at: [0, 0],
                    },
                );
            }
            let next = PlotRecord {
                n: PLOT_SLOTS + 5,
                pos: 99_999,
                done: 7,
                at: [0, 0],
            };
            let mut b = next.encode(1);
            // The bytes from `torn` on were not written (the slot held
            // record 5's); the torn one holds `erased`.
            let old = PlotRecord {
                n: 5,
                pos: 50,
                done: 5,
                at: [0, 0],
            }
            .encode(1);
            b[torn] = erased;
            b[torn + 1..].copy_from_slice(&old[torn + 1..]);
            e.write(PlotRecord::address(next.n), &b);
            let Found::Plot(p) = e.scan() else { panic!() };
            let before = PLOT_SLOTS + 4;
            assert_eq!(
                (p.pos(), p.done()),
                (10 * before as u32, before),
                "torn at {torn}"
            );
        }
    }
}

#[test]
fn a_new_header_hides_the_last_print_s_records_and_an_idle_one_ends_it() {
    let mut e = Eeprom::blank();
    e.header(header(1));
    e.record(
        1,
        PlotRecord {
            n: 1,
            pos: 400,
            done: 0,
            at: [0, 0],
        },
    );
    e.header(header(2));
    let Found::Plot(p) = e.scan() else { panic!() };
    assert_eq!(p.last, None);
    e.write(Header::address(3), &Header::idle(3).encode());
    assert_eq!(e.scan(), Found::Idle { seq: 3 });
    // A string-art job after it still reads as a job.
    let job = Header {
        seq: 4,
        phase: Some(Phase::Winding),
        nails: 12,
        count: 30,
        id: Default::default(),
    };
    e.write(Header::address(4), &job.encode());
    e.write(Record::address(1), &Record { n: 1, gap: 3 }.encode(4));
    assert!(matches!(e.scan(), Found::Job(s) if s.header == job));
}

#[test]
fn a_header_torn_mid_write_leaves_the_older_one() {
    for torn in 0..HEADER_BYTES as usize {
        let mut e = Eeprom::blank();
        e.write(Header::address(5), &Header::idle(5).encode());
        let mut b = header(6).encode();
        for x in &mut b[torn..] {
            *x = 0xFF;
        }
        e.write(Header::address(6), &b);
        let whole = b == header(6).encode();
        match e.scan() {
            Found::Plot(p) => assert!(whole && p.header == header(6), "torn at {torn}"),
            found => assert_eq!(found, Found::Idle { seq: 5 }, "torn at {torn}"),
        }
    }
}

#[test]
fn the_record_names_a_line_only_once_its_first_block_has_begun() {
    // 250 blocks begun so far, 10 queued: the line at byte 100 (3 blocks)
    // has first block 260 = 4 after wrapping.
    let mut begun = 250u8;
    let first = begun.wrapping_add(10);
    let mut t = Tracker::new();
    t.line(100, first);
    for _ in 0..10 {
        assert_eq!(t.due(begun, false, false, 700), None);
        begun = begun.wrapping_add(1);
    }
    // Its first block begins now (the count wraps past 255).
    assert_eq!(t.due(begun, false, false, 700), None);
    begun = begun.wrapping_add(1);
    assert_eq!(t.due(begun, false, true, 700), None, "the last write first");
    assert_eq!(
        t.due(begun, false, false, 700),
        Some(PlotRecord {
            n: 1,
            pos: 100,
            done: 0,
            at: [0, 0],
        })
    );
    assert_eq!(t.due(begun, false, false, 700), None);
}

/// A print's lines through a planner `depth` blocks deep, one block
/// each, `ms` each: the line moving when each record is asked for, and
/// the record.
fn run(depth: u8, ms: u32, lines: u32) -> Vec<(u32, PlotRecord)> {
    let mut t = Tracker::resuming(&PlotSaved {
        header: header(1),
        last: Some(PlotRecord {
            n: 40,
            pos: 0,
            done: 0,
            at: [0, 0],
        }),
    });
    assert_eq!(t.resume_at(), 0);
    let mut out = Vec::new();
    let (mut read, mut begun) = (0u32, 0u8);
    for moving in 0..lines {
        // The line `moving` begins: the reader keeps `depth` ahead.
        begun = begun.wrapping_add(1);
        while read < (moving + u32::from(depth)).min(lines) {
            t.line(read * 30, read as u8);
            read += 1;
        }
        if let Some(r) = t.due(begun, false, false, 1000 + moving * ms) {
            out.push((moving, r));
        }
    }
    out
}

#[test]
fn records_come_no_oftener_than_the_wear_limit_and_name_a_line_just_begun() {
    // Short lines, 20 ms each, 12 blocks ahead.
    let out = run(12, 20, 400);
    assert!(out.len() >= 14, "{out:?}");
    for w in out.windows(2) {
        assert!(20 * (w[1].0 - w[0].0) >= RECORD_EVERY_MS, "{out:?}");
        assert_eq!(w[1].1.n, w[0].1.n + 1);
    }
    assert_eq!(
        out[0].1,
        PlotRecord {
            n: 41,
            pos: 0,
            done: 0,
            at: [0, 0],
        }
    );
    // One block a line: the block named is the line's number and the
    // blocks drawn after its start (lines not followed among them).
    for (moving, r) in &out {
        let block = r.pos / 30 + u32::from(r.done);
        assert!(block <= *moving && moving - block <= 1, "{out:?}");
    }
    // A cell is written once a lap of the ring: two hours of printing a
    // day for over two years before the datasheet's 100 000 writes.
    assert!(
        hours_before_wear_out(100_000) >= 1800,
        "{}",
        hours_before_wear_out(100_000)
    );
}

#[test]
fn long_lines_are_recorded_as_each_begins() {
    // Two seconds a line, 14 blocks in flight: each line moving is
    // recorded, or the one before it.
    let out = run(14, 2000, 60);
    assert!(out.len() >= 30, "{out:?}");
    let exact = out.iter().filter(|(m, r)| r.pos == m * 30).count();
    for (moving, r) in &out {
        let block = r.pos / 30 + u32::from(r.done);
        assert!(block <= *moving && moving - block <= 1, "{out:?}");
    }
    eprintln!("{exact} of {} records name the line moving", out.len());
}

#[test]
fn a_line_that_queues_nothing_gives_its_place_to_the_next_one() {
    let mut t = Tracker::new();
    // `M3` at byte 50, nothing queued ahead: its "first block" is the
    // next line's (byte 53), which stands for it.
    t.line(50, 7);
    t.line(53, 7);
    // Too far after the oldest: not followed.
    t.line(53 + 70_000, 9);
    assert_eq!(t.due(7, false, false, 600), None);
    assert_eq!(
        t.due(8, false, false, 600),
        Some(PlotRecord {
            n: 1,
            pos: 53,
            done: 0,
            at: [0, 0],
        })
    );
    // A line read once every block is begun and none is queued has the
    // same number the moving line's count stands at: followed on its own.
    t.line(60, 8);
    assert_eq!(t.due(9, false, false, 1200).map(|r| r.pos), Some(60));
}

#[test]
fn a_long_line_s_blocks_drawn_are_counted_past_the_numbers_wrap() {
    // An arc of 700 chords at byte 200 (blocks 5…704), then a line at
    // byte 260; the planner 16 blocks ahead.
    let mut t = Tracker::new();
    t.line(120, 3);
    t.line(200, 5);
    let mut out = Vec::new();
    let mut begun = 0u8;
    for b in 1..=704u32 {
        begun = begun.wrapping_add(1);
        if b + 16 == 705 {
            t.line(260, 705u32 as u8);
        }
        if let Some(r) = t.due(begun, false, false, b * 10) {
            out.push((b, r));
        }
    }
    assert!(out.len() >= 12, "{out:?}");
    for (b, r) in &out {
        // Block `b` begun (numbered b - 1): blocks 5…b - 2 are drawn.
        assert_eq!((r.pos, u32::from(r.done)), (200, b - 6), "{out:?}");
    }
    // The last chord begins; records while it moves; then, standing, no
    // record however long.
    begun = begun.wrapping_add(1);
    let r = t.due(begun, false, false, 9_000).unwrap();
    assert_eq!((r.pos, r.done), (200, 699));
    assert_eq!(t.due(begun, true, false, 9_400), None);
    let r = t.due(begun, true, false, 9_500).unwrap();
    assert_eq!((r.pos, r.done), (200, 699));
    assert_eq!(t.due(begun, false, false, 10_000), None);
    assert_eq!(t.due(begun, false, false, 60_000), None);
    // The next line begins.
    begun = begun.wrapping_add(1);
    let r = t.due(begun, false, false, 61_000).unwrap();
    assert_eq!((r.pos, r.done), (260, 0));
}

#[test]
fn resume_homes_opens_replays_the_lines_before_then_travels_and_pens() {
    use ResumeAction as A;
    use ResumeEvent as E;
    let at = 120;
    let mut s = Some(Resume::Offered);
    let mut did = Vec::new();
    let events = [
        E::Homed, // not asked: nothing
        E::Take { homes: true },
        E::Homed,
        E::Opened,
        E::Line(0), // placed
        E::Line(0),
        E::Line(40),
        E::Line(119),
        E::Line(120),
        E::Line(140), // held: nothing until the travel is done
        E::Done,
        E::Done,
    ];
    for e in events {
        let (next, a) = s.unwrap().on(e, at);
        did.push(a);
        s = next;
    }
    assert_eq!(
        did,
        [
            A::None,
            A::Home,
            A::Open,
            A::None,
            A::Place,
            A::Check,
            A::Check,
            A::Check,
            A::Travel,
            A::None,
            A::Pen,
            A::Go
        ]
    );
    assert_eq!(s, None);
    // No switches: straight to the file; from the start: no line checked.
    assert_eq!(
        Resume::Offered.on(E::Take { homes: false }, 0),
        (Some(Resume::Opening), A::Open)
    );
    assert_eq!(
        Resume::Replaying.on(E::Line(0), 0),
        (Some(Resume::Travel), A::Travel)
    );
    assert_eq!(Resume::Offered.on(E::Discard, at), (None, A::Forget));
}
