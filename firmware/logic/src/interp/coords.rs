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
    exact.map(|v| Milli(div_round(v, PER_MILLI).clamp(-(i32::MAX as i64), i32::MAX as i64) as i32))
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
