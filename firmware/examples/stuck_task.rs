//! A firmware whose software task never returns, on the release runtime:
//! the watchdog (fed only when a dispatch round ends) must reset the
//! board, and the next boot must log the reset cause.
#![no_std]
#![no_main]
#![feature(abi_avr_interrupt, asm_experimental_arch)]

use panic_halt as _;
use taut_firmware::board::{clock, usart, watchdog::Watchdog, ResetCause};
use taut_firmware::rt::dispatch::{self, Spawned};
use taut_firmware::rt::TaskCell;
use taut_firmware::{info, nested_vector, warn};
use taut_logic::sched::{Ready, TaskId};

#[derive(Clone, Copy)]
struct Stuck;

impl TaskId for Stuck {
    const COUNT: usize = 1;
    fn index(self) -> usize {
        0
    }
    fn priority(self) -> u8 {
        0
    }
}

static SPAWNED: Spawned = Spawned::new();
static READY: TaskCell<Ready<Stuck, 1, 1>> = TaskCell::new(Ready::new());

#[avr_device::entry]
fn main() -> ! {
    let dp = avr_device::atmega2560::Peripherals::take().unwrap();
    let reset = ResetCause::take(&dp.CPU);
    let watchdog = Watchdog::start(dp.WDT);
    clock::Clock::start(dp.TC0);
    usart::Usart0::start(dp.USART0);
    // SAFETY: the handlers below are ready.
    unsafe { avr_device::interrupt::enable() };
    info!("stuck_task reset:", reset.name());
    READY.with(|r| r.spawn(Stuck));
    dispatch::run(
        &SPAWNED,
        &READY,
        |_| Stuck,
        clock::millis,
        || watchdog.feed(),
        |_| {
            warn!("task entering an endless loop");
            loop {
                avr_device::asm::nop();
            }
        },
    )
}

#[avr_device::interrupt(atmega2560)]
fn TIMER0_COMPA() {
    clock::tick();
}

// The app's entry for the transmit interrupt (see `rt::nested`).
nested_vector!(__vector_26, usart0_udre, reg = "0xC1", keep = "0xDF");

extern "avr-interrupt" fn usart0_udre() {
    usart::on_data_register_empty();
}
