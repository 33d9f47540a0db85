//! The SD reader task's state: the card on SPI (embedded-sdmmc's `SdCard`
//! driver), its FAT volume (`taut_logic::fat`), and the file being
//! streamed to the job through `CARD_OUT` in small chunks.
//!
//! One run does at most one card operation (a presence check, a mount, one
//! block read), then returns: the bus is free between runs and other tasks
//! interleave. Modules have no card-detect pin, so an absent card is
//! probed for every second with a single CMD0, and a card in the slot is
//! asked for its CSD every second, also while a file streams (a pulled
//! card is noticed between block reads). A block read that fails with a
//! CRC error or an error token is tried [`TRIES`] times; a block that
//! never reads makes the card faulty, reported once, and it is not read
//! again until it has been taken out. Any other failure is a removal.

use crate::board::delay::Delay;
use crate::board::flash::FlashStr;
use crate::board::port::Port;
use crate::board::spi::{self, CardSpi};
use crate::queues::{CardMsg, CardNews, CardRequests, CardTell, Request, Signal, What, CHUNK};
use crate::rt::{Poll, TaskCell};
use crate::{error, flash_str, info, warn};
use embedded_hal::delay::DelayNs;
use embedded_hal::spi::{Operation, SpiDevice};
use embedded_sdmmc::sdcard::spi::AcquireOpts;
use embedded_sdmmc::{BlockDevice, BlockIdx, SdCard, SdCardError};
use taut_logic::fat::{
    BlockRead, Dir, Entry, FatError, File, Name, Scan, Slot as DirSlot, Volume, BLOCK,
};
use ufmt::uwrite;

/// Free slots the reader waits for before a step of work: the most one
/// step sends (the last chunk of a block and `End`, or `Failed` and
/// `Removed`). A file's bytes leave this many free, so the readers (the
/// job, the console) wake the reader when there are more.
pub const ROOM: usize = 2;

/// Reads of one block before the card counts as faulty.
pub const TRIES: u8 = 3;

/// How often an empty slot is probed and a card checked, ms.
pub const CHECK_MS: u32 = 1000;
/// How much earlier than a second after the last check the next may come.
const CHECK_SLACK_MS: u32 = 100;

type Sd = SdCard<TimedSpi, TimedDelay>;

/// Waiting the SD driver may do in one run of the reader, in its 10 µs
/// steps: 8 ms. A card that stopped answering (pulled mid-read) would
/// otherwise keep it polling 10 000 times per command, 120 ms with the
/// other tasks shut out and the step queue (30 ms of motion) running dry;
/// real cards answer a read within a millisecond or two. Starting a card
/// (its `ACMD41` loop can take a second) is done only while the machine
/// stands, and may wait as long as the driver likes.
const WAIT_STEPS: u16 = 800;
/// The driver's waits so far in this run, and how many it may do.
static WAITED: TaskCell<(u16, u16)> = TaskCell::new((0, WAIT_STEPS));

/// The driver's delay, counting its waits.
pub struct TimedDelay;

impl DelayNs for TimedDelay {
    fn delay_ns(&mut self, ns: u32) {
        WAITED.with(|w| w.0 = w.0.saturating_add(1));
        Delay.delay_ns(ns);
    }
}

/// The card's SPI device, failing once the run has waited its budget: the
/// driver then gives up at once (a transport error, taken as a removal).
pub struct TimedSpi(pub CardSpi);

#[derive(Debug)]
pub struct OutOfTime;

impl embedded_hal::spi::Error for OutOfTime {
    fn kind(&self) -> embedded_hal::spi::ErrorKind {
        embedded_hal::spi::ErrorKind::Other
    }
}

impl embedded_hal::spi::ErrorType for TimedSpi {
    type Error = OutOfTime;
}

impl SpiDevice for TimedSpi {
    fn transaction(&mut self, ops: &mut [Operation<'_, u8>]) -> Result<(), OutOfTime> {
        if WAITED.with(|w| w.0 > w.1) {
            return Err(OutOfTime);
        }
        let _ = self.0.transaction(ops);
        Ok(())
    }
}

enum Slot {
    Empty,
    /// A card with a FAT volume, `None` when it has none.
    Mounted(Option<Volume>),
    /// In the slot, but a block would not read: nothing more is read from
    /// it until it is taken out.
    Faulty,
}

pub struct CardReader {
    /// Its end of `CARD_IN`.
    requests: CardRequests,
    /// Its end of `CARD_OUT`.
    tell: CardTell,
    sd: Sd,
    slot: Slot,
    /// The file being streamed or the listing being written.
    reading: Reading,
    /// Bytes of [`BLOCK`] not yet sent: `at..len`.
    at: u16,
    len: u16,
    /// Failed reads of the block being read.
    failures: u8,
    /// A block that never read, to report once the TX ring has room for
    /// the line (it must not be dropped): its number, how it failed, the
    /// file's ticket.
    faulty: Option<(u32, FlashStr, u8)>,
    /// When the card is next looked for or checked.
    check_at: u32,
}

/// What the reader is reading: one thing at a time (a request drops the
/// last one's).
#[derive(Clone, Copy)]
enum Reading {
    Nothing,
    /// A file, its request's ticket.
    File(File, u8),
    /// `M20` in progress.
    Listing(Listing),
}

/// A directory listing written line by line as the TX ring has room.
#[derive(Clone, Copy)]
struct Listing {
    dir: Dir,
    scan: Scan,
    /// The next entry of the block in `block`; `ENTRIES`: read the next block.
    at: u8,
    ticket: u8,
}

/// Directory entries per block.
const ENTRIES: u8 = (BLOCK / 32) as u8;

/// The block read last. Its file bytes are read in place by the job or
/// the console (`What::Data`): no block is read while one of them waits
/// in `CARD_OUT` ([`data_waits`]). All zeros: in `.bss`.
static BUF: TaskCell<[u8; BLOCK]> = TaskCell::new([0; BLOCK]);

/// The name of the file opened last (`What::Opened`), and its 8.3 name
/// as the directory holds it (a print's checkpoint keeps it).
static OPENED: TaskCell<Name> = TaskCell::new(Name::EMPTY);
static OPENED_SHORT: TaskCell<[u8; 11]> = TaskCell::new([0; 11]);

/// `f` of the file's bytes a `What::Data { at, len }` names.
pub fn bytes<R>(at: u16, len: u8, f: impl FnOnce(&[u8]) -> R) -> R {
    BUF.with(|b| f(&b[usize::from(at)..usize::from(at) + usize::from(len)]))
}

/// Byte `i` of the block (of a `What::Data`'s bytes).
pub fn byte(i: u16) -> u8 {
    BUF.with(|b| b[usize::from(i) % BLOCK])
}

/// The name of the file `What::Opened` announced.
pub fn opened_name() -> Name {
    OPENED.with(|n| *n)
}

/// Its 8.3 name as the directory holds it (`STARDR~1GCO`).
pub fn opened_short() -> [u8; 11] {
    OPENED_SHORT.with(|n| *n)
}

/// File bytes wait in `CARD_OUT`: the block is theirs.
fn data_waits(tell: &CardTell) -> bool {
    tell.any(|m| matches!(m.what, What::Data { .. }))
}

/// A pull waits in `CARD_OUT`: the file bytes queued before it (which
/// their reader leaves there until it wants them) can be dropped.
pub fn removal_waits(news: &CardNews) -> bool {
    news.any(|m| matches!(m.what, What::Removed))
}

/// The card as the FAT reader's block device; remembers the last block
/// asked for, to name it when it fails.
struct Device<'a> {
    sd: &'a Sd,
    lba: u32,
}

impl BlockRead for Device<'_> {
    type Error = SdCardError;
    fn read_block(&mut self, lba: u32, buf: &mut [u8; BLOCK]) -> Result<(), Self::Error> {
        self.lba = lba;
        self.sd
            .read(core::slice::from_mut(spi::as_block(buf)), BlockIdx(lba))
    }
}

/// What a failed read was: a bad block (worth reading again), or no card.
enum Failure {
    /// The block came with a wrong CRC16, or the card sent an error token.
    Block(FlashStr),
    Gone,
}

fn failure(e: &SdCardError) -> Failure {
    match e {
        SdCardError::CrcError(..) => Failure::Block(flash_str!("CRC error")),
        SdCardError::ReadError => Failure::Block(flash_str!("error token")),
        _ => Failure::Gone,
    }
}

impl CardReader {
    pub fn new(spi: CardSpi, requests: CardRequests, tell: CardTell) -> CardReader {
        let options = AcquireOpts {
            use_crc: true,
            acquire_retries: 4,
        };
        CardReader {
            requests,
            tell,
            sd: SdCard::new_with_options(TimedSpi(spi), TimedDelay, options),
            slot: Slot::Empty,
            reading: Reading::Nothing,
            at: 0,
            len: 0,
            failures: 0,
            faulty: None,
            check_at: 0,
        }
    }

    /// One step of work at millisecond `now`; between requests it waits
    /// for the app's once-a-second wake-up (`CHECK_MS`). While the machine
    /// is `moving`, an empty slot is not probed (the probe holds the bus at
    /// the slow init clock).
    pub fn poll(&mut self, now: u32, moving: bool) -> Poll<Signal> {
        WAITED.with(|w| *w = (0, WAIT_STEPS));
        if let Some((lba, what, ticket)) = self.faulty {
            return self.report_faulty(lba, what, ticket);
        }
        if now.wrapping_sub(self.check_at) as i32 >= 0 {
            if self.tell.free() < ROOM {
                return Poll::Wait(Signal::CardRoom);
            }
            // Due again at the app's next once-a-second wake-up, even if
            // that comes a little early against this run.
            self.check_at = now.wrapping_add(CHECK_MS - CHECK_SLACK_MS);
            match self.slot {
                Slot::Empty if moving => {}
                Slot::Empty => return self.look_for_card(),
                _ => {
                    if !self.still_there() {
                        return Poll::Idle;
                    }
                }
            }
        }
        let Slot::Mounted(volume) = self.slot else {
            // Asked of an empty or failed slot: no such file.
            if let Some(Request::Open(_, t) | Request::OpenFirst(t) | Request::List(t)) =
                self.requests.peek()
            {
                if self.tell.free() < ROOM {
                    return Poll::Wait(Signal::CardRoom);
                }
                let _ = self.requests.take();
                send(&self.tell, What::Failed, t);
                return Poll::Again;
            }
            let _ = self.requests.take();
            return Poll::Idle;
        };
        if let Some(request) = self.requests.peek() {
            // Each but `Close` reads blocks: not while file bytes wait
            // (an older request's, which their owner drops).
            let reads = !matches!(request, Request::Close);
            if self.tell.free() < ROOM || reads && data_waits(&self.tell) {
                return Poll::Wait(Signal::CardRoom);
            }
            let _ = self.requests.take();
            match request {
                Request::Open(name, ticket) => self.open(volume, ticket, Some(&name)),
                Request::OpenFirst(ticket) => self.open(volume, ticket, None),
                Request::List(ticket) => self.list_from_start(volume, ticket),
                Request::Close if matches!(self.reading, Reading::File(..)) => {
                    self.reading = Reading::Nothing
                }
                Request::Close => {}
            }
            return Poll::Again;
        }
        match volume {
            Some(v) if matches!(self.reading, Reading::Listing(_)) => self.list(v),
            Some(v) if matches!(self.reading, Reading::File(..)) => self.stream(v),
            _ => Poll::Idle,
        }
    }

    #[inline(never)]
    fn look_for_card(&mut self) -> Poll<Signal> {
        // A pulled card's last bytes may still wait: the next check then.
        if data_waits(&self.tell) {
            return Poll::Idle;
        }
        WAITED.with(|w| w.1 = u16::MAX);
        let present = self.sd.spi(|spi| {
            spi.0.bus.slow_speed();
            spi.0.idle_clocks(10);
            answers_cmd0(&mut spi.0)
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
        self.sd.spi(|spi| spi.0.bus.full_speed());
        let mut dev = Device {
            sd: &self.sd,
            lba: 0,
        };
        let volume = match BUF.with(|b| Volume::mount(&mut dev, b)) {
            Ok(v) if v.end() > blocks => past_end(v.end() - 1, blocks),
            Ok(v) => {
                log_mounted(blocks, v.is_fat32());
                Some(v)
            }
            // The partition's boot sector lies past the card's end.
            Err(FatError::Device(_)) if dev.lba >= blocks => past_end(dev.lba, blocks),
            Err(FatError::Device(e)) => {
                let lba = dev.lba;
                return match failure(&e) {
                    Failure::Block(what) => self.bad_block(lba, what, 0),
                    Failure::Gone => {
                        warn!("card: read failed");
                        self.sd.mark_card_uninit();
                        Poll::Idle
                    }
                };
            }
            Err(_) => {
                warn!("card: no FAT16/FAT32 volume on the card: format it FAT32");
                None
            }
        };
        self.failures = 0;
        self.slot = Slot::Mounted(volume);
        // A card with no usable volume is in the slot all the same: said
        // once (above), not probed for again, and not asked for files.
        let what = match volume {
            Some(_) => What::Inserted,
            None => What::Unusable,
        };
        send(&self.tell, what, 0);
        Poll::Idle
    }

    /// Open the file `name`, or the first G-code file; `Opened` and its
    /// bytes follow. One search for both requests (1 KB less than one
    /// each).
    #[inline(never)]
    fn open(&mut self, volume: Option<Volume>, ticket: u8, name: Option<&Name>) {
        self.reading = Reading::Nothing;
        self.at = 0;
        self.len = 0;
        let Some(v) = volume else {
            return send(&self.tell, What::Failed, ticket);
        };
        let mut dev = Device {
            sd: &self.sd,
            lba: 0,
        };
        let found = BUF
            .with(|b| {
                v.find(&mut dev, b, |e: &Entry| match name {
                    Some(n) => e.matches(n.as_bytes()),
                    None => e.is_gcode(),
                })
            })
            .and_then(|e| v.file(&e).map(|f| (e, f)));
        match found {
            Ok((e, f)) => {
                self.reading = Reading::File(f, ticket);
                OPENED.with(|n| *n = e.name());
                OPENED_SHORT.with(|n| *n = e.short);
                send(&self.tell, What::Opened { size: e.size }, ticket);
            }
            Err(FatError::NotFound) => send(&self.tell, What::Missing, ticket),
            // Reading the directory failed: the job asks again.
            Err(FatError::Device(e)) => {
                let _ = self.read_failed(&e, dev.lba, ticket);
            }
            Err(_) => send(&self.tell, What::Failed, ticket),
        }
    }

    /// A listing from the root directory's start; a file being read is
    /// dropped (the print's `Close` before `List` makes way for it in the
    /// one-slot request ring).
    fn list_from_start(&mut self, volume: Option<Volume>, ticket: u8) {
        match volume {
            Some(v) => {
                self.reading = Reading::Listing(Listing {
                    dir: v.root(),
                    scan: Scan::new(),
                    at: ENTRIES,
                    ticket,
                })
            }
            None => send(&self.tell, What::Failed, ticket),
        }
    }

    /// Lines of the listing while the TX ring has room, `NAME.EXT size
    /// long name` as Marlin's `M20 L`; the next directory block when
    /// this one is done.
    #[inline(never)]
    fn list(&mut self, volume: Volume) -> Poll<Signal> {
        let Reading::Listing(mut l) = self.reading else {
            return Poll::Idle;
        };
        if l.at == ENTRIES {
            let mut dev = Device {
                sd: &self.sd,
                lba: 0,
            };
            match BUF.with(|b| volume.read_dir(&mut l.dir, &mut dev, b)) {
                Ok(true) => l.at = 0,
                Ok(false) => return self.listed(l.ticket),
                // A bad block is read again: the walk moved on only past
                // good blocks.
                Err(FatError::Device(e)) => return self.read_failed(&e, dev.lba, l.ticket),
                Err(_) => return self.listed(l.ticket),
            }
        }
        while l.at < ENTRIES {
            if !crate::reply::room() {
                self.reading = Reading::Listing(l);
                return Poll::After(2);
            }
            let at = usize::from(l.at) * 32;
            let slot = BUF.with(|b| l.scan.take(&b[at..at + 32]));
            l.at += 1;
            match slot {
                DirSlot::End => return self.listed(l.ticket),
                DirSlot::Skip => {}
                DirSlot::File(e) => {
                    let mut r = crate::reply::line();
                    let _ = uwrite!(r, "{} {}", e.short_name(), e.size);
                    if !e.long.is_empty() && e.long != e.short_name() {
                        let _ = uwrite!(r, " {}", e.long);
                    }
                    r.send();
                }
            }
        }
        self.reading = Reading::Listing(l);
        Poll::Again
    }

    fn listed(&mut self, ticket: u8) -> Poll<Signal> {
        self.reading = Reading::Nothing;
        send(&self.tell, What::Listed, ticket);
        Poll::Idle
    }

    /// Sends what is left of the block, then reads the next one.
    #[inline(never)]
    fn stream(&mut self, volume: Volume) -> Poll<Signal> {
        let Reading::File(mut file, ticket) = self.reading else {
            return Poll::Idle;
        };
        while self.at < self.len {
            // `ROOM` slots stay free for the presence check's news: a
            // reader of the file that leaves its bytes waiting (winding
            // between nails, a print behind a long move) still hears of
            // a pull within the next check.
            if self.tell.free() <= ROOM {
                return Poll::Wait(Signal::CardRoom);
            }
            let n = (self.len - self.at).min(CHUNK as u16);
            let at = self.at;
            send(&self.tell, What::Data { at, len: n as u8 }, ticket);
            self.at += n;
        }
        // The next block is read over the bytes still waiting; at the
        // file's end nothing is read, and `End` follows them at once.
        let reads = file.pos() < file.size();
        if self.tell.free() < ROOM || reads && data_waits(&self.tell) {
            return Poll::Wait(Signal::CardRoom);
        }
        let mut dev = Device {
            sd: &self.sd,
            lba: 0,
        };
        match BUF.with(|b| file.read_next(&volume, &mut dev, b)) {
            Ok(0) => {
                self.reading = Reading::Nothing;
                send(&self.tell, What::End, ticket);
                Poll::Idle
            }
            Ok(n) => {
                self.failures = 0;
                self.reading = Reading::File(file, ticket);
                self.at = 0;
                self.len = n as u16;
                Poll::Again
            }
            Err(FatError::Device(e)) => self.read_failed(&e, dev.lba, ticket),
            Err(_) => {
                warn!("card: broken cluster chain");
                self.reading = Reading::Nothing;
                send(&self.tell, What::Failed, ticket);
                Poll::Idle
            }
        }
    }

    /// Block `lba` of the file or directory with `ticket` did not read:
    /// a bad block, or no card. One copy for the three readers.
    #[inline(never)]
    fn read_failed(&mut self, e: &SdCardError, lba: u32, ticket: u8) -> Poll<Signal> {
        match failure(e) {
            Failure::Block(what) => self.bad_block(lba, what, ticket),
            Failure::Gone => {
                self.removed(ticket);
                Poll::Idle
            }
        }
    }

    /// Block `lba` did not read (`what`): read it again, up to [`TRIES`]
    /// times; then the card is faulty and its file failed.
    fn bad_block(&mut self, lba: u32, what: FlashStr, ticket: u8) -> Poll<Signal> {
        self.failures += 1;
        if self.failures < TRIES {
            warn!("card: block ", lba, " ", what, ", reading it again");
            return Poll::Again;
        }
        self.failures = 0;
        self.slot = Slot::Faulty;
        self.faulty = Some((lba, what, ticket));
        self.report_faulty(lba, what, ticket)
    }

    /// Say once that the card is failing (waiting for room for the line),
    /// and fail the file (or the directory it was looked up in); a card
    /// that failed while mounted was never announced to the job.
    #[inline(never)]
    fn report_faulty(&mut self, lba: u32, what: FlashStr, ticket: u8) -> Poll<Signal> {
        if Port::Usb.tx_free() < crate::log::LINE || self.tell.free() < ROOM {
            return Poll::After(2);
        }
        self.faulty = None;
        error!(
            "card: block ",
            lba, " ", what, " ", TRIES, " times: the card is failing, replace it"
        );
        let reading = !matches!(
            core::mem::replace(&mut self.reading, Reading::Nothing),
            Reading::Nothing
        );
        if reading || ticket != 0 {
            send(&self.tell, What::Failed, ticket);
        }
        Poll::Idle
    }

    /// Is the card still in the slot? Asks for its CSD, a second time
    /// after a CRC error (a glitch on the bus is not a pull); a removal is
    /// reported.
    fn still_there(&mut self) -> bool {
        match self.sd.num_bytes() {
            Ok(_) => return true,
            Err(SdCardError::CrcError(..)) => {
                warn!("card: CSD CRC error, asking again");
                if self.sd.num_bytes().is_ok() {
                    return true;
                }
            }
            Err(_) => {}
        }
        let ticket = match self.reading {
            Reading::File(_, t) => t,
            _ => 0,
        };
        self.removed(ticket);
        false
    }

    /// The card stopped answering: pulled out (or dead, which the user
    /// treats the same way). A file being read fails first.
    fn removed(&mut self, ticket: u8) {
        if !matches!(
            core::mem::replace(&mut self.reading, Reading::Nothing),
            Reading::Nothing
        ) {
            send(&self.tell, What::Failed, ticket);
        }
        self.failures = 0;
        self.sd.mark_card_uninit();
        self.slot = Slot::Empty;
        send(&self.tell, What::Removed, 0);
    }
}

/// `card: 9 MiB FAT16`. Out of line, in a frame of its own: inlined into
/// the big frame of `look_for_card`, the AVR back end once stored the
/// digits of `16` wrongly (`FAT1\xff`).
#[inline(never)]
/// Callers check for room first: nothing is refused here.
fn send(tell: &CardTell, what: What, ticket: u8) {
    let _ = tell.push(CardMsg { ticket, what });
}

fn log_mounted(blocks: u32, fat32: bool) {
    let fat = match fat32 {
        true => flash_str!("32"),
        false => flash_str!("16"),
    };
    info!("card: ", blocks / 2048, " MiB FAT", fat);
}

/// A volume whose block `lba` lies past the card's last (`blocks` of
/// them): a partition made for a bigger card. No volume.
#[inline(never)]
fn past_end(lba: u32, blocks: u32) -> Option<Volume> {
    error!(
        "card: partition past the end (block ",
        lba, " of ", blocks, "): format the card"
    );
    None
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
