//! The board layer: the Arduino Mega 2560 on `avr-device`, one file per
//! peripheral. The pin map is `taut_logic::pinmap` (RAMPS 1.4 by default).

pub mod clock;
pub mod delay;
pub mod eeprom;
pub mod flash;
pub mod gpio;
pub mod servo;
pub mod spi;
pub mod step_timer;
pub mod usart;
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
    /// No flag set: a jump to the reset vector (e.g. a crash into address 0).
    Unknown,
}

impl ResetCause {
    /// Read and clear MCUSR. The watchdog flag must be cleared before the
    /// watchdog can be switched off or reconfigured.
    pub fn take(cpu: &avr_device::atmega2560::CPU) -> ResetCause {
        let r = cpu.mcusr().read();
        let cause = if r.wdrf().bit_is_set() {
            ResetCause::Watchdog
        } else if r.borf().bit_is_set() {
            ResetCause::BrownOut
        } else if r.extrf().bit_is_set() {
            ResetCause::External
        } else if r.porf().bit_is_set() {
            ResetCause::PowerOn
        } else if r.jtrf().bit_is_set() {
            ResetCause::Jtag
        } else {
            ResetCause::Unknown
        };
        // SAFETY: 0 is a valid MCUSR value: every reset flag cleared.
        cpu.mcusr().write(|w| unsafe { w.bits(0) });
        cause
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
