//! The board layer: the Arduino Mega 2560 on `avr-device`, one file per
//! peripheral. The pin map is `taut_logic::pinmap` (RAMPS 1.4 by default).

pub mod clock;
pub mod delay;
pub mod early;
pub mod eeprom;
pub mod flash;
pub mod gpio;
pub mod port;
pub mod servo;
pub mod spi;
pub mod step_timer;
pub mod usart;
pub mod usart1;
pub mod watchdog;

/// CPU clock of the Mega 2560.
pub const F_CPU: u32 = 16_000_000;

/// Why the MCU last reset, read from MCUSR at boot.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum ResetCause {
    PowerOn,
    External,
    BrownOut,
    Watchdog,
    Jtag,
    /// No flag set: a start through the stock bootloader (which clears
    /// them), or a jump to the reset vector (a crash into address 0).
    Unknown,
}

impl ResetCause {
    /// Why this start: MCUSR as `.init3` found it (`early`), or, when that
    /// is 0 because the stock bootloader read and cleared it, the value it
    /// read, if it came in through the watchdog entry. (A start through the
    /// bootloader's other ways, power-on or the RESET pin, is `Unknown`:
    /// it leaves no trace of the flags.) MCUSR itself is cleared already,
    /// so the watchdog can be reconfigured.
    pub fn take(_cpu: &avr_device::atmega2560::CPU) -> ResetCause {
        let at_start = early::mcusr_at_start();
        let bits = match (at_start, early::take_bootloader_mcusr()) {
            (0, Some(read_by_bootloader)) => read_by_bootloader,
            _ => at_start,
        };
        // MCUSR: JTRF 4, WDRF 3, BORF 2, EXTRF 1, PORF 0.
        let set = |bit: u8| bits & (1 << bit) != 0;
        if set(3) {
            ResetCause::Watchdog
        } else if set(2) {
            ResetCause::BrownOut
        } else if set(1) {
            ResetCause::External
        } else if set(0) {
            ResetCause::PowerOn
        } else if set(4) {
            ResetCause::Jtag
        } else {
            ResetCause::Unknown
        }
    }

    pub fn name(self) -> flash::FlashStr {
        taut_progmem::text_table!(ResetCause; [
            PowerOn => "power-on",
            External => "external",
            BrownOut => "brown-out",
            Watchdog => "watchdog",
            Jtag => "jtag",
            Unknown => "unknown",
        ])
        .get(self as usize)
    }
}
