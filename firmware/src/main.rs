//! taut firmware for the Arduino Mega 2560: the `app`.
//!
//! The machine at a glance, RTIC style. Hardware tasks (interrupts) do the
//! least work possible and spawn software tasks; software tasks run to
//! completion from the dispatcher, highest priority first, FIFO within a
//! priority, and never preempt each other. Every queue and flag they share
//! is in `queues`; a task that must wait returns `rt::Poll`, and
//! [`reschedule`] runs it again after a delay or on a [`Signal`].
//!
//! The software tasks, their priorities, inputs and outputs are declared
//! once, in the `tasks!` list below: the [`Task`] enum's doc is their
//! table. The hardware tasks:
//!
//! | interrupt | priority | input | output |
//! | --- | --- | --- | --- |
//! | `TIMER3_COMPA` step events | above all | `SEGMENTS`, `BLOCKS` | STEP/DIR pins |
//! | `TIMER0_COMPA` 1 ms tick, button sampling | nested | clock, timer alarm | `SAMPLES` |
//! | `USART0_RX` | nested | a byte | `REALTIME` (`?` `!` `~` Ctrl-X, which also stops the steps), else `RX` |
//! | `USART0_UDRE` | nested | `TX` | the wire |
//! | `USART1_RX`, `USART1_UDRE` the second console (off on the string-art machine) | nested | a byte; `TX1` | as USART0's (`?` flagged apart), `RX1`; the wire |
#![no_std]
#![no_main]
#![deny(unsafe_code)]
#![feature(abi_avr_interrupt, asm_experimental_arch, optimize_attribute)]

use embedded_hal::digital::OutputPin;
use panic_halt as _;
use taut_firmware::board::eeprom::Eeprom;
use taut_firmware::board::gpio::{Output, Pin};
use taut_firmware::board::servo::PenServo;
use taut_firmware::board::spi::CardSpi;
use taut_firmware::board::{
    self, clock, port::Port, step_timer::StepTimer, usart, usart1, watchdog::Watchdog, ResetCause,
    F_CPU,
};
use taut_firmware::buttons::{self, ButtonPins, ButtonsTask};
use taut_firmware::card::{self, CardReader};
use taut_firmware::checkpoint;
use taut_firmware::console::{Activity, Console, Owner};
use taut_firmware::drivers::{Drivers, EnablePins};
use taut_firmware::job::JobTask;
use taut_firmware::motion::{self, Motion};
use taut_firmware::queues::{
    self, CardAsk, CardNews, CardRequests, CardTell, ClaimTx, Control, JobControls, Presses,
    SampleButtons, Signal, TellJob, TxClaim, SIGNALS,
};
use taut_firmware::realtime::{self, Requests, STANDING};
use taut_firmware::rt::dispatch::{self, spawn_from_isr, Spawned};
use taut_firmware::rt::{self, stack, Poll, TaskCell};
use taut_firmware::stepper::{self, CoilPins, StepDirPins, Stepper};
use taut_firmware::store::Store;
use taut_firmware::{
    board::usart::{RXCIE0, UDRIE0},
    board::usart1::{RXCIE1, UDRIE1},
    nested_vector, step_vector,
};
use taut_firmware::{endstop, flash_str, info, reply, warn};
use taut_logic::checkpoint::Found;
use taut_logic::config::{MachineConfig, PenConfig};
use taut_logic::kinematics::{AnyKinematics, Linear};
use taut_logic::machine::Machine;
use taut_logic::planner::Overrides;
use taut_logic::sched::{Ready, Timers};

taut_firmware::tasks! {
    Timers {
        priority: 3,
        runs: timers,
        does: "fires due timers",
        input: "`TIMERS`",
        output: "",
    },
    Realtime {
        priority: 5,
        runs: realtime,
        does: "status, hold, resume, reset",
        input: "`REALTIME`",
        output: "`TX`, `TX1`, `JOB_CONTROL` (the console's end)",
    },
    Refill {
        priority: 3,
        runs: prepare_segments,
        does: "planner → segments while the step queue holds < 30 ms of motion, a part per run, yielding to a ready task between parts",
        input: "planner",
        output: "`SEGMENTS`, `BLOCKS`; signals `PlannerRoom`; `Refilled` once the queue holds 16 ms or nothing is left to cut",
    },
    Prepare {
        priority: 1,
        runs: prepare_segments,
        does: "planner → segments in the background: the step queue is long enough, or the machine is not stepping",
        input: "planner",
        output: "as `Refill`",
    },
    // Above the urgent refill: a ready console waits for at most one part
    // of a segment (the refill yields at its parts' boundaries,
    // `Motion::yield_to`), and its own runs are short.
    Console {
        priority: 4,
        runs: console,
        does: "one G-code line per run (waits for `Refilled` while the step queue runs short inside planned motion); a plotter's card print",
        input: "`RX`, `RX1`; on a plotter `BUTTONS`, `CARD_OUT`",
        output: "planner, `TX`, `TX1`, `CARD_IN`, `JOB_CONTROL`; signals `CardRoom`",
    },
    Buttons {
        priority: 2,
        runs: buttons,
        does: "debouncing, long presses",
        input: "`SAMPLES`",
        output: "`BUTTONS`",
    },
    Job {
        priority: 2,
        runs: job,
        does: "the string-art job's state machine",
        input: "`BUTTONS`, `CARD_OUT`, `JOB_CONTROL`",
        output: "planner, `CARD_IN`, `TX`; signals `CardRoom`",
    },
    Card {
        priority: 1,
        runs: card,
        does: "SD reader: one block per run",
        input: "`CARD_IN`, every 1 s",
        output: "`CARD_OUT`",
    },
    Logger {
        priority: 0,
        runs: logger,
        does: "deferred reports",
        input: "every 1 s",
        output: "`TX`",
    },
    Led {
        priority: 2,
        runs: led,
        does: "status LED pattern (timed edges: runs before the long tasks)",
        input: "its timer",
        output: "",
    },
    Store {
        priority: 0,
        runs: store,
        does: "checkpoint, settings, coordinates, startup lines → EEPROM (two copies each), a changed byte per run",
        input: "the job's checkpoint, signal `Settings`",
        output: "EEPROM",
    },
}

/// Task ids spawned by interrupts, moved into `READY` by the dispatcher.
static SPAWNED: Spawned = Spawned::new();
// Software tasks only: no masking needed.
static READY: TaskCell<Ready<Task, { Task::ALL.len() }, { Task::LEVELS }>> =
    TaskCell::new(Ready::new());
static TIMERS: TaskCell<Timers<Task, 8>> = TaskCell::new(Timers::new());
/// Tasks waiting for each [`Signal`] (bit = task).
static WAITING: TaskCell<[u16; SIGNALS]> = TaskCell::new([0; SIGNALS]);
static MOTION: TaskCell<Motion> = TaskCell::zeroed();
static CONSOLE: TaskCell<Console> = TaskCell::zeroed();
static CONFIG: TaskCell<MachineConfig> = TaskCell::zeroed();
/// The kinematics of `CONFIG`, rebuilt when a setting changes.
static KIN: TaskCell<AnyKinematics> = TaskCell::zeroed();
static BUTTONS_TASK: TaskCell<ButtonsTask> = TaskCell::zeroed();
static JOB: TaskCell<JobTask> = TaskCell::zeroed();
static CARD: TaskCell<CardReader> = TaskCell::zeroed();
static STORE: TaskCell<Store> = TaskCell::zeroed();

/// Boot blink of the status LED: this many flashes, 100 ms on, 100 ms off.
const BOOT_BLINKS: u32 = 3;
const LOGGER_PERIOD_MS: u32 = 1000;
/// A console waiting while a print moves looks at its checkpoint this
/// often (a record is due every `plot::RECORD_EVERY_MS`).
const RECORD_CHECK_MS: u32 = taut_logic::checkpoint::plot::RECORD_EVERY_MS / 4;

/// Make `task` ready, after what the interrupts spawned meanwhile.
fn spawn(task: Task) {
    READY.with(|r| {
        dispatch::admit(&SPAWNED, r, task_of);
        r.spawn(task)
    });
}

/// Run `task` again as its `poll` asks.
fn reschedule(task: Task, poll: Poll<Signal>) {
    match poll {
        Poll::Idle => {}
        Poll::Again => spawn(task),
        Poll::After(ms) => spawn_after(task, ms as u32),
        Poll::Wait(s) => WAITING.with(|w| w[s as usize] |= 1 << task as u8),
    }
}

/// `s` happened: run the tasks waiting for it.
fn signal(s: Signal) {
    let mut waiting = WAITING.with(|w| core::mem::take(&mut w[s as usize]));
    // A bit at a time: a shift by `id` is a loop on the AVR, and the
    // segment preparation signals after nearly every run, mostly to no one.
    let mut id = 0;
    while waiting != 0 {
        if waiting & 1 != 0 {
            spawn(task_of(id));
        }
        waiting >>= 1;
        id += 1;
    }
}

/// Spawn `task` in `ms`, replacing its earlier one-shot timer.
fn spawn_after(task: Task, ms: u32) {
    arm(|t, now| t.spawn_after(task, now, ms).is_ok());
}

fn spawn_every(task: Task, ms: u32) {
    arm(|t, now| t.every(task, now, ms).is_ok());
}

/// Add a timer and point the tick's alarm at the earliest deadline.
fn arm(add: impl FnOnce(&mut Timers<Task, 8>, u32) -> bool) {
    let now = clock::millis();
    let (ok, next) = TIMERS.with(|t| (add(t, now), t.ms_to_next(now)));
    if !ok {
        warn!("timers full");
    }
    if let Some(ms) = next {
        clock::set_alarm(now.wrapping_add(ms));
    }
}

#[avr_device::entry]
fn main() -> ! {
    stack::paint();
    // Before `init`: the cells' values are built on the stack (a console
    // is ~480 B), not above `init`'s frame.
    let ends = init_cells();
    let watchdog = init(ends);
    dispatch::run(
        &SPAWNED,
        &READY,
        task_of,
        clock::millis,
        || watchdog.feed(),
        Task::run,
    )
}

/// The board, the tasks' state, the first tasks. Its own frame: the
/// set-up's locals are gone from the stack before the dispatcher starts.
#[inline(never)]
#[optimize(size)]
fn init(ends: Ends) -> Watchdog {
    let dp = avr_device::atmega2560::Peripherals::take().unwrap();
    let reset = ResetCause::take(&dp.CPU);
    let watchdog = Watchdog::start(dp.WDT);
    let pins = board::gpio::Pins::new(
        dp.PORTA, dp.PORTB, dp.PORTC, dp.PORTD, dp.PORTE, dp.PORTF, dp.PORTG, dp.PORTH, dp.PORTJ,
        dp.PORTK, dp.PORTL,
    );
    let status_led = pins.d13.into_output_at(false);
    clock::Clock::start(dp.TC0);
    usart::Usart0::start(dp.USART0);
    let (store_now, found) = load_store(Eeprom::new(dp.EEPROM));
    // The stored `G54` offset in force.
    STORE.with(|s| CONSOLE.with(|c| c.boot(s.coords())));
    start_kinematics();
    let enable = EnablePins {
        base: pins.d38.into_output(),
        radial: pins.a2.into_output(),
        drill: pins.a8.into_output(),
    };
    let step_dir = StepDirPins {
        base_step: pins.a0.into_output_at(false),
        base_dir: pins.a1.into_output_at(false),
        radial_step: pins.a6.into_output_at(false),
        radial_dir: pins.a7.into_output_at(false),
        drill_step: pins.d46.into_output_at(false),
        drill_dir: pins.d48.into_output_at(false),
    };
    let coils = CoilPins {
        x: (
            pins.d22.into_output_at(false),
            pins.d23.into_output_at(false),
            pins.d24.into_output_at(false),
            pins.d25.into_output_at(false),
        ),
        y: (
            pins.d26.into_output_at(false),
            pins.d27.into_output_at(false),
            pins.d28.into_output_at(false),
            pins.d29.into_output_at(false),
        ),
        z: (
            pins.d37.into_output_at(false),
            pins.d36.into_output_at(false),
            pins.d35.into_output_at(false),
            pins.d34.into_output_at(false),
        ),
    };
    let stepper = CONFIG.with(|c| Stepper::new(step_dir, coils, StepTimer::start(dp.TC3), c));
    // After the stepper: a coil axis's driver is its coils.
    let drivers = CONFIG.with(|c| Drivers::new(enable, c));
    // The pen starts up, whatever the machine (SERVO0 is unused on the
    // string-art machine).
    let pen = PenServo::start(
        dp.TC1,
        pins.d11.into_output(),
        PenConfig::pulse_us(CONFIG.with(|c| c.pen.up_deg)),
    );
    CONFIG.with(|c| motion::configure_planner(c));
    start_motion(stepper, drivers, pen);
    start_card(
        CardSpi::start(dp.SPI, pins.d52, pins.d51, pins.d50, pins.d53),
        ends.card_requests,
        ends.card_tell,
    );
    buttons::start(
        ButtonPins {
            confirm: pins.d2.into_pull_up_input(),
            zero_base: pins.d3.into_pull_up_input(),
            zero_radial: pins.d14.into_pull_up_input(),
            zero_drill: pins.d18.into_pull_up_input(),
        },
        ends.sample_buttons,
    );
    rt::enable_interrupts();
    reply::banner();

    boot_log(reset);
    // A plotter's print a cut stopped: the console offers it.
    if let Found::Plot(_) = found {
        if !CONFIG.with(|c| c.machine.is_string_art()) {
            CONSOLE.with(|c| c.offer_print());
            spawn(Task::Console);
        }
    }
    let (saved, note) = checkpoint::found(found, reset);
    match store_now || STORE.with(|s| s.saving()) {
        true => spawn(Task::Store),
        false => reschedule(Task::Store, Poll::Wait(Signal::Settings)),
    }
    spawn_every(Task::Logger, LOGGER_PERIOD_MS);
    spawn_every(Task::Card, card::CHECK_MS);
    JOB.with(|j| j.power_on(saved, note, clock::millis()));
    spawn(Task::Job);
    spawn(Task::Card);
    // A machine that homes at power-on (the flatbed's X) does so first.
    let homing = CONFIG.with(|c| c.homing);
    let enabled = CONFIG.with(|c| STORE.with(|s| s.extras().homing_enabled(c)));
    if homing.at_start && enabled {
        info!("homing");
        MOTION.with(|m| CONSOLE.with(|c| c.start_homing(homing.axes, m, false)));
    }
    // The startup lines (after the homing, if any).
    if homing.at_start && enabled || startup_lines() {
        spawn(Task::Console);
    }
    // Last: the blinks are timed from here, the dispatcher's start. The
    // first flash begins here too: the task first runs a millisecond or
    // so later, behind the boot's higher-priority tasks.
    let mut status_led = status_led;
    let _ = status_led.set_high();
    LED.init(StatusLed {
        pin: status_led,
        start: clock::millis(),
        done: false,
    });
    spawn(Task::Led);

    watchdog
}

/// The zeroed cells' values (in `.bss`: their starting values in `.data`
/// were 2 KB of flash, nearly all zeros). Out of `init`: a value built on
/// the stack would stay in its frame under everything it calls.
#[inline(never)]
#[optimize(size)]
fn init_cells() -> Ends {
    let (job_asks, print_asks, card_requests) = queues::card_in_ends();
    let (card_tell, job_news, print_news) = queues::card_out_ends();
    let (tell_job, job_controls) = queues::job_control_ends();
    let (tell_presses, job_presses, console_presses) = queues::buttons_ends();
    let (claim_tx, tx_claim) = queues::claims_tx_ends();
    init_console(print_asks, print_news, tell_job, console_presses, tx_claim);
    init_job(job_asks, job_news, job_controls, job_presses, claim_tx);
    let (sample_buttons, samples) = queues::samples_ends();
    BUTTONS_TASK.init(ButtonsTask::new(samples, tell_presses));
    Ends {
        card_requests,
        card_tell,
        sample_buttons,
    }
}

/// The console, built in a frame of its own: not on top of the job's
/// (the deepest stack of a run is the boot's, these two).
#[inline(never)]
fn init_console(card: CardAsk, news: CardNews, job: TellJob, presses: Presses, claim: TxClaim) {
    CONSOLE.init(Console::new(card, news, job, presses, claim));
}

/// The job task, in a frame of its own.
#[inline(never)]
fn init_job(
    asks: CardAsk,
    news: CardNews,
    controls: JobControls,
    presses: Presses,
    claim: ClaimTx,
) {
    JOB.init(JobTask::new(asks, news, controls, presses, claim));
}

/// The queue ends `init_cells` leaves for `init`, which makes their
/// holders: the card reader's, the tick's.
struct Ends {
    card_requests: CardRequests,
    card_tell: CardTell,
    sample_buttons: SampleButtons,
}

/// The kinematics of the settings loaded. Settings are only taken whole,
/// their kinematics checked (`settings::check_whole`), so `of` cannot fail
/// here; were it to, the cylindrical kinematics (always made) keeps the
/// machine answering rather than halting it at boot.
#[optimize(size)]
fn start_kinematics() {
    CONFIG.with(|c| {
        KIN.init(
            AnyKinematics::of(c).unwrap_or_else(|_| AnyKinematics::Linear(Linear::cylindrical(c))),
        )
    });
}

/// `CONFIG` changed: its kinematics, the old kept if the new settings had
/// none (they cannot: they are taken whole).
fn kinematics_changed() {
    CONFIG.with(|cfg| {
        KIN.with(|kin| {
            if let Ok(k) = AnyKinematics::of(cfg) {
                *kin = k;
            }
        })
    });
}

/// Settings and checkpoint from EEPROM into `CONFIG` and `STORE`: whether
/// the store has bytes to write, and the checkpoint found. Out of `init`
/// (also `boot_log`): their locals would stay in `init`'s frame under
/// everything it calls (the stack peak at boot).
#[inline(never)]
#[optimize(size)]
fn load_store(eeprom: Eeprom) -> (bool, Found) {
    // The store made in its cell (~300 B: not on init's stack), CONFIG
    // as the defaults, read from flash (a starting value in `.data` would
    // be a second copy of them in flash), in place: a copy would sit on
    // init's stack.
    STORE.init_with(|s| s.write(Store::new(eeprom)));
    CONFIG.init_with(|c| MachineConfig::init_defaults(Machine::StringArt, c));
    STORE.with(|store| {
        let store_now = CONFIG.with(|c| store.load(c));
        usart::set_xonxoff(store.extras().xonxoff());
        usart::release_sender();
        CONFIG.with(|c| usart1::configure(store.extras().uart1(c.machine)));
        (store_now, store.load_checkpoint())
    })
}

#[inline(never)]
#[optimize(size)]
fn boot_log(reset: ResetCause) {
    info!(
        flash_str!(concat!(
            "taut ",
            env!("CARGO_PKG_VERSION"),
            " git ",
            env!("TAUT_GIT_HASH"),
            " atmega2560 "
        )),
        F_CPU / 1_000_000,
        "MHz reset:",
        reset.name()
    );
    if reset == ResetCause::Watchdog {
        warn!("watchdog reset: a task did not return");
    }
}

/// Segment preparation's state (`Motion`). Out of `init` (also `start_card`): built on
/// the stack and copied into place, a big value would stay in `init`'s
/// frame under everything `init` calls (the stack peak at boot).
#[inline(never)]
#[optimize(size)]
fn start_motion(stepper: Stepper, drivers: Drivers, pen: PenServo) {
    MOTION.init_with(|m| {
        let motion = m.write(Motion::new(stepper, drivers, pen));
        motion.yield_to(others_ready);
        motion
    });
}

/// Another task waits to run (an interrupt spawned it, or it is ready): a
/// segment preparation run ends at its next part's boundary. Read without masking, as
/// `dispatch::admit` looks first: with masked reads on every spawn and
/// check, the `scheduler` HIL test measured a cruise pulse 2.03 µs off its
/// grid (the bar is 2).
fn others_ready() -> bool {
    !SPAWNED.seems_empty() || READY.with(|r| !r.is_empty())
}

/// Every task but the console and segment preparation itself (the step
/// interrupt asks for it), as bits: a stream's bytes keep the console
/// ready nearly always, and it loses nothing by taking them a few at a
/// time.
const NOT_STREAMING: u16 =
    !(1 << Task::Console as u8 | 1 << Task::Prepare as u8 | 1 << Task::Refill as u8);

/// One of [`NOT_STREAMING`] spawned by an interrupt: during a run of
/// segment preparation the ready set changes no other way.
fn others_spawned() -> bool {
    SPAWNED.seems_any(NOT_STREAMING)
}

#[inline(never)]
#[optimize(size)]
fn start_card(spi: CardSpi, requests: CardRequests, tell: CardTell) {
    CARD.init_with(|c| c.write(CardReader::new(spi, requests, tell)));
}

/// Move due timers into the ready set and re-arm the tick's alarm.
#[inline(never)]
fn timers() {
    let now = clock::millis();
    let next = TIMERS.with(|t| {
        while let Some(task) = t.due(now) {
            spawn(task);
        }
        t.ms_to_next(now)
    });
    if let Some(ms) = next {
        clock::set_alarm(now.wrapping_add(ms));
    }
}

#[inline(never)]
#[optimize(speed)]
fn prepare_segments() {
    /// Pieces of work per run (a part of a block's profile or of a
    /// segment, ≤ ~1 ms each): one keeps a waiting task's wait short, and
    /// up to `MOST` while no task but the console waits: a stream of tiny
    /// moves needs ~10 pieces a line, and each switch between the two
    /// costs both a run's overhead (the fine curve: 649 mm/min at one
    /// piece a run, 694 at up to eight, 698 at up to twelve).
    const BATCH: usize = 1;
    const MOST: usize = 12;
    let most = match READY.with(|r| r.pending_mask() & NOT_STREAMING != 0) {
        true => BATCH,
        false => MOST,
    };
    let (freed, more, idle, stepping, release, refilling) = MOTION.with(|m| {
        let (freed, more) = m.refill(BATCH, most, others_spawned);
        let idle = m.is_idle();
        // The clock only while standing: reading it masks interrupts,
        // which would delay a step.
        let release = match idle {
            true => m.drivers.idle(clock::millis()),
            false => {
                m.drivers.moving();
                None
            }
        };
        (
            freed,
            more,
            idle,
            m.stepper.is_running(),
            release,
            m.refilling(),
        )
    });
    // Drivers wait to go off after the step idle delay (`$1`).
    if let Some(ms) = release {
        spawn_after(Task::Prepare, ms);
    }
    // Urgent only while steps run out of it: standing, a motion's first
    // profile and segments wait behind a console line (≤ 1 ms) rather
    // than keep a `?` or a line waiting ~7 ms for all their parts.
    if more {
        spawn(if stepping {
            refill_task()
        } else {
            Task::Prepare
        });
    }
    if freed || idle {
        signal(Signal::PlannerRoom);
    }
    // A console waiting for the refill (`Motion::starving`, a piece held
    // back) goes on.
    if !refilling {
        signal(Signal::Refilled);
    }
}

/// Urgent refill while the step queue is short, background otherwise.
#[inline(always)]
fn refill_task() -> Task {
    if motion::urgent() {
        Task::Refill
    } else {
        Task::Prepare
    }
}

#[inline(never)]
#[optimize(speed)]
fn console() {
    let owner = match JOB.with(|j| j.owns_motion()) {
        true => Owner::Job,
        false => Owner::Console,
    };
    let (poll, store_due) = MOTION.with(|m| {
        CONFIG.with(|cfg| {
            KIN.with(|kin| {
                STORE.with(|s| {
                    let poll = CONSOLE.with(|c| c.poll(m, kin, cfg, owner, s));
                    (poll, s.wants_run())
                })
            })
        })
    });
    // A `$` change or a coordinate write goes to EEPROM.
    if store_due {
        signal(Signal::Settings);
    }
    // New moves may be queued: segment preparation feeds them to the stepper.
    spawn(Task::Prepare);
    // A print's checkpoint write (or its offer) waits for the store or for
    // room: the console comes back for it, with no line to read too.
    let poll = match poll {
        Poll::Idle if CONSOLE.with(|c| c.checkpoint_waits()) => Poll::After(5),
        p => p,
    };
    // A print's records come while the console waits on a long move too.
    if matches!(poll, Poll::Wait(_)) && CONSOLE.with(|c| c.print_records()) {
        spawn_after(Task::Console, RECORD_CHECK_MS);
    }
    reschedule(Task::Console, poll);
    // An operator's tool for the job.
    if queues::job_control_waits() {
        spawn(Task::Job);
    }
    // A plotter's card print asks the reader and takes its messages.
    if queues::card_request_waits() {
        spawn(Task::Card);
    }
    if queues::card_out_free() > card::ROOM {
        signal(Signal::CardRoom);
    }
    if CONSOLE.with(|c| c.take_settings_changed()) {
        console_settings_changed();
    }
}

/// A `$` line changed the settings (the store has them to write). Out of
/// line: the kinematics it makes stay off the console's frame.
#[inline(never)]
fn console_settings_changed() {
    kinematics_changed();
    // The string-art job runs only on its machine.
    spawn(Task::Job);
}

/// Real-time commands, in the order that makes sense when several came
/// together: reset, hold, resume, status.
#[inline(never)]
#[optimize(speed)]
fn realtime() {
    let r = Requests::take();
    MOTION.with(|m| {
        let activity = CONSOLE.with(|c| c.activity());
        if r.reset() {
            let moving = m.stop_now();
            STORE.with(|s| {
                CONSOLE.with(|c| c.reset(s.coords()));
                // `$uart1_baud` and `$machine` set since, in force.
                CONFIG.with(|c| usart1::configure(s.extras().uart1(c.machine)));
            });
            STANDING.with(|rt| rt.reset());
            m.set_overrides(Overrides::NONE);
            control_job(Control::Abort);
            realtime::after_reset(m, activity == Activity::Homing, moving);
            // Its startup lines.
            if startup_lines() {
                spawn(Task::Console);
            }
        }
        // `!` while jogging cancels the jog; while homing only the door
        // stops (Grbl's alarm 7).
        if r.hold() && !CONSOLE.with(|c| c.cancel_jog(m)) {
            match activity {
                Activity::Homing if r.door() => CONSOLE.with(|c| c.abort_homing(m)),
                Activity::Homing => {}
                _ => {
                    m.hold();
                    STANDING.with(|rt| rt.door |= r.door());
                }
            }
        }
        if r.jog_cancel() {
            CONSOLE.with(|c| c.cancel_jog(m));
        }
        if r.resume() {
            match m.resume() {
                true => STANDING.with(|rt| rt.door = false),
                false => control_job(Control::Resume),
            }
        }
        if r.overrides() != 0 {
            if let Some(o) = STANDING.with(|rt| {
                rt.apply(r.overrides(), r.feed_presses())
                    .then_some(rt.overrides)
            }) {
                m.set_overrides(o);
            }
        }
        Port::each(|port| {
            if r.status(port) {
                status(m, activity, port);
            }
        });
    });
    // A hold or a resume changes what segment preparation makes; a reset
    // frees the planner for whoever waits.
    spawn(Task::Refill);
    signal(Signal::PlannerRoom);
}

/// A status report to `port`, or again in a millisecond when its TX ring
/// has no room. Out of line: the task's frame stays small.
#[inline(never)]
fn status(m: &Motion, activity: Activity, port: Port) {
    if !reply::room_on(port) {
        realtime::status_later(port);
        return spawn_after(Task::Realtime, 1);
    }
    let frame = CONSOLE.with(|c| c.frame());
    KIN.with(|kin| {
        CONFIG.with(|cfg| {
            STANDING.with(|rt| realtime::status(port, m, kin, cfg, activity, &frame, rt))
        })
    });
}

/// A startup line is kept: the console runs it.
fn startup_lines() -> bool {
    STORE.with(|s| s.has_startup_lines())
}

/// The console's word for the job, through its end of `JOB_CONTROL`.
fn control_job(c: Control) {
    if !CONSOLE.with(|con| con.tell_job(c)) {
        warn!("job control queue full");
    }
    spawn(Task::Job);
}

/// Who takes the buttons' presses and the card's messages: the job on
/// the string-art machine, the console (its card print) on a plotter.
fn card_owner() -> Task {
    match CONFIG.with(|cfg| cfg.machine.is_string_art()) {
        true => Task::Job,
        false => Task::Console,
    }
}

/// Debounce the tick's samples; presses go to the card's owner.
#[inline(never)]
fn buttons() {
    if BUTTONS_TASK.with(|d| d.poll()) {
        spawn(card_owner());
    }
}

#[inline(never)]
fn job() {
    if card_owner() != Task::Job {
        return;
    }
    let now = clock::millis();
    let machine = CONFIG.with(|cfg| cfg.machine);
    let (poll, saving) = MOTION.with(|m| {
        CONFIG.with(|cfg| {
            STORE.with(|s| {
                let poll = JOB.with(|j| j.poll(m, cfg, s, now));
                (poll, s.saving())
            })
        })
    });
    // The job's checkpoint goes to EEPROM.
    if saving {
        spawn(Task::Store);
    }
    if CONFIG.with(|cfg| cfg.machine) != machine {
        machine_switched();
    }
    spawn(Task::Prepare);
    reschedule(Task::Job, poll);
    if queues::card_request_waits() {
        spawn(Task::Card);
    }
    if queues::card_out_free() > card::ROOM {
        signal(Signal::CardRoom);
    }
}

/// A plotter's card switched the machine: its kinematics, kept in EEPROM.
/// Out of line: the kinematics, made on the stack, would sit in the job
/// task's frame under its deepest calls.
#[inline(never)]
fn machine_switched() {
    kinematics_changed();
    settings_changed();
    spawn(Task::Console);
}

#[inline(never)]
fn card() {
    let now = clock::millis();
    // Looking for a card holds the bus at the slow init clock for ~1.5 ms:
    // not while the machine moves (the refill would wait).
    let moving = MOTION.with(|m| !m.is_idle());
    let poll = CARD.with(|c| c.poll(now, moving));
    reschedule(Task::Card, poll);
    if queues::card_message_waits() {
        spawn(card_owner());
    }
}

/// Settings changed: their image goes to EEPROM.
fn settings_changed() {
    STORE.with(|s| s.settings_changed());
    signal(Signal::Settings);
}

/// Checkpoint, settings, coordinates and kept lines into EEPROM, a changed
/// byte per run.
#[inline(never)]
#[optimize(size)]
fn store() {
    let poll = CONFIG.with(|cfg| STORE.with(|s| s.poll(cfg)));
    reschedule(Task::Store, poll);
}

/// Deferred reports: dropped log lines, step-timing faults.
#[inline(never)]
fn logger() {
    static LAST_FAULTS: TaskCell<(u16, u16)> = TaskCell::new((0, 0));
    let faults = MOTION.with(|m| m.stepper.faults());
    LAST_FAULTS.with(|last| {
        if faults != *last {
            warn!("step late:", faults.0, " underruns:", faults.1);
            *last = faults;
        }
    });
    if taut_firmware::log::dropped() > 0 {
        // An empty-bodied line carries the pending "N lines dropped" note.
        info!("log check");
    }
}

/// The status LED, when its boot pattern started, and whether it is over.
struct StatusLed {
    pin: Pin<13, Output>,
    start: u32,
    done: bool,
}
static LED: TaskCell<StatusLed> = TaskCell::zeroed();
const _: () = assert!(taut_logic::pinmap::STATUS_LED == 13);

/// The status LED: `BOOT_BLINKS` flashes of 100 ms at boot, then off.
#[inline(never)]
fn led() {
    let now = clock::millis();
    LED.with(|l| {
        if l.done {
            return;
        }
        let t = now.wrapping_sub(l.start);
        let phase = t / 100;
        if phase >= BOOT_BLINKS * 2 {
            let _ = l.pin.set_low();
            l.done = true;
            return;
        }
        let _ = if phase % 2 == 0 {
            l.pin.set_high()
        } else {
            l.pin.set_low()
        };
        spawn_after(Task::Led, 100 - t % 100);
    });
}

// The step timer: the one handler that is never interrupted. Plain events
// take the assembly fast path (`stepper::fast`), all others this handler.
step_vector!(timer3_compa);

#[optimize(speed)]
extern "avr-interrupt" fn timer3_compa() {
    if stepper::on_compare() {
        spawn_from_isr(&SPAWNED, refill_task() as u8);
    }
}

// The others are nestable (see `rt::nested`): the step timer preempts them.
nested_vector!(__vector_21, timer0_compa); // TIMER0_COMPA
nested_vector!(__vector_25, usart0_rx, reg = "0xC1", keep = "0x7F"); // USART0_RX: RXCIE0
nested_vector!(__vector_26, usart0_udre, reg = "0xC1", keep = "0xDF"); // USART0_UDRE: UDRIE0
const _: () = assert!(usart::UCSR0B == 0xC1 && !0x7Fu8 == 1 << RXCIE0 && !0xDFu8 == 1 << UDRIE0);
nested_vector!(__vector_36, usart1_rx, reg = "0xC9", keep = "0x7F"); // USART1_RX: RXCIE1
nested_vector!(__vector_37, usart1_udre, reg = "0xC9", keep = "0xDF"); // USART1_UDRE: UDRIE1
const _: () = assert!(usart1::UCSR1B == 0xC9 && !0x7Fu8 == 1 << RXCIE1 && !0xDFu8 == 1 << UDRIE1);

#[optimize(speed)]
extern "avr-interrupt" fn timer0_compa() {
    if clock::tick() {
        spawn_from_isr(&SPAWNED, Task::Timers as u8);
    }
    let (sampled, inputs) = buttons::sample();
    if sampled {
        spawn_from_isr(&SPAWNED, Task::Buttons as u8);
    }
    if endstop::on_tick(inputs) {
        spawn_from_isr(&SPAWNED, Task::Console as u8);
    }
    // The step interrupt's assembly path cannot spawn; it leaves a flag.
    if stepper::take_refill() {
        spawn_from_isr(&SPAWNED, refill_task() as u8);
    }
}

#[optimize(speed)]
extern "avr-interrupt" fn usart0_rx() {
    let task = match usart::on_receive(realtime::on_receive) {
        true => Task::Realtime,
        false => Task::Console,
    };
    spawn_from_isr(&SPAWNED, task as u8);
}

#[optimize(speed)]
extern "avr-interrupt" fn usart0_udre() {
    usart::on_data_register_empty();
}

#[optimize(speed)]
extern "avr-interrupt" fn usart1_rx() {
    let task = match usart1::on_receive(realtime::on_receive_uart1) {
        true => Task::Realtime,
        false => Task::Console,
    };
    spawn_from_isr(&SPAWNED, task as u8);
}

#[optimize(speed)]
extern "avr-interrupt" fn usart1_udre() {
    usart1::on_data_register_empty();
}
