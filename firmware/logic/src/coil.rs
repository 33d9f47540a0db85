//! A 28BYJ-48's coils on a ULN2003 board, half-stepped: eight states of
//! IN1..IN4 (`1000 1100 0100 0110 0010 0011 0001 1001`), one half-step
//! apart, each next to the last in exactly one input. The firmware writes
//! [`pattern`] of its phase; the simulator's decoder reads the inputs back
//! with [`phase_of`].

/// The inputs of phase `phase` (its low 3 bits), IN1 in bit 0. Worked out,
/// not a table (a table would sit in the AVR's SRAM): the even phases
/// drive one coil, the odd ones it and the next.
pub const fn pattern(phase: u8) -> u8 {
    let one = 1u8 << ((phase >> 1) & 3);
    match phase & 1 {
        0 => one,
        _ => one | (((one << 1) | (one >> 3)) & 0xF),
    }
}

/// The phase whose inputs are `inputs` (IN1 in bit 0), `None` for a
/// state not in the sequence (no coil, three or four, or two opposite).
pub fn phase_of(inputs: u8) -> Option<u8> {
    (0..8).find(|&p| pattern(p) == inputs)
}

/// The signed half-steps from phase `from` to phase `to` when they are
/// neighbours (or the same): `None` for a jump a motor cannot follow.
pub fn step_between(from: u8, to: u8) -> Option<i8> {
    match to.wrapping_sub(from) & 7 {
        0 => Some(0),
        1 => Some(1),
        7 => Some(-1),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sequence as the ULN2003 boards' sellers print it, IN1 first.
    #[test]
    fn the_half_step_sequence() {
        let seq = [
            "1000", "1100", "0100", "0110", "0010", "0011", "0001", "1001",
        ];
        for (p, s) in seq.iter().enumerate() {
            let bits = s
                .bytes()
                .enumerate()
                .fold(0, |acc, (i, c)| acc | (u8::from(c == b'1') << i));
            assert_eq!(pattern(p as u8), bits, "phase {p}");
            assert_eq!(phase_of(bits), Some(p as u8));
        }
        assert_eq!(pattern(8), pattern(0));
    }

    #[test]
    fn neighbours_differ_in_one_input_and_nothing_else_is_a_phase() {
        for p in 0..8u8 {
            let diff = pattern(p) ^ pattern(p + 1);
            assert_eq!(diff.count_ones(), 1, "{p} to {}", p + 1);
            assert_eq!(step_between(p, (p + 1) & 7), Some(1));
            assert_eq!(step_between((p + 1) & 7, p), Some(-1));
            assert_eq!(step_between(p, (p + 2) & 7), None);
        }
        let legal = (0..16u8).filter(|&b| phase_of(b).is_some()).count();
        assert_eq!(legal, 8);
        assert_eq!(phase_of(0), None);
        assert_eq!(phase_of(0b0101), None);
    }
}
