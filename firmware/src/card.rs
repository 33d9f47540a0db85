//! The SD reader task's state: the card on SPI (embedded-sdmmc's `SdCard`
//! driver), its FAT volume (`taut_logic::fat`), and the file being
//! streamed to the job through [`CARD_OUT`] in small chunks.
//!
//! One run does at most one card operation (a presence check, a mount, one
//! block read), then returns: the bus is free between runs and other tasks
//! interleave. Modules have no card-detect pin, so an absent card is
//! probed for every second with a single CMD0, and a present, idle card is
//! asked for its CSD every second; a failing read is a removal.

use crate::board::delay::Delay;
use crate::board::spi::CardSpi;
use crate::queues::{CardMsg, Request, Signal, What, CARD_IN, CARD_OUT, CHUNK};
use crate::rt::Poll;
use crate::{info, warn};
use core::mem::{offset_of, size_of};
use embedded_hal::spi::SpiDevice;
use embedded_sdmmc::sdcard::spi::AcquireOpts;
use embedded_sdmmc::{Block, BlockDevice, BlockIdx, SdCard};
use taut_logic::fat::{BlockRead, FatError, File, Volume, BLOCK};
use taut_logic::job::FileName;

/// Free slots the reader waits for before a step of work: the most one
/// step sends (the last chunk of a block and `End`, or `Failed` and
/// `Removed`). The job wakes the reader when there are this many.
pub const ROOM: usize = 2;

type Sd = SdCard<CardSpi, Delay>;

enum Slot {
    Empty,
    /// A card with a FAT volume, `None` when it has none.
    Mounted(Option<Volume>),
}

pub struct CardReader {
    sd: Sd,
    slot: Slot,
    /// The file being streamed, its request's ticket.
    file: Option<(File, u8)>,
    block: Block,
    /// Bytes of `block` not yet sent: `at..len`.
    at: u16,
    len: u16,
    /// When the card is next looked for or checked.
    check_at: u32,
}

/// How often an empty slot is probed and an idle card checked, ms.
pub const CHECK_MS: u32 = 1000;

// The FAT reader fills `Block::contents` through a `[u8; 512]` view.
const _: () = assert!(size_of::<Block>() == BLOCK && offset_of!(Block, contents) == 0);

struct Device<'a>(&'a Sd);

impl BlockRead for Device<'_> {
    type Error = embedded_sdmmc::SdCardError;
    fn read_block(&mut self, lba: u32, buf: &mut [u8; BLOCK]) -> Result<(), Self::Error> {
        // SAFETY: `Block` is exactly one `[u8; 512]` at offset 0 (asserted above).
        let block = unsafe { &mut *(buf as *mut [u8; BLOCK] as *mut Block) };
        self.0.read(core::slice::from_mut(block), BlockIdx(lba))
    }
}

impl CardReader {
    pub fn new(spi: CardSpi) -> CardReader {
        let options = AcquireOpts {
            use_crc: true,
            acquire_retries: 4,
        };
        CardReader {
            sd: SdCard::new_with_options(spi, Delay, options),
            slot: Slot::Empty,
            file: None,
            block: Block::new(),
            at: 0,
            len: 0,
            check_at: 0,
        }
    }

    /// One step of work at millisecond `now`. Between requests it sleeps
    /// until the next check is due. While the machine is `moving`, an
    /// empty slot is not probed (next second).
    pub fn poll(&mut self, now: u32, moving: bool) -> Poll<Signal> {
        let due = now.wrapping_sub(self.check_at) as i32 >= 0;
        if due {
            self.check_at = now.wrapping_add(CHECK_MS);
        }
        let poll = self.work(due && !(moving && matches!(self.slot, Slot::Empty)));
        match poll {
            Poll::Idle => Poll::After(self.check_at.wrapping_sub(now).min(CHECK_MS) as u16),
            _ => poll,
        }
    }

    /// The step of work; `check`: look for the card or at it. `Idle`: until
    /// the next check (`poll` puts in the time).
    fn work(&mut self, check: bool) -> Poll<Signal> {
        match self.slot {
            Slot::Empty if check => self.look_for_card(),
            Slot::Empty => Poll::Idle,
            Slot::Mounted(volume) => {
                if let Some(Request::Open(name, ticket)) = CARD_IN.peek() {
                    if CARD_OUT.free() < ROOM {
                        return Poll::Wait(Signal::CardRoom);
                    }
                    let _ = CARD_IN.pop();
                    self.open(volume, name, ticket);
                    return Poll::Again;
                }
                match volume {
                    Some(v) if self.file.is_some() => self.stream(v),
                    _ if check => self.check_still_there(),
                    _ => Poll::Idle,
                }
            }
        }
    }

    fn send(what: What, ticket: u8) {
        // Callers check for room first: nothing is refused here.
        let _ = CARD_OUT.push(CardMsg { ticket, what });
    }

    fn look_for_card(&mut self) -> Poll<Signal> {
        if CARD_OUT.free() < ROOM {
            return Poll::Wait(Signal::CardRoom);
        }
        let present = self.sd.spi(|spi| {
            spi.bus.slow_speed();
            spi.idle_clocks(10);
            answers_cmd0(spi)
        });
        if !present {
            return Poll::Idle;
        }
        self.sd.mark_card_uninit();
        let blocks = match self.sd.num_bytes() {
            Ok(bytes) => (bytes / BLOCK as u64) as u32,
            Err(_) => {
                warn!("card: no answer to init");
                return Poll::Idle;
            }
        };
        self.sd.spi(|spi| spi.bus.full_speed());
        let volume = match Volume::mount(&mut Device(&self.sd), &mut self.block.contents) {
            Ok(v) => {
                info!(
                    "card: ",
                    blocks / 2048,
                    " MiB FAT",
                    if v.is_fat32() { 32u8 } else { 16 }
                );
                Some(v)
            }
            Err(FatError::Device(_)) => {
                warn!("card: read failed");
                self.sd.mark_card_uninit();
                return Poll::Idle;
            }
            Err(_) => {
                warn!("card: no FAT16/FAT32 volume");
                None
            }
        };
        self.slot = Slot::Mounted(volume);
        Self::send(What::Inserted, 0);
        Poll::Idle
    }

    fn open(&mut self, volume: Option<Volume>, name: FileName, ticket: u8) {
        self.file = None;
        self.at = 0;
        self.len = 0;
        let Some(v) = volume else {
            return Self::send(What::Failed, ticket);
        };
        match v.open(
            &mut Device(&self.sd),
            &mut self.block.contents,
            name.name().as_bytes(),
        ) {
            Ok(f) => self.file = Some((f, ticket)),
            Err(FatError::NotFound) => Self::send(What::Missing, ticket),
            Err(FatError::Device(_)) => self.removed(ticket),
            Err(_) => Self::send(What::Failed, ticket),
        }
    }

    /// Sends what is left of the block, then reads the next one.
    fn stream(&mut self, volume: Volume) -> Poll<Signal> {
        let Some((mut file, ticket)) = self.file else {
            return Poll::Idle;
        };
        while self.at < self.len {
            if CARD_OUT.free() == 0 {
                return Poll::Wait(Signal::CardRoom);
            }
            let from = self.at as usize;
            let n = (self.len - self.at).min(CHUNK as u16);
            let mut bytes = [0; CHUNK];
            bytes[..n as usize].copy_from_slice(&self.block.contents[from..from + n as usize]);
            Self::send(
                What::Data {
                    len: n as u8,
                    bytes,
                },
                ticket,
            );
            self.at += n;
        }
        if CARD_OUT.free() < ROOM {
            return Poll::Wait(Signal::CardRoom);
        }
        match file.read_next(&volume, &mut Device(&self.sd), &mut self.block.contents) {
            Ok(0) => {
                self.file = None;
                Self::send(What::End, ticket);
                Poll::Idle
            }
            Ok(n) => {
                self.file = Some((file, ticket));
                self.at = 0;
                self.len = n as u16;
                Poll::Again
            }
            Err(FatError::Device(_)) => {
                self.removed(ticket);
                Poll::Idle
            }
            Err(_) => {
                warn!("card: broken cluster chain");
                self.file = None;
                Self::send(What::Failed, ticket);
                Poll::Idle
            }
        }
    }

    fn check_still_there(&mut self) -> Poll<Signal> {
        if CARD_OUT.free() < ROOM {
            return Poll::Wait(Signal::CardRoom);
        }
        if self.sd.num_bytes().is_err() {
            self.removed(0);
        }
        Poll::Idle
    }

    /// The card stopped answering: pulled out (or dead, which the user
    /// treats the same way). A file being read fails first.
    fn removed(&mut self, ticket: u8) {
        if self.file.take().is_some() {
            Self::send(What::Failed, ticket);
        }
        self.sd.mark_card_uninit();
        self.slot = Slot::Empty;
        Self::send(What::Removed, 0);
    }
}

/// Does a card answer CMD0 (GO_IDLE_STATE)? A few bytes on the bus: an
/// empty slot reads 0xFF (MISO pulled up).
fn answers_cmd0(spi: &mut CardSpi) -> bool {
    let mut frame = [
        0x40, 0, 0, 0, 0, 0x95, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF,
    ];
    let _ = spi.transaction(&mut [embedded_hal::spi::Operation::TransferInPlace(&mut frame)]);
    frame[6..].iter().any(|&r| r != 0xFF)
}
