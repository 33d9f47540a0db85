//! The Arduino Mega 2560 pin numbers and the default RAMPS 1.4 pin map: the
//! one board file. The firmware's board layer, the simulator harness and the
//! HIL tests all read it, so a pin is named in exactly one place.
//!
//! | function | RAMPS name | Mega pin | port |
//! | --- | --- | --- | --- |
//! | base STEP / DIR / ENABLE | X | D54 (A0) / D55 (A1) / D38 | PF0 / PF1 / PD7 |
//! | radial STEP / DIR / ENABLE | Y | D60 (A6) / D61 (A7) / D56 (A2) | PF6 / PF7 / PF2 |
//! | drill STEP / DIR / ENABLE | Z | D46 / D48 / D62 (A8) | PL3 / PL1 / PK0 |
//! | green `confirm` button | X_MAX | D2 | PE4 |
//! | white `zero_base` button | X_MIN | D3 | PE5 |
//! | white `zero_radial` button | Y_MIN | D14 | PJ1 |
//! | white `zero_drill` button | Z_MIN | D18 | PD3 |
//! | spare end-stops | Y_MAX, Z_MAX | D15, D19 | PJ0, PD2 |
//! | servos (SERVO0: the plotters' pen, Timer1 OC1A) | SERVO0..3 | D11, D6, D5, D4 | PB5, PH3, PE3, PG5 |
//! | status LED | "L" | D13 | PB7 |
//! | SD card MISO / MOSI / SCK / CS | AUX-3 | D50 / D51 / D52 / D53 | PB3 / PB2 / PB1 / PB0 |
//! | serial console (USART0) RX / TX | | D0 / D1 | PE0 / PE1 |
//! | ULN2003 IN1..IN4 of channel X / Y / Z (coil drive) | (E0, E1 sockets) | D22–D25 / D26–D29 / D37–D34 | PA0–PA3 / PA4–PA7 / PC0–PC3 |
//!
//! Buttons switch to ground and use the internal pull-ups: pressed reads low.

use crate::axis::{Axis, PerAxis};

/// An ATmega2560 I/O port.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Port {
    A,
    B,
    C,
    D,
    E,
    F,
    G,
    H,
    J,
    K,
    L,
}

impl Port {
    /// Data-space address of the port's PINx register; DDRx is +1, PORTx +2.
    pub const fn pin_register(self) -> u16 {
        match self {
            Port::A => 0x20,
            Port::B => 0x23,
            Port::C => 0x26,
            Port::D => 0x29,
            Port::E => 0x2C,
            Port::F => 0x2F,
            Port::G => 0x32,
            Port::H => 0x100,
            Port::J => 0x103,
            Port::K => 0x106,
            Port::L => 0x109,
        }
    }

    /// The letter simavr uses to name the port.
    pub const fn letter(self) -> char {
        ['A', 'B', 'C', 'D', 'E', 'F', 'G', 'H', 'J', 'K', 'L'][self as usize]
    }
}

/// Pins D0..D69 of the Mega (A0..A15 are D54..D69), as printed on the board.
pub const PIN_COUNT: u8 = 70;

use Port::*;
#[rustfmt::skip]
const MEGA: [(Port, u8); PIN_COUNT as usize] = [
    (E, 0), (E, 1), (E, 4), (E, 5), (G, 5), (E, 3), (H, 3), (H, 4), // D0-D7
    (H, 5), (H, 6), (B, 4), (B, 5), (B, 6), (B, 7), (J, 1), (J, 0), // D8-D15
    (H, 1), (H, 0), (D, 3), (D, 2), (D, 1), (D, 0), (A, 0), (A, 1), // D16-D23
    (A, 2), (A, 3), (A, 4), (A, 5), (A, 6), (A, 7), (C, 7), (C, 6), // D24-D31
    (C, 5), (C, 4), (C, 3), (C, 2), (C, 1), (C, 0), (D, 7), (G, 2), // D32-D39
    (G, 1), (G, 0), (L, 7), (L, 6), (L, 5), (L, 4), (L, 3), (L, 2), // D40-D47
    (L, 1), (L, 0), (B, 3), (B, 2), (B, 1), (B, 0), (F, 0), (F, 1), // D48-D55
    (F, 2), (F, 3), (F, 4), (F, 5), (F, 6), (F, 7), (K, 0), (K, 1), // D56-D63
    (K, 2), (K, 3), (K, 4), (K, 5), (K, 6), (K, 7), // D64-D69
];

/// Port and bit of Mega pin `pin` (D-number). Panics at compile time when
/// used in a const context with a pin that does not exist.
pub const fn port_bit(pin: u8) -> (Port, u8) {
    MEGA[pin as usize]
}

/// A0..A15 as D-numbers.
pub const fn analog(n: u8) -> u8 {
    54 + n
}

/// SERVO0: the plotters' pen servo, on Timer1's OC1A.
pub const PEN_SERVO: u8 = 11;

/// STEP / DIR / ENABLE pins of one driver.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DriverPins {
    pub step: u8,
    pub dir: u8,
    pub enable: u8,
}

/// RAMPS 1.4 X, Y and Z drivers, in [`Axis`] order (E0 and E1 stay free).
pub const DRIVERS: PerAxis<DriverPins> = [
    DriverPins {
        step: 54,
        dir: 55,
        enable: 38,
    },
    DriverPins {
        step: 60,
        dir: 61,
        enable: 56,
    },
    DriverPins {
        step: 46,
        dir: 48,
        enable: 62,
    },
];

pub const fn driver(axis: Axis) -> DriverPins {
    DRIVERS[axis as usize]
}

/// A ULN2003 board's IN1..IN4 per channel (a 28BYJ-48's coils, driven
/// when `$x_driver=uln2003`): four bits of one port, IN1 the lowest, so
/// that one port write changes a motor's four inputs together. On a bare
/// Mega, away from the pen servo, the card, the buttons and UART1; on a
/// RAMPS 1.4 they are the E0 and E1 sockets' signals (leave those empty).
pub const COILS: PerAxis<[u8; 4]> = [[22, 23, 24, 25], [26, 27, 28, 29], [37, 36, 35, 34]];

/// The port of a channel's coil inputs and the bit of IN1 (IN2..IN4
/// follow it). Panics at compile time for a map whose four pins are not
/// consecutive bits of one port.
pub const fn coil_port(axis: usize) -> (Port, u8) {
    let pins = COILS[axis];
    let (port, first) = port_bit(pins[0]);
    let mut i = 1;
    while i < 4 {
        let (p, bit) = port_bit(pins[i]);
        assert!(p as u8 == port as u8 && bit == first + i as u8);
        i += 1;
    }
    (port, first)
}

const _: () = {
    let mut i = 0;
    while i < COILS.len() {
        let _ = coil_port(i);
        i += 1;
    }
};

/// The four buttons of the string-art machine (RAMPS end-stop inputs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Button {
    Confirm = 0,
    ZeroBase = 1,
    ZeroRadial = 2,
    ZeroDrill = 3,
}

impl Button {
    pub const ALL: [Button; 4] = [
        Button::Confirm,
        Button::ZeroBase,
        Button::ZeroRadial,
        Button::ZeroDrill,
    ];

    pub const fn pin(self) -> u8 {
        [2, 3, 14, 18][self as usize]
    }

    /// Name used in logs and as the VCD signal (`btn_<name>`).
    pub const fn name(self) -> &'static str {
        ["confirm", "zero_base", "zero_radial", "zero_drill"][self as usize]
    }
}

pub const STATUS_LED: u8 = 13;
pub const SERVOS: [u8; 4] = [11, 6, 5, 4];
pub const SD_MISO: u8 = 50;
pub const SD_MOSI: u8 = 51;
pub const SD_SCK: u8 = 52;
pub const SD_CS: u8 = 53;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn well_known_pins() {
        assert_eq!(port_bit(13), (B, 7));
        assert_eq!(port_bit(analog(0)), (F, 0));
        assert_eq!(port_bit(46), (L, 3));
        assert_eq!(port_bit(SD_CS), (B, 0));
        assert_eq!(port_bit(Button::ZeroRadial.pin()), (J, 1));
        assert_eq!(coil_port(0), (A, 0));
        assert_eq!(coil_port(1), (A, 4));
        assert_eq!(coil_port(2), (C, 0));
    }

    #[test]
    fn every_port_bit_is_one_board_pin() {
        let mut all: std::vec::Vec<_> = (0..PIN_COUNT)
            .map(|pin| {
                let (port, bit) = port_bit(pin);
                (port as u8, bit)
            })
            .collect();
        all.sort_unstable();
        all.dedup();
        assert_eq!(all.len(), usize::from(PIN_COUNT));
        assert!(all.iter().all(|&(_, bit)| bit < 8));
    }

    #[test]
    fn no_pin_is_used_twice() {
        let mut used = std::vec::Vec::new();
        for d in DRIVERS {
            used.extend([d.step, d.dir, d.enable]);
        }
        for b in Button::ALL {
            used.push(b.pin());
        }
        used.extend([STATUS_LED, SD_MISO, SD_MOSI, SD_SCK, SD_CS]);
        used.extend(SERVOS);
        used.extend(COILS.iter().flatten());
        // UART1 (D19 RX1, D18 TX1) is the zero_drill button's D18 on the
        // string-art machine: only the coils must stay off it.
        assert!(COILS.iter().flatten().all(|p| ![18, 19].contains(p)));
        let mut ports: std::vec::Vec<_> = used.iter().map(|&p| port_bit(p)).collect();
        ports.sort_by_key(|&(p, b)| (p as u8, b));
        ports.dedup();
        assert_eq!(ports.len(), used.len());
    }
}
