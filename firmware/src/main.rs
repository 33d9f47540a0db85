//! taut firmware for the Arduino Mega 2560: the `app`.
//!
//! The machine at a glance, RTIC style. Hardware tasks (interrupts) do the
//! least work possible and spawn software tasks; software tasks run to
//! completion from the dispatcher, highest priority first, FIFO within a
//! priority, and never preempt each other.
//!
//! | task | kind | priority | input | shared with |
//! | --- | --- | --- | --- | --- |
//! | `TIMER1_COMPA` step events | interrupt | above all | `SEGMENTS`, `BLOCKS` rings | motion |
//! | `TIMER0_COMPA` 1 ms tick, button sampling | interrupt | | clock, timer alarm | `SAMPLES` → buttons |
//! | `USART0_RX` / `USART0_UDRE` | interrupts | | `RX` / `TX` rings | console, logger |
//! | `Timers` fires due timers | software | 3 | `TIMERS` | |
//! | `Refill` planner → segments while the queue holds < 30 ms of motion | software | 3 | `MOTION` | console, job |
//! | `Console` G-code line in, reply out | software | 2 | `RX` | `MOTION`, `HOLDS` → job |
//! | `Buttons` debouncing, long presses | software | 2 | `SAMPLES` | `BUTTONS` → job |
//! | `Job` the string-art job's state machine | software | 2 | `BUTTONS`, `CARD_OUT`, `HOLDS` | `MOTION`, `CARD_IN` → card |
//! | `Card` SD reader: one block per run | software | 1 | `CARD_IN`, every 1 s | `CARD_OUT` → job |
//! | `Motion` planner → segments, background | software | 1 | `MOTION` | console, job |
//! | `Led` status LED pattern (timed edges: runs before the long tasks) | software | 2 | its timer | |
//! | `Logger` deferred reports | software | 0 | every 1 s | |
#![no_std]
#![no_main]
#![feature(abi_avr_interrupt, asm_experimental_arch)]

use embedded_hal::digital::OutputPin;
use panic_halt as _;
use taut_firmware::board::gpio::{Output, Pin};
use taut_firmware::board::spi::CardSpi;
use taut_firmware::board::{
    self, clock, step_timer::StepTimer, usart, watchdog::Watchdog, ResetCause, F_CPU,
};
use taut_firmware::buttons::{self, ButtonPins, Debounce};
use taut_firmware::card::{self, CardReader, Poll as CardPoll, CARD_IN, CARD_OUT};
use taut_firmware::console::{Console, Poll};
use taut_firmware::drivers::{Drivers, EnablePins};
use taut_firmware::job::{JobTask, Poll as JobPoll, HOLDS};
use taut_firmware::motion::{self, Motion};
use taut_firmware::rt::dispatch::{self, spawn_from_isr, Spawned};
use taut_firmware::rt::{stack, TaskCell};
use taut_firmware::stepper::{self, Stepper};
use taut_firmware::{
    board::usart::{RXCIE0, UDRIE0},
    nested_vector, step_vector,
};
use taut_firmware::{flash_str, info, warn};
use taut_logic::config::MachineConfig;
use taut_logic::kinematics::Linear;
use taut_logic::sched::{Ready, TaskId, Timers};

#[derive(Clone, Copy, PartialEq, Eq)]
enum Task {
    Timers,
    Refill,
    Motion,
    Console,
    Buttons,
    Job,
    Card,
    Logger,
    Led,
}

const _: () = assert!(Task::ALL.len() <= 16, "interrupt spawns are a bit per task");

impl Task {
    /// Every task, in discriminant order (`Task::X as u8` indexes it).
    const ALL: [Task; 9] = [
        Task::Timers,
        Task::Refill,
        Task::Motion,
        Task::Console,
        Task::Buttons,
        Task::Job,
        Task::Card,
        Task::Logger,
        Task::Led,
    ];
}
const _: () = {
    let mut i = 0;
    while i < Task::ALL.len() {
        assert!(Task::ALL[i] as usize == i);
        i += 1;
    }
};

impl TaskId for Task {
    const COUNT: usize = Task::ALL.len();
    fn index(self) -> usize {
        self as usize
    }
    fn priority(self) -> u8 {
        match self {
            Task::Timers | Task::Refill => 3,
            Task::Console | Task::Buttons | Task::Job | Task::Led => 2,
            Task::Card | Task::Motion => 1,
            Task::Logger => 0,
        }
    }
}

/// Task ids spawned by interrupts, moved into `READY` by the dispatcher.
static SPAWNED: Spawned = Spawned::new();
// Software tasks only: no masking needed.
static READY: TaskCell<Ready<Task, 9, 4>> = TaskCell::new(Ready::new());
static TIMERS: TaskCell<Timers<Task, 8>> = TaskCell::new(Timers::new());
static MOTION: TaskCell<Option<Motion>> = TaskCell::new(None);
static CONSOLE: TaskCell<Console> = TaskCell::new(Console::new());
static CONFIG: TaskCell<MachineConfig> = TaskCell::new(MachineConfig::STRING_ART);
static DEBOUNCE: TaskCell<Debounce> = TaskCell::new(Debounce::new());
static JOB: TaskCell<JobTask> = TaskCell::new(JobTask::new());
static CARD: TaskCell<Option<CardReader>> = TaskCell::new(None);
/// The console and the job wait for the motion task (planner room or idle).
static CONSOLE_WAITS_MOTION: TaskCell<bool> = TaskCell::new(false);
static JOB_WAITS_MOTION: TaskCell<bool> = TaskCell::new(false);
/// The card reader waits for room in `CARD_OUT`.
static CARD_WAITS_JOB: TaskCell<bool> = TaskCell::new(false);

/// Boot blink of the status LED: this many flashes, 100 ms on, 100 ms off.
const BOOT_BLINKS: u32 = 3;
const LOGGER_PERIOD_MS: u32 = 1000;

fn spawn(task: Task) {
    READY.with(|r| r.spawn(task));
}

fn task_of(id: u8) -> Task {
    Task::ALL[id as usize]
}

/// Spawn `task` in `ms`, replacing its earlier timers: a task spawned
/// often (by every received byte) must not fill the timer slots with
/// wake-ups it no longer needs.
fn spawn_after(task: Task, ms: u32) {
    arm(|t, now| {
        t.cancel(task);
        t.spawn_after(task, now, ms).is_ok()
    });
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
    let watchdog = init();
    dispatch::run(
        &SPAWNED,
        &READY,
        task_of,
        clock::millis,
        &watchdog,
        |task| match task {
            Task::Timers => timers(),
            Task::Refill | Task::Motion => motion(),
            Task::Console => console(),
            Task::Buttons => buttons(),
            Task::Job => job(),
            Task::Card => card(),
            Task::Logger => logger(),
            Task::Led => led(),
        },
    )
}

/// The board, the tasks' state, the first tasks. Its own frame: the
/// set-up's locals are gone from the stack before the dispatcher starts.
#[inline(never)]
fn init() -> Watchdog {
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
    let config = MachineConfig::STRING_ART;
    let enable = EnablePins {
        base: pins.d38.into_output(),
        radial: pins.a2.into_output(),
        drill: pins.a8.into_output(),
        aux: pins.d24.into_output(),
    };
    let drivers = Drivers::new(enable, &config);
    let stepper = Stepper::new(StepTimer::start(dp.TC1), &config);
    MOTION.with(|m| *m = Some(Motion::new(&config, stepper, drivers)));
    let spi = CardSpi::start(dp.SPI, pins.d52, pins.d51, pins.d50, pins.d53);
    CARD.with(|c| *c = Some(CardReader::new(spi)));
    buttons::start(ButtonPins {
        confirm: pins.d2.into_pull_up_input(),
        zero_base: pins.d3.into_pull_up_input(),
        zero_radial: pins.d14.into_pull_up_input(),
        zero_drill: pins.d18.into_pull_up_input(),
    });
    // SAFETY: every interrupt handler and the state it touches is ready.
    unsafe { avr_device::interrupt::enable() };

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
    LED.with(|l| *l = Some((status_led, clock::millis())));
    spawn(Task::Led);
    spawn_every(Task::Logger, LOGGER_PERIOD_MS);
    JOB.with(|j| j.power_on(clock::millis()));
    spawn(Task::Job);
    spawn(Task::Card);

    watchdog
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
fn motion() {
    /// Segments per run: a ramp segment costs up to ~4 ms, so a run stays
    /// under ~8 ms and the other tasks get their turn between runs.
    const BATCH: usize = 2;
    let (freed, more, idle) = MOTION.with(|m| {
        let m = m.as_mut().unwrap();
        let (freed, more) = m.refill(BATCH);
        (freed, more, m.is_idle())
    });
    if more {
        spawn(refill_task());
    }
    if freed || idle {
        if CONSOLE_WAITS_MOTION.with(|w| core::mem::take(w)) {
            spawn(Task::Console);
        }
        if JOB_WAITS_MOTION.with(|w| core::mem::take(w)) {
            spawn(Task::Job);
        }
    }
}

/// Urgent refill while the step queue is short, background otherwise.
#[inline(always)]
fn refill_task() -> Task {
    if motion::urgent() {
        Task::Refill
    } else {
        Task::Motion
    }
}

#[inline(never)]
fn console() {
    let poll = MOTION.with(|m| {
        CONFIG.with(|cfg| {
            let kin = Linear::cylindrical(cfg);
            CONSOLE.with(|c| c.poll(m.as_mut().unwrap(), &kin, cfg))
        })
    });
    // New moves may be queued: the motion task feeds them to the stepper.
    spawn(Task::Motion);
    match poll {
        Poll::Drained => {}
        Poll::Motion => CONSOLE_WAITS_MOTION.with(|w| *w = true),
        Poll::After(ms) => spawn_after(Task::Console, ms as u32),
        Poll::Yield => spawn(Task::Console),
    }
    if !HOLDS.is_empty() {
        spawn(Task::Job);
    }
}

/// Debounce the tick's samples; presses go to the job.
#[inline(never)]
fn buttons() {
    if DEBOUNCE.with(|d| d.poll()) {
        spawn(Task::Job);
    }
}

#[inline(never)]
fn job() {
    let now = clock::millis();
    let poll =
        MOTION.with(|m| CONFIG.with(|cfg| JOB.with(|j| j.poll(m.as_mut().unwrap(), cfg, now))));
    spawn(Task::Motion);
    match poll {
        JobPoll::Idle => {}
        JobPoll::Again => spawn(Task::Job),
        JobPoll::Motion => JOB_WAITS_MOTION.with(|w| *w = true),
        JobPoll::After(ms) => spawn_after(Task::Job, ms as u32),
    }
    if !CARD_IN.is_empty()
        || (CARD_OUT.free() >= card::ROOM && CARD_WAITS_JOB.with(|w| core::mem::take(w)))
    {
        spawn(Task::Card);
    }
}

#[inline(never)]
fn card() {
    let now = clock::millis();
    // Looking for a card holds the bus at the slow init clock for ~1.5 ms:
    // not while the machine moves (the refill would wait).
    let moving = MOTION.with(|m| !m.as_ref().unwrap().is_idle());
    match CARD.with(|c| c.as_mut().unwrap().poll(now, moving)) {
        CardPoll::Idle(ms) => spawn_after(Task::Card, ms as u32),
        CardPoll::More => spawn(Task::Card),
        CardPoll::Blocked => CARD_WAITS_JOB.with(|w| *w = true),
    }
    if !CARD_OUT.is_empty() {
        spawn(Task::Job);
    }
}

/// Deferred reports: dropped log lines, step-timing faults.
#[inline(never)]
fn logger() {
    static LAST_FAULTS: TaskCell<(u16, u16)> = TaskCell::new((0, 0));
    let faults = MOTION.with(|m| m.as_ref().unwrap().stepper.faults());
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

/// The status LED and when its boot pattern started.
static LED: TaskCell<Option<(Pin<13, Output>, u32)>> = TaskCell::new(None);

/// The status LED: `BOOT_BLINKS` flashes of 100 ms at boot, then off.
#[inline(never)]
fn led() {
    let now = clock::millis();
    LED.with(|l| {
        let Some((led, start)) = l.as_mut() else {
            return;
        };
        let t = now.wrapping_sub(*start);
        let phase = t / 100;
        if phase >= BOOT_BLINKS * 2 {
            let _ = led.set_low();
            *l = None;
            return;
        }
        let _ = if phase % 2 == 0 {
            led.set_high()
        } else {
            led.set_low()
        };
        spawn_after(Task::Led, 100 - t % 100);
    });
}

// The step timer: the one handler that is never interrupted. Plain events
// take the assembly fast path (`stepper::fast`), all others this handler.
step_vector!(timer1_compa);

extern "avr-interrupt" fn timer1_compa() {
    if stepper::on_compare() {
        spawn_from_isr(&SPAWNED, refill_task() as u8);
    }
}

// The others are nestable (see `rt::nested`): the step timer preempts them.
nested_vector!(__vector_21, timer0_compa); // TIMER0_COMPA
nested_vector!(__vector_25, usart0_rx, reg = "0xC1", keep = "0x7F"); // USART0_RX: RXCIE0
nested_vector!(__vector_26, usart0_udre, reg = "0xC1", keep = "0xDF"); // USART0_UDRE: UDRIE0
const _: () = assert!(usart::UCSR0B == 0xC1 && !0x7Fu8 == 1 << RXCIE0 && !0xDFu8 == 1 << UDRIE0);

extern "avr-interrupt" fn timer0_compa() {
    if clock::tick() {
        spawn_from_isr(&SPAWNED, Task::Timers as u8);
    }
    if buttons::sample() {
        spawn_from_isr(&SPAWNED, Task::Buttons as u8);
    }
    // The step interrupt's assembly path cannot spawn; it leaves a flag.
    if stepper::take_refill() {
        spawn_from_isr(&SPAWNED, refill_task() as u8);
    }
}

extern "avr-interrupt" fn usart0_rx() {
    usart::on_receive();
    spawn_from_isr(&SPAWNED, Task::Console as u8);
}

extern "avr-interrupt" fn usart0_udre() {
    usart::on_data_register_empty();
}
