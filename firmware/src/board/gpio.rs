//! Typed GPIO pins by Mega board number, implementing embedded-hal 1.0.
//!
//! `Pin<13, Output>` is the status LED; the mode is part of the type, so a
//! button cannot be driven and a STEP pin cannot be read by mistake. Writes go
//! through the PINx toggle register: one store changes one bit, so a pin
//! written here never races the step interrupt writing other bits of the
//! same port (RAMPS puts radial ENABLE on PORTF beside two STEP pins).

use core::convert::Infallible;
use core::marker::PhantomData;
use core::ptr::{read_volatile, write_volatile};
use taut_logic::pinmap::port_bit;

pub struct Output;
pub struct PullUp;
pub struct Floating;

pub struct Pin<const N: u8, M> {
    _mode: PhantomData<M>,
}

/// Register addresses of a pin, resolved at compile time from its number.
pub(crate) const fn regs(n: u8) -> (*mut u8, *mut u8, *mut u8, u8) {
    let (port, bit) = port_bit(n);
    let pin = port.pin_register() as *mut u8;
    // PINx, DDRx, PORTx are consecutive I/O registers.
    (pin, pin.wrapping_add(1), pin.wrapping_add(2), 1 << bit)
}

impl<const N: u8, M> Pin<N, M> {
    const REGS: (*mut u8, *mut u8, *mut u8, u8) = regs(N);

    fn set_ddr(output: bool) {
        let (_, ddr, _, mask) = Self::REGS;
        // SAFETY: DDRx of this pin's port (`regs`). Its other bits belong to
        // other pins: the read-modify-write is atomic, interrupts masked.
        avr_device::interrupt::free(|_| unsafe {
            let v = read_volatile(ddr);
            write_volatile(ddr, if output { v | mask } else { v & !mask });
        });
    }

    fn write_level(high: bool) {
        let (pin, _, port, mask) = Self::REGS;
        // SAFETY: PORTx and PINx of this pin's port (`regs`). Only this
        // pin's owner writes this bit, so read-then-toggle cannot race, and
        // the toggle register changes no other bit.
        unsafe {
            if (read_volatile(port) & mask != 0) != high {
                write_volatile(pin, mask);
            }
        }
    }

    fn read_level() -> bool {
        let (pin, _, _, mask) = Self::REGS;
        // SAFETY: reading PINx of this pin's port has no side effect.
        unsafe { read_volatile(pin) & mask != 0 }
    }

    pub fn into_output(self) -> Pin<N, Output> {
        Self::set_ddr(true);
        Pin { _mode: PhantomData }
    }

    /// Output that starts at `high` without a glitch to the other level.
    pub fn into_output_at(self, high: bool) -> Pin<N, Output> {
        Self::write_level(high);
        self.into_output()
    }

    pub fn into_pull_up_input(self) -> Pin<N, PullUp> {
        Self::set_ddr(false);
        Self::write_level(true);
        Pin { _mode: PhantomData }
    }
}

impl<const N: u8, M> embedded_hal::digital::ErrorType for Pin<N, M> {
    type Error = Infallible;
}

impl<const N: u8> embedded_hal::digital::OutputPin for Pin<N, Output> {
    fn set_high(&mut self) -> Result<(), Infallible> {
        Self::write_level(true);
        Ok(())
    }
    fn set_low(&mut self) -> Result<(), Infallible> {
        Self::write_level(false);
        Ok(())
    }
}

impl<const N: u8> embedded_hal::digital::StatefulOutputPin for Pin<N, Output> {
    fn is_set_high(&mut self) -> Result<bool, Infallible> {
        let (_, _, port, mask) = Self::REGS;
        // SAFETY: reading PORTx of this pin's port has no side effect.
        Ok(unsafe { read_volatile(port) } & mask != 0)
    }
    fn is_set_low(&mut self) -> Result<bool, Infallible> {
        self.is_set_high().map(|h| !h)
    }
}

macro_rules! input_pin {
    ($mode:ty) => {
        impl<const N: u8> embedded_hal::digital::InputPin for Pin<N, $mode> {
            fn is_high(&mut self) -> Result<bool, Infallible> {
                Ok(Self::read_level())
            }
            fn is_low(&mut self) -> Result<bool, Infallible> {
                Ok(!Self::read_level())
            }
        }
    };
}
input_pin!(PullUp);
input_pin!(Floating);

macro_rules! mega_pins {
    ($($name:ident = $n:literal),* $(,)?) => {
        /// Every pin of the Mega, named as on the board's silkscreen, each
        /// an unconfigured input until the firmware gives it a mode.
        pub struct Pins { $(pub $name: Pin<$n, Floating>,)* }

        impl Pins {
            /// Taking the port peripherals proves no one else owns the pins.
            #[allow(clippy::too_many_arguments)]
            pub fn new(
                _a: avr_device::atmega2560::PORTA, _b: avr_device::atmega2560::PORTB,
                _c: avr_device::atmega2560::PORTC, _d: avr_device::atmega2560::PORTD,
                _e: avr_device::atmega2560::PORTE, _f: avr_device::atmega2560::PORTF,
                _g: avr_device::atmega2560::PORTG, _h: avr_device::atmega2560::PORTH,
                _j: avr_device::atmega2560::PORTJ, _k: avr_device::atmega2560::PORTK,
                _l: avr_device::atmega2560::PORTL,
            ) -> Pins {
                Pins { $($name: Pin { _mode: PhantomData },)* }
            }
        }
    };
}

mega_pins!(
    d0 = 0,
    d1 = 1,
    d2 = 2,
    d3 = 3,
    d4 = 4,
    d5 = 5,
    d6 = 6,
    d7 = 7,
    d8 = 8,
    d9 = 9,
    d10 = 10,
    d11 = 11,
    d12 = 12,
    d13 = 13,
    d14 = 14,
    d15 = 15,
    d16 = 16,
    d17 = 17,
    d18 = 18,
    d19 = 19,
    d20 = 20,
    d21 = 21,
    d22 = 22,
    d23 = 23,
    d24 = 24,
    d25 = 25,
    d26 = 26,
    d27 = 27,
    d28 = 28,
    d29 = 29,
    d30 = 30,
    d31 = 31,
    d32 = 32,
    d33 = 33,
    d34 = 34,
    d35 = 35,
    d36 = 36,
    d37 = 37,
    d38 = 38,
    d39 = 39,
    d40 = 40,
    d41 = 41,
    d42 = 42,
    d43 = 43,
    d44 = 44,
    d45 = 45,
    d46 = 46,
    d47 = 47,
    d48 = 48,
    d49 = 49,
    d50 = 50,
    d51 = 51,
    d52 = 52,
    d53 = 53,
    a0 = 54,
    a1 = 55,
    a2 = 56,
    a3 = 57,
    a4 = 58,
    a5 = 59,
    a6 = 60,
    a7 = 61,
    a8 = 62,
    a9 = 63,
    a10 = 64,
    a11 = 65,
    a12 = 66,
    a13 = 67,
    a14 = 68,
    a15 = 69,
);
