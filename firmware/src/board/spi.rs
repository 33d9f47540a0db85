//! Hardware SPI master on Mega pins 50 (MISO), 51 (MOSI), 52 (SCK), 53 (SS,
//! the SD card's chip select). Starts slow (125 kHz, as SD cards require for
//! initialisation) and switches to 8 MHz with [`Spi::full_speed`].

use super::gpio::{Floating, Output, Pin};
use avr_device::atmega2560::SPI;
use core::convert::Infallible;
use embedded_hal::digital::OutputPin;
use embedded_hal::spi::{Operation, SpiBus};
use embedded_sdmmc::Block;
use taut_logic::pinmap::{SD_CS, SD_MISO, SD_MOSI, SD_SCK};

pub struct Spi {
    spi: SPI,
}

impl Spi {
    /// SS (D53) must be an output for the SPI to stay in master mode.
    pub fn start(
        spi: SPI,
        _sck: Pin<52, Output>,
        _mosi: Pin<51, Output>,
        _miso: Pin<50, Floating>,
        _ss: &Pin<53, Output>,
    ) -> Spi {
        spi.spcr()
            .write(|w| w.spe().set_bit().mstr().set_bit().spr().fosc_128_64());
        spi.spsr().write(|w| w.spi2x().clear_bit());
        Spi { spi }
    }

    pub fn slow_speed(&mut self) {
        self.spi.spcr().modify(|_, w| w.spr().fosc_128_64());
        self.spi.spsr().write(|w| w.spi2x().clear_bit());
    }

    /// f/2 = 8 MHz.
    pub fn full_speed(&mut self) {
        self.spi.spcr().modify(|_, w| w.spr().fosc_4_2());
        self.spi.spsr().write(|w| w.spi2x().set_bit());
    }

    /// Inlined: once a byte of every card block (at `z` it was a call).
    #[inline(always)]
    fn exchange(&mut self, out: u8) -> u8 {
        // SAFETY: SPDR takes any byte.
        self.spi.spdr().write(|w| unsafe { w.bits(out) });
        while self.spi.spsr().read().spif().bit_is_clear() {}
        self.spi.spdr().read().bits()
    }
}

impl embedded_hal::spi::ErrorType for Spi {
    type Error = Infallible;
}

impl embedded_hal::spi::SpiBus<u8> for Spi {
    fn read(&mut self, words: &mut [u8]) -> Result<(), Infallible> {
        for w in words {
            *w = self.exchange(0xFF);
        }
        Ok(())
    }

    fn write(&mut self, words: &[u8]) -> Result<(), Infallible> {
        for &w in words {
            self.exchange(w);
        }
        Ok(())
    }

    fn transfer(&mut self, read: &mut [u8], write: &[u8]) -> Result<(), Infallible> {
        for i in 0..read.len().max(write.len()) {
            let b = self.exchange(write.get(i).copied().unwrap_or(0xFF));
            if let Some(r) = read.get_mut(i) {
                *r = b;
            }
        }
        Ok(())
    }

    fn transfer_in_place(&mut self, words: &mut [u8]) -> Result<(), Infallible> {
        for w in words {
            *w = self.exchange(*w);
        }
        Ok(())
    }

    fn flush(&mut self) -> Result<(), Infallible> {
        Ok(())
    }
}

/// The SD card's SPI device: the bus with chip select on D53, low for the
/// length of each transaction (embedded-hal's `SpiDevice`). The pins are the
/// hardware SPI's, which the pin map names.
pub struct CardSpi {
    pub bus: Spi,
    cs: Pin<53, Output>,
}

const _: () = assert!(SD_SCK == 52 && SD_MOSI == 51 && SD_MISO == 50 && SD_CS == 53);

impl CardSpi {
    /// The card on the hardware SPI, deselected, at the slow init clock.
    pub fn start(
        spi: SPI,
        sck: Pin<52, Floating>,
        mosi: Pin<51, Floating>,
        miso: Pin<50, Floating>,
        cs: Pin<53, Floating>,
    ) -> CardSpi {
        let cs = cs.into_output_at(true);
        let bus = Spi::start(spi, sck.into_output(), mosi.into_output(), miso, &cs);
        CardSpi { bus, cs }
    }

    /// Clocks with the card deselected: 80 of them wake a card up.
    pub fn idle_clocks(&mut self, bytes: u8) {
        for _ in 0..bytes {
            self.bus.exchange(0xFF);
        }
    }
}

impl embedded_hal::spi::ErrorType for CardSpi {
    type Error = Infallible;
}

impl embedded_hal::spi::SpiDevice<u8> for CardSpi {
    fn transaction(&mut self, ops: &mut [Operation<'_, u8>]) -> Result<(), Infallible> {
        let _ = self.cs.set_low();
        for op in ops {
            match op {
                Operation::Read(b) => self.bus.read(b)?,
                Operation::Write(b) => self.bus.write(b)?,
                Operation::Transfer(r, w) => self.bus.transfer(r, w)?,
                Operation::TransferInPlace(b) => self.bus.transfer_in_place(b)?,
                Operation::DelayNs(_) => {}
            }
        }
        let _ = self.cs.set_high();
        Ok(())
    }
}

// The FAT reader fills `Block::contents` through a `[u8; 512]` view.
const _: () =
    assert!(core::mem::size_of::<Block>() == 512 && core::mem::offset_of!(Block, contents) == 0);

/// A sector buffer seen as the card driver's block.
pub fn as_block(buf: &mut [u8; 512]) -> &mut Block {
    // SAFETY: `Block` is exactly one `[u8; 512]` at offset 0 (asserted above).
    unsafe { &mut *(buf as *mut [u8; 512] as *mut Block) }
}
