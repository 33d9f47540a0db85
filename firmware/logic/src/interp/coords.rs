//! Work coordinates: positions kept exactly, and the executor's view of
//! the coordinate data Grbl keeps in EEPROM (`settings_read_coord_data`,
//! [`crate::coords::CoordData`]): the six work systems `G54`–`G59`, then
//! the `G28` and `G30` positions.

use crate::axis::AXES;
use crate::coords::{CoordData, Slot};
use crate::kinematics::Position;
use crate::units::{div_round, Milli};

/// A position or offset per channel in millionths of its unit
/// (nanometres, or micro-degrees of the base): the programmed position
/// is kept in these, exactly as the words added up, and rounded to
/// steps once, from the absolute target.
pub type Exact = [i64; AXES];

/// Millionths per thousandth.
const PER_MILLI: i64 = 1000;

/// Grbl's coordinate data indices (the store's [`Slot`]s): `G54`…`G59`
/// are 0…5.
pub const G28: u8 = Slot::G28 as u8;
pub const G30: u8 = Slot::G30 as u8;

/// `exact` in thousandths (µm), each rounded once.
pub fn milli(exact: &Exact) -> Position {
    exact.map(|v| Milli(to_milli(v)))
}

/// Millionths to thousandths, rounded half away from zero, saturated.
/// Within ±4.29 m a product, not a 64-bit division (~700 cycles on the
/// AVR, a dozen a line of the arm's path).
pub fn to_milli(v: i64) -> i32 {
    const HALF: u64 = PER_MILLI as u64 / 2;
    let a = v.unsigned_abs();
    if a <= u32::MAX as u64 - HALF {
        // ⌊x / 1000⌋ for any 32-bit x: x · ⌈2^38 / 1000⌉ >> 38 (a
        // product, ~350 cycles; the division is ~600).
        let q = (((a + HALF) * 0x1062_4DD3) >> 38) as i32;
        return if v < 0 { -q } else { q };
    }
    div_round(v, PER_MILLI).clamp(-(i32::MAX as i64), i32::MAX as i64) as i32
}

/// `pos` (thousandths) as millionths.
pub fn exact(pos: &Position) -> Exact {
    pos.map(|m| m.0 as i64 * PER_MILLI)
}

/// Coordinate data `index` (Grbl's numbering) exactly.
pub fn stored(data: &CoordData, index: u8) -> Exact {
    Slot::at(index as usize).map_or([0; AXES], |s| exact(&data.get(s)))
}

/// Keeps `value` as coordinate data `index`, rounded once to the µm (as
/// the EEPROM keeps them).
pub fn store(data: &mut CoordData, index: u8, value: &Exact) {
    if let Some(s) = Slot::at(index as usize) {
        data.set(s, milli(value));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn wide(v: i64) -> i32 {
        div_round(v, PER_MILLI).clamp(-(i32::MAX as i64), i32::MAX as i64) as i32
    }

    #[test]
    fn thousandths_round_half_away_from_zero_at_the_edges() {
        let edge = (u32::MAX as i64) - 500;
        for v in [
            0,
            499,
            500,
            -500,
            -499,
            1500,
            -1500,
            edge,
            edge + 1,
            -edge,
            -edge - 1,
            i64::MAX,
            i64::MIN,
        ] {
            assert_eq!(to_milli(v), wide(v), "{v}");
        }
    }

    proptest! {
        #[test]
        fn thousandths_are_the_wide_rounding(v in any::<i64>(), small in -5_000_000_000i64..5_000_000_000) {
            prop_assert_eq!(to_milli(v), wide(v));
            prop_assert_eq!(to_milli(small), wide(small));
        }
    }
}
