//! taut firmware for the Arduino Mega 2560.
//!
//! The `app` below is the machine at a glance: its interrupts, what each one
//! does, and the idle loop. Everything else is plain functions in `board`
//! (peripherals) and `taut_logic` (host-tested logic).
#![no_std]
#![no_main]
#![feature(abi_avr_interrupt)]

use taut_firmware::board::{self, clock, usart, ResetCause, F_CPU};
use taut_firmware::{flash_str, info};
use embedded_hal::digital::OutputPin;
use panic_halt as _;

/// Boot blink of the status LED: this many flashes, 100 ms on, 100 ms off.
const BOOT_BLINKS: u32 = 3;

#[avr_device::entry]
fn main() -> ! {
    let dp = avr_device::atmega2560::Peripherals::take().unwrap();
    let reset = ResetCause::take(&dp.CPU);
    let pins = board::gpio::Pins::new(
        dp.PORTA, dp.PORTB, dp.PORTC, dp.PORTD, dp.PORTE, dp.PORTF, dp.PORTG, dp.PORTH, dp.PORTJ,
        dp.PORTK, dp.PORTL,
    );
    let mut led = pins.d13.into_output_at(false);
    clock::Clock::start(dp.TC0);
    usart::Usart0::start(dp.USART0);
    // SAFETY: all interrupt handlers and the state they share are set up.
    unsafe { avr_device::interrupt::enable() };

    info!(flash_str!(concat!(
        "taut ",
        env!("CARGO_PKG_VERSION"),
        " git ",
        env!("TAUT_GIT_HASH"),
        " atmega2560 "
    )), F_CPU / 1_000_000, "MHz reset:", reset.name());

    loop {
        // The LED level is a function of time: exactly BOOT_BLINKS flashes.
        let ms = clock::millis();
        let on = ms < BOOT_BLINKS * 200 && (ms / 100) % 2 == 0;
        let _ = if on { led.set_high() } else { led.set_low() };
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

#[avr_device::interrupt(atmega2560)]
fn USART0_RX() {
    usart::on_receive();
}
