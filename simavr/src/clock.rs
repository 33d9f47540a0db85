//! Simulated time: the ATmega2560 of the Mega runs at 16 MHz, so one cycle
//! is 62.5 ns.

use std::time::Duration;

/// CPU clock of the simulated board.
pub const FREQ_HZ: u64 = 16_000_000;

/// Cycles in a simulated duration (rounded down).
pub fn cycles_in(d: Duration) -> u64 {
    (d.as_nanos() * FREQ_HZ as u128 / 1_000_000_000) as u64
}

/// The simulated duration of `cycles` (rounded up to whole nanoseconds,
/// so that `cycles_in` gives the cycles back).
pub fn duration_of(cycles: u64) -> Duration {
    let ns = (cycles as u128 * 1_000_000_000).div_ceil(FREQ_HZ as u128);
    Duration::from_nanos(ns as u64)
}

pub fn cycles_to_us(cycles: u64) -> f64 {
    cycles as f64 * 1e6 / FREQ_HZ as f64
}

/// Whole nanoseconds at a cycle (rounded down: cycles are 62.5 ns apart, so
/// distinct cycles stay distinct and `ns_to_cycles` finds them back).
pub fn cycles_to_ns(cycles: u64) -> u64 {
    (cycles as u128 * 1_000_000_000 / FREQ_HZ as u128) as u64
}

/// Nearest cycle to a time in nanoseconds.
pub fn ns_to_cycles(ns: u64) -> u64 {
    ((ns as u128 * FREQ_HZ as u128 + 500_000_000) / 1_000_000_000) as u64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conversions() {
        assert_eq!(cycles_in(Duration::from_millis(1)), 16_000);
        assert_eq!(cycles_to_us(16), 1.0);
        assert_eq!(cycles_to_ns(3), 187);
        for c in [0, 1, 3, 640_000_000, 640_000_001] {
            assert_eq!(cycles_in(duration_of(c)), c);
        }
        for c in [0, 1, 2, 3, 12_345_677, 16_000_000_001] {
            assert_eq!(ns_to_cycles(cycles_to_ns(c)), c);
        }
    }
}
