//! Benchmark image: cycles the segment preparer spends per segment on the
//! AVR, for a full base turn at the string-art defaults (9600 steps,
//! 2000 steps/s, 500 steps/s²). Prints `prep segments:N us:T max_us:M`.
#![no_std]
#![no_main]
#![feature(abi_avr_interrupt)]

use panic_halt as _;
use taut_firmware::board::{clock, usart};
use taut_firmware::info;
use taut_logic::config::MachineConfig;
use taut_logic::planner::{Feed, Planner};
use taut_logic::segment::Preparer;

#[avr_device::entry]
fn main() -> ! {
    let dp = avr_device::atmega2560::Peripherals::take().unwrap();
    clock::Clock::start(dp.TC0);
    usart::Usart0::start(dp.USART0);
    dp.TC1.tccr1b().write(|w| w.cs1().direct());
    unsafe { avr_device::interrupt::enable() };
    {
        use core::hint::black_box as bb;
        let t0 = dp.TC1.tcnt1().read().bits();
        let _ = bb(taut_logic::segment::isqrt(bb(0x0123_4567_89AB_CDEF)));
        let dt = dp.TC1.tcnt1().read().bits().wrapping_sub(t0);
        info!("isqrt64 cycles:", dt);
    }
    let cfg = MachineConfig::STRING_ART;
    let mut planner = Planner::new(&cfg);
    let t0 = dp.TC1.tcnt1().read().bits();
    let _ = planner.push([9600, 0, 0, 0], Feed::Rapid);
    let push = dp.TC1.tcnt1().read().bits().wrapping_sub(t0);
    let p = planner.take().unwrap();
    let mut prep = Preparer::new();
    prep.start(p.profile);
    let (mut n, mut total, mut max) = (0u32, 0u32, 0u32);
    loop {
        let t0 = clock::micros();
        let seg = core::hint::black_box(prep.next());
        let dt = clock::micros().wrapping_sub(t0);
        if seg.is_none() {
            break;
        }
        n += 1;
        total += dt;
        max = max.max(dt);
    }
    info!(
        "prep segments:",
        n, " us:", total, " max_us:", max, " push_cycles:", push
    );
    loop {
        avr_device::asm::sleep();
    }
}

#[avr_device::interrupt(atmega2560)]
fn TIMER0_COMPA() {
    clock::tick();
}

#[avr_device::interrupt(atmega2560)]
fn USART0_UDRE() {
    usart::on_data_register_empty();
}
