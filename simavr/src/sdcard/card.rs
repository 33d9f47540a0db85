//! An SD card in SPI mode as a pure state machine: every SPI byte is one
//! `exchange` — a byte in on MOSI, the byte the card drives on MISO at the
//! same time out. It follows the SD Physical Layer Simplified Specification,
//! chapter 7 (SPI mode). Nothing here knows about simavr, so the same card
//! runs under a host SD driver in tests.
//!
//! Output is a queue: a command's response (after its NCR gap), a data
//! block, busy bytes. Whatever the host clocks while the queue is empty
//! reads 0xFF, the idle level of MISO.

use super::crc::{crc16, crc7};
use super::fault::{CardFault, Faults, ReadFault, PULL_AFTER};
use super::image::{SdImage, BLOCK};
use super::registers;
use super::stats::SdStats;
use std::collections::VecDeque;

/// R1 bits.
pub const R1_IDLE: u8 = 0x01;
pub const R1_ILLEGAL: u8 = 0x04;
pub const R1_CRC: u8 = 0x08;
pub const R1_ADDRESS: u8 = 0x20;
pub const R1_PARAMETER: u8 = 0x40;

/// Data tokens.
pub const TOKEN_START: u8 = 0xFE;
pub const TOKEN_MULTI_WRITE: u8 = 0xFC;
pub const TOKEN_STOP_TRAN: u8 = 0xFD;

/// Data responses to a written block.
pub const DATA_ACCEPTED: u8 = 0x05;
pub const DATA_CRC_ERROR: u8 = 0x0B;
pub const DATA_WRITE_ERROR: u8 = 0x0D;

/// Error token of a multiple-block read that ran off the card.
const TOKEN_OUT_OF_RANGE: u8 = 0x08;
/// ACMD41 argument: the host supports high-capacity cards.
const HCS: u32 = 1 << 30;

/// Addressing the card offers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CardKind {
    /// SDHC when the image is over 2 GiB, SDSC otherwise.
    Auto,
    /// Standard capacity: byte addresses, CSD version 1, at most 4 GiB.
    Sdsc,
    /// High capacity: block addresses, CSD version 2.
    Sdhc,
}

/// How a card behaves; the timings are counted in SPI bytes.
#[derive(Clone, Copy, Debug)]
pub struct SdConfig {
    pub kind: CardKind,
    /// ACMD41 calls answered "still idle" before the card is ready.
    pub init_polls: u32,
    /// 0xFF bytes before every command response (NCR, 1..=8).
    pub ncr: u8,
    /// 0xFF bytes between a read's R1 and its data token (NAC).
    pub read_latency: u16,
    /// 0x00 bytes of busy after a written block, a stop, or CMD12.
    pub busy: u16,
}

impl Default for SdConfig {
    fn default() -> Self {
        SdConfig {
            kind: CardKind::Auto,
            init_polls: 2,
            ncr: 1,
            read_latency: 2,
            busy: 4,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum State {
    /// Powered, still in SD bus mode: only CMD0 with CS low is heard.
    PowerOn,
    /// In SPI mode after CMD0, initialising (R1 idle bit set).
    Idle,
    /// Initialised by ACMD41: data commands accepted.
    Ready,
}

#[derive(Default)]
enum Transfer {
    #[default]
    None,
    /// CMD18: the next block to stream once the current one is out.
    ReadMulti { next: u32 },
    /// CMD24/25: waiting for a data token.
    WriteWait { block: u32, multi: bool },
    /// Receiving a written block and its CRC.
    WriteData {
        block: u32,
        multi: bool,
        buf: Vec<u8>,
    },
}

pub struct SdCard {
    image: SdImage,
    config: SdConfig,
    sdhc: bool,
    csd: [u8; 16],
    capacity: u32,
    state: State,
    crc_on: bool,
    app_cmd: bool,
    polls_left: u32,
    frame: [u8; 6],
    frame_len: usize,
    out: VecDeque<u8>,
    /// Bytes of `out` until the data block in it has been sent whole.
    block_in_flight: Option<usize>,
    transfer: Transfer,
    faults: Faults,
    stats: SdStats,
    pulled: bool,
}

impl From<SdImage> for SdCard {
    fn from(image: SdImage) -> SdCard {
        SdCard::new(image)
    }
}

impl SdCard {
    /// A card with the default configuration.
    pub fn new(image: SdImage) -> SdCard {
        SdCard::with_config(image, SdConfig::default())
    }

    /// # Panics
    /// For an SDSC card over 4 GiB, or an NCR outside 1..=8.
    pub fn with_config(image: SdImage, config: SdConfig) -> SdCard {
        assert!((1..=8).contains(&config.ncr), "NCR is 1 to 8 bytes");
        let sdhc = match config.kind {
            CardKind::Auto => image.len() > 2 << 30,
            CardKind::Sdsc => false,
            CardKind::Sdhc => true,
        };
        let (csd, capacity) = if sdhc {
            registers::csd_v2(image.blocks())
        } else {
            registers::csd_v1(image.blocks()).expect("an SDSC card holds at most 4 GiB")
        };
        SdCard {
            image,
            config,
            sdhc,
            csd,
            capacity,
            state: State::PowerOn,
            crc_on: false,
            app_cmd: false,
            polls_left: config.init_polls,
            frame: [0; 6],
            frame_len: 0,
            out: VecDeque::new(),
            block_in_flight: None,
            transfer: Transfer::None,
            faults: Faults::default(),
            stats: SdStats::default(),
            pulled: false,
        }
    }

    /// One SPI byte: `mosi` in, the returned byte out. With `cs_low` false
    /// the card is not selected: it ignores the byte and leaves MISO high.
    pub fn exchange(&mut self, mosi: u8, cs_low: bool) -> u8 {
        if self.pulled {
            return 0xFF;
        }
        if !cs_low {
            self.stats.bytes_deselected += 1;
            return 0xFF;
        }
        self.stats.bytes_selected += 1;
        let miso = self.next_out();
        self.take(mosi);
        self.count_down_to_pull();
        miso
    }

    pub fn is_sdhc(&self) -> bool {
        self.sdhc
    }

    /// Initialised (ACMD41 answered ready) since the last CMD0.
    pub fn is_ready(&self) -> bool {
        self.state == State::Ready
    }

    /// Capacity the CSD states, in 512-byte blocks (at least the image).
    pub fn capacity_blocks(&self) -> u32 {
        self.capacity
    }

    pub fn image(&self) -> &SdImage {
        &self.image
    }

    pub fn into_image(self) -> SdImage {
        self.image
    }

    pub fn stats(&self) -> &SdStats {
        &self.stats
    }

    /// Pulled out by `remove_during_transfer`: silent from then on.
    pub fn is_pulled(&self) -> bool {
        self.pulled
    }

    /// Every read of `block` answers R1 fine, then error token 0x04 (card
    /// ECC failed).
    pub fn fail_read(&mut self, block: u32) {
        self.fail_read_with(block, ReadFault::ErrorToken(0x04));
    }

    pub fn fail_read_with(&mut self, block: u32, fault: ReadFault) {
        self.faults.bad_blocks.insert(block, fault);
    }

    /// The next `commands` command frames get no response at all.
    pub fn timeout_next(&mut self, commands: u32) {
        self.faults.mute_commands += commands;
    }

    /// The next data block the card sends (a read block or a register)
    /// carries a wrong CRC16.
    pub fn corrupt_crc_next(&mut self) {
        self.faults.corrupt_crc = true;
    }

    /// The next read of `block` carries a wrong CRC16; later reads are fine.
    pub fn corrupt_crc_once(&mut self, block: u32) {
        self.faults.crc_once.insert(block);
    }

    pub fn inject(&mut self, fault: CardFault) {
        match fault {
            CardFault::CrcNext => self.corrupt_crc_next(),
            CardFault::CrcOnce(block) => self.corrupt_crc_once(block),
            CardFault::BadBlock(block) => self.fail_read(block),
        }
    }

    /// The card is pulled out halfway through the next data block, read or
    /// written; it is silent from then on.
    pub fn remove_during_transfer(&mut self) {
        self.faults.pull_in_transfer = true;
    }

    /// Forgets every injected fault not yet triggered.
    pub fn clear_faults(&mut self) {
        self.faults = Faults::default();
    }

    /// Put (back) in a slot: powered up uninitialised, nothing in flight.
    /// Its image, counters and untriggered faults stay.
    pub(crate) fn power_up(&mut self) {
        self.state = State::PowerOn;
        self.crc_on = false;
        self.app_cmd = false;
        self.polls_left = self.config.init_polls;
        self.frame_len = 0;
        self.out.clear();
        self.block_in_flight = None;
        self.transfer = Transfer::None;
        self.faults.pull_countdown = None;
        self.pulled = false;
    }

    fn next_out(&mut self) -> u8 {
        if self.out.is_empty() {
            if let Transfer::ReadMulti { next } = self.transfer {
                self.transfer = if next >= self.capacity {
                    self.queue_ff(self.config.read_latency);
                    self.out.push_back(TOKEN_OUT_OF_RANGE);
                    Transfer::None
                } else if self.queue_block(next) {
                    Transfer::ReadMulti { next: next + 1 }
                } else {
                    Transfer::None
                };
            }
        }
        if let Some(left) = self.block_in_flight.as_mut() {
            *left -= 1;
            if *left == 0 {
                self.block_in_flight = None;
                self.stats.blocks_read += 1;
            }
        }
        self.out.pop_front().unwrap_or(0xFF)
    }

    fn take(&mut self, mosi: u8) {
        match &mut self.transfer {
            Transfer::WriteData { buf, .. } => {
                buf.push(mosi);
                if buf.len() == BLOCK + 2 {
                    self.finish_write();
                }
                return;
            }
            &mut Transfer::WriteWait { block, multi } => match (mosi, multi) {
                (TOKEN_START, false) | (TOKEN_MULTI_WRITE, true) => {
                    self.arm_pull(0);
                    self.transfer = Transfer::WriteData {
                        block,
                        multi,
                        buf: Vec::with_capacity(BLOCK + 2),
                    };
                    return;
                }
                (TOKEN_STOP_TRAN, true) => {
                    self.transfer = Transfer::None;
                    // One byte before busy starts (NBR).
                    self.out.push_back(0xFF);
                    self.queue_busy();
                    return;
                }
                // Anything else may start a command that ends the write.
                _ => {}
            },
            _ => {}
        }
        if self.frame_len == 0 && mosi & 0xC0 != 0x40 {
            return;
        }
        self.frame[self.frame_len] = mosi;
        self.frame_len += 1;
        if self.frame_len == self.frame.len() {
            self.frame_len = 0;
            self.command();
        }
    }

    fn command(&mut self) {
        let index = self.frame[0] & 0x3F;
        let arg = u32::from_be_bytes([self.frame[1], self.frame[2], self.frame[3], self.frame[4]]);
        let app = std::mem::take(&mut self.app_cmd);
        self.stats.count(index, app);
        let cmd0 = index == 0 && !app;
        if self.state == State::PowerOn && !cmd0 {
            return;
        }
        if self.faults.mute_commands > 0 {
            self.faults.mute_commands -= 1;
            return;
        }
        self.out.clear();
        self.block_in_flight = None;
        if index == 12 && !app {
            // The byte after CMD12 is a stuff byte, then NCR.
            self.out.push_back(0xFF);
        }
        self.queue_ff(u16::from(self.config.ncr));
        // CMD0 is checked in SD mode, CMD8 always, the rest once CMD59 says.
        let checked = self.crc_on || (cmd0 && self.state == State::PowerOn) || index == 8;
        if checked && crc7(&self.frame[..5]) != self.frame[5] >> 1 {
            self.stats.crc_errors += 1;
            self.out.push_back(self.r1() | R1_CRC);
            return;
        }
        // Any command ends the transfer in progress.
        self.transfer = Transfer::None;
        if app {
            self.app_command(index, arg);
        } else {
            self.standard_command(index, arg);
        }
    }

    fn standard_command(&mut self, index: u8, arg: u32) {
        match index {
            0 => {
                self.state = State::Idle;
                self.crc_on = false;
                self.polls_left = self.config.init_polls;
                self.out.push_back(R1_IDLE);
            }
            8 => {
                // R7: voltage accepted when the host offers 2.7–3.6 V, and
                // the check pattern echoed.
                let voltage = ((arg >> 8) & 0xF == 1) as u8;
                self.out.extend([self.r1(), 0, 0, voltage, arg as u8]);
            }
            55 => {
                self.app_cmd = true;
                self.out.push_back(self.r1());
            }
            58 => {
                let ocr = registers::ocr(self.state == State::Ready, self.sdhc);
                self.out.push_back(self.r1());
                self.out.extend(ocr.to_be_bytes());
            }
            59 => {
                self.crc_on = arg & 1 != 0;
                self.out.push_back(self.r1());
            }
            16 if arg == BLOCK as u32 => self.out.push_back(self.r1()),
            16 => self.out.push_back(self.r1() | R1_PARAMETER),
            _ if self.state != State::Ready => self.out.push_back(self.r1() | R1_ILLEGAL),
            9 => self.send_register(self.csd),
            10 => self.send_register(registers::cid()),
            12 => {
                self.out.push_back(0);
                self.queue_busy();
            }
            13 => self.out.extend([0, 0]),
            17 | 18 | 24 | 25 => match self.block_at(arg) {
                Err(r1) => self.out.push_back(r1),
                Ok(block) => {
                    self.out.push_back(0);
                    self.transfer = match index {
                        17 => {
                            self.queue_block(block);
                            Transfer::None
                        }
                        18 if self.queue_block(block) => Transfer::ReadMulti { next: block + 1 },
                        18 => Transfer::None,
                        24 => Transfer::WriteWait {
                            block,
                            multi: false,
                        },
                        _ => Transfer::WriteWait { block, multi: true },
                    };
                }
            },
            _ => self.out.push_back(self.r1() | R1_ILLEGAL),
        }
    }

    fn app_command(&mut self, index: u8, arg: u32) {
        match index {
            41 => {
                // A high-capacity card never leaves idle for a host that
                // does not announce HCS.
                if self.state == State::Idle && (arg & HCS != 0 || !self.sdhc) {
                    if self.polls_left > 0 {
                        self.polls_left -= 1;
                    } else {
                        self.state = State::Ready;
                    }
                }
                self.out.push_back(self.r1());
            }
            // Pre-erase count before CMD25: a hint the card may ignore.
            23 if self.state == State::Ready => self.out.push_back(0),
            _ => self.out.push_back(self.r1() | R1_ILLEGAL),
        }
    }

    fn r1(&self) -> u8 {
        if self.state == State::Ready {
            0
        } else {
            R1_IDLE
        }
    }

    /// The block an address argument names: a byte address on SDSC, a
    /// block number on SDHC; or the R1 that rejects it.
    fn block_at(&self, arg: u32) -> Result<u32, u8> {
        let block = if self.sdhc {
            arg
        } else if !arg.is_multiple_of(BLOCK as u32) {
            return Err(R1_ADDRESS);
        } else {
            arg / BLOCK as u32
        };
        if block >= self.capacity {
            return Err(R1_PARAMETER);
        }
        Ok(block)
    }

    /// Queues the read latency, then block `n` as a data block, or its
    /// injected fault. False when no data follows.
    fn queue_block(&mut self, n: u32) -> bool {
        self.queue_ff(self.config.read_latency);
        match self.faults.bad_blocks.get(&n) {
            Some(&ReadFault::ErrorToken(token)) => {
                self.out.push_back(token);
                false
            }
            Some(ReadFault::NoToken) => false,
            None => {
                let corrupt = self.faults.crc_once.remove(&n);
                self.queue_data(&self.image.block(n), corrupt);
                self.block_in_flight = Some(self.out.len());
                true
            }
        }
    }

    fn send_register(&mut self, reg: [u8; 16]) {
        self.out.push_back(0);
        self.queue_ff(self.config.read_latency);
        self.queue_data(&reg, false);
    }

    /// Token, data and CRC16 of a data block the card sends; the CRC is
    /// wrong when `corrupt` or when `corrupt_crc_next` asked for it.
    fn queue_data(&mut self, data: &[u8], corrupt: bool) {
        self.arm_pull(self.out.len() as u32);
        self.out.push_back(TOKEN_START);
        self.out.extend(data);
        let mut crc = crc16(data);
        if corrupt || std::mem::take(&mut self.faults.corrupt_crc) {
            crc ^= 0x0001;
        }
        self.out.extend(crc.to_be_bytes());
    }

    fn finish_write(&mut self) {
        let Transfer::WriteData { block, multi, buf } = std::mem::take(&mut self.transfer) else {
            return;
        };
        let data: &[u8; BLOCK] = buf[..BLOCK].try_into().expect("a whole block");
        let crc = u16::from_be_bytes([buf[BLOCK], buf[BLOCK + 1]]);
        let response = if self.crc_on && crc != crc16(data) {
            self.stats.crc_errors += 1;
            DATA_CRC_ERROR
        } else if block >= self.capacity {
            DATA_WRITE_ERROR
        } else {
            self.image.write_block(block, data);
            self.stats.blocks_written += 1;
            DATA_ACCEPTED
        };
        self.out.clear();
        self.out.push_back(response);
        self.queue_busy();
        if multi {
            // After an error the host stops the write with 0xFD or CMD12.
            let next = if response == DATA_ACCEPTED {
                block + 1
            } else {
                block
            };
            self.transfer = Transfer::WriteWait { block: next, multi };
        }
    }

    fn queue_ff(&mut self, n: u16) {
        self.out.extend(std::iter::repeat_n(0xFF, usize::from(n)));
    }

    fn queue_busy(&mut self) {
        self.out.extend(std::iter::repeat_n(
            0x00,
            usize::from(self.config.busy.max(1)),
        ));
    }

    /// Starts the countdown of an armed removal: `lead` bytes before the
    /// data block starts, then half of it.
    fn arm_pull(&mut self, lead: u32) {
        if std::mem::take(&mut self.faults.pull_in_transfer) {
            self.faults.pull_countdown = Some(lead + PULL_AFTER);
        }
    }

    fn count_down_to_pull(&mut self) {
        if let Some(left) = self.faults.pull_countdown.as_mut() {
            *left = left.saturating_sub(1);
            if *left == 0 {
                self.faults.pull_countdown = None;
                self.pulled = true;
                self.out.clear();
                self.block_in_flight = None;
                self.transfer = Transfer::None;
            }
        }
    }
}
