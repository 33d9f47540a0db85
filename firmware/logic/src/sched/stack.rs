//! Counting what the stack used of its painted region.

/// Bytes of stack ever used, from a region painted with `pattern` at boot.
///
/// `painted` runs from the lowest address (end of static RAM, the far end
/// of the downward-growing AVR stack) up to where painting stopped. Bytes
/// still holding the pattern at the low end were never reached; everything
/// from the first overwritten byte up counts as used. Only the deepest used
/// bytes, if they happen to equal the pattern, go uncounted: pick a pattern
/// unlikely as data (not 0x00 or 0xFF).
pub fn stack_high_water(painted: &[u8], pattern: u8) -> usize {
    let untouched = painted.iter().take_while(|&&b| b == pattern).count();
    painted.len() - untouched
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_from_the_first_overwritten_byte_up() {
        const P: u8 = 0xC5;
        assert_eq!(stack_high_water(&[P; 16], P), 0);
        let mut ram = [P; 16];
        ram[12..].copy_from_slice(&[1, 2, 3, 4]);
        assert_eq!(stack_high_water(&ram, P), 4);
        // A pattern-valued byte inside the used part still counts as used.
        ram[10] = 9;
        assert_eq!(stack_high_water(&ram, P), 6);
        assert_eq!(stack_high_water(&[0; 5], P), 5);
        assert_eq!(stack_high_water(&[], P), 0);
    }
}
