//! The virtual card on simavr's SPI bus, driven by a tiny hand-assembled
//! program: in a loop it clocks 10 bytes with chip select (D53 = PB0) high,
//! sends CMD0 with it low, and copies the next three bytes it reads from
//! SPDR to USART0.

use std::time::Duration;
use taut_simavr::sdcard::{SdCard, SdImage, R1_IDLE};
use taut_simavr::{Outcome, Sim};

/// A few AVR instructions, encoded as in the instruction set manual.
#[derive(Default)]
struct Asm(Vec<u16>);

impl Asm {
    fn here(&self) -> usize {
        self.0.len()
    }
    fn ldi(&mut self, d: u16, k: u8) {
        let k = u16::from(k);
        self.0
            .push(0xE000 | (k & 0xF0) << 4 | (d - 16) << 4 | (k & 0x0F));
    }
    fn out(&mut self, io: u16, r: u16) {
        self.0
            .push(0xB800 | (io & 0x30) << 5 | r << 4 | (io & 0x0F));
    }
    fn inp(&mut self, d: u16, io: u16) {
        self.0
            .push(0xB000 | (io & 0x30) << 5 | d << 4 | (io & 0x0F));
    }
    fn sbrs(&mut self, r: u16, bit: u16) {
        self.0.push(0xFE00 | r << 4 | bit);
    }
    fn lds(&mut self, d: u16, addr: u16) {
        self.0.extend([0x9000 | d << 4, addr]);
    }
    fn sts(&mut self, addr: u16, r: u16) {
        self.0.extend([0x9200 | r << 4, addr]);
    }
    fn dec(&mut self, d: u16) {
        self.0.push(0x940A | d << 4);
    }
    fn offset(&self, target: usize) -> u16 {
        (target as i32 - self.here() as i32 - 1) as u16
    }
    fn rjmp(&mut self, target: usize) {
        self.0.push(0xC000 | (self.offset(target) & 0xFFF));
    }
    fn rcall(&mut self, target: usize) {
        self.0.push(0xD000 | (self.offset(target) & 0xFFF));
    }
    fn brne(&mut self, target: usize) {
        self.0.push(0xF401 | (self.offset(target) & 0x7F) << 3);
    }
    fn ret(&mut self) {
        self.0.push(0x9508);
    }
}

const DDRB: u16 = 0x04;
const PORTB: u16 = 0x05;
const SPCR: u16 = 0x2C;
const SPSR: u16 = 0x2D;
const SPDR: u16 = 0x2E;
const UCSR0A: u16 = 0xC0;
const UCSR0B: u16 = 0xC1;
const UDR0: u16 = 0xC6;

fn cmd0_loop() -> Vec<u16> {
    let mut a = Asm::default();
    a.0.push(0); // rjmp main, patched below
                 // xfer: r16 out on MOSI, MISO back in r16.
    let xfer = a.here();
    a.out(SPDR, 16);
    let wait = a.here();
    a.inp(17, SPSR);
    a.sbrs(17, 7);
    a.rjmp(wait);
    a.inp(16, SPDR);
    a.ret();
    // tx: r16 to USART0.
    let tx = a.here();
    a.lds(18, UCSR0A);
    a.sbrs(18, 5);
    a.rjmp(tx);
    a.sts(UDR0, 16);
    a.ret();
    let main = a.here();
    a.0[0] = 0xC000 | (main as u16 - 1);
    a.ldi(16, 0x07); // CS, SCK, MOSI outputs
    a.out(DDRB, 16);
    a.ldi(16, 0x50); // SPI on, master, clock / 4
    a.out(SPCR, 16);
    a.ldi(16, 0x08); // transmitter on
    a.sts(UCSR0B, 16);
    let top = a.here();
    a.ldi(16, 0x01); // CS high
    a.out(PORTB, 16);
    a.ldi(19, 10);
    let clocks = a.here();
    a.ldi(16, 0xFF);
    a.rcall(xfer);
    a.dec(19);
    a.brne(clocks);
    a.ldi(16, 0x00); // CS low
    a.out(PORTB, 16);
    for byte in [0x40, 0, 0, 0, 0, 0x95] {
        a.ldi(16, byte);
        a.rcall(xfer);
    }
    a.ldi(19, 3);
    let answer = a.here();
    a.ldi(16, 0xFF);
    a.rcall(xfer);
    a.rcall(tx);
    a.dec(19);
    a.brne(answer);
    a.rjmp(top);
    a.0
}

fn us(n: u64) -> Duration {
    Duration::from_micros(n)
}

/// The three bytes read after each CMD0.
fn answers(sim: &Sim) -> Vec<[u8; 3]> {
    sim.uart_bytes()
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect()
}

#[test]
fn the_card_answers_cmd0_through_the_spi_bus() {
    let mut sim = Sim::from_program(&cmd0_loop()).unwrap();
    sim.insert_sd(SdImage::blank(2048));
    let end = sim.run_until(|s| s.uart_bytes().len() >= 6, Duration::from_millis(5));
    assert_eq!(end, Outcome::Done);
    assert_eq!(answers(&sim)[..2], [[0xFF, R1_IDLE, 0xFF]; 2]);
    let stats = sim.sd_stats().unwrap();
    assert!(stats.cmd(0) >= 2, "{stats:?}");
    assert!(stats.bytes_deselected >= 20, "{stats:?}");
    assert!(sim.sd_present());
}

#[test]
fn without_a_card_miso_reads_high_and_insertion_is_scheduled() {
    let mut sim = Sim::from_program(&cmd0_loop()).unwrap();
    sim.sd_insert_at(us(3000), SdImage::blank(2048));
    sim.sd_remove_at(us(6000));
    assert!(!sim.sd_present());
    sim.run_for(us(2900));
    assert!(!sim.sd_present());
    let before = answers(&sim).len();
    assert!(before >= 2);
    sim.run_for(us(3000));
    assert!(sim.sd_present());
    let during = answers(&sim).len();
    sim.run_for(us(3000));
    assert!(!sim.sd_present());
    // FF until the insertion, R1 while the card is in, FF after the
    // removal; the loop around each change may be cut short.
    let all = answers(&sim);
    let idle = [0xFF, R1_IDLE, 0xFF];
    let first = all.iter().position(|a| *a == idle).expect("answers");
    let last = all.iter().rposition(|a| *a == idle).unwrap();
    assert!((before..=before + 2).contains(&first), "{before} {all:?}");
    assert!(
        (during..=during + 2).contains(&(last + 1)),
        "{during} {all:?}"
    );
    assert!(all[first..=last].iter().all(|a| *a == idle), "{all:?}");
    let outside = all[..first].iter().chain(&all[last + 1..]);
    assert!(outside.clone().all(|a| *a == [0xFF; 3]), "{all:?}");
    assert!(outside.count() >= 2 * before);
    assert!(sim.remove_sd().is_none(), "the planned removal happened");
}

#[test]
fn a_removed_card_keeps_its_counts() {
    let mut sim = Sim::from_program(&cmd0_loop()).unwrap();
    sim.insert_sd(SdCard::new(SdImage::blank(64)));
    sim.run_for(us(500));
    let card = sim.remove_sd().expect("a card");
    assert!(card.stats().cmd(0) >= 2);
    let seen = sim.uart_bytes().len();
    sim.run_for(us(500));
    assert!(sim.uart_bytes()[seen..].iter().all(|&b| b == 0xFF));
    assert!(sim.sd_stats().is_none());
}

#[test]
fn faults_reach_the_card_in_the_slot() {
    let mut sim = Sim::from_program(&cmd0_loop()).unwrap();
    sim.insert_sd(SdImage::blank(64));
    sim.run_until(|s| s.uart_bytes().len() >= 3, Duration::from_millis(5));
    sim.sd_card_mut().unwrap().timeout_next(2);
    sim.run_until(|s| s.uart_bytes().len() >= 4 * 3, Duration::from_millis(5));
    let all = answers(&sim);
    let idle = [0xFF, R1_IDLE, 0xFF];
    assert_eq!(all[..4], [idle, [0xFF; 3], [0xFF; 3], idle], "{all:?}");
    assert_eq!(sim.sd_stats().unwrap().cmd(0), 4);
}

#[test]
fn a_card_pulled_and_put_back_is_the_same_card_powered_up_afresh() {
    let mut sim = Sim::from_program(&cmd0_loop()).unwrap();
    sim.insert_sd(SdImage::blank(64));
    sim.sd_remove_at(us(1000));
    sim.sd_reinsert_at(us(2000));
    sim.run_for(us(1000));
    assert!(!sim.sd_present(), "out at 1 ms sharp");
    assert!(sim.sd_stats().is_none());
    let out = answers(&sim).len();
    sim.run_for(us(999));
    assert!(!sim.sd_present());
    let while_out = answers(&sim);
    assert!(while_out.len() >= out + 2);
    // The loop under way at the removal may have had its answer already.
    assert!(while_out[out + 1..].iter().all(|a| *a == [0xFF; 3]));
    sim.run_for(us(1));
    assert!(sim.sd_present(), "back at 2 ms");
    let count_back = sim.sd_stats().unwrap().cmd(0);
    assert!(count_back >= 2, "the same card: its counters kept");
    sim.run_for(us(1000));
    assert_eq!(answers(&sim).last(), Some(&[0xFF, R1_IDLE, 0xFF]));
    assert!(sim.sd_stats().unwrap().cmd(0) > count_back);
}
