//! The card byte by byte, as the specification's SPI mode describes it.

use super::crc::{crc16, crc7};
use super::*;

/// A card of `blocks` blocks, block n filled with n as bytes.
fn card(kind: CardKind, blocks: u32) -> SdCard {
    let bytes = (0..blocks)
        .flat_map(|n| (0..BLOCK).map(move |i| (n as usize * 7 + i) as u8))
        .collect();
    let config = SdConfig {
        kind,
        ..SdConfig::default()
    };
    SdCard::with_config(SdImage::from_bytes(bytes), config)
}

fn frame(index: u8, arg: u32) -> [u8; 6] {
    let mut f = [0x40 | index, 0, 0, 0, 0, 0];
    f[1..5].copy_from_slice(&arg.to_be_bytes());
    f[5] = crc7(&f[..5]) << 1 | 1;
    f
}

fn send(card: &mut SdCard, bytes: &[u8]) -> Vec<u8> {
    bytes.iter().map(|&b| card.exchange(b, true)).collect()
}

fn read(card: &mut SdCard, n: usize) -> Vec<u8> {
    send(card, &vec![0xFF; n])
}

/// The first byte with bit 7 clear within `limit` bytes.
fn response(card: &mut SdCard, limit: usize) -> Option<u8> {
    (0..limit)
        .map(|_| card.exchange(0xFF, true))
        .find(|b| b & 0x80 == 0)
}

fn command(card: &mut SdCard, index: u8, arg: u32) -> u8 {
    send(card, &frame(index, arg));
    response(card, 8).unwrap_or_else(|| panic!("no answer to CMD{index}"))
}

fn acmd(card: &mut SdCard, index: u8, arg: u32) -> u8 {
    command(card, 55, 0);
    command(card, index, arg)
}

fn init(card: &mut SdCard) {
    assert_eq!(command(card, 0, 0), R1_IDLE);
    assert_eq!(command(card, 8, 0x1AA), R1_IDLE);
    read(card, 4);
    while acmd(card, 41, 1 << 30) != 0 {}
}

/// The data block after a read command: (token, data, CRC).
fn data_block(card: &mut SdCard, len: usize) -> (u8, Vec<u8>, u16) {
    let token = (0..100)
        .map(|_| card.exchange(0xFF, true))
        .find(|&b| b != 0xFF)
        .expect("a token");
    let data = read(card, len);
    let crc = read(card, 2);
    (token, data, u16::from_be_bytes([crc[0], crc[1]]))
}

#[test]
fn before_cmd0_only_cmd0_is_heard_and_deselected_bytes_are_ignored() {
    let mut c = card(CardKind::Sdsc, 16);
    send(&mut c, &frame(8, 0x1AA));
    assert_eq!(response(&mut c, 16), None);
    for &b in &frame(0, 0) {
        assert_eq!(c.exchange(b, false), 0xFF);
    }
    assert_eq!(read(&mut c, 16), vec![0xFF; 16]);
    assert_eq!(command(&mut c, 0, 0), R1_IDLE);
    assert_eq!(c.stats().bytes_deselected, 6);
    assert_eq!(c.stats().cmd(0), 1);
}

#[test]
fn cmd0_and_cmd8_crc_is_always_checked() {
    let mut c = card(CardKind::Sdsc, 16);
    let mut bad = frame(0, 0);
    bad[5] ^= 0x02;
    send(&mut c, &bad);
    assert_eq!(response(&mut c, 8), Some(R1_IDLE | R1_CRC));
    assert_eq!(command(&mut c, 0, 0), R1_IDLE);
    let mut bad = frame(8, 0x1AA);
    bad[5] ^= 0x02;
    send(&mut c, &bad);
    assert_eq!(response(&mut c, 8), Some(R1_IDLE | R1_CRC));
    assert_eq!(c.stats().crc_errors, 2);
}

#[test]
fn cmd8_echoes_voltage_and_check_pattern() {
    let mut c = card(CardKind::Sdsc, 16);
    command(&mut c, 0, 0);
    assert_eq!(command(&mut c, 8, 0x1AA), R1_IDLE);
    assert_eq!(read(&mut c, 4), [0, 0, 1, 0xAA]);
    assert_eq!(command(&mut c, 8, 0x25C), R1_IDLE);
    assert_eq!(read(&mut c, 4), [0, 0, 0, 0x5C], "2 is no voltage range");
}

#[test]
fn acmd41_answers_idle_the_configured_number_of_times() {
    let config = SdConfig {
        kind: CardKind::Sdhc,
        init_polls: 3,
        ..SdConfig::default()
    };
    let mut c = SdCard::with_config(SdImage::blank(64), config);
    command(&mut c, 0, 0);
    let answers: Vec<u8> = (0..5).map(|_| acmd(&mut c, 41, 1 << 30)).collect();
    assert_eq!(answers, [1, 1, 1, 0, 0]);
    assert!(c.is_ready());
    assert_eq!(c.stats().acmd(41), 5);
    assert_eq!(c.stats().cmd(55), 5);
    // CMD0 starts over; a host without HCS never gets an SDHC card ready.
    command(&mut c, 0, 0);
    assert!((0..10).all(|_| acmd(&mut c, 41, 0) == R1_IDLE));
}

#[test]
fn cmd58_reports_power_up_and_capacity_status() {
    for (kind, ccs) in [(CardKind::Sdsc, 0x80), (CardKind::Sdhc, 0xC0)] {
        let mut c = card(kind, 16);
        command(&mut c, 0, 0);
        assert_eq!(command(&mut c, 58, 0), R1_IDLE);
        assert_eq!(read(&mut c, 4), [0x00, 0xFF, 0x80, 0x00]);
        init(&mut c);
        assert_eq!(command(&mut c, 58, 0), 0);
        assert_eq!(read(&mut c, 4), [ccs, 0xFF, 0x80, 0x00], "{kind:?}");
    }
    assert!(!card(CardKind::Auto, 16).is_sdhc());
}

#[test]
fn illegal_commands_and_data_commands_before_init() {
    let mut c = card(CardKind::Sdsc, 16);
    command(&mut c, 0, 0);
    assert_eq!(command(&mut c, 17, 0), R1_IDLE | R1_ILLEGAL);
    init(&mut c);
    assert_eq!(command(&mut c, 5, 0), R1_ILLEGAL);
    assert_eq!(acmd(&mut c, 6, 0), R1_ILLEGAL);
    assert_eq!(command(&mut c, 16, 1024), R1_PARAMETER);
    assert_eq!(command(&mut c, 16, 512), 0);
}

#[test]
fn responses_wait_ncr_bytes() {
    for ncr in [1, 8] {
        let config = SdConfig {
            ncr,
            ..SdConfig::default()
        };
        let mut c = SdCard::with_config(SdImage::blank(8), config);
        let echo = send(&mut c, &frame(0, 0));
        assert_eq!(echo, [0xFF; 6]);
        let mut answer = read(&mut c, usize::from(ncr) + 1);
        assert_eq!(answer.pop(), Some(R1_IDLE));
        assert!(answer.iter().all(|&b| b == 0xFF));
    }
}

#[test]
fn single_block_read_in_both_addressings() {
    for (kind, arg) in [(CardKind::Sdsc, 5 * 512), (CardKind::Sdhc, 5)] {
        let mut c = card(kind, 16);
        init(&mut c);
        assert_eq!(command(&mut c, 17, arg), 0);
        let (token, data, crc) = data_block(&mut c, BLOCK);
        assert_eq!(token, TOKEN_START);
        assert_eq!(data, c.image().block(5));
        assert_eq!(crc, crc16(&data));
        assert_eq!(read(&mut c, 4), [0xFF; 4], "idle after the block");
        assert_eq!(c.stats().blocks_read, 1);
    }
    let mut c = card(CardKind::Sdsc, 16);
    init(&mut c);
    assert_eq!(command(&mut c, 17, 100), R1_ADDRESS, "not block aligned");
    assert_eq!(command(&mut c, 17, 16 * 512), R1_PARAMETER, "past the end");
}

#[test]
fn multiple_block_read_until_cmd12() {
    let mut c = card(CardKind::Sdhc, 16);
    init(&mut c);
    assert_eq!(command(&mut c, 18, 3), 0);
    for n in 3..6 {
        let (token, data, crc) = data_block(&mut c, BLOCK);
        assert_eq!((token, crc), (TOKEN_START, crc16(&data)));
        assert_eq!(data, c.image().block(n));
    }
    // The card streams on while CMD12 arrives; then a stuff byte, NCR, R1
    // and busy.
    send(&mut c, &frame(12, 0));
    read(&mut c, 1);
    assert_eq!(response(&mut c, 8), Some(0));
    let busy = read(&mut c, 8);
    assert_eq!(busy[0], 0x00);
    assert_eq!(busy[7], 0xFF);
    assert_eq!(c.stats().blocks_read, 3, "a block cut short is not counted");
}

#[test]
fn multiple_block_read_off_the_end_gets_an_out_of_range_token() {
    let mut c = card(CardKind::Sdhc, 1024);
    init(&mut c);
    assert_eq!(command(&mut c, 18, 1023), 0);
    assert_eq!(data_block(&mut c, BLOCK).0, TOKEN_START);
    assert_eq!(data_block(&mut c, 0).0, 0x08);
}

fn write_block(c: &mut SdCard, token: u8, data: &[u8], crc: u16) -> u8 {
    send(c, &[0xFF, token]);
    send(c, data);
    send(c, &crc.to_be_bytes());
    let response = read(c, 1)[0] & 0x1F;
    while read(c, 1)[0] != 0xFF {}
    response
}

#[test]
fn single_and_multiple_block_writes() {
    let mut c = card(CardKind::Sdsc, 16);
    init(&mut c);
    let data = [0xA5; BLOCK];
    assert_eq!(command(&mut c, 24, 2 * 512), 0);
    assert_eq!(write_block(&mut c, TOKEN_START, &data, 0), DATA_ACCEPTED);
    assert_eq!(c.image().block(2), data);
    assert_eq!(command(&mut c, 13, 0), 0);
    assert_eq!(read(&mut c, 1), [0]);
    assert_eq!(command(&mut c, 25, 7 * 512), 0);
    for fill in [1u8, 2] {
        let block = [fill; BLOCK];
        assert_eq!(
            write_block(&mut c, TOKEN_MULTI_WRITE, &block, 0),
            DATA_ACCEPTED
        );
    }
    send(&mut c, &[TOKEN_STOP_TRAN, 0xFF]);
    assert_eq!(read(&mut c, 1), [0x00], "busy after the stop token");
    while read(&mut c, 1)[0] != 0xFF {}
    assert_eq!((c.image().block(7)[0], c.image().block(8)[0]), (1, 2));
    assert_eq!(
        c.image().block(9),
        card(CardKind::Sdsc, 16).image().block(9)
    );
    assert_eq!(c.stats().blocks_written, 3);
}

#[test]
fn with_crc_on_bad_frames_and_bad_blocks_are_rejected() {
    let mut c = card(CardKind::Sdhc, 16);
    init(&mut c);
    assert_eq!(command(&mut c, 59, 1), 0);
    let mut bad = frame(17, 0);
    bad[5] ^= 0x10;
    send(&mut c, &bad);
    assert_eq!(response(&mut c, 8), Some(R1_CRC));
    let before = c.image().block(1);
    let data = [0x3C; BLOCK];
    assert_eq!(command(&mut c, 24, 1), 0);
    assert_eq!(
        write_block(&mut c, TOKEN_START, &data, 0x1234),
        DATA_CRC_ERROR
    );
    assert_eq!(c.image().block(1), before);
    assert_eq!(command(&mut c, 24, 1), 0);
    assert_eq!(
        write_block(&mut c, TOKEN_START, &data, crc16(&data)),
        DATA_ACCEPTED
    );
    assert_eq!(c.image().block(1), data);
    assert_eq!(c.stats().crc_errors, 2);
    // With CRC off again any CRC goes.
    assert_eq!(command(&mut c, 59, 0), 0);
    send(&mut c, &bad);
    assert_eq!(response(&mut c, 8), Some(0));
}

#[test]
fn registers_read_as_data_blocks() {
    let mut c = card(CardKind::Sdhc, 4096);
    init(&mut c);
    assert_eq!(command(&mut c, 9, 0), 0);
    let (token, csd, crc) = data_block(&mut c, 16);
    assert_eq!((token, crc), (TOKEN_START, crc16(&csd)));
    assert_eq!(csd[0] >> 6, 1, "CSD version 2");
    let c_size = u32::from_be_bytes([0, csd[7] & 0x3F, csd[8], csd[9]]);
    assert_eq!((c_size + 1) * 1024, 4096);
    assert_eq!(c.capacity_blocks(), 4096);
    assert_eq!(command(&mut c, 10, 0), 0);
    let (_, cid, _) = data_block(&mut c, 16);
    assert_eq!(&cid[3..8], b"TAUT1");
    assert_eq!(cid[15], crc7(&cid[..15]) << 1 | 1);
}

#[test]
fn failing_blocks_answer_an_error_token_or_nothing() {
    let mut c = card(CardKind::Sdhc, 16);
    init(&mut c);
    c.fail_read(4);
    c.fail_read_with(6, ReadFault::NoToken);
    assert_eq!(command(&mut c, 17, 4), 0);
    assert_eq!(data_block(&mut c, 0).0, 0x04);
    assert_eq!(command(&mut c, 17, 6), 0);
    assert_eq!(read(&mut c, 2000), vec![0xFF; 2000]);
    assert_eq!(command(&mut c, 17, 5), 0, "other blocks still read");
    assert_eq!(data_block(&mut c, BLOCK).0, TOKEN_START);
    assert_eq!(c.stats().blocks_read, 1);
}

#[test]
fn timeouts_and_corrupt_crc_hit_only_the_next_ones() {
    let mut c = card(CardKind::Sdhc, 16);
    init(&mut c);
    c.timeout_next(2);
    for _ in 0..2 {
        send(&mut c, &frame(13, 0));
        assert_eq!(response(&mut c, 64), None);
    }
    assert_eq!(command(&mut c, 13, 0), 0);
    read(&mut c, 1);
    c.corrupt_crc_next();
    for corrupt in [true, false] {
        command(&mut c, 17, 2);
        let (_, data, crc) = data_block(&mut c, BLOCK);
        assert_eq!(crc != crc16(&data), corrupt);
    }
}

#[test]
fn a_card_pulled_mid_block_goes_silent() {
    let mut c = card(CardKind::Sdhc, 16);
    init(&mut c);
    c.remove_during_transfer();
    assert_eq!(command(&mut c, 13, 0), 0, "commands without data go on");
    read(&mut c, 1);
    assert_eq!(command(&mut c, 17, 1), 0);
    let (token, data, _) = data_block(&mut c, BLOCK);
    assert_eq!(token, TOKEN_START);
    assert_eq!(data[..255], c.image().block(1)[..255]);
    assert!(data[256..].iter().all(|&b| b == 0xFF));
    assert!(c.is_pulled());
    send(&mut c, &frame(0, 0));
    assert_eq!(response(&mut c, 16), None);
    assert_eq!(c.stats().blocks_read, 0);
}

#[test]
fn crc_once_hits_one_read_of_its_block_only() {
    let mut c = card(CardKind::Sdhc, 16);
    init(&mut c);
    c.corrupt_crc_once(3);
    let read_block = |c: &mut SdCard, n: u32| {
        assert_eq!(command(c, 17, n), 0);
        let (token, data, crc) = data_block(c, BLOCK);
        assert_eq!((token, &data[..]), (TOKEN_START, &c.image().block(n)[..]));
        crc == crc16(&data)
    };
    assert!(read_block(&mut c, 2), "other blocks read fine");
    assert!(!read_block(&mut c, 3), "the first read of block 3 is bad");
    assert!(read_block(&mut c, 3), "the second one is fine");
    // In a multiple-block read too.
    c.corrupt_crc_once(5);
    assert_eq!(command(&mut c, 18, 4), 0);
    let good: Vec<bool> = (0..3)
        .map(|_| {
            let (_, data, crc) = data_block(&mut c, BLOCK);
            crc == crc16(&data)
        })
        .collect();
    assert_eq!(good, [true, false, true]);
}

#[test]
fn injected_faults_act_as_their_methods() {
    let mut c = card(CardKind::Sdsc, 16);
    init(&mut c);
    c.inject(CardFault::BadBlock(4));
    c.inject(CardFault::CrcNext);
    for _ in 0..2 {
        assert_eq!(command(&mut c, 17, 4 * 512), 0);
        assert_eq!(data_block(&mut c, 0).0, 0x04, "card ECC failed, every time");
    }
    assert_eq!(command(&mut c, 17, 2 * 512), 0);
    let (_, data, crc) = data_block(&mut c, BLOCK);
    assert_ne!(crc, crc16(&data), "the next block sent after CrcNext");
    c.inject(CardFault::CrcOnce(2));
    assert_eq!(command(&mut c, 17, 2 * 512), 0);
    let (_, data, crc) = data_block(&mut c, BLOCK);
    assert_ne!(crc, crc16(&data));
}

#[test]
fn a_card_put_back_powers_up_with_its_image_counters_and_faults() {
    let mut c = card(CardKind::Sdhc, 16);
    init(&mut c);
    c.fail_read(5);
    assert_eq!(command(&mut c, 24, 1), 0);
    assert_eq!(
        write_block(&mut c, TOKEN_START, &[0x5A; BLOCK], 0),
        DATA_ACCEPTED
    );
    assert_eq!(command(&mut c, 17, 2), 0);
    c.power_up();
    assert!(!c.is_ready());
    assert_eq!(read(&mut c, 8), [0xFF; 8], "the block in flight is gone");
    send(&mut c, &frame(17, 2));
    assert_eq!(response(&mut c, 16), None, "SD bus mode until CMD0");
    init(&mut c);
    assert_eq!(c.image().block(1), [0x5A; BLOCK]);
    assert_eq!(c.stats().blocks_written, 1);
    assert_eq!(command(&mut c, 17, 5), 0);
    assert_eq!(data_block(&mut c, 0).0, 0x04, "still a bad block");
}

#[test]
fn a_slot_applies_planned_changes_in_time_then_plan_order() {
    use slot::Change;
    let mut s = slot::Slot::default();
    assert_eq!(s.exchange(0x40, true), 0xFF, "empty: MISO floats high");
    s.plan(0, 30, Change::Reinsert);
    s.plan(0, 10, Change::Insert(Box::new(card(CardKind::Sdhc, 8))));
    s.plan(0, 20, Change::Remove);
    s.plan(0, 30, Change::Fault(CardFault::BadBlock(2)));
    assert_eq!(s.next_due(), Some(10));
    s.apply_due(9);
    assert!(s.card().is_none());
    s.apply_due(10);
    init(s.card_mut().unwrap());
    let seen = s.card().unwrap().stats().commands;
    s.apply_due(29);
    assert!(s.card().is_none(), "out at 20");
    assert_eq!(s.exchange(0x40, true), 0xFF);
    s.apply_due(30);
    assert_eq!(s.next_due(), None);
    let c = s.card_mut().expect("the same card back");
    assert_eq!(c.stats().commands, seen, "its counters kept");
    assert!(!c.is_ready(), "powered up afresh");
    init(c);
    assert_eq!(command(c, 17, 2), 0);
    assert_eq!(data_block(c, 0).0, 0x04, "the fault planned after it");
}

#[test]
fn a_fault_planned_for_an_empty_slot_waits_for_the_next_card() {
    let mut s = slot::Slot::default();
    s.plan(5, 5, slot::Change::Fault(CardFault::CrcOnce(3)));
    s.insert(card(CardKind::Sdhc, 8));
    let c = s.card_mut().unwrap();
    init(c);
    assert_eq!(command(c, 17, 3), 0);
    let (_, data, crc) = data_block(c, BLOCK);
    assert_ne!(crc, crc16(&data));
}

#[test]
fn reinsertion_pushes_back_a_card_that_pulled_itself_out() {
    let mut s = slot::Slot::default();
    s.insert(card(CardKind::Sdhc, 8));
    let c = s.card_mut().unwrap();
    init(c);
    c.remove_during_transfer();
    assert_eq!(command(c, 17, 1), 0);
    read(c, 600);
    assert!(c.is_pulled());
    s.plan(0, 0, slot::Change::Reinsert);
    let c = s.card_mut().unwrap();
    assert!(!c.is_pulled());
    init(c);
    assert_eq!(command(c, 17, 1), 0);
    assert_eq!(data_block(c, BLOCK).0, TOKEN_START);
}
