//! The card reader alone, for `cargo xtask bench` (`sd_read_kib_per_s`):
//! streams `poradi.txt` through the firmware's `CardReader` into its queue,
//! drains the queue at once, and logs `read <bytes> B in <µs> us`. The
//! release image's job parses what it reads; this measures the reader.
#![no_std]
#![no_main]
#![feature(abi_avr_interrupt)]

use panic_halt as _;
use taut_firmware::board::spi::CardSpi;
use taut_firmware::board::{clock, gpio::Pins, usart};
use taut_firmware::card::CardReader;
use taut_firmware::info;
use taut_firmware::queues::{self, Request, Signal, What};
use taut_firmware::rt::Poll;
use taut_logic::fat::Name;

#[avr_device::entry]
fn main() -> ! {
    let dp = avr_device::atmega2560::Peripherals::take().unwrap();
    let pins = Pins::new(
        dp.PORTA, dp.PORTB, dp.PORTC, dp.PORTD, dp.PORTE, dp.PORTF, dp.PORTG, dp.PORTH, dp.PORTJ,
        dp.PORTK, dp.PORTL,
    );
    clock::Clock::start(dp.TC0);
    usart::Usart0::start(dp.USART0);
    let spi = CardSpi::start(dp.SPI, pins.d52, pins.d51, pins.d50, pins.d53);
    let (ask, _, requests) = queues::card_in_ends();
    let (tell, news, _) = queues::card_out_ends();
    let mut reader = CardReader::new(spi, requests, tell);
    // SAFETY: the two handlers below touch only the clock and the TX ring.
    unsafe { avr_device::interrupt::enable() };
    loop {
        let _ = reader.poll(clock::millis(), false);
        if let Some(m) = news.pop() {
            if matches!(m.what, What::Inserted) {
                break;
            }
        }
    }
    let poradi = Name::new(b"poradi.txt").unwrap_or(Name::EMPTY);
    ask.put(Request::Open(poradi, 1));
    let start = clock::micros();
    let mut bytes: u32 = 0;
    loop {
        if reader.poll(clock::millis(), false) == Poll::Wait(Signal::CardRoom)
            && !queues::card_message_waits()
        {
            break;
        }
        match news.pop().map(|m| m.what) {
            Some(What::Data { len, .. }) => bytes += len as u32,
            Some(What::End) => break,
            Some(What::Opened { .. }) => {}
            Some(_) => break,
            None => {}
        }
    }
    let us = clock::micros().wrapping_sub(start);
    info!("read ", bytes, " B in ", us, " us");
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
    // Entered with the interrupt enabled: switch it off, the handler
    // switches it back on while bytes are waiting.
    // SAFETY: UCSR0B; the main loop never writes it while interrupts run.
    unsafe {
        let ucsr0b = usart::UCSR0B as *mut u8;
        ucsr0b.write_volatile(ucsr0b.read_volatile() & !(1 << usart::UDRIE0));
    }
    usart::on_data_register_empty();
}
