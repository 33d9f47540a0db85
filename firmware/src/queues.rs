//! Every queue, mailbox and flag that tasks and interrupts share, and the
//! messages they carry: the `app`'s (src/main.rs) table in code. A full
//! ring is back-pressure — the producer keeps its message and tries again
//! — and every ring counts what it sent, refused, and its high-water mark
//! (`$Q`, and the end of a job).
//!
//! The shared state declared here is below, each with its writer → its
//! reader. State that crosses contexts but is kept private beside the
//! one module that reads and writes it (so no other module can touch it):
//!
//! | static | where | writer → reader |
//! | --- | --- | --- |
//! | `EXEC` the step interrupt's state | `stepper.rs` | `TIMER3_COMPA`; tasks only through `Stepper` with the interrupt off or masked (`kick`, `position`, `faults`) |
//! | `WATCHED`, `HIT`, `LAST` the homing switch watched, caught, last read | `endstop.rs` | console (homing) ↔ `TIMER0_COMPA` (`endstop::on_tick` stops the steps) |
//! | `SAMPLER` the buttons' pins and last sample | `buttons.rs` (`IsrCell`) | `TIMER0_COMPA` only (handed over at init) |
//! | `MILLIS`, `ALARM` the clock and the timers' alarm | `board/clock.rs` (masked) | `TIMER0_COMPA` ↔ every task (`clock::millis`, `set_alarm`) |
//! | `FLOW`, `CUT`; USART1's `ON`, `RATE`, `CUT` | `board/usart.rs`, `board/usart1.rs` | receive interrupts ↔ console, `$` settings |
//! | `RX`, `RX1` the ports' received line bytes | `board/usart.rs`, `board/usart1.rs` (the board's only) | receive interrupts → console, through `Port::receive` |
//! | `TX`, `TX1` the ports' replies and log lines | `board/usart.rs`, `board/usart1.rs` (the board's only) | tasks, through a port's `OUTBOX` (`log::Line`, `Port::send`) → transmit interrupts |
//! | `OUTBOX` a port's staged reply | `board/usart.rs`, `board/usart1.rs` | tasks → transmit interrupt (through `TX`, `TX1`) |
//! | `ANSWER` the port a line came from | `board/port.rs` | console → replies (tasks only) |
//! | `DROPPED` log lines lost | `log.rs` (masked) | any context → logger |
//! | `LOG` the log line being built | `log.rs` (`TaskCell`) | tasks only |
//! | `BUF` the card's block, `OPENED` its file's name | `card.rs` (`TaskCell`) | card → job or console, read in place while a `Data` message names it (`card::bytes`) |
//! | `STANDING` overrides, door | `realtime.rs` (`TaskCell`) | `Realtime` task → status reports |
//! | `REALTIME` the real-time commands, `FEED_PRESSES` the feed override's presses | `realtime.rs` (`Flags`, `Tally`) | receive interrupts (`realtime::on_receive`) → `Realtime` task (`Requests::take`) |
//! | `PLANNER` | `motion.rs` (`TaskCell`) | console, job → segment preparation, through `Motion` |
//! | `SHORT_AT` the queued segments under which the refill is urgent | `motion.rs` (an atomic byte) | segment preparation → step interrupt and tick (`motion::urgent`, which spawn the urgent `Refill`) |
//! | `BEGUN` blocks begun, wrapping | `stepper.rs` (an atomic byte) | `TIMER3_COMPA` → console, job, card print (`stepper::blocks_begun`: a checkpoint names the line whose block moves) |
//! | each task's state (`MOTION`, `CONSOLE`, `JOB`, `CARD`, `STORE`, `KIN`, `LED` …), the dispatcher's `SPAWNED`, `READY`, `TIMERS`, `WAITING` | `main.rs` | the app (`SPAWNED`: interrupts → dispatcher) |
//!
//! Queues reached only through their ends: the static is private here,
//! each end a zero-sized type (no RAM, no code) whose push or pop is the
//! only way in, made once by the app's `init_cells` and held in its
//! owner's state. Where two tasks take turns at one side (the card's
//! owner is the job on the string-art machine, the console on a
//! plotter), each holds an end of its own; software tasks never run in
//! each other's middle. The app itself only asks whether a message waits
//! (to spawn its reader), `$Q` reads the counters.
//!
//! | queue | sending end: holder | receiving end: holder |
//! | --- | --- | --- |
//! | `CARD_IN` | [`CardAsk`]: the job, the card print | [`CardRequests`]: the card reader |
//! | `CARD_OUT` | [`CardTell`]: the card reader | [`CardNews`]: the job, the card print |
//! | `JOB_CONTROL` | [`TellJob`]: the console (the `Realtime` task through `Console::tell_job`) | [`JobControls`]: the job |
//! | `SAMPLES` | [`SampleButtons`]: the tick (`buttons::SAMPLER`, with the pins) | [`Samples`]: the buttons task |
//! | `BUTTONS` | [`TellPresses`]: the buttons task | [`Presses`]: the job, the console |
//! | `JOB_CLAIMS_TX` (a flag) | [`ClaimTx`]: the job | [`TxClaim`]: the console |
//!
//! The UART rings (`RX`, `TX`, `RX1`, `TX1`) are private to the board's
//! serial drivers (above): tasks reach them through `Port`. Still `pub
//! static`, reached by name: the step rings (`SEGMENTS`, `BLOCKS`: the
//! step interrupt's assembly addresses `SEGMENTS` by its symbol).

use crate::rt::byte;
use crate::rt::{Mailbox, Ring};
use core::sync::atomic::AtomicBool;
use taut_logic::buttons::ButtonEvent;
use taut_logic::fat::Name;
use taut_logic::sched::QueueStats;
use taut_logic::segment::{Segment, StepBlock};

/// Segment preparation → step interrupt: segments, and the blocks they start.
pub static SEGMENTS: Ring<Segment, SEGMENTS_CAPACITY> = Ring::new();
/// Slots of the segment ring (one fewer can be queued). The shortest
/// segments are a top-speed ramp's, 128 events (2.2 ms at 59 kHz): 15 of
/// them are 33 ms, above the 30 ms under which the refill is urgent; slower
/// segments fill the 40 ms budget with fewer (`motion.rs`). 32 slots were
/// 176 B more.
pub const SEGMENTS_CAPACITY: usize = 16;
pub static BLOCKS: Ring<StepBlock, 8> = Ring::new();

/// Tick → buttons task: one raw sample (bit `Button as u8` = pressed) per
/// millisecond while active. Full: the sample is refused and counted (the
/// task fell 15 ms behind; a press then counts a little late). Private:
/// reached through its ends, [`SampleButtons`] and [`Samples`].
static SAMPLES: Ring<u8, 16> = Ring::new();

/// `SAMPLES`' sending end: the tick's, kept with the pins it samples
/// (`buttons::start` hands both to the interrupt).
pub struct SampleButtons(());

impl SampleButtons {
    #[inline(always)]
    pub fn push(&self, raw: u8) -> Result<(), u8> {
        SAMPLES.push(raw)
    }
}

/// `SAMPLES`' receiving end: the buttons task's.
pub struct Samples(());

impl Samples {
    #[inline(always)]
    pub fn pop(&self) -> Option<u8> {
        SAMPLES.pop()
    }
}

/// `SAMPLES`' ends, made once, by the app's init: the tick's, the buttons
/// task's.
pub fn samples_ends() -> (SampleButtons, Samples) {
    (SampleButtons(()), Samples(()))
}

/// `SAMPLES`' counters and capacity (`$Q`).
pub fn samples_stats() -> (QueueStats, usize) {
    (SAMPLES.stats(), SAMPLES.capacity())
}
/// Buttons task → job, or a plotter's console (its card print). Full:
/// refused and counted (the job is far behind a human's presses).
/// Private: reached through its ends, [`TellPresses`] and [`Presses`].
static BUTTONS: Ring<ButtonEvent, 8> = Ring::new();

/// `BUTTONS`' sending end: the buttons task's.
pub struct TellPresses(());

impl TellPresses {
    #[inline(always)]
    pub fn push(&self, e: ButtonEvent) -> Result<(), ButtonEvent> {
        BUTTONS.push(e)
    }
}

/// `BUTTONS`' receiving end: the job's and the console's (only the card's
/// owner, the job on the string-art machine, the console on a plotter,
/// runs to take presses).
pub struct Presses(());

impl Presses {
    #[inline(always)]
    pub fn pop(&self) -> Option<ButtonEvent> {
        BUTTONS.pop()
    }
}

/// `BUTTONS`' ends, made once, by the app's init: the buttons task's, the
/// job's, the console's.
pub fn buttons_ends() -> (TellPresses, Presses, Presses) {
    (TellPresses(()), Presses(()), Presses(()))
}

/// `BUTTONS`' counters and capacity (`$Q`).
pub fn buttons_stats() -> (QueueStats, usize) {
    (BUTTONS.stats(), BUTTONS.capacity())
}

/// Job or console (a plotter's card print) → card reader: the newest
/// request (the reader takes them first; a newer one replaces it).
/// Private: reached through its ends, [`CardAsk`] and [`CardRequests`].
static CARD_IN: Mailbox<Request> = Mailbox::new();

/// `CARD_IN`'s sending end: the job's and the console's card print's.
/// Zero-sized: a right, not a pointer.
pub struct CardAsk(());

impl CardAsk {
    /// Leave `request` for the reader, replacing one still waiting.
    pub fn put(&self, request: Request) {
        CARD_IN.put(request)
    }
}

/// `CARD_IN`'s receiving end: the card reader's.
pub struct CardRequests(());

impl CardRequests {
    pub fn peek(&self) -> Option<Request> {
        CARD_IN.peek()
    }

    pub fn take(&self) -> Option<Request> {
        CARD_IN.take()
    }
}

/// `CARD_IN`'s ends, made once, by the app's init: the job's, the card
/// print's, the reader's.
pub fn card_in_ends() -> (CardAsk, CardAsk, CardRequests) {
    (CardAsk(()), CardAsk(()), CardRequests(()))
}

/// A request waits for the reader (the app then spawns it).
pub fn card_request_waits() -> bool {
    !CARD_IN.is_empty()
}

/// `CARD_IN`'s counters and capacity (`$Q`).
pub fn card_in_stats() -> (QueueStats, usize) {
    (CARD_IN.stats(), CARD_IN.capacity())
}
/// Card reader → job or console, its four slots usable. Full: the reader
/// keeps its block and waits. A file's bytes take at most two
/// (`card::ROOM` stay free for a removal's news). Private: reached
/// through its ends, [`CardTell`] and [`CardNews`].
static CARD_OUT: Ring<CardMsg, 4, true> = Ring::new();

/// `CARD_OUT`'s sending end: the card reader's.
pub struct CardTell(());

impl CardTell {
    #[inline(always)]
    pub fn push(&self, msg: CardMsg) -> Result<(), CardMsg> {
        CARD_OUT.push(msg)
    }

    #[inline(always)]
    pub fn free(&self) -> usize {
        CARD_OUT.free()
    }

    /// Whether a message still waiting is `f`'s: the reader's block is
    /// lent to the file bytes waiting.
    #[inline(always)]
    pub fn any(&self, f: impl Fn(&CardMsg) -> bool) -> bool {
        CARD_OUT.any(f)
    }
}

/// `CARD_OUT`'s receiving end: the job's and the card print's (only the
/// card's owner, the job on the string-art machine, the console on a
/// plotter, runs to take messages). `Clone` so that its holder can lend
/// it to itself: the job handles a message read in place with all of
/// itself borrowed (a copy of the message would deepen the stack).
#[derive(Clone)]
pub struct CardNews(());

impl CardNews {
    /// `f` of the oldest message, read in place.
    #[inline(always)]
    pub fn peek_with<R>(&self, f: impl FnOnce(&CardMsg) -> R) -> Option<R> {
        CARD_OUT.peek_with(f)
    }

    #[inline(always)]
    pub fn pop(&self) -> Option<CardMsg> {
        CARD_OUT.pop()
    }

    /// Whether any waiting message is `f`'s.
    #[inline(always)]
    pub fn any(&self, f: impl Fn(&CardMsg) -> bool) -> bool {
        CARD_OUT.any(f)
    }
}

/// `CARD_OUT`'s ends, made once, by the app's init: the reader's, the
/// job's, the card print's.
pub fn card_out_ends() -> (CardTell, CardNews, CardNews) {
    (CardTell(()), CardNews(()), CardNews(()))
}

/// A message waits for the card's owner (the app then spawns it).
#[inline(always)]
pub fn card_message_waits() -> bool {
    !CARD_OUT.is_empty()
}

/// `CARD_OUT`'s free slots (the app signals `CardRoom` over `card::ROOM`).
#[inline(always)]
pub fn card_out_free() -> usize {
    CARD_OUT.free()
}

/// `CARD_OUT`'s counters and capacity (`$Q`).
pub fn card_out_stats() -> (QueueStats, usize) {
    (CARD_OUT.stats(), CARD_OUT.capacity())
}
/// File bytes per message at most.
pub const CHUNK: usize = 32;

/// Console → job: its operator's tools, and from its real-time bytes
/// (the `Realtime` task) `~` with no feed hold and Ctrl-X. Private:
/// reached through its ends, [`TellJob`] and [`JobControls`].
static JOB_CONTROL: Ring<Control, 4> = Ring::new();

/// `JOB_CONTROL`'s sending end: the console's, which the `Realtime` task
/// uses too (both are software tasks, never running in each other's
/// middle).
pub struct TellJob(());

impl TellJob {
    #[inline(always)]
    pub fn push(&self, c: Control) -> Result<(), Control> {
        JOB_CONTROL.push(c)
    }
}

/// `JOB_CONTROL`'s receiving end: the job's.
pub struct JobControls(());

impl JobControls {
    #[inline(always)]
    pub fn pop(&self) -> Option<Control> {
        JOB_CONTROL.pop()
    }
}

/// `JOB_CONTROL`'s ends, made once, by the app's init: the console's,
/// the job's.
pub fn job_control_ends() -> (TellJob, JobControls) {
    (TellJob(()), JobControls(()))
}

/// A word waits for the job (the app then spawns it).
#[inline(always)]
pub fn job_control_waits() -> bool {
    !JOB_CONTROL.is_empty()
}

/// `JOB_CONTROL`'s counters and capacity (`$Q`).
pub fn job_control_stats() -> (QueueStats, usize) {
    (JOB_CONTROL.stats(), JOB_CONTROL.capacity())
}

/// The job waits for room in the TX ring for a line it must not drop (a
/// prompt, a bad file's message): the console holds its replies meanwhile,
/// or a stream of replies would keep the ring full for as long as it lasts.
/// Private: reached through its ends, [`ClaimTx`] and [`TxClaim`].
static JOB_CLAIMS_TX: AtomicBool = AtomicBool::new(false);

/// `JOB_CLAIMS_TX`'s writing end: the job's.
pub struct ClaimTx(());

impl ClaimTx {
    #[inline(always)]
    pub fn set(&self, claimed: bool) {
        byte::store_bool(&JOB_CLAIMS_TX, claimed)
    }

    #[inline(always)]
    pub fn claimed(&self) -> bool {
        byte::load_bool(&JOB_CLAIMS_TX)
    }
}

/// `JOB_CLAIMS_TX`'s reading end: the console's.
pub struct TxClaim(());

impl TxClaim {
    #[inline(always)]
    pub fn claimed(&self) -> bool {
        byte::load_bool(&JOB_CLAIMS_TX)
    }
}

/// `JOB_CLAIMS_TX`'s ends, made once, by the app's init: the job's, the
/// console's.
pub fn claims_tx_ends() -> (ClaimTx, TxClaim) {
    (ClaimTx(()), TxClaim(()))
}

/// What the job (string art) or the console (a plotter's card print)
/// asks of the card reader.
#[derive(Clone, Copy)]
pub enum Request {
    /// Stream this file (8.3 or long name) from its start, dropping the
    /// one being read; the number is the ticket its messages carry.
    Open(Name, u8),
    /// The same for the first G-code file of the root directory.
    OpenFirst(u8),
    /// Write the root directory's files to the serial line, then `Listed`.
    List(u8),
    /// Stop streaming the file.
    Close,
}

/// What the card reader tells the job. `ticket` numbers the `Open` request
/// a file message answers, so the job can drop what an older one sent.
#[derive(Clone, Copy)]
pub struct CardMsg {
    pub ticket: u8,
    pub what: What,
}

#[derive(Clone, Copy)]
pub enum What {
    Inserted,
    /// A card is in the slot, but without a volume to read (no FAT, or a
    /// partition past its end): the reason is logged.
    Unusable,
    Removed,
    /// The file asked for is open (its name: `card::opened_name`); its
    /// bytes follow.
    Opened {
        size: u32,
    },
    /// The listing asked for is written.
    Listed,
    /// The next bytes of the file: `len` bytes of the reader's block from
    /// `at`, read in place (`card::bytes`): no copy of them in the queue.
    /// The reader reads no block while one waits.
    Data {
        at: u16,
        len: u8,
    },
    End,
    /// No such file on the card.
    Missing,
    /// The card failed mid-file (a `Removed` follows), or holds no volume.
    Failed,
}

/// The console's word for the job.
#[derive(Clone, Copy)]
pub enum Control {
    /// `~` with no feed hold on: resume a paused job.
    Resume,
    /// Ctrl-X: the machine was stopped at once; end the job.
    Abort,
    /// Console → job: an operator's tool (`crate::tools`).
    Tool(taut_logic::stringart::job::tools::Tool),
}

/// Conditions a task can wait for ([`crate::rt::Poll::Wait`]): the app
/// runs the waiting tasks when the condition's producer signals it.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Signal {
    /// The planner has room for a block: the refill took one, the step
    /// interrupt began one, or the machine came to rest (all of it free).
    PlannerRoom,
    /// The step queue is refilled (`Motion::refilling` is over).
    Refilled,
    /// The job took messages from `CARD_OUT`.
    CardRoom,
    /// A `$` setting changed: the store writes it to EEPROM.
    Settings,
}

/// Number of [`Signal`]s.
pub const SIGNALS: usize = 4;
