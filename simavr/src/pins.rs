//! Arduino Mega 2560 board pins (D0..D69, A0..A15 = D54..D69) to ATmega2560
//! port letter and bit, as in the Arduino core's `pins_arduino.h` for the Mega.

/// Number of board pins: D0..D69.
pub const PIN_COUNT: u8 = 70;

/// First analog pin: A0 is D54.
pub const A0: u8 = 54;

/// Board pin number of analog pin `An` (A0..A15).
pub const fn analog(n: u8) -> u8 {
    A0 + n
}

/// (port letter, bit) of every board pin, indexed by pin number.
const MEGA: [(u8, u8); PIN_COUNT as usize] = [
    // D0..D9: serial 0 on PE0/PE1, then PWM pins.
    (b'E', 0),
    (b'E', 1),
    (b'E', 4),
    (b'E', 5),
    (b'G', 5),
    (b'E', 3),
    (b'H', 3),
    (b'H', 4),
    (b'H', 5),
    (b'H', 6),
    // D10..D13 (D13 = on-board LED).
    (b'B', 4),
    (b'B', 5),
    (b'B', 6),
    (b'B', 7),
    // D14..D21: serial 3, 2, 1 and I2C.
    (b'J', 1),
    (b'J', 0),
    (b'H', 1),
    (b'H', 0),
    (b'D', 3),
    (b'D', 2),
    (b'D', 1),
    (b'D', 0),
    // D22..D29: port A in bit order.
    (b'A', 0),
    (b'A', 1),
    (b'A', 2),
    (b'A', 3),
    (b'A', 4),
    (b'A', 5),
    (b'A', 6),
    (b'A', 7),
    // D30..D37: port C in reverse bit order.
    (b'C', 7),
    (b'C', 6),
    (b'C', 5),
    (b'C', 4),
    (b'C', 3),
    (b'C', 2),
    (b'C', 1),
    (b'C', 0),
    // D38..D41.
    (b'D', 7),
    (b'G', 2),
    (b'G', 1),
    (b'G', 0),
    // D42..D49: port L in reverse bit order.
    (b'L', 7),
    (b'L', 6),
    (b'L', 5),
    (b'L', 4),
    (b'L', 3),
    (b'L', 2),
    (b'L', 1),
    (b'L', 0),
    // D50..D53: SPI MISO, MOSI, SCK, SS.
    (b'B', 3),
    (b'B', 2),
    (b'B', 1),
    (b'B', 0),
    // D54..D61 = A0..A7: port F.
    (b'F', 0),
    (b'F', 1),
    (b'F', 2),
    (b'F', 3),
    (b'F', 4),
    (b'F', 5),
    (b'F', 6),
    (b'F', 7),
    // D62..D69 = A8..A15: port K.
    (b'K', 0),
    (b'K', 1),
    (b'K', 2),
    (b'K', 3),
    (b'K', 4),
    (b'K', 5),
    (b'K', 6),
    (b'K', 7),
];

/// Port letter (`'A'`..`'L'`) and bit of a board pin, or `None` past D69.
pub fn port_bit(pin: u8) -> Option<(char, u8)> {
    MEGA.get(pin as usize)
        .map(|&(port, bit)| (port as char, bit))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_mega_pins() {
        let cases = [
            (0, ('E', 0)),
            (13, ('B', 7)),
            (26, ('A', 4)),
            (38, ('D', 7)),
            (46, ('L', 3)),
            (50, ('B', 3)),
            (51, ('B', 2)),
            (52, ('B', 1)),
            (53, ('B', 0)),
            (54, ('F', 0)),
            (60, ('F', 6)),
            (69, ('K', 7)),
        ];
        for (pin, want) in cases {
            assert_eq!(port_bit(pin), Some(want), "D{pin}");
        }
        assert_eq!(analog(6), 60);
        assert_eq!(port_bit(PIN_COUNT), None);
    }

    #[test]
    fn every_port_bit_used_once() {
        let mut seen = std::collections::HashSet::new();
        for pin in 0..PIN_COUNT {
            assert!(seen.insert(port_bit(pin).unwrap()), "D{pin} duplicated");
        }
    }
}
